//! Native scenes: every evaluation runs in Rust, with the GIL released.

use pyo3::prelude::*;
use varmech::integrators::Dynamics;
use varmech::model::{HolonomicConstraints, MechanicalSystem};
use varmech::scenes::{Scene, SceneModel};

use crate::generator::Generator;

/// A native scene, the core's [`SceneModel`]: every evaluation runs in Rust, with the GIL
/// released.
#[pyclass(frozen, module = "varmech._core")]
pub struct NativeModel {
    pub native: SceneModel,
    name: &'static str,
}

impl NativeModel {
    pub fn new(native: SceneModel, name: &'static str) -> Self {
        NativeModel { native, name }
    }

    /// Runs `body` with the scene as the core's [`Dynamics`] ([`SceneModel::with_dynamics`]).
    pub fn with_integrable<R>(&self, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        self.native.with_dynamics(body)
    }
}

#[pymethods]
impl NativeModel {
    #[getter]
    pub fn dim(&self) -> usize {
        self.with_integrable(|sys| sys.dim())
    }

    #[getter]
    fn name(&self) -> &'static str {
        self.name
    }

    /// (G, masses) of an N-body scene, None for the others.
    #[getter]
    fn gravity(&self) -> Option<(f64, Vec<f64>)> {
        match &self.native {
            SceneModel::Mechanical(Scene::NBody(s)) => Some((s.gravitational_constant(), s.masses().to_vec())),
            _ => None,
        }
    }

    /// The declared symmetries.
    #[getter]
    fn symmetries(&self) -> Vec<Generator> {
        let declared = match &self.native {
            SceneModel::Mechanical(s) => s.symmetries(),
            SceneModel::General(s) => s.symmetries(),
            SceneModel::Constrained(s) => s.system.symmetries(),
            SceneModel::ConstrainedGeneral(_) => Vec::new(),
            SceneModel::Nonholonomic(s) => s.symmetries(),
        };
        declared.into_iter().map(Generator::from).collect()
    }

    /// Number of holonomic constraints (0 for unconstrained models).
    #[getter]
    fn constraints(&self) -> usize {
        match &self.native {
            SceneModel::Constrained(s) => s.constraints.count(),
            SceneModel::ConstrainedGeneral(s) => s.constraints.count(),
            _ => 0,
        }
    }

    /// Number of velocity constraints A(q)q̇ + b(q) = 0 (0 for models without them).
    #[getter]
    fn velocity_constraints(&self) -> usize {
        match &self.native {
            SceneModel::Nonholonomic(s) => s.count(),
            _ => 0,
        }
    }

    fn __repr__(&self) -> String {
        format!("NativeModel({:?}, dim={})", self.name, self.dim())
    }
}
