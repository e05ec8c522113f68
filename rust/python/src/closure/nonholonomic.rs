//! A closure model with velocity constraints A(q)q̇ + b(q) = 0 given by Python closures (b
//! optional: linear constraints without it), alone or beside holonomic ones.

use std::cell::RefCell;

use nalgebra::DMatrix;
use numpy::PyArray1;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use varmech::integrators::Dynamics;
use varmech::model::{Mixed, Natural, Nonholonomic, VelocityConstraints};
use varmech::ModelError;

use super::constraints::{ClosureConstrained, ClosureConstraints, ConstrainedSystem};
use super::lagrangian::{ClosureLagrangian, ClosureLagrangianSystem};
use super::mechanical::{ClosureModel, ClosureSystem};
use super::natural::{ClosureNatural, ClosureNaturalSystem};
use super::readers::{call_array, check_closures, check_count, check_total};
use crate::errors::boxed;

/// A closure model (separable [`ClosureModel`], natural [`ClosureNatural`] or general
/// [`ClosureLagrangian`], or either of the first two on holonomic constraints,
/// [`ClosureConstrained`]) with m velocity constraints A(q)q̇ + b(q) = 0, `matrix(q) -> array
/// (m, n)` and optionally the affine term `offset(q) -> array (m,)`: the discrete
/// Lagrange–d'Alembert integrator's model.
#[pyclass(frozen, module = "varmech._core")]
pub struct ClosureNonholonomic {
    system: Unconstrained,
    count: usize,
    matrix: Py<PyAny>,
    offset: Option<Py<PyAny>>,
}

/// The model under a [`ClosureNonholonomic`]'s velocity constraints.
enum Unconstrained {
    Separable(Py<ClosureModel>),
    Natural(Py<ClosureNatural>),
    Lagrangian(Py<ClosureLagrangian>),
    /// On holonomic constraints: the core's [`Mixed`] model.
    Holonomic(Py<ClosureConstrained>),
}

#[pymethods]
impl ClosureNonholonomic {
    #[new]
    #[pyo3(signature = (system, count, matrix, offset=None))]
    fn new(
        system: Bound<'_, PyAny>,
        count: usize,
        matrix: Bound<'_, PyAny>,
        offset: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let (system, dim) = if let Ok(s) = system.cast::<ClosureModel>() {
            (Unconstrained::Separable(s.clone().unbind()), s.get().dim())
        } else if let Ok(s) = system.cast::<ClosureNatural>() {
            (Unconstrained::Natural(s.clone().unbind()), s.get().dim())
        } else if let Ok(s) = system.cast::<ClosureLagrangian>() {
            (Unconstrained::Lagrangian(s.clone().unbind()), s.get().dim())
        } else if let Ok(s) = system.cast::<ClosureConstrained>() {
            (Unconstrained::Holonomic(s.clone().unbind()), s.get().dim())
        } else {
            return Err(PyTypeError::new_err(
                "system: expected a ClosureModel, a ClosureNatural, a ClosureLagrangian or a ClosureConstrained",
            ));
        };
        check_closures(
            dim,
            [
                ("velocity_constraints", Some(&matrix)),
                ("velocity_constraint_offset", offset.as_ref()),
            ],
        )?;
        check_count("velocity_constraint_count", count, dim)?;
        if let Unconstrained::Holonomic(s) = &system {
            check_total("velocity_constraint_count", s.get().count(), count, dim)?;
        }
        Ok(ClosureNonholonomic {
            system,
            count,
            matrix: matrix.unbind(),
            offset: offset.map(Bound::unbind),
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        match &self.system {
            Unconstrained::Separable(s) => s.get().dim(),
            Unconstrained::Natural(s) => s.get().dim(),
            Unconstrained::Lagrangian(s) => s.get().dim(),
            Unconstrained::Holonomic(s) => s.get().dim(),
        }
    }

    #[getter]
    fn velocity_constraints(&self) -> usize {
        self.count
    }

    /// Number of holonomic constraints g(q) = 0 beside the velocity constraints (0 without).
    #[getter]
    fn constraints(&self) -> usize {
        match &self.system {
            Unconstrained::Holonomic(s) => s.get().count(),
            _ => 0,
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "ClosureNonholonomic(dim={}, constraints={}, velocity_constraints={})",
            self.dim(),
            self.constraints(),
            self.count
        )
    }
}

impl ClosureNonholonomic {
    /// Runs `body` with the model bound to the GIL as the core's [`Nonholonomic`] system, or
    /// its [`Mixed`] one on holonomic constraints.
    pub fn with_integrable<R>(&self, py: Python<'_>, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        let constraints = ClosureVelocityConstraints {
            py,
            count: self.count,
            matrix: self.matrix.bind(py).clone(),
            offset: self.offset.as_ref().map(|b| b.bind(py).clone()),
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
            Unconstrained::Holonomic(s) => {
                let (s, holonomic) = (s.get(), ClosureConstraints::new(py, s.get()));
                match s.system() {
                    ConstrainedSystem::Separable(system) => body(&Mixed {
                        system: ClosureSystem::new(py, system.get()),
                        holonomic,
                        velocity: constraints,
                    }),
                    ConstrainedSystem::Natural(system) => body(&Mixed {
                        system: Natural::new(ClosureNaturalSystem::new(py, system.get())),
                        holonomic,
                        velocity: constraints,
                    }),
                }
            }
        }
    }
}

/// The velocity constraints of a [`ClosureNonholonomic`] bound to the GIL: they implement the
/// core's [`VelocityConstraints`] (∂A/∂q and ∂b/∂q by the trait's differences).
struct ClosureVelocityConstraints<'py> {
    py: Python<'py>,
    count: usize,
    matrix: Bound<'py, PyAny>,
    offset: Option<Bound<'py, PyAny>>,
    rows: RefCell<Vec<f64>>,
}

/// A closure's values are finite, or its error names the call and q.
fn finite(values: &[f64], call: &str, q: &[f64]) -> Result<(), ModelError> {
    if values.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(boxed(PyValueError::new_err(format!(
            "{call} returned non-finite values at q = {q:?}"
        ))))
    }
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
        finite(rows, call, q)?;
        for (i, row) in rows.chunks_exact(n).enumerate() {
            a.row_mut(i).iter_mut().zip(row).for_each(|(x, r)| *x = *r);
        }
        Ok(())
    }

    fn is_affine(&self) -> bool {
        self.offset.is_some()
    }

    /// `velocity_constraint_offset(q)`, an array (m,), finite; 0 without it.
    fn offset(&self, q: &[f64], b: &mut [f64]) -> Result<(), ModelError> {
        let Some(offset) = &self.offset else {
            b.fill(0.0);
            return Ok(());
        };
        let call = "velocity_constraint_offset(q)";
        call_array(offset.call1((PyArray1::from_slice(self.py, q),)), call, &[b.len()], b)?;
        finite(b, call, q)
    }
}
