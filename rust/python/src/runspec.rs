//! A run's specification as Python's `RunSpec` gives it (python/varmech/_runspec.py): the one
//! argument beside the model and its state that `integrate`, `ensemble`, `resume` and the
//! `Stepper` take, its counts and method converted once, its jumps as Python's tuples. A new kind
//! of jump is a field here.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::integrators::{Checkpoint, Method, NewtonOptions, Options};

use crate::contacts::{ContactSpecs, ContactTuple};
use crate::convert;
use crate::errors::to_pyerr;
use crate::events::EventTuple;
use crate::run::{newton_max_iterations_count, save_every_count, steps_count};
use crate::schedule::{ImpulseTuple, ScheduleSpecs};

/// How a run goes: a new one's method, step and options, or a continued one's (its method and
/// `dt`, if given, checked against the checkpoint, whose own state sets the rest), and what it
/// watches and applies: `events`, `contacts`, `impulses` and the samples `t_eval`.
#[pyclass(frozen, module = "varmech._core")]
pub struct RunSpec {
    method: Option<Method>,
    dt: Option<f64>,
    pub steps: usize,
    pub save_every: usize,
    compensated: bool,
    max_energy_error: Option<f64>,
    keep_energy_check: bool,
    t0: f64,
    newton: NewtonOptions,
    events: Option<Py<PyAny>>,
    contacts: Option<Py<PyAny>>,
    impulses: Option<Py<PyAny>>,
    t_eval: Vec<f64>,
}

#[pymethods]
impl RunSpec {
    #[new]
    #[pyo3(signature = (*, method=None, dt=None, steps=0, save_every=1, compensated=true, max_energy_error=None, keep_energy_check=true, t0=0.0, newton_tolerance=1e-14, newton_max_iterations=50, events=None, contacts=None, impulses=None, t_eval=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        #[pyo3(from_py_with = optional_method)] method: Option<Method>,
        dt: Option<f64>,
        #[pyo3(from_py_with = steps_count)] steps: usize,
        #[pyo3(from_py_with = save_every_count)] save_every: usize,
        compensated: bool,
        max_energy_error: Option<f64>,
        keep_energy_check: bool,
        t0: f64,
        newton_tolerance: f64,
        #[pyo3(from_py_with = newton_max_iterations_count)] newton_max_iterations: usize,
        events: Option<Py<PyAny>>,
        contacts: Option<Py<PyAny>>,
        impulses: Option<Py<PyAny>>,
        t_eval: Option<Vec<f64>>,
    ) -> Self {
        RunSpec {
            method,
            dt,
            steps,
            save_every,
            compensated,
            max_energy_error,
            keep_energy_check,
            t0,
            newton: NewtonOptions {
                tolerance: newton_tolerance,
                max_iterations: newton_max_iterations,
            },
            events,
            contacts,
            impulses,
            t_eval: t_eval.unwrap_or_default(),
        }
    }
}

impl RunSpec {
    /// A new run's method and [`Options`]; refused without a method and a step (a continued
    /// run's spec).
    pub fn options(&self) -> PyResult<(Method, Options)> {
        let (Some(method), Some(dt)) = (self.method, self.dt) else {
            return Err(PyValueError::new_err("spec: a new run needs its method and dt"));
        };
        let options = Options {
            dt,
            steps: self.steps,
            save_every: self.save_every,
            compensated: self.compensated,
            max_energy_error: self.max_energy_error,
            t0: self.t0,
            newton: self.newton,
        };
        Ok((method, options))
    }

    /// The checkpoint in `bytes` that a continued run goes on from, refused unless of the spec's
    /// method and dt where given, with the spec's energy check unless it keeps its own.
    pub fn checkpoint(&self, py: Python<'_>, bytes: &[u8]) -> PyResult<Checkpoint> {
        let mut checkpoint = Checkpoint::from_bytes(bytes).map_err(|e| to_pyerr(py, e))?;
        checkpoint.expect(self.method, self.dt).map_err(|e| to_pyerr(py, e))?;
        if !self.keep_energy_check {
            checkpoint.check_energy(self.max_energy_error);
        }
        Ok(checkpoint)
    }

    /// The events' tuples, if any.
    pub fn events<'py>(&self, py: Python<'py>) -> PyResult<Option<Vec<EventTuple<'py>>>> {
        self.events.as_ref().map(|e| e.bind(py).extract()).transpose()
    }

    /// The contacts, if any, checked.
    pub fn contacts(&self, py: Python<'_>) -> PyResult<Option<ContactSpecs>> {
        let tuples: Option<Vec<ContactTuple<'_>>> = self.contacts.as_ref().map(|c| c.bind(py).extract()).transpose()?;
        tuples.map(ContactSpecs::new).transpose()
    }

    /// The impulses and the samples `t_eval`, checked.
    pub fn schedule(&self, py: Python<'_>) -> PyResult<ScheduleSpecs> {
        let impulses: Option<Vec<ImpulseTuple<'_>>> =
            self.impulses.as_ref().map(|i| i.bind(py).extract()).transpose()?;
        ScheduleSpecs::new(impulses.unwrap_or_default(), self.t_eval.clone())
    }

    /// The samples `t_eval`.
    pub fn t_eval(&self) -> &[f64] {
        &self.t_eval
    }
}

/// A method's name, or None.
fn optional_method(x: &Bound<'_, PyAny>) -> PyResult<Option<Method>> {
    if x.is_none() {
        return Ok(None);
    }
    convert::method(x).map(Some)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<RunSpec>()
}
