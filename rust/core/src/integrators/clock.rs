//! The stepper's clock: the time of each step as t₀ + (n − n₀)·h, from the step count, and
//! the resolution below which its steps' times are not told apart.

use serde::{Deserialize, Serialize};

use crate::Error;

/// tₙ = t₀ + (n − n₀)·h: the time t₀ and steps n₀ when the step h was last set (see
/// [`super::Stepper::set_dt`]).
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub(in crate::integrators) struct Clock {
    pub(super) t0: f64,
    pub(super) n0: usize,
    pub(in crate::integrators) h: f64,
}

impl Clock {
    /// The clock of a run from t0 in steps of h.
    pub(in crate::integrators) fn new(t0: f64, h: f64) -> Self {
        Clock { t0, n0: 0, h }
    }

    /// The time after `steps` steps.
    #[inline]
    pub(in crate::integrators) fn at(self, steps: usize) -> f64 {
        // Through i64: one instruction, where usize → f64 takes a dozen on x86-64.
        self.t0 + (steps - self.n0) as i64 as f64 * self.h
    }

    /// Refuses, naming `dt`, steps up to step `end` whose times [`Clock::at`] does not tell
    /// apart: t₀ + k·h rounds to a float, and where h is below the floats' spacing near the
    /// run's times, successive steps would share a time (a run at t₀ = 1.7·10⁹ s, Unix time,
    /// of steps of 0.1 µs) and the saved rows, which a time tells apart, would be lost.
    ///
    /// k·h is within u/2 of its value and t₀ + k·h within u, u the spacing of the floats at
    /// the largest of |t₀|, |t_end| and k·h, so that steps h ≥ 4u are a time apart at least u:
    /// that is the bound. Refuses, naming `steps`, more than 2⁵³ steps from t₀, whose count k
    /// is no longer a float's.
    pub(in crate::integrators) fn check_resolution(self, end: usize) -> Result<(), Error> {
        let k = end.saturating_sub(self.n0);
        if k > 1 << 53 {
            let reason = format!(
                "{k} steps from t0 = {:?} are more than 2**53, past which step counts are not floats",
                self.t0
            );
            return Err(Error::invalid("steps", reason));
        }
        let span = k as f64 * self.h;
        let largest = self.t0.abs().max((self.t0 + span).abs()).max(span);
        let ulp = f64::from_bits(largest.to_bits() + 1) - largest;
        if self.h >= 4.0 * ulp {
            return Ok(());
        }
        let near = if self.t0.abs() >= (self.t0 + span).abs() {
            self.t0
        } else {
            self.t0 + span
        };
        let reason = format!(
            "{:?} is below the resolution of the time over this run: the floats near t = {near:e} are {ulp:.4e} apart \
             (ulp(t)), and steps shorter than 4 ulp(t) = {:.4e} are not told apart (t0 + k·dt would repeat values, and \
             the run would lose steps); count the time from the run's start (t0 = 0, adding {:e} to its times \
             afterwards), or take dt ≥ {:.4e}",
            self.h,
            4.0 * ulp,
            self.t0,
            4.0 * ulp
        );
        Err(Error::invalid("dt", reason))
    }
}
