use crate::integrators::Trajectory;
use crate::model::{hamiltonian, MechanicalSystem};
use crate::ModelError;

/// H(q, p) = ½ pᵀ M⁻¹ p + V(q) (see [`hamiltonian`]) at every saved state of `traj`.
pub fn energies<S: MechanicalSystem + ?Sized>(sys: &S, traj: &Trajectory) -> Result<Vec<f64>, ModelError> {
    (0..traj.len())
        .map(|k| hamiltonian(sys, traj.q_at(k), traj.p_at(k)))
        .collect()
}
