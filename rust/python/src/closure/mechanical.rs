//! A separable mechanical system L = ½q̇ᵀMq̇ − V(q) from Python closures.

use std::cell::RefCell;

use numpy::PyArray1;
use pyo3::prelude::*;
use varmech::model::{Generator, Mass, MechanicalSystem};
use varmech::solve::difference::central_gradient;
use varmech::ModelError;

use super::readers::{call_scalar, call_vector, check_closures};
use crate::convert;
use crate::generator::{self, Generator as Spec};

/// A mechanical system L = ½q̇ᵀMq̇ − V(q) given by Python closures `potential(q) -> float` and,
/// optionally, `gradient(q) -> array (n,)`; without a gradient, central differences of the
/// potential are used (2n potential calls per gradient).
#[pyclass(frozen, module = "varmech._core")]
pub struct ClosureModel {
    dim: usize,
    mass: Mass,
    potential: Py<PyAny>,
    gradient: Option<Py<PyAny>>,
    symmetries: Vec<Generator>,
}

#[pymethods]
impl ClosureModel {
    #[new]
    #[pyo3(signature = (dim, potential, gradient, mass, symmetries))]
    fn new(
        dim: usize,
        potential: Bound<'_, PyAny>,
        gradient: Option<Bound<'_, PyAny>>,
        mass: &Bound<'_, PyAny>,
        symmetries: Vec<Spec>,
    ) -> PyResult<Self> {
        check_closures(dim, [("potential", Some(&potential)), ("gradient", gradient.as_ref())])?;
        let mass = convert::mass(mass, dim)?;
        let symmetries = generator::generators(symmetries, dim)?;
        Ok(ClosureModel {
            dim,
            mass,
            potential: potential.unbind(),
            gradient: gradient.map(Bound::unbind),
            symmetries,
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.dim
    }

    #[getter]
    fn has_gradient(&self) -> bool {
        self.gradient.is_some()
    }

    fn __repr__(&self) -> String {
        format!("ClosureModel(dim={})", self.dim)
    }
}

/// The closures `potential(q)` and `gradient(q)` bound to the GIL: V(q) and ∇V(q), the
/// gradient by central differences of V where no closure gives it.
pub struct ClosurePotential<'py> {
    py: Python<'py>,
    potential: Bound<'py, PyAny>,
    gradient: Option<Bound<'py, PyAny>>,
    work: RefCell<Vec<f64>>,
}

impl<'py> ClosurePotential<'py> {
    pub fn new(py: Python<'py>, dim: usize, potential: &Py<PyAny>, gradient: Option<&Py<PyAny>>) -> Self {
        ClosurePotential {
            py,
            potential: potential.bind(py).clone(),
            gradient: gradient.map(|g| g.bind(py).clone()),
            work: RefCell::new(vec![0.0; dim]),
        }
    }

    pub fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        call_scalar(
            self.potential.call1((PyArray1::from_slice(self.py, q),)),
            "potential(q)",
        )
    }

    pub fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        match &self.gradient {
            Some(f) => call_vector(f.call1((PyArray1::from_slice(self.py, q),)), "gradient(q)", grad),
            None => central_gradient(|x| self.potential(x), q, &mut self.work.borrow_mut(), grad),
        }
    }
}

/// A [`ClosureModel`] bound to the GIL for the duration of a call: it implements the core's
/// [`MechanicalSystem`] by calling the closures.
pub struct ClosureSystem<'a, 'py> {
    model: &'a ClosureModel,
    potential: ClosurePotential<'py>,
}

impl<'a, 'py> ClosureSystem<'a, 'py> {
    pub fn new(py: Python<'py>, model: &'a ClosureModel) -> Self {
        ClosureSystem {
            model,
            potential: ClosurePotential::new(py, model.dim, &model.potential, model.gradient.as_ref()),
        }
    }
}

impl MechanicalSystem for ClosureSystem<'_, '_> {
    fn dim(&self) -> usize {
        self.model.dim
    }

    fn mass(&self) -> &Mass {
        &self.model.mass
    }

    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        self.potential.potential(q)
    }

    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        self.potential.gradient(q, grad)
    }

    fn symmetries(&self) -> Vec<Generator> {
        self.model.symmetries.clone()
    }
}
