//! The reflection law: the exact reflection in the metric of the kinetic energy.

use crate::model::Lagrangian;
use crate::ModelError;

/// λ of p⁺ = p + λn at (t, q, p) such that the normal velocity n·q̇ goes to −e times itself:
/// λ = −(1 + e)(n·q̇)/(nᵀM⁻¹n), with q̇ = q̇(q, p) and M⁻¹n = q̇(q, n) − q̇(q, 0) by the model's
/// inverse Legendre map (which holds for any Lagrangian quadratic in q̇). It keeps H at the
/// impact for e = 1. `v` and `w` are work buffers of n entries, `zeros` n zeros.
pub(super) fn multiplier(
    model: &dyn Lagrangian,
    (t, q, p): (f64, &[f64], &[f64]),
    normal: &[f64],
    restitution: f64,
    (v, w, zeros): (&mut [f64], &mut [f64], &[f64]),
) -> Result<f64, ModelError> {
    model.velocity(q, p, t, v)?;
    let normal_velocity = dot(normal, v);
    model.velocity(q, normal, t, v)?;
    model.velocity(q, zeros, t, w)?;
    let metric = normal
        .iter()
        .zip(v.iter().zip(w.iter()))
        .map(|(n, (a, b))| n * (a - b))
        .sum::<f64>();
    Ok(-(1.0 + restitution) * normal_velocity / metric)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
