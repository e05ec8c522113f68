//! The fixed-step run: a [`Stepper`] advanced to the end, its states saved on the way.

use serde::{Deserialize, Serialize};

use super::jumps::{Watch, Watcher};
use super::{Checkpoint, Detector, Dynamics, Failure, Method, Options, Poll, Stepper, Trajectory};
use crate::model::{EnergyTerms, Rest, Scale};
use crate::solve::difference;
use crate::solve::newton::norm;
use crate::{memory, Error, ModelError};

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

// Events: the run with a [`Detector`] (begin).
/// As [`integrate`], watching the `events`' functions after every step (the steps are then
/// taken one at a time): each crossing is located by a partial step of the method
/// ([`Detector`]) and pushed to [`Trajectory::events`]. When an event reaches its terminal
/// count, the run stops at the end of that step, its state saved, with
/// [`Trajectory::terminated_by`] set.
pub fn integrate_with_events<S, P>(
    sys: &S,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    options: &Options,
    poll: P,
    events: &mut Detector<'_>,
) -> Result<Trajectory, Box<Failure>>
where
    S: Dynamics + ?Sized,
    P: Poll,
{
    let watch = Watch {
        events: Some(events),
        ..Watch::default()
    };
    integrate_watching(sys, method, q0, p0, options, poll, watch)
}
// Events (end).

/// As [`integrate`], watching `watch`'s events (as [`integrate_with_events`] does) and
/// resolving the impacts on its contacts.
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
/// another model's ([`Checkpoint::resume_on`]), and `save_every` = 0.
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

/// As [`resume`], watching the `events` as [`integrate_with_events`] does, from the
/// checkpoint's state on (crossings before it are the first run's; a terminal count is this
/// run's).
pub fn resume_with_events<S, P>(
    sys: &S,
    checkpoint: Checkpoint,
    steps: usize,
    save_every: usize,
    poll: P,
    events: &mut Detector<'_>,
) -> Result<Trajectory, Box<Failure>>
where
    S: Dynamics + ?Sized,
    P: Poll,
{
    let watch = Watch {
        events: Some(events),
        ..Watch::default()
    };
    resume_watching(sys, checkpoint, steps, save_every, poll, watch)
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
        if let Some(error) = watch.as_mut().and_then(|w| w.check(sys, &stepper, (&first.0, first.1))) {
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

/// A step beyond the method's stability limit on the model's fastest mode: h·ω_max, the limit
/// h_ω on q̈ = −ω²q, and ω_max.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeyondLimit {
    pub h_omega: f64,
    pub limit: f64,
    pub omega: f64,
}

/// Whether a step `dt` of `method` at (q, t) is beyond its stability limit, ω_max the fastest
/// frequency of the small oscillations there from at most `iterations` of Lanczos
/// ([`Rest::fastest`]): the one test of the check before a run and of a divergence's diagnosis.
/// None within the limit, for a method without a finite one (unconditionally stable, or with
/// none on an oscillator) and for a model with velocity constraints.
///
/// # Errors
/// The model's own.
pub fn beyond_limit<S: Dynamics + ?Sized>(
    sys: &S,
    (method, dt): (Method, f64),
    (q, t): (&[f64], f64),
    iterations: usize,
) -> Result<Option<BeyondLimit>, ModelError> {
    let limit = method.info().h_omega_max;
    if !(limit.is_finite() && limit > 0.0) || sys.velocity_constraints().is_some() {
        return Ok(None);
    }
    let omega = Rest::new(sys.as_lagrangian(), sys.holonomic(), q, t)?
        .fastest(iterations)?
        .omega;
    Ok((dt * omega > limit).then_some(BeyondLimit {
        h_omega: dt * omega,
        limit,
        omega,
    }))
}

/// A divergence with its likely cause named: h·ω_max at the run's first state beyond the
/// method's stability limit ([`beyond_limit`]). Other errors, and divergences within the limit
/// (or where the frequency does not evaluate), as they are.
fn diagnosed<S: Dynamics + ?Sized>(
    error: Error,
    sys: &S,
    (method, dt): (Method, f64),
    (q, t): (Vec<f64>, f64),
) -> Error {
    let Error::Divergence { step, time, reason } = error else {
        return error;
    };
    let reason = match beyond_limit(sys, (method, dt), (&q, t), Rest::AFTER_FAILURE) {
        Ok(Some(BeyondLimit { h_omega, limit, omega })) => format!(
            "{reason}; h·ω_max = {h_omega:.4} at the run's first state (t = {t}) is beyond {}'s stability limit {limit} \
             (ω_max = {omega:.6e}, the fastest frequency of the small oscillations there): take dt below {:.6e} \
             (varmech.suggest_dt)",
            method.info().name,
            limit / omega
        ),
        _ => reason,
    };
    Error::Divergence { step, time, reason }
}

/// The steps between two checks of the energy of a run that saves its samples alone.
const SAMPLING_PERIOD: usize = 1024;

/// The run's energy check: E − W against its value at the start, judged by a running [`Scale`].
/// An error beyond `tolerance` × the scale stops the run at once where the step is beyond the
/// method's stability limit at the run's first state ([`beyond_limit`]; explicit Euler's, 0, at
/// every step): a blow-up foretold, which the check before the run warned of. Within the limit
/// it stops the run only where it grows, or the state does ([`Growth`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct EnergyWatch {
    initial: f64,
    scale: Scale,
    tolerance: f64,
    growth: Growth,
    /// The size of the state, max |qᵢ|, judged as the error is: an orbit thrown out of its well, or
    /// a pendulum thrown over its top, has an error that jumps once and stays, and a state that
    /// grows from then on.
    spread: Growth,
    /// Whether the step is beyond the limit, once an error has passed the scale: asked then
    /// (Lanczos on the first state, as a divergence's diagnosis does), once a run.
    beyond: Option<bool>,
}

/// Whether an energy error grows: the error at the n-th check (saved state) is at least
/// [`Growth::FACTOR`] times the largest at the checks up to P, the largest power of two ≤ n/2
/// (the run then at most half as long), from check [`Growth::FIRST`] on.
///
/// Why growth, not size, within the stability limit: a stable step of a symplectic method
/// conserves a modified energy H̃ = H + O(hᵖ) (Hairer, Lubich & Wanner, GNI IX.8), so its error
/// E − E₀ is an offset that stays bounded however large it is: on q̈ = −ω²q Verlet's H/H̃ reaches
/// 1/(1 − (hω/2)²), 50 at 0.99 of its limit, many times the mean kinetic energy. The offset
/// swings with the angle the step turns a mode by, slowly near a limit (at 0.99 of it: in 11
/// steps for Verlet, 62 for kahan_li8, 99 for blanes_moan6; a mode far from its limit carries
/// an offset far below the scale), rising from zero at the start over half that. A baseline of
/// 32 checks spans that rise, so from check 64 on a bounded offset no longer doubles in a
/// doubling of the run. An error that grows geometrically (a mode that turns unstable along a
/// nonlinear run), or drifts or diffuses at least linearly, doubles in every doubling of the
/// run, and is stopped within a doubling of passing `max_energy_error` × the scale. An offset
/// that varies more slowly than the run has been long (a step yet closer to the limit, saved
/// states that alias a near-limit oscillation) reads as growth; an error that jumps once and
/// stays (an orbit thrown out of its well at one pericentre) does not, but the state it leaves
/// grows, and the same test of max |qᵢ| stops it. The maxima at powers of two keep the test to four numbers, carried in the checkpoint
/// so that a resumed run is judged as one run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
struct Growth {
    /// Checks so far (the initial state is check 0, with error 0).
    checks: u64,
    /// The largest |error| over every check.
    largest: f64,
    /// The largest |error| up to check 2ᵏ, 2ᵏ ≤ checks < 2ᵏ⁺¹, and up to check 2ᵏ⁻¹.
    at_power: f64,
    baseline: f64,
}

impl Growth {
    /// How much an error must grow in a doubling of the run.
    const FACTOR: f64 = 2.0;
    /// The first check judged: the baseline then spans 32 checks, a bounded offset's rise.
    const FIRST: u64 = 64;

    /// Adds the next check's |error|; whether it grows.
    fn grows(&mut self, error: f64) -> bool {
        // Saturating: a crafted checkpoint's count must not overflow.
        self.checks = self.checks.saturating_add(1);
        self.largest = self.largest.max(error);
        if self.checks.is_power_of_two() {
            self.baseline = self.at_power;
            self.at_power = self.largest;
        }
        self.checks >= Self::FIRST && error >= Self::FACTOR * self.baseline
    }
}

impl EnergyWatch {
    /// None for a model without an energy (L depends on t); an error when the initial energy
    /// does not evaluate or is not finite.
    fn new<S, M>(sys: &S, stepper: &Stepper<M>, tolerance: f64) -> Option<Result<Self, Error>>
    where
        S: Dynamics + ?Sized,
        M: std::ops::Deref<Target: Dynamics>,
    {
        let (step, time) = (0, stepper.t());
        let terms = match sys.energy(stepper.q(), stepper.p(), time)? {
            Ok(terms) => terms,
            Err(source) => return Some(Err(Error::model(step, time, source))),
        };
        if !terms.energy.is_finite() {
            let reason = not_finite(&terms);
            return Some(Err(Error::Divergence { step, time, reason }));
        }
        let mut watch = EnergyWatch {
            initial: terms.energy - stepper.work(),
            scale: Scale::default(),
            tolerance,
            growth: Growth::default(),
            spread: Growth {
                largest: norm(stepper.q()),
                ..Growth::default()
            },
            beyond: None,
        };
        watch.push(&terms, stepper.work());
        Some(Ok(watch))
    }

    pub(super) fn set_tolerance(&mut self, tolerance: f64) {
        self.tolerance = tolerance;
    }

    fn push(&mut self, terms: &EnergyTerms, work: f64) {
        self.scale.push(terms.kinetic, terms.size() + work.abs());
    }

    /// The error that ends the run at the stepper's state, if any; `first` is the run's first
    /// state (q, t), where the stability limit is judged.
    fn check<S, M>(&mut self, sys: &S, stepper: &Stepper<M>, first: (&[f64], f64)) -> Option<Error>
    where
        S: Dynamics + ?Sized,
        M: std::ops::Deref<Target: Dynamics>,
    {
        let (step, time, work) = (stepper.steps(), stepper.t(), stepper.work());
        let terms = match sys.energy(stepper.q(), stepper.p(), time)? {
            Ok(terms) => terms,
            Err(source) => return Some(Error::model(step, time, source)),
        };
        self.push(&terms, work);
        let error = terms.energy - work - self.initial;
        if !error.is_finite() {
            let reason = not_finite(&terms);
            return Some(Error::Divergence { step, time, reason });
        }
        let (baseline, spread) = (self.growth.baseline, self.spread.baseline);
        let size = norm(stepper.q());
        let grows = self.growth.grows(error.abs());
        let spreads = self.spread.grows(size);
        if !self.scale.fails(error, step as u64, self.tolerance) {
            return None;
        }
        let (method, dt) = (stepper.method(), stepper.dt());
        let beyond = *self.beyond.get_or_insert_with(|| {
            method.info().h_omega_max == 0.0
                || matches!(beyond_limit(sys, (method, dt), first, Rest::AFTER_FAILURE), Ok(Some(_)))
        });
        if !(beyond || grows || spreads) {
            return None;
        }
        let scale = self.scale.scale();
        let growing = if beyond {
            String::new()
        } else if grows {
            format!(", and growing: it was at most {baseline:.3e} while the run was half as long")
        } else {
            format!(
                ", and the state growing: max |qᵢ| = {size:.3e}, at most {spread:.3e} while the run was half as long"
            )
        };
        let advice = differences_advice(sys, (stepper.q(), stepper.p(), time), first.0, error.abs())
            .unwrap_or_else(|| step_advice(method));
        let reason = format!(
            "energy error {:.3e} is {:.3e} times the energy scale {scale:.3e} (the mean kinetic energy), \
             beyond max_energy_error = {:.3e}{growing}; {advice}",
            error.abs(),
            error.abs() / scale,
            self.tolerance,
        );
        Some(Error::Divergence { step, time, reason })
    }
}

/// The advice for an energy error that the rounding of derivatives taken by differences
/// accounts for: their noise in the forces at (q, p, t), times the motion from the run's first
/// state `first`, at least `error` (a motion far below the differences' step, as at amplitudes
/// of 1e-100, loses its forces to rounding). None where derivatives are exact, or the noise
/// accounts for less: then the step is to blame.
fn differences_advice<S: Dynamics + ?Sized>(
    sys: &S,
    (q, p, t): (&[f64], &[f64], f64),
    first: &[f64],
    error: f64,
) -> Option<String> {
    let model = sys.as_lagrangian();
    let (mut v, mut forces) = (vec![0.0; q.len()], vec![0.0; q.len()]);
    difference::take_noise();
    model.velocity(q, p, t, &mut v).ok()?;
    model.gradients(q, &v, t, &mut forces, &mut vec![0.0; q.len()]).ok()?;
    let noise = difference::take_noise();
    let motion = q.iter().zip(first).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    (noise * motion >= error).then(|| {
        format!(
            "the error is within the rounding of the derivatives taken by differences (forces to ±{noise:.1e} \
             over a motion of {motion:.1e}), which a smaller step does not lower: supply the model's \
             derivatives, or scale its coordinates to order 1"
        )
    })
}

/// What helps an energy error that a step too coarse accounts for. A method that is not
/// symplectic conserves no modified energy: its error grows along any run, so a smaller step
/// only slows it (a run k times as long needs a step k times smaller at order 1), and a
/// symplectic method bounds it.
fn step_advice(method: Method) -> String {
    let info = method.info();
    if info.symplectic {
        return "reduce dt".into();
    }
    format!(
        "reduce dt ({} is not symplectic: its energy error grows along the run, slower at a smaller step, by \
         order {}), or take a symplectic method, whose error stays bounded: verlet (rattle on a constrained model)",
        info.name, info.order
    )
}

fn not_finite(terms: &EnergyTerms) -> String {
    format!(
        "the energy is not finite (E = {}, T = {}, V = {}): the model's energy does not evaluate there",
        terms.energy, terms.kinetic, terms.potential
    )
}
