use super::{Problem, State};
use crate::model::{Generator, Lagrangian};
use crate::{Error, ModelError};

/// A charged particle moving in the plane (x, y) through the magnetic field
/// B(q) = B₀(1 + κ|q|²) ẑ normal to it (B₀ is `b`), in the symmetric gauge:
///
/// L = ½m|q̇|² + e A(q)·q̇,   A(q) = ½B₀(1 + ½κ|q|²)(−y, x),   ∇×A = B(q).
///
/// κ = 0 is the uniform field, in which the particle gyrates at Ω = eB₀/m. L is invariant
/// under rotations about the origin, so the canonical angular momentum
/// J = x p_y − y p_x = m(xẏ − yẋ) + ½eB₀(1 + ½κ|q|²)|q|² is conserved (by the variational
/// integrators, to round-off), with the energy E = ½m|q̇|². L is linear in q̇ beyond the kinetic
/// term, so it is a general Lagrangian (integrated by the implicit variational methods).
#[derive(Clone, Debug)]
pub struct ChargedParticle {
    m: f64,
    charge: f64,
    b: f64,
    kappa: f64,
}

impl ChargedParticle {
    pub fn new(m: f64, charge: f64, b: f64, kappa: f64) -> Result<Self, Error> {
        super::positive(&[("m", m)])?;
        super::finite(&[("charge", charge), ("B", b), ("kappa", kappa)])?;
        Ok(ChargedParticle { m, charge, b, kappa })
    }

    /// The gyrofrequency Ω = eB₀/m at the origin (everywhere when κ = 0).
    pub fn gyrofrequency(&self) -> f64 {
        self.charge * self.b / self.m
    }

    /// Rotation about the origin, whose momentum J = x p_y − y p_x is conserved.
    pub fn symmetries(&self) -> Vec<Generator> {
        vec![Generator::Rotation {
            axis: 2,
            spatial_dim: 2,
        }]
    }

    /// eA(q) = a(|q|²)(−y, x) with a(r²) = ½eB₀(1 + ½κr²): returns a and da/d(r²).
    fn gauge(&self, q: &[f64]) -> (f64, f64) {
        let c = 0.5 * self.charge * self.b;
        (
            c * (1.0 + 0.5 * self.kappa * (q[0] * q[0] + q[1] * q[1])),
            0.5 * c * self.kappa,
        )
    }

    /// m = e = 1 in the uniform field B ẑ, from q = (1, 0), q̇ = (0, −B) to t = 10: the circle
    /// q(t) = (cos Ωt, −sin Ωt) about the origin with Ω = B, exact.
    pub fn uniform_field(b: f64) -> Result<Problem<Self>, Error> {
        let system = Self::new(1.0, 1.0, b, 0.0)?;
        let omega = system.gyrofrequency();
        let state = |t: f64| {
            let (s, c) = (omega * t).sin_cos();
            let q = vec![c, -s];
            let mut p = vec![0.0; 2];
            system.dl_dv(&q, &[-omega * s, -omega * c], t, &mut p).expect("exact");
            State { t, q, p }
        };
        let t_end = 10.0;
        Ok(Problem {
            initial: state(0.0),
            reference: Some((state(t_end), "exact solution (gyration at Ω = eB/m)")),
            t_end,
            system,
        })
    }

    /// m = e = B₀ = 1 and κ = 1/4, the field B(q) = (1 + |q|²/4) ẑ, from q = (1, 0),
    /// q̇ = (0, −1) to t = 200 (E = ½, J = −7/16): gyration with a drift about the origin.
    pub fn nonuniform_field() -> Problem<Self> {
        let system = Self::new(1.0, 1.0, 1.0, 0.25).expect("valid parameters");
        let q = vec![1.0, 0.0];
        let mut p = vec![0.0; 2];
        system.dl_dv(&q, &[0.0, -1.0], 0.0, &mut p).expect("exact");
        Problem {
            initial: State::start(q, p),
            t_end: 200.0,
            reference: None,
            system,
        }
    }
}

impl Lagrangian for ChargedParticle {
    fn dim(&self) -> usize {
        2
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        let (a, _) = self.gauge(q);
        Ok(0.5 * self.m * (v[0] * v[0] + v[1] * v[1]) + a * (q[0] * v[1] - q[1] * v[0]))
    }

    /// ∂L/∂q = a (v_y, −v_x) + 2a′(xv_y − yv_x) q.
    fn dl_dq(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let (a, da) = self.gauge(q);
        let w = 2.0 * da * (q[0] * v[1] - q[1] * v[0]);
        out[0] = a * v[1] + w * q[0];
        out[1] = -a * v[0] + w * q[1];
        Ok(())
    }

    /// p = mq̇ + eA(q).
    fn dl_dv(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let (a, _) = self.gauge(q);
        out[0] = self.m * v[0] - a * q[1];
        out[1] = self.m * v[1] + a * q[0];
        Ok(())
    }

    /// q̇ = (p − eA(q))/m.
    fn velocity(&self, q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        let (a, _) = self.gauge(q);
        v[0] = (p[0] + a * q[1]) / self.m;
        v[1] = (p[1] - a * q[0]) / self.m;
        Ok(())
    }
}
