//! The discrete constraint of velocity constraints A(q)q̇ + b(q) = 0 in the discrete
//! Lagrange–d'Alembert step (see [`super::Del`]): A(q̃)δq + h b(q̃) = 0 at the midpoint
//! q̃ = q₀ + δq/2 (reversible) or at the start q̃ = q₀ (not), and its derivatives for Newton's
//! exact Jacobian.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::constrained::Multipliers;
use crate::model::VelocityConstraints;
use crate::ModelError;

/// Where the discrete constraint A(q̃)(q₁ − q₀) = 0 takes A.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub(in crate::integrators) enum DiscreteConstraint {
    /// q̃ = (q₀ + q₁)/2, symmetric in the step's ends: McLachlan & Perlmutter's (2006)
    /// reversible choice.
    Midpoint,
    /// q̃ = q₀, at the step's start: the tangent chord of Cortés & Martínez (2001), which is
    /// not symmetric, so the step is not reversible (and of order 1).
    Start,
}

impl DiscreteConstraint {
    /// ∂q̃/∂δq: how far q̃ moves with δq.
    fn weight(self) -> f64 {
        match self {
            DiscreteConstraint::Midpoint => 0.5,
            DiscreteConstraint::Start => 0.0,
        }
    }
}

/// q̃ = q₀ + wδq into `mp.midpoint`, A(q̃) into `mp.a_mid` and b(q̃) into `mp.b_mid`.
fn at_point(
    c: &dyn VelocityConstraints,
    at: DiscreteConstraint,
    mp: &mut Multipliers,
    q0: &[f64],
    dq: &[f64],
) -> Result<(), ModelError> {
    let w = at.weight();
    for ((b, q), d) in mp.midpoint.iter_mut().zip(q0).zip(dq) {
        *b = q + w * d;
    }
    c.matrix(&mp.midpoint, &mut mp.a_mid)?;
    c.offset(&mp.midpoint, &mut mp.b_mid)
}

/// A(q̃)δq + h b(q̃) (m entries) into `out`.
pub(super) fn discrete_constraint(
    (c, at): (&dyn VelocityConstraints, DiscreteConstraint),
    mp: &mut Multipliers,
    (q0, h): (&[f64], f64),
    dq: &[f64],
    out: &mut [f64],
) -> Result<(), ModelError> {
    at_point(c, at, mp, q0, dq)?;
    for (k, o) in out.iter_mut().enumerate() {
        *o = mp.a_mid.row(k).iter().zip(dq).map(|(a, d)| a * d).sum::<f64>() + h * mp.b_mid[k];
    }
    Ok(())
}

/// ∂F/∂x for x = (λ, s) from the scheme's exact Jacobian `block` (u × u, in s):
///
/// ∂F_s/∂s = block,   ∂F_s/∂λ = −(h/2)A(q₀)ᵀ (last block),
/// ∂(A(q̃)δq + h b(q̃))/∂δqᵢ = A(q̃)eᵢ + w((∂A/∂qᵢ)(q̃)δq + h(∂b/∂qᵢ)(q̃)),
///
/// the derivatives of A and b counting by w = ∂q̃/∂δq: half at the midpoint, none at the start.
pub(super) fn jacobian(
    (c, at): (&dyn VelocityConstraints, DiscreteConstraint),
    mp: &mut Multipliers,
    block: &DMatrix<f64>,
    (q0, h): (&[f64], f64),
    x: &[f64],
    jac: &mut DMatrix<f64>,
) -> Result<(), ModelError> {
    let (n, m) = (q0.len(), mp.g0.nrows());
    let u = x.len() - m;
    let dq = &x[x.len() - n..];
    at_point(c, at, mp, q0, dq)?;
    jac.fill(0.0);
    jac.view_mut((0, m), (u, u)).copy_from(block);
    // At the start A(q̃) does not move with δq: its derivatives are not needed.
    let w = at.weight();
    for i in 0..n {
        if w != 0.0 {
            c.derivative(&mp.midpoint, i, &mut mp.da)?;
            c.offset_derivative(&mp.midpoint, i, &mut mp.db)?;
        }
        for k in 0..m {
            let bend = if w != 0.0 {
                w * (mp.da.row(k).iter().zip(dq).map(|(a, d)| a * d).sum::<f64>() + h * mp.db[k])
            } else {
                0.0
            };
            jac[(u + k, m + u - n + i)] = mp.a_mid[(k, i)] + bend;
            jac[(u - n + i, k)] = -0.5 * h * mp.g0[(k, i)];
        }
    }
    Ok(())
}
