//! Small oscillations: equilibria, the linearized equations and their normal modes at a point,
//! on holonomic constraints too, the fastest frequency there, and the step a method takes on
//! them ([`varmech::diagnostics`]'s `modes`).

use nalgebra::{Complex, DMatrix};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::diagnostics::{self, Equilibrium, Linearization, Model, Modes, Shapes};
use varmech::integrators::{self, NewtonOptions};
use varmech::model::{Fastest, Rest};
use varmech::{Error, ModelError};

use crate::bind::{bind_model, dim_of};
use crate::convert::{self, slice};
use crate::errors::{model_error, to_pyerr};
use crate::generator::{generators, Generator};

/// A matrix as a NumPy array (row-major).
fn array<'py>(py: Python<'py>, m: &DMatrix<f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    convert::matrix(py, m.transpose().as_slice().to_vec(), m.ncols())
}

/// `body` on the model at q (its dimension checked): its Lagrangian and holonomic constraints
/// (`Model::of`, which refuses velocity constraints).
fn on_model<R: Send>(
    model: &Bound<'_, PyAny>,
    q: &PyReadonlyArray1<'_, f64>,
    name: &str,
    body: impl for<'s> FnOnce(Model<'s>, &[f64]) -> R + Send,
) -> PyResult<R> {
    let py = model.py();
    let q = point(model, q, name)?;
    let found: Result<R, Error> = bind_model(py, model, |sys, _poll| Ok(body(Model::of(sys)?, q)))?;
    found.map_err(|e| to_pyerr(py, e))
}

/// The point `q` (the argument `name`), of the model's dimension.
fn point<'a>(model: &Bound<'_, PyAny>, q: &'a PyReadonlyArray1<'_, f64>, name: &str) -> PyResult<&'a [f64]> {
    let n = dim_of(model.py(), model)?;
    let q = slice(name, q)?;
    if q.len() != n {
        return Err(PyValueError::new_err(format!(
            "{name}: has length {}, the model has dim = {n}",
            q.len()
        )));
    }
    Ok(q)
}

/// The linearized equations at (q, q̇ = 0, t) in the tangent coordinates: (M, K, G, D, T, λ).
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
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let py = model.py();
    let linear: Result<Linearization, ModelError> = on_model(model, &q, "q", |m, q| diagnostics::linearize(m, q, t))?;
    let l = linear.map_err(model_error)?;
    Ok((
        array(py, &l.mass)?,
        array(py, &l.stiffness)?,
        array(py, &l.gyroscopic)?,
        array(py, &l.damping)?,
        array(py, &l.basis)?,
        PyArray1::from_vec(py, l.multipliers),
    ))
}

/// The normal modes at (q, t), the zero modes named after `symmetries` (the model's generators):
/// (frequencies, growth, curvatures, inertia, shapes (real or complex, n × r), the index of the
/// symmetry of each mode or None).
#[pyfunction]
#[pyo3(signature = (model, q, t=0.0, symmetries=Vec::new()))]
#[allow(clippy::type_complexity)]
fn normal_modes<'py>(
    model: &Bound<'py, PyAny>,
    q: PyReadonlyArray1<'py, f64>,
    t: f64,
    symmetries: Vec<Generator>,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    [usize; 3],
    Bound<'py, PyAny>,
    Vec<Option<usize>>,
)> {
    let py = model.py();
    let symmetries = generators(symmetries, dim_of(py, model)?)?;
    let modes: Result<Modes, ModelError> = on_model(model, &q, "q", |m, q| {
        let fields: Vec<Vec<f64>> = symmetries
            .iter()
            .map(|g| {
                let mut xi = vec![0.0; q.len()];
                g.field(q, &mut xi);
                xi
            })
            .collect();
        let linear = diagnostics::linearize(m, q, t)?;
        let mut modes = diagnostics::modes(&linear)?;
        modes.name_symmetries(&linear, &fields);
        Ok(modes)
    })?;
    let modes = modes.map_err(model_error)?;
    let shapes = match &modes.shapes {
        Shapes::Real(s) => array(py, s)?.into_any(),
        Shapes::Complex(s) => complex_array(py, s)?.into_any(),
    };
    Ok((
        PyArray1::from_vec(py, modes.frequencies),
        PyArray1::from_vec(py, modes.growth),
        PyArray1::from_vec(py, modes.curvatures),
        modes.inertia,
        shapes,
        modes.symmetries,
    ))
}

/// A complex matrix as a NumPy array (row-major).
fn complex_array<'py>(py: Python<'py>, m: &DMatrix<Complex<f64>>) -> PyResult<Bound<'py, PyArray2<Complex<f64>>>> {
    PyArray1::from_vec(py, m.transpose().as_slice().to_vec()).reshape([m.nrows(), m.ncols()])
}

/// The equilibrium nearest `guess` at time t: (q, λ, residual, iterations).
#[pyfunction]
#[pyo3(signature = (model, guess, t=0.0, newton_tolerance=1e-14, newton_max_iterations=50))]
#[allow(clippy::type_complexity)]
fn equilibrium<'py>(
    model: &Bound<'py, PyAny>,
    guess: PyReadonlyArray1<'py, f64>,
    t: f64,
    newton_tolerance: f64,
    newton_max_iterations: usize,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, f64, usize)> {
    let py = model.py();
    let options = NewtonOptions {
        tolerance: newton_tolerance,
        max_iterations: newton_max_iterations,
    };
    let found: Result<Equilibrium, Error> = on_model(model, &guess, "guess", |m, guess| {
        diagnostics::equilibrium(m, guess, t, &options)
    })?;
    let found = found.map_err(|e| to_pyerr(py, e))?;
    Ok((
        PyArray1::from_vec(py, found.q),
        PyArray1::from_vec(py, found.multipliers),
        found.residual,
        found.iterations,
    ))
}

/// The fastest frequency of the small oscillations at (q, t), by Lanczos: (ω_max, iterations,
/// converged).
#[pyfunction]
#[pyo3(signature = (model, q, t=0.0))]
fn fastest_frequency<'py>(
    model: &Bound<'py, PyAny>,
    q: PyReadonlyArray1<'py, f64>,
    t: f64,
) -> PyResult<(f64, usize, bool)> {
    let found: Result<Fastest, ModelError> = on_model(model, &q, "q", |m, q| m.fastest(q, t))?;
    let found = found.map_err(model_error)?;
    Ok((found.omega, found.iterations, found.converged))
}

/// (h·ω_max, the limit, ω_max) where a step `dt` of `method` at (q, t) is beyond its stability
/// limit ([`varmech::integrators::beyond_limit`], the check before a run), else None.
#[pyfunction]
#[pyo3(signature = (model, method, q, dt, t=0.0))]
fn beyond_limit<'py>(
    model: &Bound<'py, PyAny>,
    method: &Bound<'py, PyAny>,
    q: PyReadonlyArray1<'py, f64>,
    dt: f64,
    t: f64,
) -> PyResult<Option<(f64, f64, f64)>> {
    let py = model.py();
    let method = convert::method(method)?;
    let q = point(model, &q, "q")?;
    let found = bind_model(py, model, |sys, _poll| {
        integrators::beyond_limit(sys, (method, dt), (q, t), Rest::BEFORE_RUN)
    })?;
    Ok(found.map_err(model_error)?.map(|b| (b.h_omega, b.limit, b.omega)))
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
    add_functions!(
        m,
        [
            linearize,
            normal_modes,
            equilibrium,
            fastest_frequency,
            beyond_limit,
            stable_step,
            accurate_step
        ]
    );
    Ok(())
}
