//! A natural mechanical system L = ½q̇ᵀM(q)q̇ − V(q) from Python closures.

use std::cell::RefCell;

use nalgebra::DMatrix;
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::memory::check_allocation;
use varmech::model::{differenced_kinetic_gradient, kinetic_gradient_from_mass_derivative, NaturalSystem};
use varmech::ModelError;

use super::mechanical::ClosurePotential;
use super::readers::{call_array, check_closures};
use crate::errors::boxed;
use crate::generator::{self, Generator as Spec};

/// A natural mechanical system L = ½q̇ᵀM(q)q̇ − V(q) given by Python closures `mass(q) -> array
/// (n, n)`, `potential(q) -> float` and, optionally, `gradient(q) -> array (n,)` and
/// `mass_derivative(q) -> array (n, n, n)` (∂M/∂qᵢ at index i); missing derivatives come from
/// central differences.
#[pyclass(frozen, module = "varmech._core")]
pub struct ClosureNatural {
    dim: usize,
    mass: Py<PyAny>,
    potential: Py<PyAny>,
    gradient: Option<Py<PyAny>>,
    mass_derivative: Option<Py<PyAny>>,
}

#[pymethods]
impl ClosureNatural {
    #[new]
    /// `symmetries` are only checked here (the core's Lagrangian trait declares none); the
    /// Python model keeps them for the conservation report.
    #[pyo3(signature = (dim, mass, potential, gradient, mass_derivative, symmetries))]
    fn new(
        dim: usize,
        mass: Bound<'_, PyAny>,
        potential: Bound<'_, PyAny>,
        gradient: Option<Bound<'_, PyAny>>,
        mass_derivative: Option<Bound<'_, PyAny>>,
        symmetries: Vec<Spec>,
    ) -> PyResult<Self> {
        generator::generators(symmetries, dim)?;
        check_closures(
            dim,
            [
                ("mass", Some(&mass)),
                ("potential", Some(&potential)),
                ("gradient", gradient.as_ref()),
                ("mass_derivative", mass_derivative.as_ref()),
            ],
        )?;
        if mass_derivative.is_some() {
            check_allocation(
                "mass_derivative",
                dim.saturating_mul(dim).saturating_mul(dim),
                size_of::<f64>(),
            )
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        }
        Ok(ClosureNatural {
            dim,
            mass: mass.unbind(),
            potential: potential.unbind(),
            gradient: gradient.map(Bound::unbind),
            mass_derivative: mass_derivative.map(Bound::unbind),
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.dim
    }

    fn __repr__(&self) -> String {
        format!("ClosureNatural(dim={})", self.dim)
    }
}

/// A [`ClosureNatural`] bound to the GIL: it implements the core's [`NaturalSystem`] trait
/// (a Lagrangian through `varmech::model::Natural`).
pub struct ClosureNaturalSystem<'py> {
    py: Python<'py>,
    dim: usize,
    mass: Bound<'py, PyAny>,
    potential: ClosurePotential<'py>,
    mass_derivative: Option<Bound<'py, PyAny>>,
    /// ∂M/∂qᵢ for i = 0..n, C order.
    derivative: RefCell<Vec<f64>>,
}

impl<'py> ClosureNaturalSystem<'py> {
    pub fn new(py: Python<'py>, model: &ClosureNatural) -> Self {
        let n = model.dim;
        ClosureNaturalSystem {
            py,
            dim: n,
            mass: model.mass.bind(py).clone(),
            potential: ClosurePotential::new(py, n, &model.potential, model.gradient.as_ref()),
            mass_derivative: model.mass_derivative.as_ref().map(|f| f.bind(py).clone()),
            // Only read with `mass_derivative` (whose n³ numbers the constructor checked).
            derivative: RefCell::new(vec![0.0; if model.mass_derivative.is_some() { n * n * n } else { 0 }]),
        }
    }
}

impl NaturalSystem for ClosureNaturalSystem<'_> {
    fn dim(&self) -> usize {
        self.dim
    }

    /// M(q), which must be symmetric (to 1e-12 relative): Cholesky reads one triangle only.
    fn mass_matrix(&self, q: &[f64], m: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let n = self.dim;
        let call = self.mass.call1((PyArray1::from_slice(self.py, q),));
        call_array(call, "mass(q)", &[n, n], m.as_mut_slice())?;
        let scale = m.amax();
        if (0..n).any(|i| (0..i).any(|j| (m[(i, j)] - m[(j, i)]).abs() > 1e-12 * scale)) {
            return Err(boxed(PyValueError::new_err(format!(
                "mass(q) returned a matrix that is not symmetric at q = {q:?}"
            ))));
        }
        Ok(())
    }

    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        self.potential.potential(q)
    }

    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        self.potential.gradient(q, grad)
    }

    /// ∂T/∂q from `mass_derivative`, or the trait's differences of M.
    fn kinetic_gradient(&self, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        let Some(f) = &self.mass_derivative else {
            return differenced_kinetic_gradient(self, q, v, out);
        };
        let n = self.dim;
        let derivative = &mut *self.derivative.borrow_mut();
        call_array(
            f.call1((PyArray1::from_slice(self.py, q),)),
            "mass_derivative(q)",
            &[n, n, n],
            derivative,
        )?;
        kinetic_gradient_from_mass_derivative(derivative, v, out);
        Ok(())
    }
}
