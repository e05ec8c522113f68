use super::{Problem, State};
use crate::model::Lagrangian;
use crate::{Error, ModelError};

/// The damped, driven pendulum in its angle θ from the downward vertical:
///
/// L = ½ml²θ̇² + mgl cos θ,   f(θ, θ̇, t) = −γθ̇ + A cos Ωt,
///
/// the generalized force of the Rayleigh dissipation R = ½γθ̇² and of a driving torque. The
/// equation of motion ml²θ̈ + γθ̇ + mgl sin θ = A cos Ωt is, for m = l = g = 1, Baker & Gollub's
/// θ̈ + θ̇/q + sin θ = g cos ω_D t. Forced, so its energy E = ½ml²θ̇² − mgl cos θ is not
/// conserved: it changes by the work of f (the discrete Lagrange–d'Alembert principle).
#[derive(Clone, Debug)]
pub struct DampedDrivenPendulum {
    m: f64,
    l: f64,
    g: f64,
    gamma: f64,
    amplitude: f64,
    drive: f64,
}

impl DampedDrivenPendulum {
    pub fn new(m: f64, l: f64, g: f64, gamma: f64, amplitude: f64, drive: f64) -> Result<Self, Error> {
        super::positive(&[("m", m), ("l", l)])?;
        // R = ½γθ̇² dissipates only for γ ≥ 0.
        if !(gamma.is_finite() && gamma >= 0.0) {
            return Err(Error::invalid(
                "gamma",
                format!("must be finite and non-negative, got {gamma}"),
            ));
        }
        super::finite(&[("g", g), ("amplitude", amplitude), ("drive", drive)])?;
        Ok(DampedDrivenPendulum {
            m,
            l,
            g,
            gamma,
            amplitude,
            drive,
        })
    }

    /// m = l = g = 1 with damping γ, driving amplitude A and frequency Ω, from rest at the
    /// bottom to t = 100. No reference: in Baker & Gollub's chaotic regime γ = 1/q = 0.5,
    /// A = g = 1.5, Ω = ω_D = 2/3 (Chaotic Dynamics, 1990) nearby solutions part exponentially.
    pub fn problem(gamma: f64, amplitude: f64, drive: f64) -> Result<Problem<Self>, Error> {
        Ok(Problem {
            system: Self::new(1.0, 1.0, 1.0, gamma, amplitude, drive)?,
            initial: State::start(vec![0.0], vec![0.0]),
            t_end: 100.0,
            reference: None,
        })
    }
}

impl Lagrangian for DampedDrivenPendulum {
    fn dim(&self) -> usize {
        1
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        Ok(0.5 * self.m * self.l * self.l * v[0] * v[0] + self.m * self.g * self.l * q[0].cos())
    }

    fn dl_dq(&self, q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out[0] = -self.m * self.g * self.l * q[0].sin();
        Ok(())
    }

    fn dl_dv(&self, _q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out[0] = self.m * self.l * self.l * v[0];
        Ok(())
    }

    fn velocity(&self, _q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        v[0] = p[0] / (self.m * self.l * self.l);
        Ok(())
    }

    fn is_forced(&self) -> bool {
        true
    }

    /// f = −γθ̇ + A cos Ωt.
    fn force(&self, _q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out[0] = -self.gamma * v[0] + self.amplitude * (self.drive * t).cos();
        Ok(())
    }
}
