use super::{Series, Statistics};
use crate::integrators::Trajectory;
use crate::model::{hamiltonian, EnergyTerms, Lagrangian, MechanicalSystem};
use crate::{Error, ModelError};

/// H(q, p) = ½ pᵀ M⁻¹ p + V(q) (see [`hamiltonian`]) at every saved state of `traj`.
pub fn energies<S: MechanicalSystem + ?Sized>(sys: &S, traj: &Trajectory) -> Result<Vec<f64>, ModelError> {
    (0..traj.len())
        .map(|k| hamiltonian(sys, traj.q_at(k), traj.p_at(k)))
        .collect()
}

/// The energy function E = p·q̇ − L and its terms T and V ([`EnergyTerms`]) at every saved
/// state of `traj`.
pub fn energy_terms<L: Lagrangian + ?Sized>(sys: &L, traj: &Trajectory) -> Result<Vec<EnergyTerms>, ModelError> {
    (0..traj.len())
        .map(|k| sys.energy_terms(traj.q_at(k), traj.p_at(k), traj.t[k]))
        .collect()
}

/// The statistics and verdict of the energy along a run of `steps` steps sampled at times `t`:
/// the error of E − W (W the work of the non-conservative forces, zero without them, so that
/// the check is the energy balance of a forced run), of size |T| and terms |T| + |V| + |W|.
pub fn energy_statistics(t: &[f64], terms: &[EnergyTerms], work: &[f64], steps: u64) -> Result<Statistics, Error> {
    if work.len() != terms.len() {
        return Err(Error::invalid("work", "needs one value per energy"));
    }
    let balance = |(e, w): (&EnergyTerms, &f64)| e.energy - w;
    let initial = terms.first().zip(work.first()).map(balance).unwrap_or(0.0);
    let error: Vec<f64> = terms.iter().zip(work).map(|x| balance(x) - initial).collect();
    let size: Vec<f64> = terms.iter().map(|e| e.kinetic).collect();
    let sizes: Vec<f64> = terms.iter().zip(work).map(|(e, w)| e.size() + w.abs()).collect();
    Statistics::new(&Series {
        t,
        error: &error,
        size: &size,
        terms: &sizes,
        steps,
    })
}
