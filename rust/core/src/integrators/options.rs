//! The options of a fixed-step run, and of a stepper (its t₀, h, summation and Newton).

use super::clock::Clock;
use crate::model::Scale;
use crate::solve::NewtonOptions;
use crate::Error;

/// Options of a fixed-step run.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// The step h > 0.
    pub dt: f64,
    /// Number of steps.
    pub steps: usize,
    /// Keep every k-th state (the initial and the final state are always kept).
    pub save_every: usize,
    /// Add the increments with compensated summation (on by default, as in Hairer's GNI codes).
    pub compensated: bool,
    /// Stop with [`Error::Divergence`] when the energy error |E − E₀| at a saved state is
    /// beyond this times the energy's scale, the mean kinetic energy over the states saved so
    /// far ([`Scale`]; errors at round-off never stop a run), where the step is beyond the
    /// method's stability limit at the run's first state, or, within it, where the error grows:
    /// it has at least doubled since the run was half as long, or the state, max |qᵢ|, has
    /// (`Growth` says why that tells a blow-up from a symplectic method's bounded offset); or at once when the energy is not
    /// finite. A forced run checks its balance E − W against the work W instead; a Lagrangian
    /// that depends on t has no energy to check. `None`: only non-finite states stop the run.
    /// Default [`Scale::FAILURE`] = 1: the energy is then wrong by the size of the motion.
    /// Checking costs one energy evaluation per saved state.
    pub max_energy_error: Option<f64>,
    /// The initial time.
    pub t0: f64,
    /// Tolerance and iteration cap of the implicit methods' Newton iteration.
    pub newton: NewtonOptions,
}

impl Options {
    /// `steps` steps of size `dt`, every state kept, compensated summation on, the energy
    /// checked against [`Scale::FAILURE`].
    pub fn new(dt: f64, steps: usize) -> Self {
        Options {
            dt,
            steps,
            save_every: 1,
            compensated: true,
            max_energy_error: Some(Scale::FAILURE),
            t0: 0.0,
            newton: NewtonOptions::default(),
        }
    }

    pub(super) fn check(&self) -> Result<(), Error> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::invalid(
                "dt",
                format!("must be finite and positive, got {}", self.dt),
            ));
        }
        if self.save_every == 0 {
            return Err(Error::invalid("save_every", "must be at least 1"));
        }
        if !self.t0.is_finite() {
            return Err(Error::invalid("t0", "must be finite"));
        }
        let t_end = self.t0 + self.dt * self.steps as f64;
        if !t_end.is_finite() {
            return Err(Error::invalid(
                "dt",
                format!(
                    "{} steps of {:?} from t0 = {:?} end past the largest float",
                    self.steps, self.dt, self.t0
                ),
            ));
        }
        Clock::new(self.t0, self.dt).check_resolution(self.steps)?;
        self.newton.check()?;
        match self.max_energy_error {
            Some(x) if x.is_nan() || x <= 0.0 => {
                Err(Error::invalid("max_energy_error", format!("must be positive, got {x}")))
            }
            _ => Ok(()),
        }
    }
}
