//! A closure model with velocity constraints A(q)q̇ = 0 given by a Python closure.

use std::cell::RefCell;

use nalgebra::DMatrix;
use numpy::PyArray1;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use varmech::integrators::Dynamics;
use varmech::model::{Natural, Nonholonomic, VelocityConstraints};
use varmech::ModelError;

use super::lagrangian::{ClosureLagrangian, ClosureLagrangianSystem};
use super::mechanical::{ClosureModel, ClosureSystem};
use super::natural::{ClosureNatural, ClosureNaturalSystem};
use super::readers::{call_array, check_closures, check_count};
use crate::errors::boxed;

/// A closure model (separable [`ClosureModel`], natural [`ClosureNatural`] or general
/// [`ClosureLagrangian`]) with m velocity constraints A(q)q̇ = 0, `matrix(q) -> array (m, n)`:
/// the discrete Lagrange–d'Alembert integrator's model.
#[pyclass(frozen, module = "varmech._core")]
pub struct ClosureNonholonomic {
    system: Unconstrained,
    count: usize,
    matrix: Py<PyAny>,
}

/// The model under a [`ClosureNonholonomic`].
enum Unconstrained {
    Separable(Py<ClosureModel>),
    Natural(Py<ClosureNatural>),
    Lagrangian(Py<ClosureLagrangian>),
}

#[pymethods]
impl ClosureNonholonomic {
    #[new]
    #[pyo3(signature = (system, count, matrix))]
    fn new(system: Bound<'_, PyAny>, count: usize, matrix: Bound<'_, PyAny>) -> PyResult<Self> {
        let (system, dim) = if let Ok(s) = system.cast::<ClosureModel>() {
            (Unconstrained::Separable(s.clone().unbind()), s.get().dim())
        } else if let Ok(s) = system.cast::<ClosureNatural>() {
            (Unconstrained::Natural(s.clone().unbind()), s.get().dim())
        } else if let Ok(s) = system.cast::<ClosureLagrangian>() {
            (Unconstrained::Lagrangian(s.clone().unbind()), s.get().dim())
        } else {
            return Err(PyTypeError::new_err(
                "system: expected a ClosureModel, a ClosureNatural or a ClosureLagrangian",
            ));
        };
        check_closures(dim, [("velocity_constraints", Some(&matrix))])?;
        check_count("velocity_constraint_count", count, dim)?;
        Ok(ClosureNonholonomic {
            system,
            count,
            matrix: matrix.unbind(),
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        match &self.system {
            Unconstrained::Separable(s) => s.get().dim(),
            Unconstrained::Natural(s) => s.get().dim(),
            Unconstrained::Lagrangian(s) => s.get().dim(),
        }
    }

    #[getter]
    fn velocity_constraints(&self) -> usize {
        self.count
    }

    fn __repr__(&self) -> String {
        format!(
            "ClosureNonholonomic(dim={}, velocity_constraints={})",
            self.dim(),
            self.count
        )
    }
}

impl ClosureNonholonomic {
    /// Runs `body` with the model bound to the GIL as the core's [`Nonholonomic`] system.
    pub fn with_integrable<R>(&self, py: Python<'_>, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        let constraints = ClosureVelocityConstraints {
            py,
            count: self.count,
            matrix: self.matrix.bind(py).clone(),
            rows: RefCell::new(vec![0.0; self.count * self.dim()]),
        };
        match &self.system {
            Unconstrained::Separable(s) => body(&Nonholonomic {
                system: ClosureSystem::new(py, s.get()),
                constraints,
            }),
            Unconstrained::Natural(s) => body(&Nonholonomic {
                system: Natural::new(ClosureNaturalSystem::new(py, s.get())),
                constraints,
            }),
            Unconstrained::Lagrangian(s) => body(&Nonholonomic {
                system: ClosureLagrangianSystem::new(py, s.get()),
                constraints,
            }),
        }
    }
}

/// The velocity constraints of a [`ClosureNonholonomic`] bound to the GIL: they implement the
/// core's [`VelocityConstraints`] (∂A/∂q by the trait's differences).
struct ClosureVelocityConstraints<'py> {
    py: Python<'py>,
    count: usize,
    matrix: Bound<'py, PyAny>,
    rows: RefCell<Vec<f64>>,
}

impl VelocityConstraints for ClosureVelocityConstraints<'_> {
    fn count(&self) -> usize {
        self.count
    }

    /// `velocity_constraints(q)`, an array (m, n) in C order, finite.
    fn matrix(&self, q: &[f64], a: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let (m, n) = a.shape();
        let rows = &mut *self.rows.borrow_mut();
        let call = "velocity_constraints(q)";
        call_array(
            self.matrix.call1((PyArray1::from_slice(self.py, q),)),
            call,
            &[m, n],
            rows,
        )?;
        if !rows.iter().all(|x| x.is_finite()) {
            return Err(boxed(PyValueError::new_err(format!(
                "{call} returned non-finite values at q = {q:?}"
            ))));
        }
        for (i, row) in rows.chunks_exact(n).enumerate() {
            a.row_mut(i).iter_mut().zip(row).for_each(|(x, r)| *x = *r);
        }
        Ok(())
    }
}
