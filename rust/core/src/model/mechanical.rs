use super::{Generator, Mass, NBody};
use crate::ModelError;

/// A separable mechanical system, L(q, q̇) = ½ q̇ᵀ M q̇ − V(q), with constant mass matrix M.
///
/// Its Hamiltonian is H(q, p) = ½ pᵀ M⁻¹ p + V(q) and its equations of motion are
/// q̇ = M⁻¹p, ṗ = −∇V(q): the setting of Störmer–Verlet and of its compositions.
pub trait MechanicalSystem {
    /// Number of generalized coordinates n.
    fn dim(&self) -> usize;

    /// The constant mass matrix M.
    fn mass(&self) -> &Mass;

    /// The potential V(q).
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError>;

    /// Writes ∇V(q) into `grad` (length n). Step loops call this; it must not allocate.
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError>;

    /// Writes ∂²V/∂q² at q into `out` (n × n, symmetric), where the model has it; None where it
    /// has not, and the tangent map differences the gradient ([`crate::integrators::Tangent`]).
    fn hessian(&self, _q: &[f64], _out: &mut [f64]) -> Option<Result<(), ModelError>> {
        None
    }

    /// The symmetries the model declares; each has a conserved Noether momentum J = p·ξ(q).
    fn symmetries(&self) -> Vec<Generator> {
        Vec::new()
    }

    /// The model as a gravitational N-body problem, for the Wisdom–Holman methods, which
    /// integrate nothing else; None for other models.
    fn as_nbody(&self) -> Option<&NBody> {
        None
    }
}
