//! The discrete constraint of velocity constraints A(q)q̇ + b(q) = 0 in the reversible
//! discrete Lagrange–d'Alembert step (see [`super::Del`]): A(q̄)δq + h b(q̄) = 0 at the
//! midpoint q̄ = q₀ + δq/2, and its derivatives for Newton's exact Jacobian.

use nalgebra::DMatrix;

use super::constrained::Multipliers;
use crate::model::VelocityConstraints;
use crate::ModelError;

/// q̄ = q₀ + δq/2 into `mp.midpoint`, A(q̄) into `mp.a_mid` and b(q̄) into `mp.b_mid`.
fn at_midpoint(c: &dyn VelocityConstraints, mp: &mut Multipliers, q0: &[f64], dq: &[f64]) -> Result<(), ModelError> {
    for ((b, q), d) in mp.midpoint.iter_mut().zip(q0).zip(dq) {
        *b = q + 0.5 * d;
    }
    c.matrix(&mp.midpoint, &mut mp.a_mid)?;
    c.offset(&mp.midpoint, &mut mp.b_mid)
}

/// A(q̄)δq + h b(q̄) (m entries) into `out`.
pub(super) fn discrete_constraint(
    c: &dyn VelocityConstraints,
    mp: &mut Multipliers,
    (q0, h): (&[f64], f64),
    dq: &[f64],
    out: &mut [f64],
) -> Result<(), ModelError> {
    at_midpoint(c, mp, q0, dq)?;
    for (k, o) in out.iter_mut().enumerate() {
        *o = mp.a_mid.row(k).iter().zip(dq).map(|(a, d)| a * d).sum::<f64>() + h * mp.b_mid[k];
    }
    Ok(())
}

/// ∂F/∂x for x = (λ, s) from the scheme's exact Jacobian `block` (u × u, in s):
///
/// ∂F_s/∂s = block,   ∂F_s/∂λ = −(h/2)A(q₀)ᵀ (last block),
/// ∂(A(q̄)δq + h b(q̄))/∂δqᵢ = A(q̄)eᵢ + ½(∂A/∂qᵢ)(q̄)δq + ½h(∂b/∂qᵢ)(q̄),
///
/// the derivatives of A and b counting half since q̄ moves by half of δq.
pub(super) fn jacobian(
    c: &dyn VelocityConstraints,
    mp: &mut Multipliers,
    block: &DMatrix<f64>,
    (q0, h): (&[f64], f64),
    x: &[f64],
    jac: &mut DMatrix<f64>,
) -> Result<(), ModelError> {
    let (n, m) = (q0.len(), mp.g0.nrows());
    let u = x.len() - m;
    let dq = &x[x.len() - n..];
    at_midpoint(c, mp, q0, dq)?;
    jac.fill(0.0);
    jac.view_mut((0, m), (u, u)).copy_from(block);
    for i in 0..n {
        c.derivative(&mp.midpoint, i, &mut mp.da)?;
        c.offset_derivative(&mp.midpoint, i, &mut mp.db)?;
        for k in 0..m {
            let bend: f64 = mp.da.row(k).iter().zip(dq).map(|(a, d)| a * d).sum();
            jac[(u + k, m + u - n + i)] = mp.a_mid[(k, i)] + 0.5 * (bend + h * mp.db[k]);
            jac[(u - n + i, k)] = -0.5 * h * mp.g0[(k, i)];
        }
    }
    Ok(())
}
