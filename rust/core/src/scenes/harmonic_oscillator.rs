use super::{Problem, State};
use crate::model::{Mass, MechanicalSystem};
use crate::{Error, ModelError};

/// The harmonic oscillator, H = p²/2 + ω²q²/2: the linear test equation q̈ = −ω²q on which
/// linear stability limits hω_max are defined.
#[derive(Clone, Debug)]
pub struct HarmonicOscillator {
    omega: f64,
    mass: Mass,
}

impl HarmonicOscillator {
    pub fn new(omega: f64) -> Result<Self, Error> {
        super::positive(&[("omega", omega)])?;
        Ok(HarmonicOscillator {
            omega,
            mass: Mass::Scalar(1.0),
        })
    }

    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// The exact flow: q(t) = q₀cos ωt + (p₀/ω)sin ωt, p(t) = −q₀ω sin ωt + p₀cos ωt.
    pub fn exact(&self, q0: f64, p0: f64, t: f64) -> (f64, f64) {
        let (s, c) = (self.omega * t).sin_cos();
        (q0 * c + p0 / self.omega * s, -q0 * self.omega * s + p0 * c)
    }

    /// From (q, p) = (0, 1) to t = 10, against the exact solution.
    pub fn problem(omega: f64) -> Result<Problem<Self>, Error> {
        let system = Self::new(omega)?;
        let t_end = 10.0;
        let (q, p) = system.exact(0.0, 1.0, t_end);
        let reference = State {
            t: t_end,
            q: vec![q],
            p: vec![p],
        };
        Ok(Problem {
            system,
            initial: State::start(vec![0.0], vec![1.0]),
            t_end,
            reference: Some((reference, "exact solution")),
        })
    }
}

impl MechanicalSystem for HarmonicOscillator {
    fn dim(&self) -> usize {
        1
    }
    fn mass(&self) -> &Mass {
        &self.mass
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok(0.5 * self.omega * self.omega * q[0] * q[0])
    }
    #[inline]
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad[0] = self.omega * self.omega * q[0];
        Ok(())
    }
}
