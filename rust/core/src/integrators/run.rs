//! The fixed-step run: a [`Stepper`] advanced to the end, its states saved on the way.

use super::{Dynamics, Failure, Method, NewtonOptions, Stepper, Trajectory};
use crate::{memory, Error, ModelError};

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
    /// Stop with [`Error::Divergence`] when the relative energy error |H − H₀|/|H₀| at a saved
    /// state exceeds this (the absolute error when H₀ = 0). `None`: only non-finite states stop
    /// the run. Checking costs one potential evaluation per saved state.
    pub max_energy_error: Option<f64>,
    /// The initial time.
    pub t0: f64,
    /// Tolerance and iteration cap of the implicit methods' Newton iteration.
    pub newton: NewtonOptions,
}

impl Options {
    /// `steps` steps of size `dt`, every state kept, compensated summation on.
    pub fn new(dt: f64, steps: usize) -> Self {
        Options {
            dt,
            steps,
            save_every: 1,
            compensated: true,
            max_energy_error: None,
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
        self.newton.check()?;
        match self.max_energy_error {
            Some(x) if x.is_nan() || x <= 0.0 => {
                Err(Error::invalid("max_energy_error", format!("must be positive, got {x}")))
            }
            _ => Ok(()),
        }
    }
}

/// Integrates `sys` from (q0, p0) with `method` for `options.steps` steps of `options.dt`.
///
/// `poll` is called every 10–40 ms of run time; an error from it stops the run with
/// [`Error::Interrupted`] (the binding checks for Ctrl-C there). The step loop allocates
/// nothing beyond the saved states, whose storage is reserved up front.
///
/// On failure the returned [`Failure`] holds every state saved so far and the last good state.
pub fn integrate<S, P>(
    sys: &S,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    options: &Options,
    mut poll: P,
) -> Result<Trajectory, Box<Failure>>
where
    S: Dynamics + ?Sized,
    P: FnMut() -> Result<(), ModelError>,
{
    let n = sys.dim();
    let mut traj = Trajectory {
        dim: n,
        ..Default::default()
    };
    let fail = |error, partial| Box::new(Failure { error, partial });
    let mut stepper = match Stepper::new(sys, method, q0, p0, options) {
        Ok(stepper) => stepper,
        Err(e) => return Err(fail(e, traj)),
    };
    let Options {
        steps,
        save_every,
        max_energy_error,
        t0,
        ..
    } = *options;
    let saved = (steps / save_every).saturating_add(2);
    // Reserving succeeds beyond the memory there is (Linux overcommits) and the run would then
    // be killed when it fills the states: check against what is available first.
    if let Err(e) = memory::check_allocation("save_every", saved, (2 * n + 3) * std::mem::size_of::<f64>()) {
        return Err(fail(e, traj));
    }
    let reserved = saved.checked_mul(n).is_some_and(|len| {
        traj.t.try_reserve_exact(saved).is_ok()
            && traj.newton.try_reserve_exact(saved).is_ok()
            && traj.work.try_reserve_exact(saved).is_ok()
            && traj.q.try_reserve_exact(len).is_ok()
            && traj.p.try_reserve_exact(len).is_ok()
    });
    if !reserved {
        let gib = saved as f64 * (2 * n + 3) as f64 * 8.0 / (1u64 << 30) as f64;
        let reason =
            format!("keeping {saved} states needs {gib:.3e} GiB, more than can be allocated; raise save_every");
        return Err(fail(Error::invalid("save_every", reason), traj));
    }

    traj.push(t0, &stepper);
    let h0 = match max_energy_error.and_then(|_| sys.energy(stepper.q(), stepper.p())) {
        None => None,
        Some(energy) => match energy {
            Ok(h) => Some(h),
            Err(source) => {
                return Err(fail(
                    Error::Model {
                        step: 0,
                        time: t0,
                        source,
                    },
                    traj,
                ))
            }
        },
    };

    while stepper.steps() < steps {
        // Every `save_every`-th state is saved, and the last.
        let save = (stepper.steps() / save_every + 1).saturating_mul(save_every).min(steps);
        if let Err(error) = stepper.advance(save - stepper.steps(), &mut poll) {
            // Stops with the last good state kept, and the work counted.
            let time = stepper.t();
            if traj.t.last() != Some(&time) {
                traj.push(time, &stepper);
            }
            traj.count(&stepper);
            return Err(fail(error, traj));
        }
        let t = stepper.t();
        traj.push(t, &stepper);
        if let (Some(tol), Some(h0)) = (max_energy_error, h0) {
            // The state of this step is kept: it is finite, only its energy is off.
            let step = stepper.steps();
            let error = match sys
                .energy(stepper.q(), stepper.p())
                .expect("checked before the first step")
            {
                Ok(h) => {
                    let err = (h - h0).abs() / if h0 != 0.0 { h0.abs() } else { 1.0 };
                    (err.is_nan() || err > tol).then(|| {
                        let reason = format!("energy error {err:.3e} exceeds max_energy_error = {tol:.3e}");
                        Error::Divergence { step, time: t, reason }
                    })
                }
                Err(source) => Some(Error::Model { step, time: t, source }),
            };
            if let Some(error) = error {
                traj.count(&stepper);
                return Err(fail(error, traj));
            }
        }
    }
    traj.count(&stepper);
    Ok(traj)
}
