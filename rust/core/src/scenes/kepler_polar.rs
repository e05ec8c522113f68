use super::{Problem, State};
use crate::model::{Generator, Hessians, Lagrangian};
use crate::{Error, ModelError};

/// The Kepler problem in plane polar coordinates q = (r, θ):
///
/// L = ½m(ṙ² + r²θ̇²) + k/r.
///
/// Its mass matrix depends on r, so it is a general Lagrangian; θ is cyclic, and its momentum
/// (the angular momentum) p_θ = mr²θ̇ is conserved (by the variational integrators, to
/// round-off). It is the Cartesian [`super::Kepler`] in other coordinates (m = k = 1), written
/// for Routh reduction: R = ½mṙ² − p_θ²/(2mr²) + k/r.
#[derive(Clone, Debug)]
pub struct KeplerPolar {
    m: f64,
    k: f64,
}

impl KeplerPolar {
    pub fn new(m: f64, k: f64) -> Result<Self, Error> {
        super::positive(&[("m", m), ("k", k)])?;
        Ok(KeplerPolar { m, k })
    }

    /// The cyclic polar angle, whose momentum p_θ is conserved.
    pub fn symmetries(&self) -> Vec<Generator> {
        vec![Generator::Cyclic { index: 1 }]
    }

    /// The orbit of [`super::Kepler::problem`] in polar coordinates (m = k = 1): from the
    /// pericentre r₀ = 1 − e, θ₀ = 0, ṙ₀ = 0 with p_θ = √(1 − e²), whose period is 2π and
    /// energy −½, over 200 periods. The exact final state is r = 1 − e, θ = 400π (θ is not
    /// reduced modulo 2π), p = (0, √(1 − e²)).
    pub fn problem(e: f64) -> Result<Problem<Self>, Error> {
        if !(0.0..1.0).contains(&e) {
            return Err(Error::invalid("e", format!("eccentricity must lie in [0, 1), got {e}")));
        }
        let t_end = 200.0 * 2.0 * std::f64::consts::PI;
        let p = vec![0.0, (1.0 - e * e).sqrt()];
        let initial = State::start(vec![1.0 - e, 0.0], p.clone());
        let reference = State {
            t: t_end,
            q: vec![1.0 - e, 400.0 * std::f64::consts::PI],
            p,
        };
        Ok(Problem {
            system: Self::new(1.0, 1.0)?,
            initial,
            t_end,
            reference: Some((reference, "exact: 200 whole periods")),
        })
    }
}

impl Lagrangian for KeplerPolar {
    fn dim(&self) -> usize {
        2
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        let r = q[0];
        Ok(0.5 * self.m * (v[0] * v[0] + r * r * v[1] * v[1]) + self.k / r)
    }

    /// ∂L/∂r = mrθ̇² − k/r², ∂L/∂θ = 0.
    fn dl_dq(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let r = q[0];
        out[0] = self.m * r * v[1] * v[1] - self.k / (r * r);
        out[1] = 0.0;
        Ok(())
    }

    /// p_r = mṙ, p_θ = mr²θ̇.
    fn dl_dv(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let r = q[0];
        out[0] = self.m * v[0];
        out[1] = self.m * r * r * v[1];
        Ok(())
    }

    /// L_qq = [[mθ̇² + 2k/r³, 0], [0, 0]], L_qq̇ = [[0, 2mrθ̇], [0, 0]] (entry (i, j) is
    /// ∂²L/∂qᵢ∂q̇ⱼ), L_q̇q̇ = diag(m, mr²).
    fn hessians(&self, q: &[f64], v: &[f64], _t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        let r = q[0];
        out.qq.fill(0.0);
        out.qq[(0, 0)] = self.m * v[1] * v[1] + 2.0 * self.k / (r * r * r);
        out.qv.fill(0.0);
        out.qv[(0, 1)] = 2.0 * self.m * r * v[1];
        out.vv.fill(0.0);
        out.vv[(0, 0)] = self.m;
        out.vv[(1, 1)] = self.m * r * r;
        Ok(true)
    }

    /// ṙ = p_r/m, θ̇ = p_θ/(mr²).
    fn velocity(&self, q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        let r = q[0];
        v[0] = p[0] / self.m;
        v[1] = p[1] / (self.m * r * r);
        Ok(())
    }
}
