//! Routh reduction: the reduced model and the functions that reconstruct the ignored
//! coordinates.

use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use varmech::discrete::{DiscreteLagrangian, Midpoint, Trapezoidal};
use varmech::model::{Lagrangian, Routhian};
use varmech::ModelError;

use crate::bind::bind_full;
use crate::convert::{self, states};
use crate::errors::{model_error, to_pyerr};

/// A Routh-reduced model: the Routhian R = L − μ·ċ of a full model (native or closures) on
/// its non-cyclic coordinates, built by `_core.routh` (which checks it).
#[pyclass(frozen, module = "varmech._core")]
pub struct RouthModel {
    pub full: Py<PyAny>,
    cyclic: Vec<usize>,
    momenta: Vec<f64>,
    reference: Vec<f64>,
    dim: usize,
}

impl RouthModel {
    /// The Routhian of the full model's Lagrangian `full`.
    pub fn routhian<'a>(&self, full: &'a dyn Lagrangian) -> Routhian<'a, dyn Lagrangian + 'a> {
        Routhian::new(full, &self.cyclic, &self.momenta, &self.reference)
            .expect("the arguments were checked when the model was built")
    }
}

#[pymethods]
impl RouthModel {
    #[getter]
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The model whose cyclic coordinates are ignored.
    #[getter]
    fn full(&self, py: Python<'_>) -> Py<PyAny> {
        self.full.clone_ref(py)
    }

    #[getter]
    fn cyclic(&self) -> Vec<usize> {
        self.cyclic.clone()
    }

    #[getter]
    fn momenta(&self) -> Vec<f64> {
        self.momenta.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "RouthModel(cyclic={:?}, momenta={:?}, dim={})",
            self.cyclic, self.momenta, self.dim
        )
    }
}

/// The model as a [`RouthModel`], or a TypeError.
fn reduced<'a>(model: &'a Bound<'_, PyAny>) -> PyResult<&'a RouthModel> {
    model
        .cast::<RouthModel>()
        .map(|m| m.get())
        .map_err(|_| PyTypeError::new_err("model: expected a Routh-reduced model (varmech.routh)"))
}

/// Runs `body` with the [`Routhian`] of a reduced model.
fn with_routhian<R: Send>(
    py: Python<'_>,
    reduced: &RouthModel,
    body: impl for<'s> FnOnce(&Routhian<'s, dyn Lagrangian + 's>) -> R + Send,
) -> PyResult<R> {
    bind_full(py, reduced.full.bind(py), |full, _poll| {
        body(&reduced.routhian(full.as_lagrangian()))
    })
}

/// The Routh-reduced model of `full` that ignores the coordinates `cyclic` at momenta
/// `momenta`; `reference` holds values for those coordinates, which L does not see.
#[pyfunction]
fn routh(
    py: Python<'_>,
    full: &Bound<'_, PyAny>,
    cyclic: Vec<usize>,
    momenta: Vec<f64>,
    reference: Vec<f64>,
) -> PyResult<RouthModel> {
    if full.cast::<RouthModel>().is_ok() {
        return Err(PyValueError::new_err(
            "model: is reduced already; ignore all the cyclic coordinates of the full model at once",
        ));
    }
    let constraints = full
        .getattr("constraints")
        .and_then(|c| c.extract::<usize>())
        .unwrap_or(0);
    if constraints > 0 {
        return Err(PyValueError::new_err(
            "model: has holonomic constraints; Routh reduction needs generalized coordinates",
        ));
    }
    let dim = bind_full(py, full, |sys, _poll| {
        Routhian::new(sys.as_lagrangian(), &cyclic, &momenta, &reference).map(|r| r.dim())
    })?
    .map_err(|e| to_pyerr(py, e))?;
    Ok(RouthModel {
        full: full.clone().unbind(),
        cyclic,
        momenta,
        reference,
        dim,
    })
}

/// The increments of the ignored coordinates between consecutive states (t, x, p) of a reduced
/// trajectory, shape (N − 1, m): by the discrete momentum equation of `rule` ("midpoint" or
/// "trapezoid"), or by Gauss quadrature along the Hermite interpolant (`rule` None).
#[pyfunction]
fn cyclic_increments<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
    rule: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let reduced = reduced(model)?;
    let (t, x, p) = states(reduced.dim, &t, &x, &p)?;
    let rule = match rule {
        None => None,
        Some("midpoint") => Some(Midpoint.quadrature()),
        Some("trapezoid") => Some(Trapezoidal.quadrature()),
        Some(other) => {
            return Err(PyValueError::new_err(format!(
                "rule: expected \"midpoint\", \"trapezoid\" or None, got {other:?}"
            )))
        }
    };
    let result = with_routhian(py, reduced, |r| r.cyclic_increments(t, x, p, rule))?;
    Ok(convert::matrix(py, result.map_err(model_error)?, reduced.cyclic.len())?.into_any())
}

/// The amended potential V_μ(x, t) = −R(x, 0, t) at each state, shape (N,).
#[pyfunction]
fn amended_potential<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let reduced = reduced(model)?;
    let n = reduced.dim;
    let (t, x, _) = states(n, &t, &x, &x)?;
    let result: Result<Vec<f64>, ModelError> = with_routhian(py, reduced, |r| {
        t.iter()
            .zip(x.chunks_exact(n))
            .map(|(t, x)| r.amended_potential(x, *t))
            .collect()
    })?;
    Ok(PyArray1::from_vec(py, result.map_err(model_error)?))
}

/// The velocities ċ of the ignored coordinates at each state (t, x, ẋ), shape (N, m).
#[pyfunction]
fn cyclic_velocity<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray2<'py, f64>,
    xdot: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let reduced = reduced(model)?;
    let (n, m) = (reduced.dim, reduced.cyclic.len());
    let (t, x, xdot) = states(n, &t, &x, &xdot)?;
    let result: Result<Vec<f64>, ModelError> = with_routhian(py, reduced, |r| {
        let mut out = vec![0.0; t.len() * m];
        t.iter()
            .zip(x.chunks_exact(n).zip(xdot.chunks_exact(n)))
            .zip(out.chunks_exact_mut(m))
            .try_for_each(|((t, (x, v)), c)| r.cyclic_velocity(x, v, *t, c))
            .map(|()| out)
    })?;
    Ok(convert::matrix(py, result.map_err(model_error)?, m)?.into_any())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<RouthModel>()?;
    add_functions!(m, [routh, cyclic_increments, amended_potential, cyclic_velocity]);
    Ok(())
}
