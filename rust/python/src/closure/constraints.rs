//! A closure model on holonomic constraints g(q) = 0 given by Python closures.

use std::cell::RefCell;

use nalgebra::DMatrix;
use numpy::PyArray1;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use varmech::integrators::{Dynamics, General};
use varmech::model::{differenced_jacobian, Constrained, HolonomicConstraints, Natural};
use varmech::ModelError;

use super::mechanical::{ClosureModel, ClosureSystem};
use super::natural::{ClosureNatural, ClosureNaturalSystem};
use super::readers::{call_array, call_vector, check_closures, check_count};

/// A closure model (a [`ClosureModel`], or a [`ClosureNatural`] with configuration-dependent
/// mass) on holonomic constraints given by Python closures `constraints(q) -> array (m,)` and,
/// optionally, `jacobian(q) -> array (m, n)`; without a Jacobian, central differences of g are
/// used (2n calls of g per Jacobian).
#[pyclass(frozen, module = "varmech._core")]
pub struct ClosureConstrained {
    system: ConstrainedSystem,
    count: usize,
    constraints: Py<PyAny>,
    jacobian: Option<Py<PyAny>>,
}

#[pymethods]
impl ClosureConstrained {
    #[new]
    #[pyo3(signature = (system, count, constraints, jacobian))]
    fn new(
        system: Bound<'_, PyAny>,
        count: usize,
        constraints: Bound<'_, PyAny>,
        jacobian: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let system = if let Ok(s) = system.cast::<ClosureModel>() {
            ConstrainedSystem::Separable(s.clone().unbind())
        } else if let Ok(s) = system.cast::<ClosureNatural>() {
            ConstrainedSystem::Natural(s.clone().unbind())
        } else {
            return Err(PyTypeError::new_err(
                "system: expected a ClosureModel or a ClosureNatural",
            ));
        };
        let dim = system.dim();
        check_closures(
            dim,
            [
                ("constraints", Some(&constraints)),
                ("constraint_jacobian", jacobian.as_ref()),
            ],
        )?;
        check_count("constraint_count", count, dim)?;
        Ok(ClosureConstrained {
            system,
            count,
            constraints: constraints.unbind(),
            jacobian: jacobian.map(Bound::unbind),
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.system.dim()
    }

    #[getter]
    fn constraints(&self) -> usize {
        self.count
    }

    fn __repr__(&self) -> String {
        format!("ClosureConstrained(dim={}, constraints={})", self.dim(), self.count)
    }
}

impl ClosureConstrained {
    /// Number of constraints m.
    pub fn count(&self) -> usize {
        self.count
    }

    pub fn system(&self) -> &ConstrainedSystem {
        &self.system
    }

    /// Runs `body` with the model bound to the GIL as the core's constrained system: RATTLE's
    /// for a separable system, the constrained DEL equations' for a natural one.
    pub fn with_integrable<R>(&self, py: Python<'_>, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        let constraints = ClosureConstraints::new(py, self);
        match &self.system {
            ConstrainedSystem::Separable(system) => body(&Constrained {
                system: ClosureSystem::new(py, system.get()),
                constraints,
            }),
            ConstrainedSystem::Natural(system) => {
                let natural = Natural::new(ClosureNaturalSystem::new(py, system.get()));
                body(&Constrained {
                    system: General(&natural),
                    constraints,
                })
            }
        }
    }
}

/// The unconstrained model under a [`ClosureConstrained`]: RATTLE integrates a separable one,
/// the constrained DEL equations a natural one.
pub enum ConstrainedSystem {
    Separable(Py<ClosureModel>),
    Natural(Py<ClosureNatural>),
}

impl ConstrainedSystem {
    fn dim(&self) -> usize {
        match self {
            ConstrainedSystem::Separable(s) => s.get().dim(),
            ConstrainedSystem::Natural(s) => s.get().dim(),
        }
    }
}

/// The constraints of a [`ClosureConstrained`] bound to the GIL: they implement the core's
/// [`HolonomicConstraints`] trait.
pub struct ClosureConstraints<'py> {
    py: Python<'py>,
    count: usize,
    constraints: Bound<'py, PyAny>,
    jacobian: Option<Bound<'py, PyAny>>,
    rows: RefCell<Vec<f64>>,
}

impl<'py> ClosureConstraints<'py> {
    pub fn new(py: Python<'py>, model: &ClosureConstrained) -> Self {
        ClosureConstraints {
            py,
            count: model.count,
            constraints: model.constraints.bind(py).clone(),
            jacobian: model.jacobian.as_ref().map(|f| f.bind(py).clone()),
            rows: RefCell::new(vec![0.0; model.count * model.dim()]),
        }
    }
}

impl HolonomicConstraints for ClosureConstraints<'_> {
    fn count(&self) -> usize {
        self.count
    }

    fn residual(&self, q: &[f64], g: &mut [f64]) -> Result<(), ModelError> {
        call_vector(
            self.constraints.call1((PyArray1::from_slice(self.py, q),)),
            "constraints(q)",
            g,
        )
    }

    /// `jacobian(q)`, an array (m, n) in C order, or the trait's differences of g.
    fn jacobian(&self, q: &[f64], jac: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let Some(f) = &self.jacobian else {
            return differenced_jacobian(self, q, jac);
        };
        let (m, n) = jac.shape();
        let rows = &mut *self.rows.borrow_mut();
        call_array(
            f.call1((PyArray1::from_slice(self.py, q),)),
            "constraint_jacobian(q)",
            &[m, n],
            rows,
        )?;
        for (i, row) in rows.chunks_exact(n).enumerate() {
            jac.row_mut(i).iter_mut().zip(row).for_each(|(j, r)| *j = *r);
        }
        Ok(())
    }
}
