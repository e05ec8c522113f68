use super::MechanicalSystem;
use crate::ModelError;

/// H(q, p) = ½ pᵀ M⁻¹ p + V(q), the energy of a mechanical system.
pub fn hamiltonian<S: MechanicalSystem + ?Sized>(sys: &S, q: &[f64], p: &[f64]) -> Result<f64, ModelError> {
    Ok(sys.mass().kinetic_energy(p) + sys.potential(q)?)
}
