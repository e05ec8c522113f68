use super::{Problem, State};
use crate::model::{Anchor, Constrained, Distances, Lagrangian, Link};
use crate::{Error, ModelError};

/// A rigid body about a fixed point in unit quaternions q = (q₁, q₂, q₃, q₄), scalar part
/// first, with principal moments I and a potential U(q) = q₁² − q₂² − q₃² + q₄² (HLW's GNI
/// rigid-body example), on the constraint |q|² = 1 (HLW VII.5).
///
/// The body angular velocity is ω = 2E(q)q̇ with E(q) = [−q_v, q₁I − \[q_v\]×] (3 × 4), so
/// T = ½ωᵀIω = 2q̇ᵀE(q)ᵀIE(q)q̇. That quadratic form is singular along q, so T gets
/// (α/2)(q·q̇)², which vanishes on the hidden constraint q·q̇ = 0 and leaves the motion
/// unchanged: L = 2q̇ᵀEᵀIEq̇ + (α/2)(q·q̇)² − U(q), a natural system with
/// M(q) = 4EᵀIE + αqqᵀ, inverted in closed form (the rows of E and q are orthogonal, each of
/// norm |q|).
#[derive(Clone, Debug)]
pub struct RigidBody {
    inertia: [f64; 3],
    alpha: f64,
}

/// The 3-vector E(q)x = q₁x_v − x₁q_v − q_v × x_v.
fn e_times(q: &[f64], x: &[f64]) -> [f64; 3] {
    let (qv, xv) = ([q[1], q[2], q[3]], [x[1], x[2], x[3]]);
    let cross = [
        qv[1] * xv[2] - qv[2] * xv[1],
        qv[2] * xv[0] - qv[0] * xv[2],
        qv[0] * xv[1] - qv[1] * xv[0],
    ];
    [0, 1, 2].map(|k| q[0] * xv[k] - x[0] * qv[k] - cross[k])
}

/// E(q)ᵀw, the 4-vector: (−q_v·w, q₁w + q_v × w).
fn e_transpose_times(q: &[f64], w: &[f64; 3]) -> [f64; 4] {
    let qv = [q[1], q[2], q[3]];
    [
        -(qv[0] * w[0] + qv[1] * w[1] + qv[2] * w[2]),
        q[0] * w[0] + qv[1] * w[2] - qv[2] * w[1],
        q[0] * w[1] + qv[2] * w[0] - qv[0] * w[2],
        q[0] * w[2] + qv[0] * w[1] - qv[1] * w[0],
    ]
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl RigidBody {
    pub fn new(inertia: [f64; 3]) -> Result<Self, Error> {
        if !inertia.iter().all(|i| i.is_finite() && *i > 0.0) {
            return Err(Error::invalid(
                "inertia",
                format!("must be finite and positive, got {inertia:?}"),
            ));
        }
        let alpha = 4.0 * inertia.iter().sum::<f64>() / 3.0;
        Ok(RigidBody { inertia, alpha })
    }

    /// HLW's data: I = (0.5, 0.9, 1.0), q₀ = (0.4, 0.2, 0.4, √0.64), body angular momentum
    /// m₀ = Iω₀ = (0.2, 1, 0.4), q̇₀ = ½q₀ ⊗ (0, ω₀), to T = 10.
    pub fn problem() -> Problem<Constrained<RigidBody, Distances>> {
        let system = RigidBody::new([0.5, 0.9, 1.0]).expect("valid parameters");
        let q0 = vec![0.4, 0.2, 0.4, 0.64f64.sqrt()];
        let omega = [0.2 / 0.5, 1.0 / 0.9, 0.4 / 1.0];
        // q̇ = ½E(q)ᵀω for unit q (E has orthonormal rows and Eq = 0).
        let v0 = e_transpose_times(&q0, &omega).map(|x| 0.5 * x);
        let mut p0 = vec![0.0; 4];
        system.dl_dv(&q0, &v0, 0.0, &mut p0).expect("exact");
        let constraints = Distances::new(
            4,
            vec![Link {
                body: 0,
                to: Anchor::Fixed(vec![0.0; 4]),
                length: 1.0,
            }],
        );
        Problem {
            system: Constrained { system, constraints },
            initial: State::start(q0, p0),
            t_end: 10.0,
            reference: None,
        }
    }
}

impl Lagrangian for RigidBody {
    fn dim(&self) -> usize {
        4
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        let w = e_times(q, v);
        let rotation: f64 = (0..3).map(|k| self.inertia[k] * w[k] * w[k]).sum();
        let s = dot(q, v);
        let potential = q[0] * q[0] - q[1] * q[1] - q[2] * q[2] + q[3] * q[3];
        Ok(2.0 * rotation + 0.5 * self.alpha * s * s - potential)
    }

    /// ∂T/∂q = −4E(q̇)ᵀIE(q)q̇ + α(q·q̇)q̇, since E(q)q̇ = −E(q̇)q; minus ∇U.
    fn dl_dq(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let w = e_times(q, v);
        let iw = [0, 1, 2].map(|k| self.inertia[k] * w[k]);
        let back = e_transpose_times(v, &iw);
        let s = dot(q, v);
        let grad_u = [2.0 * q[0], -2.0 * q[1], -2.0 * q[2], 2.0 * q[3]];
        for i in 0..4 {
            out[i] = -4.0 * back[i] + self.alpha * s * v[i] - grad_u[i];
        }
        Ok(())
    }

    /// p = M(q)q̇ = 4E(q)ᵀIE(q)q̇ + α(q·q̇)q.
    fn dl_dv(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let w = e_times(q, v);
        let iw = [0, 1, 2].map(|k| self.inertia[k] * w[k]);
        let back = e_transpose_times(q, &iw);
        let s = dot(q, v);
        for i in 0..4 {
            out[i] = 4.0 * back[i] + self.alpha * s * q[i];
        }
        Ok(())
    }

    /// q̇ = M(q)⁻¹p = (E(q)ᵀ(4I)⁻¹E(q)p + α⁻¹(q·p)q)/|q|⁴, exact.
    fn velocity(&self, q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        let w = e_times(q, p);
        let scaled = [0, 1, 2].map(|k| w[k] / (4.0 * self.inertia[k]));
        let back = e_transpose_times(q, &scaled);
        let (s, r2) = (dot(q, p), dot(q, q));
        for i in 0..4 {
            v[i] = (back[i] + s * q[i] / self.alpha) / (r2 * r2);
        }
        Ok(())
    }
}
