use super::MechanicalSystem;
use crate::ModelError;

/// H(q, p) = ½ pᵀ M⁻¹ p + V(q), the energy of a mechanical system.
pub fn hamiltonian<S: MechanicalSystem + ?Sized>(sys: &S, q: &[f64], p: &[f64]) -> Result<f64, ModelError> {
    Ok(sys.mass().kinetic_energy(p) + sys.potential(q)?)
}

/// The energy function E = p·q̇ − L at one state and its two terms: the potential
/// V = E(q, q̇ = 0, t) = −L(q, 0, t), the energy the configuration has at rest, and the
/// kinetic T = E − V, the energy of the motion.
///
/// For L = T₂ + T₁ + T₀ (parts homogeneous of degree 2, 1, 0 in q̇) E = T₂ − T₀, so T = T₂ and
/// V = −T₀: ½pᵀM⁻¹p and V(q) for a mechanical system, with the gyroscopic (velocity-linear)
/// terms, which do no work, in neither. The conservation verdicts measure energy errors
/// against T and E's round-off against |T| + |V| (see [`crate::diagnostics::Statistics`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyTerms {
    pub energy: f64,
    pub kinetic: f64,
    pub potential: f64,
}

impl EnergyTerms {
    /// |T| + |V|: the size of the terms E is the sum of, and so of its rounding error.
    pub fn size(&self) -> f64 {
        self.kinetic.abs() + self.potential.abs()
    }
}
