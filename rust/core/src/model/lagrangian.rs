use super::{finite_difference, MechanicalSystem};
use crate::ModelError;

/// A Lagrangian system L(q, q̇, t) with n generalized coordinates.
///
/// The discrete layer builds discrete Lagrangians L_d ≈ ∫ L dt from it and their Legendre
/// transforms from ∂L/∂q and ∂L/∂q̇. Separable mechanical systems ([`MechanicalSystem`])
/// implement it exactly; general Lagrangians (configuration-dependent mass, velocity-linear
/// terms, explicit time dependence) implement [`Lagrangian::lagrangian`] and, where they can,
/// the derivatives exactly: the defaults are central differences.
pub trait Lagrangian {
    /// Number of generalized coordinates n.
    fn dim(&self) -> usize;

    /// L(q, q̇, t).
    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError>;

    /// Writes ∂L/∂q at (q, q̇, t) into `out`. Default: central differences of L (they allocate
    /// a scratch vector; models used in long runs should supply it).
    fn dl_dq(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let mut work = vec![0.0; q.len()];
        finite_difference::central_gradient(|x| self.lagrangian(x, v, t), q, &mut work, out)
    }

    /// Writes the momentum p = ∂L/∂q̇ at (q, q̇, t) into `out`. Default: central differences.
    fn dl_dv(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let mut work = vec![0.0; v.len()];
        finite_difference::central_gradient(|x| self.lagrangian(q, x, t), v, &mut work, out)
    }

    /// Whether L depends on t explicitly; if it does, the energy function E = p·q̇ − L is not
    /// conserved and no report may claim it is.
    fn is_time_dependent(&self) -> bool {
        false
    }
}

/// L = ½ q̇ᵀ M q̇ − V(q): ∂L/∂q = −∇V(q), ∂L/∂q̇ = M q̇.
impl<S: MechanicalSystem + ?Sized> Lagrangian for S {
    fn dim(&self) -> usize {
        MechanicalSystem::dim(self)
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        Ok(self.mass().kinetic_energy_of_velocity(v) - self.potential(q)?)
    }

    fn dl_dq(&self, q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.gradient(q, out)?;
        out.iter_mut().for_each(|x| *x = -*x);
        Ok(())
    }

    fn dl_dv(&self, _q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.mass().momentum(v, out);
        Ok(())
    }
}
