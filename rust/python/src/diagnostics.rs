//! Diagnostics of saved states: the energy function, first derivatives of L, Noether momenta,
//! and statistics of conserved quantities.

use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use varmech::diagnostics::{EnergyStatistics, InvariantStatistics};
use varmech::model;
use varmech::ModelError;

use crate::bind::{bind_model, dim_of};
use crate::convert::{self, rows, slice, states};
use crate::errors::{model_error, to_pyerr};
use crate::generator::Generator;

/// The energy function E = p·q̇ − L (= ½pᵀM⁻¹p + V for mechanical systems) at each state.
#[pyfunction]
fn energy<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let n = dim_of(py, model)?;
    let (t, q, p) = states(n, &t, &q, &p)?;
    let result: Result<Vec<f64>, ModelError> = bind_model(py, model, |sys, _poll| {
        let l = sys.as_lagrangian();
        t.iter()
            .zip(q.chunks_exact(n).zip(p.chunks_exact(n)))
            .map(|(t, (q, p))| l.energy(q, p, *t))
            .collect()
    })?;
    Ok(PyArray1::from_vec(py, result.map_err(model_error)?))
}

/// A first derivative of L at each state (t, q, x): `"momentum"`, p = ∂L/∂q̇(q, x, t) from
/// velocities x (Mq̇ for mechanical systems); `"velocity"`, the inverse Legendre transform,
/// q̇ with ∂L/∂q̇ = x from momenta x (M⁻¹p); `"dl_dq"`, ∂L/∂q(q, x, t) from velocities x.
#[pyfunction]
fn derivative<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    what: &str,
    t: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    x: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    if !matches!(what, "momentum" | "velocity" | "dl_dq") {
        return Err(PyValueError::new_err(format!(
            "what: expected \"momentum\", \"velocity\" or \"dl_dq\", got {what:?}"
        )));
    }
    let n = dim_of(py, model)?;
    let (t, q, x) = states(n, &t, &q, &x)?;
    let result: Result<Vec<f64>, ModelError> = bind_model(py, model, |sys, _poll| {
        let l = sys.as_lagrangian();
        let mut y = vec![0.0; x.len()];
        let mut rows = t
            .iter()
            .zip(q.chunks_exact(n).zip(x.chunks_exact(n)))
            .zip(y.chunks_exact_mut(n));
        rows.try_for_each(|((t, (q, x)), y)| match what {
            "velocity" => l.velocity(q, x, *t, y),
            "momentum" => l.dl_dv(q, x, *t, y),
            _ => l.dl_dq(q, x, *t, y),
        })
        .map(|()| y)
    })?;
    Ok(convert::matrix(py, result.map_err(model_error)?, n)?.into_any())
}

/// J = p·ξ(q) of a generator for each row of (q, p).
#[pyfunction]
fn momentum<'py>(
    py: Python<'py>,
    generator: Generator,
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let g = model::Generator::from(generator);
    let ((q, n), (p, _)) = (rows("q", &q)?, rows("p", &p)?);
    g.check(n).map_err(|e| to_pyerr(py, e))?;
    let j = q
        .chunks_exact(n.max(1))
        .zip(p.chunks_exact(n.max(1)))
        .map(|(q, p)| g.momentum(q, p))
        .collect();
    Ok(PyArray1::from_vec(py, j))
}

/// The energy statistics of a series, as a dict.
#[pyfunction]
fn energy_statistics<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    h: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let (t, h) = (slice("t", &t)?, slice("energy", &h)?);
    if t.len() != h.len() || t.is_empty() {
        return Err(PyValueError::new_err("energy: needs one value per time, at least one"));
    }
    let s = EnergyStatistics::new(t, h);
    let d = PyDict::new(py);
    d.set_item("initial", s.initial)?;
    d.set_item("max_error", s.max_error)?;
    d.set_item("band", s.band)?;
    d.set_item("max_error_first_tenth", s.max_error_first_tenth)?;
    d.set_item("max_error_last_tenth", s.max_error_last_tenth)?;
    d.set_item("drift_rate", s.drift_rate)?;
    d.set_item("drift_rate_stderr", s.drift_rate_stderr)?;
    d.set_item("verdict", s.verdict.to_string())?;
    d.set_item("noise_floor", EnergyStatistics::NOISE_FLOOR)?;
    Ok(d)
}

/// (initial, max_abs_error, max_rel_error) of a conserved quantity's series.
#[pyfunction]
fn invariant_statistics(values: PyReadonlyArray1<'_, f64>) -> PyResult<(f64, f64, f64)> {
    let s = InvariantStatistics::new(slice("values", &values)?);
    Ok((s.initial, s.max_abs_error, s.max_rel_error))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(energy, m)?)?;
    m.add_function(wrap_pyfunction!(derivative, m)?)?;
    m.add_function(wrap_pyfunction!(momentum, m)?)?;
    m.add_function(wrap_pyfunction!(energy_statistics, m)?)?;
    m.add_function(wrap_pyfunction!(invariant_statistics, m)?)?;
    Ok(())
}
