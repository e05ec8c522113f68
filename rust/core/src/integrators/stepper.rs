//! One model, one method and the state, advanced step by step; the state apart from its model.

use serde::{Deserialize, Serialize};
mod carry;
mod decoded;
mod own_variables;
mod phase;

pub use carry::Carry;
pub(super) use phase::{array, Phase};

use std::borrow::{Borrow, BorrowMut};
use std::ops::Deref;

use super::clear::Gaps;
use super::clock::Clock;
use super::{check_method, compensated, Dynamics, Increment, Integrator, Method, Options, Poll, StepStart, Tangent};
use crate::error::check_vector;
use crate::solve::interrupt::InterruptPoll;
use crate::Error;

/// A model `M` (a reference `&S` to borrow it, a `Box<S>` to own it) with its [`StepperState`]
/// `St`: a method's [`Integrator`] and the state (tₙ, qₙ, pₙ) after n steps of size h from
/// (t₀, q₀, p₀): tₙ = t₀ + n·h, (qₙ₊₁, pₙ₊₁) = (qₙ + δq, pₙ + δp), the increments added with
/// compensated summation (Kahan; the lost low-order bits carried in (e_q, e_p)) unless switched
/// off.
///
/// The state is owned (`St = StepperState`, the default) or borrowed (`&mut StepperState`):
/// [`Stepper::into_state`] takes a stepper apart and [`Stepper::resume`] puts it back together
/// with its model, and the steps continue bit for bit as if it had never been taken apart. A
/// stepper reads as its state ([`StepperState::t`], [`StepperState::q`], …).
///
/// A step allocates nothing, and a step that fails leaves the last good state in place.
#[derive(Debug)]
pub struct Stepper<M, St = StepperState> {
    model: M,
    state: St,
}

/// Everything of a [`Stepper`] but its model: the [`Integrator`] with its caches and Newton
/// predictor, the time, the steps, (qₙ, pₙ), the compensated-summation carries and the work
/// buffers. Kept between calls, it lets a stepper run on a model that is only borrowed for the
/// length of each call.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StepperState {
    integrator: Integrator,
    clock: Clock,
    steps: usize,
    compensated: bool,
    q: Vec<f64>,
    p: Vec<f64>,
    eq: Vec<f64>,
    ep: Vec<f64>,
    dq: Vec<f64>,
    dp: Vec<f64>,
    // The next state is written beside the current one and swapped in once it is known to be
    // finite, so that a failing step leaves the last good state intact.
    q_next: Vec<f64>,
    p_next: Vec<f64>,
    eq_next: Vec<f64>,
    ep_next: Vec<f64>,
    /// The energy the jumps and held contacts put in so far (friction's work, the impacts'
    /// losses, the impulses' energy), and whether it is counted (a stepper watching what can
    /// put energy in or take it out: [`super::Watch::exchanges`]).
    contact_work: f64,
    exchanges: bool,
    // Wall-clock pacing, not state: a restored state starts a fresh one.
    #[serde(skip)]
    interrupt: InterruptPoll,
}

impl<M> Stepper<M>
where
    M: Deref<Target: Dynamics>,
{
    /// A stepper of `method` on `model` from (q0, p0) at `options.t0`, with the step
    /// `options.dt`, `options.compensated` summation and `options.newton` for the implicit
    /// methods.
    ///
    /// Refuses, in this order: q0 or p0 of the wrong length or not finite, malformed options, a
    /// method that does not integrate the model's kind or its delays (`check_method`), and
    /// initial data off the constraints ([`Dynamics::check_initial`]).
    pub fn new(model: M, method: Method, q0: &[f64], p0: &[f64], options: &Options) -> Result<Self, Error> {
        let n = model.dim();
        check_vector("q0", q0, n)?;
        check_vector("p0", p0, n)?;
        options.check()?;
        check_method(&*model, method, options.dt)?;
        check_initial(&*model, q0, p0, options.t0)?;
        let mut state = StepperState::fresh(method, q0, p0, options);
        state.integrator.keep_history(n, model.as_lagrangian(), options.dt);
        Ok(Stepper { model, state })
    }
}

impl<M, St> Stepper<M, St>
where
    M: Deref<Target: Dynamics>,
    St: BorrowMut<StepperState>,
{
    /// The stepper of `state` on `model`, continuing where [`Stepper::into_state`] left it.
    ///
    /// `model` must be the one the state was stepped on: a model with another number of
    /// coordinates, or of a kind or delays the state's method does not integrate, is refused (the state,
    /// if owned, is dropped; pass `&mut state` to keep it whatever happens).
    pub fn resume(model: M, state: St) -> Result<Self, Error> {
        let s = state.borrow();
        if model.dim() != s.q.len() {
            let reason = format!("has {} coordinates, the stepper's state {}", model.dim(), s.q.len());
            return Err(Error::invalid("model", reason));
        }
        check_method(&*model, s.method(), s.dt())?;
        Ok(Stepper { model, state })
    }

    /// The state without its model, to [`Stepper::resume`] later.
    pub fn into_state(self) -> St {
        self.state
    }

    /// The model stepped.
    pub fn model(&self) -> &M::Target {
        &self.model
    }

    /// Advances one step. On failure the state stays at the last good step, and the error
    /// names the step (counted from 1) and the time it started at. Unlike
    /// [`Stepper::advance`] it does not check the time's resolution
    /// ([`StepperState::check_horizon`]): the partial steps of a located event or impact, far
    /// below it, take it.
    pub fn step(&mut self) -> Result<(), Error> {
        let state = self.state.borrow_mut();
        // The model's own loop, one step long: the fixed-size loops of small systems (the bits
        // of a generic step, at half its cost: the partial steps of impacts take it), and the
        // own variables of a method that has them, which a step from (q, p) would restart.
        let result = self.model.advance(state, 1, Carry::Nothing);
        state.synchronise();
        result.map(drop)
    }

    /// Advances one step, as [`Stepper::step`], and carries the tangent vectors in `x` (2n × k,
    /// column-major, a column (δq, δp)) by the step's tangent map DΨ_h from its start
    /// ([`Tangent`], made for this stepper's method and model). The states are those of
    /// [`Stepper::step`], bit for bit.
    pub fn step_with_tangent(&mut self, tangent: &mut Tangent, x: &mut [f64]) -> Result<(), Error> {
        let state = self.state.borrow_mut();
        let result = self.model.advance(state, 1, Carry::Tangent(tangent, x, f64::MAX));
        state.synchronise();
        result.map(drop)
    }

    /// As [`Stepper::step_with_tangent`], `n` steps, `poll` called as [`Stepper::advance`]
    /// calls it. The vectors are not renormalized: over many steps of a chaotic run they grow
    /// ([`crate::diagnostics::lyapunov`] renormalizes them), and a step that takes them past
    /// the largest float stops the call with [`Error::Divergence`] (renormalize them between
    /// shorter calls), the step kept.
    pub fn advance_with_tangent<P: Poll>(
        &mut self,
        n: usize,
        tangent: &mut Tangent,
        x: &mut [f64],
        poll: P,
    ) -> Result<(), Error> {
        self.advance_with_tangent_below(n, (tangent, x), f64::MAX, poll)
            .map(drop)
    }

    /// As [`Stepper::advance_with_tangent`], stopping after the first step that takes a
    /// component of the vectors past `large` in magnitude: true then. A kick–drift step's
    /// tangent map is carried inside the method's own loop (`super::tangent::Carried`), so
    /// that the states are those of [`Stepper::advance`] at its cost per step. A step that
    /// takes them past the largest float (or to NaN) is a [`Error::Divergence`]: its map
    /// stretched them by more than a float holds, so no renormalization after it can recover
    /// them.
    pub fn advance_with_tangent_below<P: Poll>(
        &mut self,
        n: usize,
        (tangent, x): (&mut Tangent, &mut [f64]),
        large: f64,
        poll: P,
    ) -> Result<bool, Error> {
        let (state, model) = (self.state.borrow_mut(), &*self.model);
        state.check_horizon(n)?;
        let stopped = state.polled(n, poll, |state, steps| {
            model.advance(state, steps, Carry::Tangent(&mut *tangent, &mut *x, large))
        })?;
        if stopped && !x.iter().all(|v| v.is_finite()) {
            let (step, time) = (state.steps, state.clock.at(state.steps.saturating_sub(1)));
            let reason = "the tangent vectors overflowed in one step: its tangent map stretched them past the largest \
                          float (by more than 1e208 a step, h·λ beyond 480, from vectors renormalized at 1e100), \
                          so no renormalization can recover them; take a smaller dt, at which the step resolves the \
                          motion's instability (and renormalize them more often)"
                .to_string();
            return Err(Error::Divergence { step, time, reason });
        }
        Ok(stopped)
    }

    /// Advances `n` steps, calling `poll` before a step every 10–40 ms of run time; an error
    /// from it stops with [`Error::Interrupted`] (the binding checks for Ctrl-C there). On
    /// failure the state stays at the last good step.
    ///
    /// A method that keeps its own variables (the Wisdom–Holman methods) takes the n steps on
    /// them and synchronises (q, p) once, at the end (see `own_variables.rs`).
    pub fn advance<P: Poll>(&mut self, n: usize, poll: P) -> Result<(), Error> {
        let state = self.state.borrow_mut();
        state.check_horizon(n)?;
        let model = &*self.model;
        let result = state.polled(n, poll, |state, steps| model.advance(state, steps, Carry::Nothing));
        state.synchronise();
        result.map(drop)
    }

    /// As [`Stepper::advance`], with the contacts' `gaps` checked at the end of every step
    /// ([`Gaps::clear`]): up to `n` steps, in the method's own loop, stopping after the first
    /// that is not clear (it crosses a contact, or a φ failed). Then true, with that step kept
    /// and its start (tₙ, qₙ, pₙ) written into `start`, for the step to be redone in pieces. A
    /// method with its own variables takes its steps one at a time, (q, p) synchronised after
    /// each.
    pub(in crate::integrators) fn advance_while<P: Poll>(
        &mut self,
        n: usize,
        poll: P,
        gaps: &mut Gaps<'_, '_>,
        start: (&mut f64, &mut [f64], &mut [f64]),
    ) -> Result<bool, Error> {
        let state = self.state.borrow_mut();
        let model = &*self.model;
        let result = state.polled(n, poll, |state, steps| {
            model.advance(state, steps, Carry::Gaps(&mut *gaps))
        });
        state.synchronise();
        if result? {
            let (t, q, p) = start;
            *t = state.clock.at(state.steps - 1);
            q.copy_from_slice(&state.q_next);
            p.copy_from_slice(&state.p_next);
            return Ok(true);
        }
        Ok(false)
    }

    /// Starts afresh from (q0, p0) at time t0, with the step count at 0: the next steps are
    /// those of a new stepper from there (the force and Newton counts go on). The
    /// compensated-summation carries and the integrator's caches and predictor
    /// ([`Integrator::reset`]) are cleared, since the next step does not start where the last
    /// one ended. Refuses, as [`Stepper::new`] does, q0 or p0 of the wrong length or not
    /// finite, a t0 not finite and initial data off the constraints; the state is then
    /// unchanged.
    pub fn reset(&mut self, t0: f64, q0: &[f64], p0: &[f64]) -> Result<(), Error> {
        let state = self.state.borrow_mut();
        let n = state.q.len();
        check_vector("q0", q0, n)?;
        check_vector("p0", p0, n)?;
        if !t0.is_finite() {
            return Err(Error::invalid("t0", "must be finite"));
        }
        check_initial(&*self.model, q0, p0, t0)?;
        let h = state.clock.h;
        state.restart(t0, q0, p0, h);
        // A new initial state has no past.
        state.integrator.keep_history(n, self.model.as_lagrangian(), h);
        Ok(())
    }

    /// As [`Stepper::reset`] followed by [`Stepper::set_dt`] to h, unchecked: the partial steps
    /// of a located event or impact, from states the run has checked.
    pub(in crate::integrators) fn restart(&mut self, t0: f64, q0: &[f64], p0: &[f64], h: f64) {
        self.state.borrow_mut().restart(t0, q0, p0, h);
    }

    /// Sets the state (qₙ, pₙ) to (q, p) after a jump, keeping the clock and the steps: the
    /// state at the end of a step that an impact split ([`super::Contacts`]). The
    /// compensated-summation carries and the integrator's caches and predictor are cleared, as
    /// a restart from (q, p) would: the next step does not start where the last one ended.
    /// Refuses q or p of the wrong length or not finite; the state is then unchanged.
    pub fn jump_to(&mut self, q: &[f64], p: &[f64]) -> Result<(), Error> {
        let state = self.state.borrow_mut();
        let n = state.q.len();
        check_vector("q", q, n)?;
        check_vector("p", p, n)?;
        let (t0, n0, h, steps) = (state.clock.t0, state.clock.n0, state.clock.h, state.steps);
        state.restart(t0, q, p, h);
        (state.clock.n0, state.steps) = (n0, steps);
        Ok(())
    }

    /// Counts the energy the contacts and impulses put in from now on (a watcher of what can
    /// exchange it begun on this stepper): it is then reported, as a forced model's work is.
    pub(in crate::integrators) fn count_contact_work(&mut self) {
        self.state.borrow_mut().exchanges = true;
    }

    /// Adds w to the energy the contacts and impulses put in.
    pub(in crate::integrators) fn add_contact_work(&mut self, w: f64) {
        self.state.borrow_mut().contact_work += w;
    }

    /// One step on the clock, taken outside the method (the step of a held contact, which the
    /// resolver takes), `poll` called before it when due as [`Stepper::advance`] calls it:
    /// (q, p) are left for [`Stepper::jump_to`] to set.
    pub(in crate::integrators) fn tick<P: Poll>(&mut self, poll: P) -> Result<(), Error> {
        let state = self.state.borrow_mut();
        state
            .polled(1, poll, |state, _| {
                state.steps += 1;
                Ok(false)
            })
            .map(|_| ())
    }

    /// Back to (q, p) one step before the last, after a step whose impacts could not be
    /// resolved: the run's last good state, restarted (carries and caches cleared).
    pub(in crate::integrators) fn rewind(&mut self, q: &[f64], p: &[f64]) -> Result<(), Error> {
        self.jump_to(q, p)?;
        let state = self.state.borrow_mut();
        state.steps = state.steps.saturating_sub(1).max(state.clock.n0);
        Ok(())
    }

    /// Sets the step size h for the next steps, from the current time on (tₙ₊ₖ = tₙ + k·h).
    /// Refuses an h that is not finite and positive, keeping the old one.
    pub fn set_dt(&mut self, h: f64) -> Result<(), Error> {
        if !(h.is_finite() && h > 0.0) {
            return Err(Error::invalid("dt", format!("must be finite and positive, got {h}")));
        }
        if !self.model.as_lagrangian().delays().is_empty() {
            let reason = "a model with delayed forces keeps its step: its history holds the steps taken";
            return Err(Error::invalid("dt", reason));
        }
        let state = self.state.borrow_mut();
        state.clock = Clock {
            t0: state.t(),
            n0: state.steps,
            h,
        };
        Ok(())
    }
}

impl<M, St: Borrow<StepperState>> Deref for Stepper<M, St> {
    type Target = StepperState;

    fn deref(&self) -> &StepperState {
        self.state.borrow()
    }
}

impl StepperState {
    /// The state of a new stepper from (q0, p0), checked by the caller.
    fn fresh(method: Method, q0: &[f64], p0: &[f64], options: &Options) -> Self {
        let n = q0.len();
        let zeros = || vec![0.0; n];
        StepperState {
            integrator: Integrator::with_newton(method, n, options.newton),
            clock: Clock {
                t0: options.t0,
                n0: 0,
                h: options.dt,
            },
            steps: 0,
            compensated: options.compensated,
            q: q0.to_vec(),
            p: p0.to_vec(),
            eq: zeros(),
            ep: zeros(),
            dq: zeros(),
            dp: zeros(),
            q_next: zeros(),
            p_next: zeros(),
            eq_next: zeros(),
            ep_next: zeros(),
            contact_work: 0.0,
            exchanges: false,
            interrupt: InterruptPoll::new(),
        }
    }

    /// The state (q0, p0) at t0 after 0 steps of size h, restarted: carries and caches cleared.
    fn restart(&mut self, t0: f64, q0: &[f64], p0: &[f64], h: f64) {
        self.q.copy_from_slice(q0);
        self.p.copy_from_slice(p0);
        self.eq.fill(0.0);
        self.ep.fill(0.0);
        self.clock = Clock { t0, n0: 0, h };
        self.steps = 0;
        self.integrator.reset();
    }

    /// One step of `model`, which has as many coordinates as the state (checked when the
    /// stepper was made or resumed).
    pub(super) fn step<S: Dynamics + ?Sized>(&mut self, model: &S) -> Result<(), Error> {
        let step = self.steps + 1;
        let time = self.t();
        let start = StepStart {
            t: time,
            h: self.clock.h,
            q: &self.q,
            p: &self.p,
        };
        let mut increment = Increment {
            dq: &mut self.dq,
            dp: &mut self.dp,
        };
        if let Err(e) = model.increment(&mut self.integrator, &start, &mut increment) {
            return Err(e.at(step, time));
        }
        let finite = if self.compensated {
            compensated::add(&self.q, &self.eq, &self.dq, &mut self.q_next, &mut self.eq_next)
                & compensated::add(&self.p, &self.ep, &self.dp, &mut self.p_next, &mut self.ep_next)
        } else {
            compensated::add_plain(&self.q, &self.dq, &mut self.q_next)
                & compensated::add_plain(&self.p, &self.dp, &mut self.p_next)
        };
        if !finite {
            return Err(diverged(step, time));
        }
        std::mem::swap(&mut self.q, &mut self.q_next);
        std::mem::swap(&mut self.p, &mut self.p_next);
        if self.compensated {
            std::mem::swap(&mut self.eq, &mut self.eq_next);
            std::mem::swap(&mut self.ep, &mut self.ep_next);
        }
        self.steps = step;
        Ok(())
    }

    /// `n` steps in runs of those that need no poll before them, `poll` called before a run
    /// when due; `run(state, k)` takes k steps, true when it stopped after fewer (then so does
    /// this, true).
    fn polled<P: Poll>(
        &mut self,
        n: usize,
        mut poll: P,
        mut run: impl FnMut(&mut Self, usize) -> Result<bool, Error>,
    ) -> Result<bool, Error> {
        let mut left = n;
        while left > 0 {
            if self.interrupt.due() {
                if let Err(source) = poll.poll(self.steps) {
                    return Err(Error::Interrupted {
                        step: self.steps + 1,
                        time: self.t(),
                        source,
                    });
                }
            }
            let steps = 1 + self.interrupt.quiet(left - 1);
            let before = self.steps;
            if run(self, steps)? {
                // The steps not taken go back to the countdown, keeping the polls' pace.
                self.interrupt.unquiet(steps - (self.steps - before));
                return Ok(true);
            }
            left -= steps;
        }
        Ok(false)
    }

    /// The integrator, and the state as a method's own loop advances it.
    fn phase(&mut self) -> (&mut Integrator, Phase<'_>) {
        let StepperState {
            integrator,
            clock,
            steps,
            compensated,
            q,
            p,
            eq,
            ep,
            q_next,
            p_next,
            ..
        } = self;
        let phase = Phase {
            q,
            p,
            eq,
            ep,
            start_q: q_next,
            start_p: p_next,
            compensated: *compensated,
            steps,
            clock: *clock,
        };
        (integrator, phase)
    }

    /// Refuses, naming `dt`, `steps` more steps whose times the clock would not tell apart
    /// (`Clock::check_resolution`).
    pub fn check_horizon(&self, steps: usize) -> Result<(), Error> {
        self.clock.check_resolution(self.steps.saturating_add(steps))
    }

    /// The time tₙ = t₀ + n·h (counted from the last change of h, see [`Stepper::set_dt`]).
    pub fn t(&self) -> f64 {
        self.clock.at(self.steps)
    }

    /// The time after `steps` steps on the present clock (the run's ahead).
    pub(in crate::integrators) fn time_at(&self, steps: usize) -> f64 {
        self.clock.at(steps)
    }

    /// The steps n completed.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// The step size h.
    pub fn dt(&self) -> f64 {
        self.clock.h
    }

    /// The positions qₙ.
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// The momenta pₙ.
    pub fn p(&self) -> &[f64] {
        &self.p
    }

    /// The method applied.
    pub fn method(&self) -> Method {
        self.integrator.method()
    }

    /// Whether the increments are added with compensated summation.
    pub fn compensated(&self) -> bool {
        self.compensated
    }

    /// The options of the implicit methods' Newton iteration; None for the explicit methods.
    pub fn newton_options(&self) -> Option<super::NewtonOptions> {
        self.integrator.newton_options()
    }

    /// Force evaluations made so far (see [`Integrator::force_evaluations`]).
    pub fn force_evaluations(&self) -> u64 {
        self.integrator.force_evaluations()
    }

    /// Newton iterations made so far (0 for the explicit methods).
    pub fn newton_iterations(&self) -> u64 {
        self.integrator.newton_iterations()
    }

    /// Newton iterations made so far; None for the methods that solve no equations.
    pub fn newton(&self) -> Option<u64> {
        self.integrator.newton()
    }

    /// The energy put in so far, against which E − E₀ balances: the work of a forced
    /// Lagrangian's forces and of the held contacts' friction, less Σ∂L_d/∂t, what an L that
    /// depends on t takes.
    pub fn work(&self) -> f64 {
        self.integrator.work() + self.contact_work
    }
}

impl<M: Deref<Target: Dynamics>, St: Borrow<StepperState>> Stepper<M, St> {
    /// The energy put in so far by the non-conservative forces and by L's dependence on t
    /// (−Σ∂L_d/∂t); None for a model with neither
    /// watched without friction.
    pub fn forced_work(&self) -> Option<f64> {
        let lagrangian = self.model.as_lagrangian();
        (lagrangian.is_forced() || lagrangian.is_time_dependent() || self.exchanges).then(|| self.work())
    }
}

/// [`Dynamics::check_initial`], a model's error dated at t0.
fn check_initial<S: Dynamics + ?Sized>(model: &S, q0: &[f64], p0: &[f64], t0: f64) -> Result<(), Error> {
    model.check_initial(q0, p0).map_err(|e| match e {
        Error::Model { step, source, .. } => Error::model(step, t0, source),
        e => e,
    })
}

/// The error of a step whose state is not finite.
pub(super) fn diverged(step: usize, time: f64) -> Error {
    let reason =
        "the state became non-finite (the method is unstable at this step size, or the model is singular here)";
    Error::Divergence {
        step,
        time,
        reason: reason.to_string(),
    }
}
