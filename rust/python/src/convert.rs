//! Conversion of arguments and results between numpy and the core.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use varmech::integrators::Trajectory;
use varmech::model::{Generator, Mass};

/// A contiguous view of a float64 vector argument.
pub fn slice<'a>(name: &str, a: &'a PyReadonlyArray1<'_, f64>) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name}: must be a contiguous float64 array")))
}

/// Rows of a float64 (N, n) array, as one contiguous row-major slice.
pub fn rows<'a>(name: &str, a: &'a PyReadonlyArray2<'_, f64>) -> PyResult<(&'a [f64], usize)> {
    let n = a.shape()[1];
    let s = a
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name}: must be a C-contiguous float64 array")))?;
    Ok((s, n))
}

/// The mass matrix from a scalar (0-d), a diagonal (n,) or a full (n, n) float64 array.
pub fn mass(m: &Bound<'_, PyAny>) -> PyResult<Mass> {
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
    result.map_err(|e| PyValueError::new_err(e.to_string()))
}

/// A generator from its spec: ("translation", axis, spatial_dim), ("rotation", axis,
/// spatial_dim) or ("cyclic", index, 0).
pub fn generator(spec: (String, usize, usize)) -> PyResult<Generator> {
    let (kind, a, d) = spec;
    match kind.as_str() {
        "translation" => Ok(Generator::Translation {
            axis: a,
            spatial_dim: d,
        }),
        "rotation" => Ok(Generator::Rotation {
            axis: a,
            spatial_dim: d,
        }),
        "cyclic" => Ok(Generator::Cyclic { index: a }),
        _ => Err(PyValueError::new_err(format!("generator: unknown kind {kind:?}"))),
    }
}

/// Generators from their specs, each checked to apply to `dim` coordinates.
pub fn generators(specs: Vec<(String, usize, usize)>, dim: usize) -> PyResult<Vec<Generator>> {
    specs
        .into_iter()
        .map(|spec| {
            let g = generator(spec)?;
            g.check(dim).map_err(|e| PyValueError::new_err(e.to_string()))?;
            Ok(g)
        })
        .collect()
}

/// The spec of a generator, as [`generator`] reads it, with its name.
pub fn generator_spec(g: Generator) -> (&'static str, usize, usize, String) {
    match g {
        Generator::Translation { axis, spatial_dim } => ("translation", axis, spatial_dim, g.name()),
        Generator::Rotation { axis, spatial_dim } => ("rotation", axis, spatial_dim, g.name()),
        Generator::Cyclic { index } => ("cyclic", index, 0, g.name()),
    }
}

/// A row-major buffer of N rows as an (N, n) array.
pub fn matrix<'py>(py: Python<'py>, data: Vec<f64>, n: usize) -> PyResult<Bound<'py, PyAny>> {
    let rows = data.len().checked_div(n).unwrap_or(0);
    Ok(PyArray1::from_vec(py, data).reshape([rows, n])?.into_any())
}

/// (t, q, p, steps, force_evaluations, newton, work) of a trajectory: `newton` the cumulative
/// Newton iterations and `work` the cumulative work of non-conservative forces at each saved
/// state.
pub fn trajectory_tuple(py: Python<'_>, traj: Trajectory) -> PyResult<Bound<'_, PyTuple>> {
    let n = traj.dim;
    let t = PyArray1::from_vec(py, traj.t).into_any();
    let q = matrix(py, traj.q, n)?;
    let p = matrix(py, traj.p, n)?;
    let newton = PyArray1::from_vec(py, traj.newton).into_any();
    let work = PyArray1::from_vec(py, traj.work).into_any();
    (t, q, p, traj.steps, traj.force_evaluations, newton, work).into_pyobject(py)
}
