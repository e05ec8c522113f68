use super::MechanicalSystem;
use crate::ModelError;

/// A Lagrangian system L(q, q̇, t) with n generalized coordinates.
///
/// This is the trait the discrete layer builds discrete Lagrangians L_d ≈ ∫ L dt from. The
/// separable mechanical systems of [`MechanicalSystem`] implement it exactly; general
/// Lagrangians (configuration-dependent mass M(q), velocity-linear terms, explicit time
/// dependence) implement it directly, and may supply ∂L/∂q and ∂L/∂q̇ exactly.
pub trait Lagrangian {
    /// Number of generalized coordinates n.
    fn dim(&self) -> usize;

    /// L(q, q̇, t).
    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError>;

    /// Whether L depends on t explicitly; if it does, the energy function E = p·q̇ − L is not
    /// conserved and no report may claim it is.
    fn is_time_dependent(&self) -> bool {
        false
    }
}

/// L = ½ q̇ᵀ M q̇ − V(q).
impl<S: MechanicalSystem + ?Sized> Lagrangian for S {
    fn dim(&self) -> usize {
        MechanicalSystem::dim(self)
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        Ok(self.mass().kinetic_energy_of_velocity(v) - self.potential(q)?)
    }
}
