use super::{add_gradient, velocity_momentum, DiscreteLagrangian};
use crate::model::{Lagrangian, MechanicalSystem};
use crate::ModelError;

/// The left rectangle rule, L_d = h·L(q₀, v) with v = (q₁ − q₀)/h.
///
/// For L = ½vᵀMv − V its Legendre transforms are p₀ = Mv + h∇V(q₀) and p₁ = Mv: solved for
/// (q₁, p₁) they are symplectic Euler, p₁ = p₀ − h∇V(q₀), q₁ = q₀ + hM⁻¹p₁.
#[derive(Clone, Copy, Debug, Default)]
pub struct Rectangle;

impl DiscreteLagrangian for Rectangle {
    fn value<S: MechanicalSystem + ?Sized>(&self, sys: &S, q0: &[f64], q1: &[f64], h: f64) -> Result<f64, ModelError> {
        let (v, _) = velocity_momentum(sys, q0, q1, h);
        Ok(h * sys.lagrangian(q0, &v, 0.0)?)
    }

    fn momentum_minus<S: MechanicalSystem + ?Sized>(
        &self,
        sys: &S,
        q0: &[f64],
        q1: &[f64],
        h: f64,
    ) -> Result<Vec<f64>, ModelError> {
        let (_, mut p) = velocity_momentum(sys, q0, q1, h);
        add_gradient(sys, h, q0, &mut p)?;
        Ok(p)
    }

    fn momentum_plus<S: MechanicalSystem + ?Sized>(
        &self,
        sys: &S,
        q0: &[f64],
        q1: &[f64],
        h: f64,
    ) -> Result<Vec<f64>, ModelError> {
        Ok(velocity_momentum(sys, q0, q1, h).1)
    }
}
