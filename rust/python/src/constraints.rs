//! Holonomic and velocity constraints seen from Python: residuals of saved states, and
//! projection of an initial state onto the constraints.

use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::model::{Reactions, Residuals};
use varmech::ModelError;

use crate::bind::{bind_model, dim_of};
use crate::convert::{matrix, rows, slice, states, ArrayPair};
use crate::errors::{model_error, to_pyerr};

fn unconstrained() -> PyErr {
    PyValueError::new_err("model: has no holonomic constraints (nor velocity constraints)")
}

/// |g(q)|∞, |G(q)M⁻¹p|∞ and their sizes ‖G‖∞‖q‖∞, ‖G‖∞‖M⁻¹p‖∞ at each state of a constrained
/// model; 0, |A(q)q̇|∞, 0 and ‖A‖∞‖q̇‖∞ with velocity constraints.
#[pyfunction]
fn constraint_residuals<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
) -> PyResult<(ArrayPair<'py>, ArrayPair<'py>)> {
    let n = dim_of(py, model)?;
    let ((q, nq), (p, np)) = (rows("q", &q)?, rows("p", &p)?);
    if nq != n || np != n || q.len() != p.len() {
        return Err(PyValueError::new_err(format!(
            "q, p: need two (N, {n}) arrays of states"
        )));
    }
    let result: Option<Result<Vec<Residuals>, ModelError>> = bind_model(py, model, |sys, _poll| {
        q.chunks_exact(n)
            .zip(p.chunks_exact(n))
            .map(|(q, p)| sys.constraint_residuals(q, p))
            .collect()
    })?;
    let residuals = result.ok_or_else(unconstrained)?.map_err(model_error)?;
    let column = |f: fn(&Residuals) -> f64| PyArray1::from_vec(py, residuals.iter().map(f).collect());
    Ok((
        (column(|r| r.position), column(|r| r.velocity)),
        (column(|r| r.position_size), column(|r| r.velocity_size)),
    ))
}

/// The multipliers λ (N, m), the generalized constraint forces Cᵀλ (N, n), their power and its
/// size (N,) at each state (t, q, p) of a constrained model ([`varmech::model::Reactions`]).
type ReactionArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, ArrayPair<'py>);

#[pyfunction]
fn reactions<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
) -> PyResult<ReactionArrays<'py>> {
    let n = dim_of(py, model)?;
    let (t, q, p) = states(n, &t, &q, &p)?;
    let result: Option<Result<Reactions, ModelError>> = bind_model(py, model, |sys, _poll| sys.reactions(t, q, p))?;
    let r = result.ok_or_else(unconstrained)?.map_err(model_error)?;
    let m = r.multipliers.len().checked_div(t.len()).unwrap_or(0);
    Ok((
        matrix(py, r.multipliers, m)?,
        matrix(py, r.force, n)?,
        (PyArray1::from_vec(py, r.power), PyArray1::from_vec(py, r.power_size)),
    ))
}

/// The nearest consistent state (q on the constraints, p on the hidden constraint; with velocity
/// constraints q as it is, p on A(q)q̇ = 0).
#[pyfunction]
fn project<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q0: PyReadonlyArray1<'py, f64>,
    p0: PyReadonlyArray1<'py, f64>,
) -> PyResult<ArrayPair<'py>> {
    let (q0, p0) = (slice("q0", &q0)?, slice("p0", &p0)?);
    let result = bind_model(py, model, |sys, _poll| sys.project(q0, p0))?;
    let (q, p) = result.ok_or_else(unconstrained)?.map_err(|e| to_pyerr(py, e))?;
    Ok((PyArray1::from_vec(py, q), PyArray1::from_vec(py, p)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(m, [constraint_residuals, project, reactions]);
    Ok(())
}
