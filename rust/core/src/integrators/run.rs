//! The fixed-step run: a [`Stepper`] advanced to the end, its states saved on the way.

use super::divergence::{diagnosed, EnergyWatch};
use super::jumps::{Watch, Watcher};
use super::{Checkpoint, Dynamics, Failure, Method, Options, Poll, Stepper, Trajectory};
use crate::{memory, Error};

/// Integrates `sys` from (q0, p0) with `method` for `options.steps` steps of `options.dt`.
///
/// `poll` ([`Poll`]) is called with the steps completed every 10–40 ms of run time; an error
/// from it stops the run with [`Error::Interrupted`] (the binding checks for Ctrl-C there, and
/// reports progress). The step loop allocates nothing beyond the saved states, whose storage
/// is reserved up front.
///
/// The trajectory ends with the [`Checkpoint`] of its last state ([`Trajectory::checkpoint`]),
/// from which [`resume`] goes on. On failure the returned [`Failure`] holds every state saved
/// so far and the last good state, with its checkpoint.
pub fn integrate<S, P>(
    sys: &S,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    options: &Options,
    poll: P,
) -> Result<Trajectory, Box<Failure>>
where
    S: Dynamics + ?Sized,
    P: Poll,
{
    let (stepper, watch) = start(sys, method, q0, p0, options)?;
    run(
        sys,
        stepper,
        watch,
        options.steps,
        options.save_every,
        poll,
        (Watcher::idle(), true),
    )
}

/// As [`integrate`], watching `watch`'s events and resolving the impacts on its contacts.
///
/// The events' functions are evaluated after every step (the steps are then taken one at a
/// time): each crossing is located by a partial step of the method
/// ([`Detector`](super::Detector)) and pushed to [`Trajectory::events`]. When an event reaches
/// its terminal count, the run stops at the end of that step, its state saved, with
/// [`Trajectory::terminated_by`] set.
///
/// The step that crosses a contact's φ = 0 is split at the contact: the method's partial step
/// of size αh from (qₙ, pₙ) to the contact configuration q̃ (α located to round-off), the jump
/// p⁺ = p⁻ + λ∇φ(q̃) of the contact's [`Law`](super::Law) (∇φ projected on the constraints of a
/// constrained model), then the method's partial step of (1 − α)h to tₙ₊₁; the rest of the step
/// is checked against every contact again (a corner, a second bounce), up to
/// [`MAX_IMPACTS`](super::MAX_IMPACTS) impacts in one step. A step without an impact is bit for
/// bit the step without contacts. The impacts go to [`Trajectory::impacts`], and the saved
/// states include the state just before and just after each (one time, two rows). The energy
/// check ([`Options::max_energy_error`]) balances E − E₀ against the work W, which holds the
/// energy the contacts and impulses put in ([`super::Watch::exchanges`]: each law's own loss,
/// none for e = 1).
///
/// Refuses, naming `contacts`, a surface that does not fit the model's coordinates and the
/// variational law on a method or model it does not fit; naming `q0`, an initial state outside
/// φ ≥ 0. Fails with [`Error::Contact`] (the run ending at the start of the step, its last good
/// state) when an impact cannot be resolved: a non-finite state after a jump, a resting or
/// grazing contact, or more than `MAX_IMPACTS` impacts in a step.
pub fn integrate_watching<S, P>(
    sys: &S,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    options: &Options,
    poll: P,
    watch: Watch<'_, '_, '_>,
) -> Result<Trajectory, Box<Failure>>
where
    S: Dynamics + ?Sized,
    P: Poll,
{
    let (stepper, energy) = start(sys, method, q0, p0, options)?;
    watched(
        sys,
        stepper,
        energy,
        (options.steps, options.save_every),
        poll,
        watch,
        true,
    )
}

/// The run of `stepper` to step `end` watching `watch` (its [`Watcher`] begun on the
/// stepper's state): a `fresh` run (its schedule's times at t0 taken, a state outside a contact
/// named `q0`) or a resumed one (named `checkpoint`).
fn watched<'s, S, P>(
    sys: &'s S,
    mut stepper: Stepper<&'s S>,
    energy: Option<EnergyWatch>,
    (end, save_every): (usize, usize),
    poll: P,
    watch: Watch<'_, '_, '_>,
    fresh: bool,
) -> Result<Trajectory, Box<Failure>>
where
    S: Dynamics + ?Sized,
    P: Poll,
{
    let argument = if fresh { "q0" } else { "checkpoint" };
    match Watcher::begin(sys, &mut stepper, watch, argument) {
        Ok(watcher) => run(sys, stepper, energy, end, save_every, poll, (watcher, fresh)),
        Err(error) => Err(fail(error, first_state(sys, &stepper))),
    }
}

/// The stepper of a new run and its energy check.
#[allow(clippy::type_complexity)]
fn start<'s, S: Dynamics + ?Sized>(
    sys: &'s S,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    options: &Options,
) -> Result<(Stepper<&'s S>, Option<EnergyWatch>), Box<Failure>> {
    let stepper = Stepper::new(sys, method, q0, p0, options).map_err(|e| fail(e, empty(sys)))?;
    match options
        .max_energy_error
        .and_then(|tol| EnergyWatch::new(sys, &stepper, tol))
    {
        None => Ok((stepper, None)),
        Some(Ok(watch)) => Ok((stepper, Some(watch))),
        // The initial state is kept: the check failed on it.
        Some(Err(error)) => Err(fail(error, first_state(sys, &stepper))),
    }
}

/// Goes on from `checkpoint` (of a run of `sys`) for `steps` more steps, saving every
/// `save_every`-th state (counted from the first run's start) and the last: the states are
/// those of one run of the whole length, bit for bit, and the first is the checkpoint's.
///
/// Refuses a model with another number of coordinates or of a kind the checkpoint's method
/// does not integrate, a checkpoint whose state does not fit the model or whose fingerprint is
/// another model's (`Checkpoint::resume_on`), and `save_every` = 0.
pub fn resume<S, P>(
    sys: &S,
    checkpoint: Checkpoint,
    steps: usize,
    save_every: usize,
    poll: P,
) -> Result<Trajectory, Box<Failure>>
where
    S: Dynamics + ?Sized,
    P: Poll,
{
    let (stepper, watch, end) = resumed(sys, checkpoint, steps, save_every)?;
    run(sys, stepper, watch, end, save_every, poll, (Watcher::idle(), false))
}

/// As [`resume`], watching `watch`'s events and contacts as [`integrate_watching`] does, from
/// the checkpoint's state on (give the first run's contacts again: a run with contacts and its
/// resumption are one run, bit for bit). A checkpoint whose state is outside a contact is
/// refused, naming `checkpoint`.
pub fn resume_watching<S, P>(
    sys: &S,
    checkpoint: Checkpoint,
    steps: usize,
    save_every: usize,
    poll: P,
    watch: Watch<'_, '_, '_>,
) -> Result<Trajectory, Box<Failure>>
where
    S: Dynamics + ?Sized,
    P: Poll,
{
    let (stepper, energy, end) = resumed(sys, checkpoint, steps, save_every)?;
    watched(sys, stepper, energy, (end, save_every), poll, watch, false)
}

/// The stepper of a checkpoint, its energy check and the step to reach.
#[allow(clippy::type_complexity)]
fn resumed<S: Dynamics + ?Sized>(
    sys: &S,
    checkpoint: Checkpoint,
    steps: usize,
    save_every: usize,
) -> Result<(Stepper<&S>, Option<EnergyWatch>, usize), Box<Failure>> {
    if save_every == 0 {
        return Err(fail(Error::invalid("save_every", "must be at least 1"), empty(sys)));
    }
    let fresh = checkpoint.fresh_check;
    let (state, watch) = checkpoint.resume_on(sys).map_err(|e| fail(e, empty(sys)))?;
    let stepper = Stepper::resume(sys, state).map_err(|e| fail(e, empty(sys)))?;
    let watch = match (watch, fresh) {
        (None, Some(tolerance)) => EnergyWatch::new(sys, &stepper, tolerance)
            .transpose()
            .map_err(|e| fail(e, empty(sys)))?,
        (watch, _) => watch,
    };
    let end = (stepper.steps().checked_add(steps)).filter(|_| (stepper.t() + steps as f64 * stepper.dt()).is_finite());
    let Some(end) = end else {
        let reason = format!(
            "{steps} more steps from step {} end past the largest float",
            stepper.steps()
        );
        return Err(fail(Error::invalid("steps", reason), empty(sys)));
    };
    stepper.check_horizon(steps).map_err(|e| fail(e, empty(sys)))?;
    Ok((stepper, watch, end))
}

fn fail(error: Error, partial: Trajectory) -> Box<Failure> {
    Box::new(Failure { error, partial })
}

fn empty<S: Dynamics + ?Sized>(sys: &S) -> Trajectory {
    Trajectory {
        dim: sys.dim(),
        ..Default::default()
    }
}

/// The trajectory of the stepper's (initial) state alone.
fn first_state<S: Dynamics + ?Sized>(sys: &S, stepper: &Stepper<&S>) -> Trajectory {
    let mut traj = empty(sys);
    traj.push(stepper.t(), stepper);
    traj
}

/// Advances `stepper` to step `end`, saving every `save_every`-th state, the first and the
/// last, with the energy checked at each saved state (and the events searched, if any); with
/// samples, saving those alone, the energy checked every [`SAMPLING_PERIOD`] steps. A `fresh`
/// run starts its watcher ([`Watcher::start`]).
fn run<'s, S, P>(
    sys: &'s S,
    mut stepper: Stepper<&'s S>,
    mut watch: Option<EnergyWatch>,
    end: usize,
    save_every: usize,
    mut poll: P,
    (mut watcher, fresh): (Watcher<'_, '_, '_, &'s S>, bool),
) -> Result<Trajectory, Box<Failure>>
where
    S: Dynamics + ?Sized,
    P: Poll,
{
    let n = sys.dim();
    let mut traj = empty(sys);
    traj.impacts.dim = n;
    let start = stepper.steps();
    // With samples their states alone are kept (and those about jumps, which grow the rows).
    let (argument, saved, advice) = match watcher.samples() {
        0 => (
            "save_every",
            ((end - start) / save_every).saturating_add(2),
            "raise save_every",
        ),
        samples => ("t_eval", samples.saturating_add(2), "pass fewer t_eval times"),
    };
    // Reserving succeeds beyond the memory there is (Linux overcommits) and the run would then
    // be killed when it fills the states: check against what is available first.
    if let Err(Error::InvalidArgument { reason, .. }) =
        memory::check_allocation(argument, saved, (2 * n + 3) * std::mem::size_of::<f64>())
    {
        let reason = format!("{reason}: {saved} states of {n} coordinates; {advice}");
        return Err(fail(Error::invalid(argument, reason), traj));
    }
    // Newton counts and work only for the runs that have them (see `Trajectory::push`).
    let (newton, work) = (
        stepper.newton().map_or(0, |_| saved),
        stepper.forced_work().map_or(0, |_| saved),
    );
    let reserved = saved.checked_mul(n).is_some_and(|len| {
        traj.t.try_reserve_exact(saved).is_ok()
            && traj.newton.try_reserve_exact(newton).is_ok()
            && traj.work.try_reserve_exact(work).is_ok()
            && traj.q.try_reserve_exact(len).is_ok()
            && traj.p.try_reserve_exact(len).is_ok()
    });
    if !reserved {
        let gib = saved as f64 * (2 * n + 3) as f64 * 8.0 / (1u64 << 30) as f64;
        let reason = format!("keeping {saved} states needs {gib:.3e} GiB, more than can be allocated; {advice}");
        return Err(fail(Error::invalid(argument, reason), traj));
    }

    // The first state, which a divergence's diagnosis linearizes at.
    let first = (stepper.q().to_vec(), stepper.t());
    let mut outcome = if fresh {
        watcher.start(&mut stepper, &mut traj)
    } else {
        Ok(())
    };
    // With samples their states alone are saved; a state already saved at its time (just after
    // a jump there) is not saved again.
    let sampling = watcher.sampling();
    let keep = |traj: &mut Trajectory, stepper: &Stepper<&'s S>| {
        if !sampling && traj.t.last() != Some(&stepper.t()) {
            traj.push(stepper.t(), stepper);
        }
    };
    keep(&mut traj, &stepper);
    // With samples no state is saved at a period's end, where the energy alone is checked.
    let period = if sampling {
        save_every.max(SAMPLING_PERIOD)
    } else {
        save_every
    };
    // What the energy check's advice needs of the contacts, fixed for the run.
    let reflects = watcher.reflects();
    while stepper.steps() < end && outcome.is_ok() {
        // Every `save_every`-th state is saved, and the last.
        let save = (stepper.steps() / period + 1).saturating_mul(period).min(end);
        let n = save - stepper.steps();
        // Events and contacts: step by step, stopping after a terminal event's step.
        let advanced = watcher.advance(&mut stepper, n, &mut traj, &mut poll);
        let advanced = advanced.map(|stop| traj.terminated_by = stop);
        // A failure stops with the last good state kept, and the work counted.
        keep(&mut traj, &stepper);
        if let Err(error) = advanced {
            outcome = Err(error);
            break;
        }
        if let Some(error) = watch
            .as_mut()
            .and_then(|w| w.check(sys, &stepper, (&first.0, first.1), reflects))
        {
            // The state of this step is kept: it is finite, only its energy is off.
            outcome = Err(error);
            break;
        }
        if traj.terminated_by.is_some() {
            break;
        }
    }
    traj.count(&stepper);
    // Events: the partial steps' force evaluations are the run's too.
    traj.force_evaluations += watcher.force_evaluations();
    let (method, dt) = (stepper.method(), stepper.dt());
    traj.checkpoint = Checkpoint::new(sys, stepper.into_state(), watch).to_bytes();
    match outcome {
        Ok(()) => Ok(traj),
        Err(error) => Err(fail(diagnosed(error, sys, (method, dt), first), traj)),
    }
}

/// The steps between two checks of the energy of a run that saves its samples alone.
const SAMPLING_PERIOD: usize = 1024;
