//! Lagrange's impulsive equations at one state, seen from Python: a blow's components and the
//! state after it, constraints that engage suddenly, M(q)⁻¹, and the Jacobian of Python's
//! constraints by the core's central differences.

use nalgebra::DMatrix;
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::integrators::impulsive;
use varmech::solve::difference::{central_jacobian, unit, Evaluations};

use crate::bind::bind_model;
use crate::closure::readers::{call_array, call_vector};
use crate::convert::{matrix, rows, slice};
use crate::errors::model_error;
use crate::schedule::Kind;

type Array<'py> = Bound<'py, PyArray1<f64>>;

/// The blow of `kind` and `payload` (as in a run's impulses), checked on n coordinates.
fn blow_of(kind: &str, payload: &Bound<'_, PyAny>, n: usize) -> PyResult<Kind> {
    let blow =
        Kind::new(kind, payload)?.ok_or_else(|| PyValueError::new_err(format!("impulse: unknown kind {kind:?}")))?;
    if let Some(reason) = blow.blow().misfit(n) {
        return Err(PyValueError::new_err(format!("{}: {reason}", blow.argument())));
    }
    Ok(blow)
}

/// The components of impulse P(q) of a blow.
#[pyfunction]
fn impulse_components<'py>(
    py: Python<'py>,
    kind: &str,
    payload: &Bound<'py, PyAny>,
    q: PyReadonlyArray1<'py, f64>,
) -> PyResult<Array<'py>> {
    let q = slice("q", &q)?;
    let mut out = vec![0.0; q.len()];
    blow_of(kind, payload, q.len())?
        .blow()
        .components(q, &mut out)
        .map_err(model_error)?;
    Ok(PyArray1::from_vec(py, out))
}

/// The state just after a blow at (q, p) at time t: p⁺, q̇⁺, q̇⁻ and T⁺ − T⁻.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn impulse_response<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: f64,
    q: PyReadonlyArray1<'py, f64>,
    p: PyReadonlyArray1<'py, f64>,
    kind: &str,
    payload: &Bound<'py, PyAny>,
) -> PyResult<(Array<'py>, Array<'py>, Array<'py>, f64)> {
    let (q, p) = (slice("q", &q)?, slice("p", &p)?);
    let blow = blow_of(kind, payload, q.len())?;
    let blow = &blow;
    let response = bind_model(py, model, |sys, _| {
        impulsive::respond(sys.as_lagrangian(), t, (q, p), blow.blow().as_ref())
    })?
    .map_err(model_error)?;
    Ok((
        PyArray1::from_vec(py, response.p),
        PyArray1::from_vec(py, response.v),
        PyArray1::from_vec(py, response.v_before),
        response.kinetic_change,
    ))
}

/// The state just after the constraints A(q)q̇ = 0 (`a`, (m, n)) engage at (q, p) at time t:
/// p⁺, q̇⁺, λ, T⁻ − T⁺ and Carnot's term; dependent constraints are a ValueError naming
/// `argument`, the user's name for A.
#[pyfunction]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
fn engage<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: f64,
    q: PyReadonlyArray1<'py, f64>,
    p: PyReadonlyArray1<'py, f64>,
    a: PyReadonlyArray2<'py, f64>,
    argument: &str,
) -> PyResult<(Array<'py>, Array<'py>, Array<'py>, f64, f64)> {
    let (q, p) = (slice("q", &q)?, slice("p", &p)?);
    let (data, n) = rows(argument, &a)?;
    let a = DMatrix::from_row_slice(data.len() / n.max(1), n, data);
    let a = &a;
    let engaged = bind_model(py, model, |sys, _| impulsive::engage(sys.as_lagrangian(), t, (q, p), a))?
        .map_err(model_error)?
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "{argument}: the constraints are dependent here (A M⁻¹ Aᵀ is singular)"
            ))
        })?;
    Ok((
        PyArray1::from_vec(py, engaged.p),
        PyArray1::from_vec(py, engaged.v),
        PyArray1::from_vec(py, engaged.multipliers),
        engaged.energy_lost,
        engaged.carnot,
    ))
}

/// M(q)⁻¹ at time t.
#[pyfunction]
fn inverse_mass<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: PyReadonlyArray1<'py, f64>,
    t: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q = slice("q", &q)?;
    let minv =
        bind_model(py, model, |sys, _| impulsive::inverse_mass(sys.as_lagrangian(), q, t))?.map_err(model_error)?;
    matrix(py, minv.transpose().as_slice().to_vec(), q.len())
}

/// ∂g/∂q (m, n) of Python's g(q) → (m,) by central differences (`call` names g in errors).
#[pyfunction]
fn central_differences<'py>(
    py: Python<'py>,
    g: &Bound<'py, PyAny>,
    q: PyReadonlyArray1<'py, f64>,
    call: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q = slice("q", &q)?;
    let evaluate = |y: &[f64], out: &mut [f64]| call_vector(g.call1((PyArray1::from_slice(py, y),)), call, out);
    let first = g.call1((PyArray1::from_slice(py, q),))?;
    let m = first
        .len()
        .map_err(|_| PyValueError::new_err(format!("{call}: must return a 1-d array")))?;
    let mut scratch = vec![0.0; m];
    call_array(Ok(first), call, &[m], &mut scratch).map_err(model_error)?;
    let (mut jac, mut plus, mut minus) = (DMatrix::zeros(m, q.len()), vec![0.0; m], vec![0.0; m]);
    let at = Evaluations {
        plus: &mut plus,
        minus: &mut minus,
    };
    central_jacobian(evaluate, &mut q.to_vec(), unit, at, &mut jac).map_err(model_error)?;
    matrix(py, jac.transpose().as_slice().to_vec(), q.len())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(
        m,
        [
            impulse_components,
            impulse_response,
            engage,
            inverse_mass,
            central_differences
        ]
    );
    Ok(())
}
