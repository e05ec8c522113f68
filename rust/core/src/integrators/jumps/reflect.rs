//! The reflection law: the exact reflection in the metric of the kinetic energy.

use super::{Impact, Jump};
use crate::model::Lagrangian;
use crate::ModelError;

/// Newton's law: the reflection with the contact's restitution, and its loss.
pub(super) fn newton(impact: &mut dyn Impact) -> Jump {
    let (reflection, e) = impact.newton();
    Jump {
        lambda: reflection.lambda,
        loss: reflection.loss(e),
        restitution: e,
        grazing: false,
    }
}

/// The reflection of p at (t, q) off the normal n in the metric of the kinetic energy: λ of
/// p⁺ = p + λn such that the normal velocity n·q̇ goes to −e times itself,
/// λ = −(1 + e)(n·q̇)/(nᵀM⁻¹n), with q̇ = q̇(q, p) and M⁻¹n = q̇(q, n) − q̇(q, 0) by the model's
/// inverse Legendre map (which holds for any Lagrangian quadratic in q̇), and the energy it
/// takes ([`Reflection::loss`]). `v` and `w` are work buffers of n entries, `zeros` n zeros.
pub(super) fn reflection(
    model: &dyn Lagrangian,
    (t, q, p): (f64, &[f64], &[f64]),
    normal: &[f64],
    restitution: f64,
    (v, w, zeros): (&mut [f64], &mut [f64], &[f64]),
) -> Result<Reflection, ModelError> {
    model.velocity(q, p, t, v)?;
    let normal_velocity = dot(normal, v);
    model.velocity(q, normal, t, v)?;
    model.velocity(q, zeros, t, w)?;
    let metric = normal
        .iter()
        .zip(v.iter().zip(w.iter()))
        .map(|(n, (a, b))| n * (a - b))
        .sum::<f64>();
    Ok(Reflection {
        lambda: -(1.0 + restitution) * normal_velocity / metric,
        normal_velocity,
        metric,
    })
}

/// A reflection: its multiplier λ, the normal velocity n·q̇ before it and the metric nᵀM⁻¹n.
#[derive(Clone, Copy, Debug)]
pub(super) struct Reflection {
    pub lambda: f64,
    normal_velocity: f64,
    metric: f64,
}

impl Reflection {
    /// The change of the energy E = ½(p − a)ᵀM⁻¹(p − a) + V by the reflection with
    /// restitution e from the same state: λ(n·q̇) + ½λ²nᵀM⁻¹n = −(1 − e²)/2 (n·q̇)²/(nᵀM⁻¹n),
    /// the law's own loss, 0 for e = 1 exactly (the method's energy error is not counted as
    /// one), all the normal kinetic energy for e = 0 (a contact that closes).
    pub(super) fn loss(&self, e: f64) -> f64 {
        -(1.0 - e * e) / 2.0 * self.normal_velocity * self.normal_velocity / self.metric
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
