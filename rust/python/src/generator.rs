//! Generators of symmetries, as Python names them and passes them.

use pyo3::prelude::*;
use varmech::model;

use pyo3::exceptions::PyValueError;

/// A generator ξ(q) of a symmetry (the core's `Generator`): `Translation(axis, spatial_dim)`,
/// `Rotation(axis, spatial_dim)` or `Cyclic(index)`.
#[pyclass(frozen, from_py_object, module = "varmech._core")]
#[derive(Clone, Copy)]
pub enum Generator {
    Translation { axis: usize, spatial_dim: usize },
    Rotation { axis: usize, spatial_dim: usize },
    Cyclic { index: usize },
}

impl From<Generator> for model::Generator {
    fn from(g: Generator) -> Self {
        match g {
            Generator::Translation { axis, spatial_dim } => model::Generator::Translation { axis, spatial_dim },
            Generator::Rotation { axis, spatial_dim } => model::Generator::Rotation { axis, spatial_dim },
            Generator::Cyclic { index } => model::Generator::Cyclic { index },
        }
    }
}

impl From<model::Generator> for Generator {
    fn from(g: model::Generator) -> Self {
        match g {
            model::Generator::Translation { axis, spatial_dim } => Generator::Translation { axis, spatial_dim },
            model::Generator::Rotation { axis, spatial_dim } => Generator::Rotation { axis, spatial_dim },
            model::Generator::Cyclic { index } => Generator::Cyclic { index },
        }
    }
}

#[pymethods]
impl Generator {
    /// The name of the conserved momentum (P_x, L, p\[1\], ...).
    #[getter]
    fn name(&self) -> String {
        model::Generator::from(*self).name()
    }
}

/// Generators, each checked (by the core) to apply to `dim` coordinates: ValueError naming
/// `symmetries[i]` and the model's dimension if not.
pub fn generators(specs: Vec<Generator>, dim: usize) -> PyResult<Vec<model::Generator>> {
    (specs.into_iter().enumerate())
        .map(|(i, spec)| checked(spec, dim, &format!("symmetries[{i}]")))
        .collect()
}

/// The core's generator of `spec`, checked to apply to `dim` coordinates: ValueError naming
/// `argument` if not.
pub fn checked(spec: Generator, dim: usize, argument: &str) -> PyResult<model::Generator> {
    let g = model::Generator::from(spec);
    match g.misfit(dim) {
        Some(reason) => Err(PyValueError::new_err(format!("{argument}: {reason}"))),
        None => Ok(g),
    }
}
