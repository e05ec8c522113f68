use nalgebra::DVector;

use super::constraints::{momentum_projection, row_norm};
use super::{
    inverse_mass, project, ConstraintSet, HolonomicConstraints, Lagrangian, PhaseState, Residuals, VelocityConstraints,
};
use crate::{Error, ModelError};

/// A Lagrangian system S on holonomic constraints H, g(q) = 0, and velocity constraints C,
/// A(q)q̇ + b(q) = 0, together: a rolling body whose contact is held on a surface, say. The
/// constraint forces are Gᵀλ + Aᵀμ (Lagrange–d'Alembert), and a consistent state has g(q) = 0
/// and the velocity on both, [G(q); A(q)]q̇ + [0; b(q)] = 0 (the hidden constraint G(q)q̇ = 0
/// of the positions' and the velocity constraints). What the discrete Lagrange–d'Alembert
/// integrator with holonomic constraints ([`crate::integrators::Del`]) integrates.
#[derive(Clone, Debug)]
pub struct Mixed<S, H, C> {
    pub system: S,
    pub holonomic: H,
    pub velocity: C,
}

impl<S: Lagrangian, H: HolonomicConstraints, C: VelocityConstraints> Mixed<S, H, C> {
    /// Both sets of constraints, as one record.
    pub fn constraints(&self) -> ConstraintSet<'_> {
        ConstraintSet {
            holonomic: Some(&self.holonomic),
            velocity: Some(&self.velocity),
        }
    }

    /// q̇(q, p), the inverse Legendre transform.
    fn velocity(&self) -> impl Fn(&[f64], &[f64], &mut [f64]) -> Result<(), ModelError> + '_ {
        |q, p, v| self.system.velocity(q, p, 0.0, v)
    }

    /// |g(q)|∞ against ‖G(q)‖∞‖q‖∞, and |[G; A]q̇ + [0; b]|∞ with q̇ = q̇(q, p) against
    /// ‖[G; A]‖∞‖q̇‖∞ + |b(q)|∞: the position and the velocity residuals of both sets at once.
    pub fn residuals(&self, q: &[f64], p: &[f64]) -> Result<Residuals, ModelError> {
        let k = self.holonomic.count();
        let mut g = vec![0.0; k];
        self.holonomic.residual(q, &mut g)?;
        let (stacked, b) = self.constraints().stacked(q)?;
        let mut v = vec![0.0; q.len()];
        self.velocity()(q, p, &mut v)?;
        let v = DVector::from_column_slice(&v);
        let amax = |x: &[f64]| x.iter().fold(0.0_f64, |a, y| a.max(y.abs()));
        Ok(Residuals {
            position: amax(&g),
            velocity: (&stacked * &v + &b).amax(),
            position_size: row_norm(&stacked.rows(0, k).into_owned()) * amax(q),
            velocity_size: row_norm(&stacked) * v.amax() + b.amax(),
        })
    }

    /// The nearest consistent state: q onto g = 0 as [`project`] puts it, then p ← p − [G; A]ᵀν
    /// with ([G; A]M⁻¹[G; A]ᵀ)ν = [G; A]q̇(q, p) + [0; b(q)], the M-orthogonal projection onto
    /// both velocity constraints (M⁻¹ from the inverse Legendre transform, exact for L
    /// quadratic in q̇).
    pub fn project(&self, q0: &[f64], p0: &[f64]) -> Result<PhaseState, Error> {
        let model = |e: ModelError| Error::invalid("q0", format!("the constraints failed to evaluate: {e}"));
        let velocity = self.velocity();
        let minv = inverse_mass(&velocity);
        let (q, _) = project(&self.holonomic, &minv, &velocity, q0, p0)?;
        let (stacked, b) = self.constraints().stacked(&q).map_err(model)?;
        let p = momentum_projection(&stacked, &b, &minv, &velocity, &q, p0)?;
        Ok((q, p))
    }
}
