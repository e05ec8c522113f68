use super::{Problem, State};
use crate::model::{Generator, Mass, MechanicalSystem};
use crate::{Error, ModelError};

/// The Kepler problem in the plane, H = |p|²/2 − 1/|q| (HLW I.2): two Cartesian coordinates,
/// rotation invariant (its angular momentum L = q₁p₂ − q₂p₁ is conserved).
#[derive(Clone, Debug)]
pub struct Kepler {
    mass: Mass,
}

unit_mass!(Kepler);

impl Kepler {
    /// HLW's work–precision protocol: q = (1 − e, 0), p = (0, √((1+e)/(1−e))), whose orbit has
    /// period 2π, H = −1/2 and L = √(1 − e²); integrated over 200 periods, after which the exact
    /// state is the initial state.
    pub fn problem(e: f64) -> Result<Problem<Self>, Error> {
        if !(0.0..1.0).contains(&e) {
            return Err(Error::invalid("e", format!("eccentricity must lie in [0, 1), got {e}")));
        }
        let initial = State::start(vec![1.0 - e, 0.0], vec![0.0, ((1.0 + e) / (1.0 - e)).sqrt()]);
        let t_end = 200.0 * 2.0 * std::f64::consts::PI;
        let reference = State {
            t: t_end,
            ..initial.clone()
        };
        Ok(Problem {
            system: Self::new(),
            initial,
            t_end,
            reference: Some((reference, "exact: 200 whole periods")),
        })
    }
}

impl MechanicalSystem for Kepler {
    fn dim(&self) -> usize {
        2
    }
    fn mass(&self) -> &Mass {
        &self.mass
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok(-1.0 / q[0].hypot(q[1]))
    }
    #[inline]
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        let r2 = q[0] * q[0] + q[1] * q[1];
        let k = 1.0 / (r2 * r2.sqrt());
        grad[0] = k * q[0];
        grad[1] = k * q[1];
        Ok(())
    }
    fn symmetries(&self) -> Vec<Generator> {
        vec![Generator::Rotation {
            axis: 2,
            spatial_dim: 2,
        }]
    }
}
