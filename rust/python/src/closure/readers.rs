//! Calling Python closures: each result is read into the core's buffers, and a result of the
//! wrong type or shape is an error that names the closure.
//!
//! A result is admitted when it converts to float64 exactly: float64, Python floats and ints,
//! and NumPy floats of at most 64 bits and integers (upcast deliberately). Complex, bool,
//! bytes, strings, objects and masked arrays are refused with a TypeError naming the closure:
//! NumPy would drop an imaginary part, read bytes as their codes and a mask as nothing.

use numpy::ndarray::Dimension;
use numpy::{
    PyArray, PyArray1, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyInt, PyList, PyTuple};
use varmech::ModelError;

use varmech::memory::check_allocation;
use varmech::model::check_dense;

use crate::errors::boxed;

/// A positive dimension whose dense n × n matrices fit in memory (the Hessian blocks of L and
/// the Newton Jacobian), and callable closures (the optional ones may be None).
pub fn check_closures<const N: usize>(dim: usize, closures: [(&str, Option<&Bound<'_, PyAny>>); N]) -> PyResult<()> {
    if dim == 0 {
        return Err(PyValueError::new_err("dim: must be at least 1"));
    }
    for (name, f) in closures {
        if f.is_some_and(|f| !f.is_callable()) {
            return Err(PyTypeError::new_err(format!("{name}: must be callable")));
        }
    }
    check_allocation("dim", dim.saturating_mul(dim), 4 * std::mem::size_of::<f64>())
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// A number of constraints m on `dim` coordinates: 1 ≤ m < dim, and their dense matrices within
/// the memory available ([`check_dense`]); errors name `argument`.
pub fn check_count(argument: &'static str, count: usize, dim: usize) -> PyResult<()> {
    if count == 0 || count >= dim {
        return Err(PyValueError::new_err(format!(
            "{argument}: must be between 1 and dim − 1 = {}, got {count}",
            dim.saturating_sub(1)
        )));
    }
    check_dense(argument, count, dim).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// `velocity` velocity constraints beside `holonomic` holonomic ones on `dim` coordinates: at
/// most dim − 1 rows together; errors name `argument`.
pub fn check_total(argument: &'static str, holonomic: usize, velocity: usize, dim: usize) -> PyResult<()> {
    if holonomic + velocity >= dim {
        return Err(PyValueError::new_err(format!(
            "{argument}: with the {holonomic} holonomic constraints, at most dim − 1 − {holonomic} = {} velocity \
             constraints fit on {dim} coordinates, got {velocity}",
            dim.saturating_sub(1 + holonomic)
        )));
    }
    Ok(())
}

/// The name of a Python object's type, for messages.
pub fn type_name(x: &Bound<'_, PyAny>) -> String {
    x.get_type().name().map(|n| n.to_string()).unwrap_or_default()
}

/// A plain float64 ndarray (not a subclass such as a masked array), read in place.
fn plain_float64(x: &Bound<'_, PyAny>) -> bool {
    x.is_exact_instance_of::<PyUntypedArray>() && x.cast::<PyArrayDyn<f64>>().is_ok()
}

/// A closure's result admitted as float64 (see the module's doc): Python floats and ints as
/// they are, anything else as a float64 ndarray. A refusal is a TypeError naming `call` and
/// what it should return, `expected`.
fn admit<'py>(result: Bound<'py, PyAny>, call: &str, expected: &str) -> Result<Bound<'py, PyAny>, ModelError> {
    if result.is_instance_of::<PyFloat>() || (result.is_instance_of::<PyInt>() && !result.is_instance_of::<PyBool>()) {
        return Ok(result);
    }
    let refuse = |what: String| {
        boxed(PyTypeError::new_err(format!(
            "{call} must return {expected}, got {what} (float64 is read as it is, ints and float32 are converted)"
        )))
    };
    let numpy = result.py().import("numpy").map_err(boxed)?;
    let masked = numpy
        .getattr("ma")
        .and_then(|ma| ma.getattr("MaskedArray"))
        .map_err(boxed)?;
    if result.is_instance(&masked).map_err(boxed)? {
        return Err(refuse("a masked array (fill it first, numpy.ma.filled)".into()));
    }
    let array = numpy
        .call_method1("asarray", (&result,))
        .map_err(|_| refuse(type_name(&result)))?
        .cast_into::<PyUntypedArray>()
        .map_err(|_| refuse(type_name(&result)))?;
    let dtype = array.dtype();
    let (kind, size) = (dtype.kind(), dtype.itemsize());
    if !(kind == b'i' || kind == b'u' || (kind == b'f' && size <= 8)) {
        let name = dtype.getattr("name").map(|n| n.to_string()).unwrap_or_default();
        let what = if result.is_instance_of::<PyUntypedArray>() {
            format!("a {name} array")
        } else if result.is_instance_of::<PyList>() || result.is_instance_of::<PyTuple>() {
            format!("{} of {name}", type_name(&result))
        } else {
            type_name(&result)
        };
        return Err(refuse(what));
    }
    array.call_method1("astype", ("float64",)).map_err(boxed)
}

/// A closure's array result: a plain float64 ndarray as it is, anything else [`admit`]ted.
fn admitted<'py>(
    result: PyResult<Bound<'py, PyAny>>,
    call: &str,
    expected: &str,
) -> Result<Bound<'py, PyAny>, ModelError> {
    let result = result.map_err(boxed)?;
    if plain_float64(&result) {
        Ok(result)
    } else {
        admit(result, call, expected)
    }
}

/// Reads a closure's result, a float; a wrong type is a TypeError naming the closure as `call`.
pub fn call_scalar(result: PyResult<Bound<'_, PyAny>>, call: &str) -> Result<f64, ModelError> {
    let result = result.map_err(boxed)?;
    let returned = type_name(&result);
    admit(result, call, "a float")?.extract::<f64>().map_err(|_| {
        boxed(PyTypeError::new_err(format!(
            "{call} must return a float, got {returned}"
        )))
    })
}

/// Reads a closure's result, an array (n,) of floats, into `out`. A wrong length is a
/// ValueError and a wrong type a TypeError, both naming the closure as `call`.
pub fn call_vector(result: PyResult<Bound<'_, PyAny>>, call: &str, out: &mut [f64]) -> Result<(), ModelError> {
    let n = out.len();
    let expected = format!("a 1-d array of {n} floats");
    let result = admitted(result, call, &expected)?;
    let Ok(arr) = result.cast::<PyArray1<f64>>() else {
        let shape = result
            .getattr("shape")
            .map(|s| format!(" of shape {s}"))
            .unwrap_or_default();
        return Err(boxed(PyTypeError::new_err(format!(
            "{call} must return {expected}, got {}{shape}",
            type_name(&result)
        ))));
    };
    read_into(arr, out, |got| {
        (got[0] != n).then(|| format!("{call} returned {} values, expected {n} (one per coordinate)", got[0]))
    })
}

/// Reads a closure's result, a float array of `shape`, into `out` in C order. A wrong shape is
/// a ValueError and a wrong type a TypeError, both naming the closure as `call`.
pub fn call_array(
    result: PyResult<Bound<'_, PyAny>>,
    call: &str,
    shape: &[usize],
    out: &mut [f64],
) -> Result<(), ModelError> {
    let expected = format!("an array of shape {shape:?} of floats");
    let result = admitted(result, call, &expected)?;
    let array = result.cast::<PyArrayDyn<f64>>().map_err(|_| {
        boxed(PyTypeError::new_err(format!(
            "{call} must return {expected}, got {}",
            type_name(&result)
        )))
    })?;
    read_into(array, out, |got| {
        (got != shape).then(|| format!("{call} returned an array of shape {got:?}, expected {shape:?}"))
    })
}

/// Copies a closure's result `array` into `out` in C order, or refuses its shape with the
/// ValueError that `wrong` words (None: the shape expected).
fn read_into<D: Dimension>(
    array: &Bound<'_, PyArray<f64, D>>,
    out: &mut [f64],
    wrong: impl FnOnce(&[usize]) -> Option<String>,
) -> Result<(), ModelError> {
    let readonly = array.readonly();
    let view = readonly.as_array();
    if let Some(message) = wrong(view.shape()) {
        return Err(boxed(PyValueError::new_err(message)));
    }
    out.iter_mut().zip(view.iter()).for_each(|(o, v)| *o = *v);
    Ok(())
}
