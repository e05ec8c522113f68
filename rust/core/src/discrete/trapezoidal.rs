use super::{add_gradient, velocity_momentum, DiscreteLagrangian};
use crate::model::{Lagrangian, MechanicalSystem};
use crate::ModelError;

/// The trapezoidal rule, L_d = (h/2)[L(q₀, v) + L(q₁, v)] with v = (q₁ − q₀)/h.
///
/// For L = ½vᵀMv − V its Legendre transforms are p₀ = Mv + (h/2)∇V(q₀) and
/// p₁ = Mv − (h/2)∇V(q₁): solved for (q₁, p₁) they are Störmer–Verlet.
#[derive(Clone, Copy, Debug, Default)]
pub struct Trapezoidal;

impl DiscreteLagrangian for Trapezoidal {
    fn value<S: MechanicalSystem + ?Sized>(&self, sys: &S, q0: &[f64], q1: &[f64], h: f64) -> Result<f64, ModelError> {
        let (v, _) = velocity_momentum(sys, q0, q1, h);
        Ok(0.5 * h * (sys.lagrangian(q0, &v, 0.0)? + sys.lagrangian(q1, &v, h)?))
    }

    fn momentum_minus<S: MechanicalSystem + ?Sized>(
        &self,
        sys: &S,
        q0: &[f64],
        q1: &[f64],
        h: f64,
    ) -> Result<Vec<f64>, ModelError> {
        let (_, mut p) = velocity_momentum(sys, q0, q1, h);
        add_gradient(sys, 0.5 * h, q0, &mut p)?;
        Ok(p)
    }

    fn momentum_plus<S: MechanicalSystem + ?Sized>(
        &self,
        sys: &S,
        q0: &[f64],
        q1: &[f64],
        h: f64,
    ) -> Result<Vec<f64>, ModelError> {
        let (_, mut p) = velocity_momentum(sys, q0, q1, h);
        add_gradient(sys, -0.5 * h, q1, &mut p)?;
        Ok(p)
    }
}
