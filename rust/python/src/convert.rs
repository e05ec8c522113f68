//! Conversion of arguments and results between numpy and the core.

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyInt;
use varmech::integrators::Method;
use varmech::model::Mass;

use crate::closure::readers::type_name;
use crate::errors::to_pyerr;

/// A contiguous view of a float64 vector argument.
/// Two arrays of one value per state.
pub type ArrayPair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

pub fn slice<'a>(name: &str, a: &'a PyReadonlyArray1<'_, f64>) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name}: must be a contiguous float64 array")))
}

/// A count argument (steps, save_every, an iteration cap) as usize: a negative or huge int is a
/// ValueError and anything else a TypeError, both naming the argument (pyo3's own extraction
/// raises OverflowError and names the argument only in the message).
pub fn count(name: &str, x: &Bound<'_, PyAny>) -> PyResult<usize> {
    x.extract::<usize>().map_err(|_| {
        if x.is_instance_of::<PyInt>() {
            PyValueError::new_err(format!("{name}: must be an integer from 0 to {}, got {x}", usize::MAX))
        } else {
            PyTypeError::new_err(format!("{name}: must be an integer, got {}", type_name(x)))
        }
    })
}

/// The `method` argument, a method's name, as the core's [`Method`]: anything but a str is a
/// TypeError and an unknown name a ValueError, both naming `method` (pyo3's own extraction
/// says only that the object is not a str).
pub fn method(x: &Bound<'_, PyAny>) -> PyResult<Method> {
    let name = x.extract::<String>().map_err(|_| {
        PyTypeError::new_err(format!(
            "method: must be a method's name, a str (see varmech.methods()), got {}",
            type_name(x)
        ))
    })?;
    Method::from_name(&name).map_err(|e| to_pyerr(x.py(), e))
}

/// Rows of a float64 (N, n) array, as one contiguous row-major slice.
pub fn rows<'a>(name: &str, a: &'a PyReadonlyArray2<'_, f64>) -> PyResult<(&'a [f64], usize)> {
    let n = a.shape()[1];
    let s = a
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name}: must be a C-contiguous float64 array")))?;
    Ok((s, n))
}

/// Times, positions and a second quantity per state, as flat rows.
pub type States<'a> = (&'a [f64], &'a [f64], &'a [f64]);

/// N times `t` and two (N, `dim`) arrays of states `q` and `x`, checked and read.
pub fn states<'a>(
    dim: usize,
    t: &'a PyReadonlyArray1<'_, f64>,
    q: &'a PyReadonlyArray2<'_, f64>,
    x: &'a PyReadonlyArray2<'_, f64>,
) -> PyResult<States<'a>> {
    let (t, (q, n), (x, m)) = (slice("t", t)?, rows("q", q)?, rows("x", x)?);
    if n != dim || m != dim || q.len() != x.len() || q.len() != t.len() * dim {
        return Err(PyValueError::new_err(format!(
            "t, q: need N times and two (N, {dim}) arrays of states"
        )));
    }
    Ok((t, q, x))
}

/// The mass matrix of a model with `dim` coordinates from a scalar (0-d), a diagonal (n,) or a
/// full (n, n) float64 array.
pub fn mass(m: &Bound<'_, PyAny>, dim: usize) -> PyResult<Mass> {
    let arr = m
        .cast::<numpy::PyArrayDyn<f64>>()
        .map_err(|_| PyValueError::new_err("mass: must be a float64 array"))?;
    let ro = arr.readonly();
    let view = ro.as_array();
    let result = match view.ndim() {
        0 => Mass::scalar(view.iter().copied().next().unwrap_or(f64::NAN)),
        1 => Mass::diagonal(view.iter().copied().collect()),
        2 => {
            let (r, c) = (view.shape()[0], view.shape()[1]);
            Mass::full(nalgebra::DMatrix::from_row_iterator(r, c, view.iter().copied()))
        }
        d => {
            return Err(PyValueError::new_err(format!(
                "mass: must be a scalar, a vector or a matrix, got {d} dimensions"
            )))
        }
    };
    let mass = result.map_err(|e| to_pyerr(m.py(), e))?;
    match mass.dim().filter(|n| *n != dim) {
        Some(n) => Err(PyValueError::new_err(format!(
            "mass: has dimension {n}, the model has dim = {dim}"
        ))),
        None => Ok(mass),
    }
}

/// A row-major buffer of N rows as an (N, n) array.
pub fn matrix(py: Python<'_>, data: Vec<f64>, n: usize) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let rows = data.len().checked_div(n).unwrap_or(0);
    PyArray1::from_vec(py, data).reshape([rows, n])
}
