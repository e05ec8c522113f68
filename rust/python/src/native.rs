//! Native scenes: every evaluation runs in Rust, with the GIL released.

use pyo3::prelude::*;
use varmech::integrators::{Dynamics, General};
use varmech::model::{Constrained, Distances, HolonomicConstraints, MechanicalSystem};
use varmech::scenes::{LagrangianScene, LinkedMasses, RigidBody, Scene};

use crate::generator::Generator;

/// A native scene: a separable mechanical system, a general Lagrangian, or a mechanical
/// system on holonomic constraints.
pub enum Native {
    Mechanical(Scene),
    General(LagrangianScene),
    Constrained(LinkedMasses),
    /// A general Lagrangian on constraints (the rigid body in quaternions).
    ConstrainedGeneral(Constrained<RigidBody, Distances>),
}

/// A native scene: every evaluation runs in Rust, with the GIL released.
#[pyclass(frozen, module = "varmech._core")]
pub struct NativeModel {
    pub native: Native,
    name: &'static str,
}

impl NativeModel {
    pub fn new(native: Native, name: &'static str) -> Self {
        NativeModel { native, name }
    }

    /// Runs `body` with the scene as the core's [`Dynamics`]: a general Lagrangian wrapped in
    /// [`General`] for the variational methods.
    pub fn with_integrable<R>(&self, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        match &self.native {
            Native::Mechanical(scene) => body(scene),
            Native::General(scene) => body(&General(scene)),
            Native::Constrained(scene) => body(scene),
            Native::ConstrainedGeneral(scene) => body(&Constrained {
                system: General(&scene.system),
                constraints: scene.constraints.clone(),
            }),
        }
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
            Native::Mechanical(Scene::NBody(s)) => Some((s.gravitational_constant(), s.masses().to_vec())),
            _ => None,
        }
    }

    /// The declared symmetries.
    #[getter]
    fn symmetries(&self) -> Vec<Generator> {
        let declared = match &self.native {
            Native::Mechanical(s) => s.symmetries(),
            Native::General(s) => s.symmetries(),
            Native::Constrained(s) => s.system.symmetries(),
            Native::ConstrainedGeneral(_) => Vec::new(),
        };
        declared.into_iter().map(Generator::from).collect()
    }

    /// Number of holonomic constraints (0 for unconstrained models).
    #[getter]
    fn constraints(&self) -> usize {
        match &self.native {
            Native::Constrained(s) => s.constraints.count(),
            Native::ConstrainedGeneral(s) => s.constraints.count(),
            _ => 0,
        }
    }

    fn __repr__(&self) -> String {
        format!("NativeModel({:?}, dim={})", self.name, self.dim())
    }
}
