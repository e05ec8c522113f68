use super::{Problem, State};
use crate::model::{Hessians, Lagrangian};
use crate::{Error, ModelError};

/// The planar double pendulum in its two angles from the downward vertical:
///
/// L = ½(m₁+m₂)l₁²θ̇₁² + ½m₂l₂²θ̇₂² + m₂l₁l₂θ̇₁θ̇₂cos(θ₁−θ₂) + (m₁+m₂)gl₁cos θ₁ + m₂gl₂cos θ₂.
///
/// Its mass matrix depends on the configuration, so it is a general Lagrangian (integrated by
/// the implicit variational methods), with exact derivatives.
#[derive(Clone, Debug)]
pub struct DoublePendulum {
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
}

impl DoublePendulum {
    pub fn new(m1: f64, m2: f64, l1: f64, l2: f64, g: f64) -> Result<Self, Error> {
        super::positive(&[("m1", m1), ("m2", m2), ("l1", l1), ("l2", l2)])?;
        if !g.is_finite() {
            return Err(Error::invalid("g", "must be finite"));
        }
        Ok(DoublePendulum { m1, m2, l1, l2, g })
    }

    /// The mass matrix M(θ): L = ½θ̇ᵀM(θ)θ̇ − V(θ).
    fn mass(&self, q: &[f64]) -> [[f64; 2]; 2] {
        self.mass_at((q[0] - q[1]).cos())
    }

    /// M(θ) from cos(θ₁ − θ₂).
    fn mass_at(&self, cos_delta: f64) -> [[f64; 2]; 2] {
        let c = self.m2 * self.l1 * self.l2 * cos_delta;
        [
            [(self.m1 + self.m2) * self.l1 * self.l1, c],
            [c, self.m2 * self.l2 * self.l2],
        ]
    }

    /// ∂L/∂θ = ∓m₂l₁l₂θ̇₁θ̇₂ sin(θ₁ − θ₂) − ∂V/∂θ, from sin(θ₁ − θ₂).
    fn dl_dq_at(&self, q: &[f64], v: &[f64], sin_delta: f64, out: &mut [f64]) {
        let k = self.m2 * self.l1 * self.l2 * v[0] * v[1] * sin_delta;
        out[0] = -k - (self.m1 + self.m2) * self.g * self.l1 * q[0].sin();
        out[1] = k - self.m2 * self.g * self.l2 * q[1].sin();
    }

    /// ∂L/∂θ̇ = M(θ)θ̇, from cos(θ₁ − θ₂).
    fn dl_dv_at(&self, v: &[f64], cos_delta: f64, out: &mut [f64]) {
        let [[a, b], [_, d]] = self.mass_at(cos_delta);
        out[0] = a * v[0] + b * v[1];
        out[1] = b * v[0] + d * v[1];
    }

    /// GeometricProblems.jl's defaults (l = (2, 3), m = (1, 2), g = 9.80665), from
    /// θ = (π/4, π/2), θ̇ = (0, π/8) to T = 10, against its reference (accurate to about 1e-11).
    pub fn problem() -> Problem<Self> {
        let system = Self::new(1.0, 2.0, 2.0, 3.0, 9.80665).expect("valid parameters");
        let momentum = |q: &[f64], v: &[f64]| {
            let mut p = vec![0.0; 2];
            system.dl_dv(q, v, 0.0, &mut p).expect("exact");
            p
        };
        let q0 = vec![std::f64::consts::FRAC_PI_4, std::f64::consts::FRAC_PI_2];
        let p0 = momentum(&q0, &[0.0, std::f64::consts::PI / 8.0]);
        let q_ref = vec![0.87467888012, 0.55850349694];
        let p_ref = momentum(&q_ref, &[-4.08255226002, 1.66594428518]);
        Problem {
            initial: State::start(q0, p0),
            t_end: 10.0,
            reference: Some((
                State {
                    t: 10.0,
                    q: q_ref,
                    p: p_ref,
                },
                "GeometricProblems.jl (double pendulum), accurate to about 1e-11",
            )),
            system,
        }
    }
}

impl Lagrangian for DoublePendulum {
    fn dim(&self) -> usize {
        2
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        let [[a, b], [_, d]] = self.mass(q);
        let kinetic = 0.5 * (a * v[0] * v[0] + 2.0 * b * v[0] * v[1] + d * v[1] * v[1]);
        let potential = -(self.m1 + self.m2) * self.g * self.l1 * q[0].cos() - self.m2 * self.g * self.l2 * q[1].cos();
        Ok(kinetic - potential)
    }

    fn dl_dq(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.dl_dq_at(q, v, (q[0] - q[1]).sin(), out);
        Ok(())
    }

    fn dl_dv(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.dl_dv_at(v, (q[0] - q[1]).cos(), out);
        Ok(())
    }

    /// Both first derivatives from one sin_cos(θ₁ − θ₂), which they share.
    fn gradients(&self, q: &[f64], v: &[f64], _t: f64, dq: &mut [f64], dv: &mut [f64]) -> Result<(), ModelError> {
        // Every length checked first, so that no branch parts sin and cos (one libm sincos).
        let (q, v, dq, dv) = (&q[..2], &v[..2], &mut dq[..2], &mut dv[..2]);
        let (s, c) = (q[0] - q[1]).sin_cos();
        self.dl_dq_at(q, v, s, dq);
        self.dl_dv_at(v, c, dv);
        Ok(())
    }

    /// With δ = θ₁ − θ₂, k = m₂l₁l₂: L_qq = [[−kθ̇₁θ̇₂cos δ − (m₁+m₂)gl₁cos θ₁, kθ̇₁θ̇₂cos δ],
    /// [kθ̇₁θ̇₂cos δ, −kθ̇₁θ̇₂cos δ − m₂gl₂cos θ₂]], L_qq̇ = k sin δ·[[−θ̇₂, −θ̇₁], [θ̇₂, θ̇₁]],
    /// L_q̇q̇ = M(θ).
    fn hessians(&self, q: &[f64], v: &[f64], _t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        let k = self.m2 * self.l1 * self.l2;
        let (s, c) = (q[0] - q[1]).sin_cos();
        let w = k * v[0] * v[1] * c;
        out.qq.copy_from_slice(&[
            -w - (self.m1 + self.m2) * self.g * self.l1 * q[0].cos(),
            w,
            w,
            -w - self.m2 * self.g * self.l2 * q[1].cos(),
        ]);
        // Column-major: (0,0), (1,0), (0,1), (1,1).
        out.qv
            .copy_from_slice(&[-k * s * v[1], k * s * v[1], -k * s * v[0], k * s * v[0]]);
        let [[a, b], [_, d]] = self.mass(q);
        out.vv.copy_from_slice(&[a, b, b, d]);
        Ok(true)
    }

    /// θ̇ = M(θ)⁻¹p.
    fn velocity(&self, q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        let [[a, b], [_, d]] = self.mass(q);
        let det = a * d - b * b;
        v[0] = (d * p[0] - b * p[1]) / det;
        v[1] = (a * p[1] - b * p[0]) / det;
        Ok(())
    }
}
