//! A stepper of a Python model: the core's [`StepperState`] kept between calls and resumed on
//! the model, through the one dispatch [`bind_model`], for each call.

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use varmech::integrators::{self, Checkpoint, Dynamics, Method, NewtonOptions, Options, StepperState};
use varmech::Error;

use crate::bind::{bind_model, Poll};
use crate::convert::{self, slice};
use crate::errors::to_pyerr;
use crate::run::decode;

/// One model, one method and the state, advanced step by step
/// ([`varmech::integrators::Stepper`]): native models with the GIL released, Ctrl-C honoured
/// by `advance`, and a failed step leaves the last good state.
///
/// A call holds the stepper mutably (pyo3's borrow flag, not a lock): another call while one
/// runs (a thread while the GIL is released, a closure model re-entering) raises RuntimeError
/// rather than wait on a lock that the running call's Ctrl-C poll, which takes the GIL, could
/// deadlock against.
#[pyclass(module = "varmech._core")]
pub struct Stepper {
    model: Py<PyAny>,
    state: StepperState,
}

type Core<'s, 'a> = integrators::Stepper<&'s dyn Dynamics, &'a mut StepperState>;

impl Stepper {
    /// Runs `body` on the state resumed on the model; the state stays put whatever happens.
    fn with<R, F>(&mut self, py: Python<'_>, body: F) -> PyResult<R>
    where
        R: Send,
        F: for<'s, 'a> FnOnce(&mut Core<'s, 'a>, Poll<'s>) -> Result<R, Error> + Send,
    {
        let Stepper { model, state } = self;
        bind_model(py, model.bind(py), |sys, poll| {
            body(&mut integrators::Stepper::resume(sys, state)?, poll)
        })?
        .map_err(|e| to_pyerr(py, e))
    }
}

#[pymethods]
impl Stepper {
    #[new]
    #[pyo3(signature = (model, q0, p0, *, dt, method, t0=0.0, compensated=true, newton_tolerance=1e-14, newton_max_iterations=50))]
    #[allow(clippy::too_many_arguments)]
    fn new<'py>(
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
        q0: PyReadonlyArray1<'py, f64>,
        p0: PyReadonlyArray1<'py, f64>,
        dt: f64,
        #[pyo3(from_py_with = convert::method)] method: Method,
        t0: f64,
        compensated: bool,
        newton_tolerance: f64,
        newton_max_iterations: usize,
    ) -> PyResult<Self> {
        let options = Options {
            compensated,
            t0,
            newton: NewtonOptions {
                tolerance: newton_tolerance,
                max_iterations: newton_max_iterations,
            },
            ..Options::new(dt, 0)
        };
        let (q0, p0) = (slice("q0", &q0)?, slice("p0", &p0)?);
        let state = bind_model(py, model, |sys, _| {
            integrators::Stepper::new(sys, method, q0, p0, &options).map(integrators::Stepper::into_state)
        })?
        .map_err(|e| to_pyerr(py, e))?;
        Ok(Stepper {
            model: model.clone().unbind(),
            state,
        })
    }

    /// The stepper's whole state as bytes, with its model's fingerprint (see [`Checkpoint`]).
    fn checkpoint<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self.with(py, |stepper, _| Ok(Checkpoint::of(stepper.model(), stepper).to_bytes()))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// The stepper of `model` at the state of `checkpoint` (from `checkpoint()`, or a run's),
    /// checked against the model (and `method` and `dt` where given).
    #[staticmethod]
    #[pyo3(signature = (model, checkpoint, *, method=None, dt=None))]
    fn from_checkpoint<'py>(
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
        checkpoint: &[u8],
        method: Option<&str>,
        dt: Option<f64>,
    ) -> PyResult<Self> {
        let checkpoint = decode(py, checkpoint, method, dt)?;
        let state = bind_model(py, model, |sys, _| {
            let state = checkpoint.into_state(sys)?;
            integrators::Stepper::resume(sys, state).map(integrators::Stepper::into_state)
        })?
        .map_err(|e| to_pyerr(py, e))?;
        Ok(Stepper {
            model: model.clone().unbind(),
            state,
        })
    }

    /// Advances one step.
    fn step(&mut self, py: Python<'_>) -> PyResult<()> {
        self.with(py, |stepper, _| stepper.step())
    }

    /// Advances `n` steps, checking for Ctrl-C on the way.
    fn advance(&mut self, py: Python<'_>, n: usize) -> PyResult<()> {
        self.with(py, |stepper, poll| stepper.advance(n, poll))
    }

    /// Starts afresh from (q0, p0) at t0, with the step count at 0.
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        q0: PyReadonlyArray1<'py, f64>,
        p0: PyReadonlyArray1<'py, f64>,
        t0: f64,
    ) -> PyResult<()> {
        let (q0, p0) = (slice("q0", &q0)?, slice("p0", &p0)?);
        self.with(py, |stepper, _| stepper.reset(t0, q0, p0))
    }

    #[getter]
    fn t(&self) -> f64 {
        self.state.t()
    }

    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.state.q())
    }

    #[getter]
    fn p<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.state.p())
    }

    #[getter]
    fn steps(&self) -> usize {
        self.state.steps()
    }

    #[getter]
    fn dt(&self) -> f64 {
        self.state.dt()
    }

    #[setter]
    fn set_dt(&mut self, py: Python<'_>, dt: f64) -> PyResult<()> {
        self.with(py, |stepper, _| stepper.set_dt(dt))
    }

    #[getter]
    fn method(&self) -> &'static str {
        self.state.method().info().name
    }

    #[getter]
    fn force_evaluations(&self) -> u64 {
        self.state.force_evaluations()
    }

    #[getter]
    fn newton_iterations(&self) -> u64 {
        self.state.newton_iterations()
    }

    #[getter]
    fn work(&self) -> f64 {
        self.state.work()
    }
}
