use super::{Problem, State};
use crate::model::{Generator, Hessians, Lagrangian};
use crate::{Error, ModelError};

/// The spherical pendulum in its polar angle θ from the downward vertical and its azimuth φ:
///
/// L = ½ml²(θ̇² + sin²θ φ̇²) + mgl cos θ.
///
/// Its mass matrix depends on θ, so it is a general Lagrangian; φ is cyclic, and its momentum
/// p_φ = ml² sin²θ φ̇ is conserved (by the variational integrators, to round-off).
#[derive(Clone, Debug)]
pub struct SphericalPendulum {
    m: f64,
    l: f64,
    g: f64,
}

impl SphericalPendulum {
    pub fn new(m: f64, l: f64, g: f64) -> Result<Self, Error> {
        super::positive(&[("m", m), ("l", l)])?;
        if !g.is_finite() {
            return Err(Error::invalid("g", "must be finite"));
        }
        Ok(SphericalPendulum { m, l, g })
    }

    /// The cyclic azimuth, whose momentum is conserved.
    pub fn symmetries(&self) -> Vec<Generator> {
        vec![Generator::Cyclic { index: 1 }]
    }

    /// m = l = g = 1 from θ = 1, θ̇ = 0, φ̇ = 1.2 to T = 50, against the reference of
    /// reference/scenes.json (p_φ = 0.8496881019282854, E = −0.030489444711168545).
    pub fn problem() -> Problem<Self> {
        let system = Self::new(1.0, 1.0, 1.0).expect("valid parameters");
        let momentum = |q: &[f64], v: &[f64]| {
            let mut p = vec![0.0; 2];
            system.dl_dv(q, v, 0.0, &mut p).expect("exact");
            p
        };
        let q0 = vec![1.0, 0.0];
        let p0 = momentum(&q0, &[0.0, 1.2]);
        // The reference gives the angles; p_φ is conserved and p_θ is not given, so the
        // reference momentum holds p_φ and NaN for p_θ.
        let reference = State {
            t: 50.0,
            q: vec![0.962577918129, 65.170838533326],
            p: vec![f64::NAN, p0[1]],
        };
        Problem {
            initial: State::start(q0, p0),
            t_end: 50.0,
            reference: Some((
                reference,
                "reference/scenes.json (spherical pendulum; angles at T = 50)",
            )),
            system,
        }
    }
}

impl Lagrangian for SphericalPendulum {
    fn dim(&self) -> usize {
        2
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        let ml2 = self.m * self.l * self.l;
        let s = q[0].sin();
        Ok(0.5 * ml2 * (v[0] * v[0] + s * s * v[1] * v[1]) + self.m * self.g * self.l * q[0].cos())
    }

    fn dl_dq(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let ml2 = self.m * self.l * self.l;
        let (s, c) = q[0].sin_cos();
        out[0] = ml2 * s * c * v[1] * v[1] - self.m * self.g * self.l * s;
        out[1] = 0.0;
        Ok(())
    }

    fn dl_dv(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let ml2 = self.m * self.l * self.l;
        let s = q[0].sin();
        out[0] = ml2 * v[0];
        out[1] = ml2 * s * s * v[1];
        Ok(())
    }

    /// ∂²L/∂θ² = ml²cos 2θ φ̇² − mgl cos θ, ∂²L/∂θ∂φ̇ = ml² sin 2θ φ̇,
    /// ∂²L/∂q̇² = ml² diag(1, sin²θ).
    fn hessians(&self, q: &[f64], v: &[f64], _t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        let ml2 = self.m * self.l * self.l;
        let (s, c) = q[0].sin_cos();
        out.qq.fill(0.0);
        out.qv.fill(0.0);
        out.vv.fill(0.0);
        out.qq[(0, 0)] = ml2 * (c * c - s * s) * v[1] * v[1] - self.m * self.g * self.l * c;
        out.qv[(0, 1)] = 2.0 * ml2 * s * c * v[1];
        out.vv[(0, 0)] = ml2;
        out.vv[(1, 1)] = ml2 * s * s;
        Ok(true)
    }

    fn velocity(&self, q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        let ml2 = self.m * self.l * self.l;
        let s = q[0].sin();
        v[0] = p[0] / ml2;
        v[1] = p[1] / (ml2 * s * s);
        Ok(())
    }
}
