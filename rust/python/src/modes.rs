//! Small oscillations: equilibria, the linearized equations and their normal modes at a point,
//! and the step a method takes on them ([`varmech::diagnostics`]'s `modes`).

use nalgebra::DMatrix;
use numpy::{PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::diagnostics::{self, Equilibrium, Linearization, Modes};
use varmech::integrators::Dynamics;
use varmech::integrators::NewtonOptions;
use varmech::{Error, ModelError};

use crate::bind::{bind_model, dim_of};
use crate::convert::{self, slice};
use crate::errors::{model_error, to_pyerr};

/// A square matrix as a NumPy array (row-major).
fn array<'py>(py: Python<'py>, m: &DMatrix<f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    convert::matrix(py, m.transpose().as_slice().to_vec(), m.ncols())
}

/// `body` on the model's Lagrangian at q (its dimension checked), for the models that have
/// no constraints of their own.
fn on_model<R: Send>(
    model: &Bound<'_, PyAny>,
    q: &PyReadonlyArray1<'_, f64>,
    name: &str,
    body: impl for<'s> FnOnce(&'s dyn Dynamics, &[f64]) -> R + Send,
) -> PyResult<R> {
    let py = model.py();
    let n = dim_of(py, model)?;
    let q = slice(name, q)?;
    if q.len() != n {
        return Err(PyValueError::new_err(format!(
            "{name}: has length {}, the model has dim = {n}",
            q.len()
        )));
    }
    bind_model(py, model, |sys, _poll| {
        if sys.constraint_counts() != (0, 0) || sys.velocity_constraints().is_some() {
            return Err(PyValueError::new_err(
                "model: a constrained model's small oscillations are not linearized on its constraints yet; \
                 write the model in coordinates that satisfy them (the fewest coordinates)",
            ));
        }
        Ok(body(sys, q))
    })?
}

/// The linearized equations at (q, q̇ = 0, t): (M, K, G, D), each (n, n).
#[pyfunction]
#[pyo3(signature = (model, q, t=0.0))]
#[allow(clippy::type_complexity)]
fn linearize<'py>(
    model: &Bound<'py, PyAny>,
    q: PyReadonlyArray1<'py, f64>,
    t: f64,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
)> {
    let py = model.py();
    let linear: Result<Linearization, ModelError> = on_model(model, &q, "q", |sys, q| {
        diagnostics::linearize(sys.as_lagrangian(), q, t)
    })?;
    let l = linear.map_err(model_error)?;
    Ok((
        array(py, &l.mass)?,
        array(py, &l.stiffness)?,
        array(py, &l.gyroscopic)?,
        array(py, &l.damping)?,
    ))
}

/// The normal modes at (q, t): (frequencies, growth, curvatures, inertia, shapes or None).
#[pyfunction]
#[pyo3(signature = (model, q, t=0.0))]
#[allow(clippy::type_complexity)]
fn normal_modes<'py>(
    model: &Bound<'py, PyAny>,
    q: PyReadonlyArray1<'py, f64>,
    t: f64,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    [usize; 3],
    Option<Bound<'py, PyArray2<f64>>>,
)> {
    let py = model.py();
    let modes: Result<Modes, ModelError> = on_model(model, &q, "q", |sys, q| {
        diagnostics::modes(&diagnostics::linearize(sys.as_lagrangian(), q, t)?)
    })?;
    let modes = modes.map_err(model_error)?;
    let shapes = modes.shapes.as_ref().map(|s| array(py, s)).transpose()?;
    Ok((
        PyArray1::from_vec(py, modes.frequencies),
        PyArray1::from_vec(py, modes.growth),
        PyArray1::from_vec(py, modes.curvatures),
        modes.inertia,
        shapes,
    ))
}

/// The equilibrium nearest `guess` at time t: (q, residual, iterations).
#[pyfunction]
#[pyo3(signature = (model, guess, t=0.0, newton_tolerance=1e-14, newton_max_iterations=50))]
fn equilibrium<'py>(
    model: &Bound<'py, PyAny>,
    guess: PyReadonlyArray1<'py, f64>,
    t: f64,
    newton_tolerance: f64,
    newton_max_iterations: usize,
) -> PyResult<(Bound<'py, PyArray1<f64>>, f64, usize)> {
    let py = model.py();
    let options = NewtonOptions {
        tolerance: newton_tolerance,
        max_iterations: newton_max_iterations,
    };
    let found: Result<Equilibrium, Error> = on_model(model, &guess, "guess", |sys, guess| {
        diagnostics::equilibrium(sys.as_lagrangian(), guess, t, &options)
    })?;
    let found = found.map_err(|e| to_pyerr(py, e))?;
    Ok((PyArray1::from_vec(py, found.q), found.residual, found.iterations))
}

/// The largest stable step of `method` on frequencies up to `omega_max`.
#[pyfunction]
fn stable_step(method: &Bound<'_, PyAny>, omega_max: f64) -> PyResult<f64> {
    diagnostics::stable_step(convert::method(method)?, omega_max).map_err(|e| to_pyerr(method.py(), e))
}

/// The largest step of `method` with a phase error per period of at most `accuracy` on
/// frequencies up to `omega_max`.
#[pyfunction]
fn accurate_step(method: &Bound<'_, PyAny>, omega_max: f64, accuracy: f64) -> PyResult<f64> {
    let py = method.py();
    let method = convert::method(method)?;
    py.detach(|| diagnostics::accurate_step(method, omega_max, accuracy))
        .map_err(|e| to_pyerr(py, e))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(linearize, m)?)?;
    m.add_function(wrap_pyfunction!(normal_modes, m)?)?;
    m.add_function(wrap_pyfunction!(equilibrium, m)?)?;
    m.add_function(wrap_pyfunction!(stable_step, m)?)?;
    m.add_function(wrap_pyfunction!(accurate_step, m)?)?;
    Ok(())
}
