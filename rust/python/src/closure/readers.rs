//! Calling Python closures: each result is read into the core's buffers, and a result of the
//! wrong type or shape is an error that names the closure.

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use varmech::ModelError;

use crate::errors::boxed;

/// A positive dimension and callable closures (the optional ones may be None).
pub fn check_closures<const N: usize>(dim: usize, closures: [(&str, Option<&Bound<'_, PyAny>>); N]) -> PyResult<()> {
    if dim == 0 {
        return Err(PyValueError::new_err("dim: must be at least 1"));
    }
    for (name, f) in closures {
        if f.is_some_and(|f| !f.is_callable()) {
            return Err(PyTypeError::new_err(format!("{name}: must be callable")));
        }
    }
    Ok(())
}

/// The name of a Python object's type, for messages.
pub fn type_name(x: &Bound<'_, PyAny>) -> String {
    x.get_type().name().map(|n| n.to_string()).unwrap_or_default()
}

/// Reads a closure's result, a float; a wrong type is a TypeError naming the closure as `call`.
pub fn call_scalar(result: PyResult<Bound<'_, PyAny>>, call: &str) -> Result<f64, ModelError> {
    let result = result.map_err(boxed)?;
    result.extract::<f64>().map_err(|_| {
        boxed(PyTypeError::new_err(format!(
            "{call} must return a float, got {}",
            type_name(&result)
        )))
    })
}

/// Reads a closure's result, an array (n,) of floats, into `out`: a float64 numpy array is
/// read in place, any other sequence of numbers is converted. A wrong length is a ValueError
/// and a wrong type a TypeError, both naming the closure as `call`.
pub fn call_vector(result: PyResult<Bound<'_, PyAny>>, call: &str, out: &mut [f64]) -> Result<(), ModelError> {
    let result = result.map_err(boxed)?;
    let n = out.len();
    let wrong_length = |len: usize| {
        boxed(PyValueError::new_err(format!(
            "{call} returned {len} values, expected {n} (one per coordinate)"
        )))
    };
    if let Ok(arr) = result.cast::<PyArray1<f64>>() {
        let ro = arr.readonly();
        let view = ro.as_array();
        if view.len() != n {
            return Err(wrong_length(view.len()));
        }
        out.iter_mut().zip(view.iter()).for_each(|(o, v)| *o = *v);
        return Ok(());
    }
    let values: Vec<f64> = result.extract().map_err(|_| {
        let shape = result
            .getattr("shape")
            .map(|s| format!(" of shape {s}"))
            .unwrap_or_default();
        boxed(PyTypeError::new_err(format!(
            "{call} must return a 1-d array of {n} floats, got {}{shape}",
            type_name(&result)
        )))
    })?;
    if values.len() != n {
        return Err(wrong_length(values.len()));
    }
    out.copy_from_slice(&values);
    Ok(())
}

/// Reads a closure's result, a float array of `shape`, into `out` in C order: a float64 numpy
/// array is read in place, anything else goes through `numpy.asarray`. A wrong shape is a
/// ValueError and a wrong type a TypeError, both naming the closure as `call`.
pub fn call_array(
    result: PyResult<Bound<'_, PyAny>>,
    call: &str,
    shape: &[usize],
    out: &mut [f64],
) -> Result<(), ModelError> {
    let result = result.map_err(boxed)?;
    let wrong_type = || {
        boxed(PyTypeError::new_err(format!(
            "{call} must return an array of shape {shape:?} of floats, got {}",
            type_name(&result)
        )))
    };
    let array = match result.cast::<PyArrayDyn<f64>>() {
        Ok(a) => a.clone(),
        Err(_) => {
            let numpy = result.py().import("numpy").map_err(boxed)?;
            let converted = numpy
                .call_method1("asarray", (&result, "float64"))
                .map_err(|_| wrong_type())?;
            converted.cast_into::<PyArrayDyn<f64>>().map_err(|_| wrong_type())?
        }
    };
    let readonly = array.readonly();
    let view = readonly.as_array();
    if view.shape() != shape {
        return Err(boxed(PyValueError::new_err(format!(
            "{call} returned an array of shape {:?}, expected {shape:?}",
            view.shape()
        ))));
    }
    out.iter_mut().zip(view.iter()).for_each(|(o, v)| *o = *v);
    Ok(())
}
