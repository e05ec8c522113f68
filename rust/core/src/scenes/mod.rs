//! Native test problems, each in the fewest coordinates its physics needs, with its initial
//! data and, where one is published or exact, a reference solution; [`CATALOGUE`] lists them
//! by name with their parameters, descriptions, steps and invariants.
//!
//! Scenes use the model layer only: the contact surfaces of the impact scenes (the bouncing
//! ball's floor, the billiard's wall) are attached where the runs are, in Python.
//!
//! The data and references are copied from the literature into `reference/` of the repository,
//! which names the sources; tests and benches use these problems (as diffsol ships its test
//! problems in the library).

/// `new()`, the system of unit mass, and `Default` as `new()`: for the scenes whose system has
/// no parameter (its one field its mass, 1), as the Hénon–Heiles, Kepler and pendulum ones.
macro_rules! unit_mass {
    ($scene:ident) => {
        impl $scene {
            pub fn new() -> Self {
                $scene {
                    mass: Mass::Scalar(1.0),
                }
            }
        }

        impl Default for $scene {
            fn default() -> Self {
                Self::new()
            }
        }
    };
}

mod bouncing_ball;
mod catalogue;
mod chaplygin_sleigh;
mod charged_particle;
mod constrained;
mod damped_driven_pendulum;
mod double_pendulum;
mod elliptic_billiard;
mod fermi_pasta_ulam;
mod free_body;
mod harmonic_oscillator;
mod heavy_top;
mod henon_heiles;
mod kepler;
mod kepler_polar;
mod nbody;
mod pendulum;
mod rigid_body;
mod rolling_disk;
mod rolling_sphere;
mod spherical_pendulum;

pub use crate::model::NBody;
pub use bouncing_ball::BouncingBall;
pub use catalogue::{lookup, CatalogueEntry, Parameter, SceneModel, Setup, CATALOGUE};
pub use chaplygin_sleigh::{Blade, ChaplyginSleigh};
pub use charged_particle::ChargedParticle;
pub use constrained::{cartesian_pendulum, cartesian_spherical_pendulum, planar_chain, LinkedMasses, PointMasses};
pub use damped_driven_pendulum::DampedDrivenPendulum;
pub use double_pendulum::DoublePendulum;
pub use elliptic_billiard::EllipticBilliard;
pub use fermi_pasta_ulam::FermiPastaUlam;
pub use free_body::FreeBody;
pub use harmonic_oscillator::HarmonicOscillator;
pub use heavy_top::HeavyTop;
pub use henon_heiles::HenonHeiles;
pub use kepler::Kepler;
pub use kepler_polar::KeplerPolar;
pub use pendulum::Pendulum;
pub use rigid_body::RigidBody;
pub use rolling_disk::{Rolling, RollingDisk};
pub use rolling_sphere::{sphere_symmetries, RollingSphere, SphereContact};
pub use spherical_pendulum::SphericalPendulum;

use crate::model::{Generator, Hessians, Lagrangian, Mass, MechanicalSystem, Nonholonomic, VelocityConstraints};
use crate::ModelError;

/// A state (q, p) at time t.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub t: f64,
    pub q: Vec<f64>,
    pub p: Vec<f64>,
}

impl State {
    /// The state (q, p) at t = 0, where a scene's protocol starts.
    pub(crate) fn start(q: Vec<f64>, p: Vec<f64>) -> State {
        State { t: 0.0, q, p }
    }
}

/// A system with its initial state, the horizon of its test protocol and a reference solution.
#[derive(Clone, Debug)]
pub struct Problem<S> {
    pub system: S,
    pub initial: State,
    pub t_end: f64,
    /// The exact or published solution, and where it comes from.
    pub reference: Option<(State, &'static str)>,
}

impl<S> Problem<S> {
    /// The same problem with the system mapped by `f` (into an enum of systems, say).
    pub fn map<T>(self, f: impl FnOnce(S) -> T) -> Problem<T> {
        Problem {
            system: f(self.system),
            initial: self.initial,
            t_end: self.t_end,
            reference: self.reference,
        }
    }
}

/// Any native scene, for callers (the Python binding) that choose one at run time.
#[derive(Clone, Debug)]
pub enum Scene {
    HarmonicOscillator(HarmonicOscillator),
    Pendulum(Pendulum),
    Kepler(Kepler),
    HenonHeiles(HenonHeiles),
    FermiPastaUlam(FermiPastaUlam),
    NBody(NBody),
    /// The ball above its floor (the floor a contact, attached in Python).
    BouncingBall(BouncingBall),
    /// The free particle of an elliptic billiard (the wall a contact, attached in Python).
    EllipticBilliard(EllipticBilliard),
}

macro_rules! dispatch {
    ($self:ident, $s:ident => $e:expr) => {
        match $self {
            Scene::HarmonicOscillator($s) => $e,
            Scene::Pendulum($s) => $e,
            Scene::Kepler($s) => $e,
            Scene::HenonHeiles($s) => $e,
            Scene::FermiPastaUlam($s) => $e,
            Scene::NBody($s) => $e,
            Scene::BouncingBall($s) => $e,
            Scene::EllipticBilliard($s) => $e,
        }
    };
}

impl MechanicalSystem for Scene {
    fn dim(&self) -> usize {
        dispatch!(self, s => MechanicalSystem::dim(s))
    }
    fn mass(&self) -> &Mass {
        dispatch!(self, s => s.mass())
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        dispatch!(self, s => s.potential(q))
    }
    #[inline]
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        dispatch!(self, s => s.gradient(q, grad))
    }
    fn hessian(&self, q: &[f64], out: &mut [f64]) -> Option<Result<(), ModelError>> {
        dispatch!(self, s => s.hessian(q, out))
    }
    fn symmetries(&self) -> Vec<Generator> {
        dispatch!(self, s => s.symmetries())
    }
    fn as_nbody(&self) -> Option<&NBody> {
        dispatch!(self, s => s.as_nbody())
    }
}

/// Any native scene that is a general Lagrangian (integrated by the implicit methods).
#[derive(Clone, Debug)]
pub enum LagrangianScene {
    DoublePendulum(DoublePendulum),
    SphericalPendulum(SphericalPendulum),
    /// In a uniform or a non-uniform magnetic field.
    ChargedParticle(ChargedParticle),
    DampedDrivenPendulum(DampedDrivenPendulum),
    /// The heavy symmetric top in Euler angles; φ and ψ cyclic.
    HeavyTop(HeavyTop),
    /// Kepler in polar coordinates; θ cyclic.
    KeplerPolar(KeplerPolar),
}

macro_rules! dispatch_lagrangian {
    ($self:ident, $s:ident => $e:expr) => {
        match $self {
            LagrangianScene::DoublePendulum($s) => $e,
            LagrangianScene::SphericalPendulum($s) => $e,
            LagrangianScene::ChargedParticle($s) => $e,
            LagrangianScene::DampedDrivenPendulum($s) => $e,
            LagrangianScene::HeavyTop($s) => $e,
            LagrangianScene::KeplerPolar($s) => $e,
        }
    };
}

impl LagrangianScene {
    /// The symmetries the scene declares.
    pub fn symmetries(&self) -> Vec<Generator> {
        match self {
            LagrangianScene::SphericalPendulum(s) => s.symmetries(),
            LagrangianScene::ChargedParticle(s) => s.symmetries(),
            LagrangianScene::HeavyTop(s) => s.symmetries(),
            LagrangianScene::KeplerPolar(s) => s.symmetries(),
            LagrangianScene::DoublePendulum(_) | LagrangianScene::DampedDrivenPendulum(_) => Vec::new(),
        }
    }
}

impl Lagrangian for LagrangianScene {
    fn dim(&self) -> usize {
        dispatch_lagrangian!(self, s => Lagrangian::dim(s))
    }
    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        dispatch_lagrangian!(self, s => s.lagrangian(q, v, t))
    }
    fn dl_dq(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        dispatch_lagrangian!(self, s => s.dl_dq(q, v, t, out))
    }
    fn dl_dv(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        dispatch_lagrangian!(self, s => s.dl_dv(q, v, t, out))
    }
    fn velocity(&self, q: &[f64], p: &[f64], t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        dispatch_lagrangian!(self, s => s.velocity(q, p, t, v))
    }
    fn hessians(&self, q: &[f64], v: &[f64], t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        dispatch_lagrangian!(self, s => s.hessians(q, v, t, out))
    }
    fn is_time_dependent(&self) -> bool {
        dispatch_lagrangian!(self, s => s.is_time_dependent())
    }
    fn is_forced(&self) -> bool {
        dispatch_lagrangian!(self, s => s.is_forced())
    }
    fn force(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        dispatch_lagrangian!(self, s => s.force(q, v, t, out))
    }
}

/// Any native scene with velocity constraints A(q)q̇ + b(q) = 0, integrated by the discrete
/// Lagrange–d'Alembert integrator. Such systems conserve their energy when L and the
/// constraints do not depend on t and b = 0, but not, in general, the momenta of the
/// symmetries of L: each declares the momenta it does conserve.
#[derive(Clone, Debug)]
pub enum NonholonomicScene {
    /// The vertical disk (a coin) rolling on a plane; p_θ, p_φ conserved.
    RollingDisk(Nonholonomic<FreeBody, Rolling>),
    /// The Chaplygin sleigh; no momentum conserved.
    ChaplyginSleigh(Nonholonomic<FreeBody, Blade>),
    /// The ball on a rough incline or on a turntable (affine constraints).
    RollingSphere(Nonholonomic<RollingSphere, SphereContact>),
}

impl NonholonomicScene {
    /// The symmetries whose momenta the scene conserves (not every symmetry of its L).
    pub fn symmetries(&self) -> Vec<Generator> {
        match self {
            NonholonomicScene::RollingDisk(_) => RollingDisk::symmetries(),
            NonholonomicScene::ChaplyginSleigh(_) => Vec::new(),
            NonholonomicScene::RollingSphere(s) => sphere_symmetries(&s.constraints),
        }
    }

    /// Number of velocity constraints m.
    pub fn count(&self) -> usize {
        match self {
            NonholonomicScene::RollingDisk(s) => s.constraints.count(),
            NonholonomicScene::ChaplyginSleigh(s) => s.constraints.count(),
            NonholonomicScene::RollingSphere(s) => s.constraints.count(),
        }
    }
}

/// Refuses the first of a scene's named values that is not finite and positive, naming it.
pub(crate) fn positive(values: &[(&'static str, f64)]) -> Result<(), crate::Error> {
    match values.iter().find(|(_, x)| !(x.is_finite() && *x > 0.0)) {
        Some((name, x)) => Err(crate::Error::invalid(
            name,
            format!("must be finite and positive, got {x}"),
        )),
        None => Ok(()),
    }
}

/// Refuses the first of a scene's named values that is not finite, naming it.
pub(crate) fn finite(values: &[(&'static str, f64)]) -> Result<(), crate::Error> {
    match values.iter().find(|(_, x)| !x.is_finite()) {
        Some((name, x)) => Err(crate::Error::invalid(name, format!("must be finite, got {x}"))),
        None => Ok(()),
    }
}
