//! The jumps' resolution: a step that ends with some φ < 0, or that holds an impulse's time, redone
//! in pieces on a scratch stepper, each piece a partial step of the method from its start, split
//! at the first contact crossed (located to round-off) or at the impulse, the jump applied there,
//! and the rest of the step re-checked against every contact, up to [`MAX_IMPACTS`] impacts in
//! the step. The samples of a step are partial steps from the last jump before them.

use std::borrow::{Borrow, BorrowMut};
use std::ops::Deref;

use super::hold::{Held, Hold};
use super::unsolved::run_error;
use super::{
    reflect, round_off, variational, Contact, Contacts, Impacts, Law, NativeSurface, Schedule, Switch, MAX_IMPACTS,
};
use crate::integrators::events::Search;
use crate::integrators::DiscreteEnergy;
use crate::integrators::{Clear, Counting, Dynamics, Method, Occurrence, Poll, Stepper, StepperState, Trajectory};
use crate::model::Lagrangian;
use crate::solve::bracket::{illinois, newton};
use crate::{Error, ModelError};

/// Why the variational law does not fit `method` on `model`, if it does not: it needs the
/// method's discrete energy ([`DiscreteEnergy`]) and a conservative, autonomous, unconstrained
/// model (the energy balance is E_d's alone).
pub(super) fn variational_misfit<S: Dynamics + ?Sized>(model: &S, method: Method) -> Option<String> {
    if DiscreteEnergy::new(method, 0).is_none() {
        return Some(format!(
            "needs a kick–drift method, a two-point rule (midpoint, trapezoid) or a Galerkin rule, not {}; give \
             the contact law reflect or use such a method",
            method.info().name
        ));
    }
    let lagrangian = model.as_lagrangian();
    let constrained = model.constraint_counts() != (0, 0) || model.velocity_constraints().is_some();
    if lagrangian.is_forced() || lagrangian.is_time_dependent() || constrained {
        return Some(
            "keeps the discrete energy, which needs a conservative, autonomous, unconstrained model; give the \
             contact law reflect"
                .into(),
        );
    }
    None
}

/// A run's resolver: the contacts and the schedule, the scratch stepper of the partial steps
/// (a copy of the run's stepper) and every buffer of the resolution, made once per run.
pub(in crate::integrators) struct Resolver<'c, 's, M> {
    contacts: &'c [Contact<'s>],
    /// Each contact's surface, if native ([`Gaps`]).
    native: Vec<Option<&'c NativeSurface>>,
    schedule: Option<&'c Schedule<'s>>,
    /// The next impulse and sample of the schedule (those before are done).
    next_impulse: usize,
    next_sample: usize,
    scratch: Stepper<M>,
    /// The scratch's force evaluations when it was made (the run's so far).
    counted: u64,
    /// φ of every contact at the run's state (the next step's start), at a piece's start, at
    /// its end.
    phi: Vec<f64>,
    phi_start: Vec<f64>,
    phi_end: Vec<f64>,
    /// The step's start (tₙ, qₙ, pₙ).
    t: f64,
    q: Vec<f64>,
    p: Vec<f64>,
    /// The piece's start.
    piece_q: Vec<f64>,
    piece_p: Vec<f64>,
    /// The jump's state (q̃, p⁻), the normal and the laws' work buffers.
    contact_q: Vec<f64>,
    contact_p: Vec<f64>,
    normal: Vec<f64>,
    v: Vec<f64>,
    w: Vec<f64>,
    zeros: Vec<f64>,
    /// The step's impacts, kept when the step is resolved, and its impulses (by their index in
    /// the schedule).
    pending: Impacts,
    blown: Impacts,
    /// The method's discrete energy, for the variational law.
    discrete: Option<DiscreteEnergy>,
    /// The contacts held closed, in order (indices into `contacts`), and the held step (None
    /// where the method or the model cannot hold one: a contact that would close then bounces
    /// on until [`Error::Contact`]).
    closed: Vec<usize>,
    hold: Option<Hold>,
    /// The closed set at the step's start, restored when the step fails.
    closed_start: Vec<usize>,
    /// The closed set at a sample's time, and the multipliers of a closed set.
    closed_then: Vec<usize>,
    lambda: Vec<f64>,
    lambda_end: Vec<f64>,
    /// The step's releases and friction switches (their states, to start its samples from)
    /// and its changes of the closed and stuck sets in order, (time in the run, contact,
    /// switch), to undo back to a sample's time.
    released: Impacts,
    changes: Vec<(f64, usize, Switch)>,
    /// Whether some contact has friction; the closed contacts whose friction sticks, in
    /// order, at the step's start and at a sample's time.
    frictional: bool,
    stuck: Vec<usize>,
    stuck_start: Vec<usize>,
    stuck_then: Vec<usize>,
    /// Each contact's slip direction at the piece's start ([`Held`]), a contact's slip and its
    /// direction in q.
    directions: Vec<f64>,
    slip: Vec<f64>,
    direction: Vec<f64>,
    /// The energy put in by the step's pieces and jumps up to each of its impacts (just before,
    /// just after), impulses (likewise) and releases: what its saved states inside the step
    /// are behind its end.
    pending_work: Vec<[f64; 2]>,
    blown_work: Vec<[f64; 2]>,
    released_work: Vec<f64>,
    /// The friction work of the last partial step, and the energy the step's pieces and jumps
    /// put in so far (friction's work, the laws' losses, the impulses' energy, the projections
    /// onto closed contacts): the stepper's contact work once the step is resolved.
    piece_work: f64,
    step_work: f64,
    /// A partial step's end kept to be taken again: the location's nearest to the surface,
    /// the contact state; the variational law's last, the next piece.
    kept: Kept,
}

/// The end (q, p) of the free partial step of size s from ta, `at` = (ta, s), started from the
/// momenta `from` (the piece's start q is the piece's own): [`Resolver::partial`] takes it
/// instead of stepping again.
struct Kept {
    at: Option<(f64, f64)>,
    from: Vec<f64>,
    q: Vec<f64>,
    p: Vec<f64>,
}

/// Friction switches in one step at most: more is a stick–slip chatter the step cannot
/// resolve, which ends the run with [`Error::Contact`].
const MAX_SWITCHES: usize = 4 * MAX_IMPACTS;

impl<'c, 's, M: Deref<Target: Dynamics>> Resolver<'c, 's, M> {
    /// The resolver of `contacts` (checked by the caller, [`Contacts::check`]) and `schedule`
    /// for a run of `stepper` on `model` from its state. The schedule's times after the state's
    /// are to come (and those at it, for [`Resolver::start`]).
    pub(in crate::integrators) fn begin<St: Borrow<StepperState>>(
        model: M,
        stepper: &Stepper<M, St>,
        (contacts, schedule): (Option<&'c Contacts<'s>>, Option<&'c Schedule<'s>>),
    ) -> Result<Self, Error> {
        let n = stepper.q().len();
        if let Some(schedule) = schedule {
            schedule.fit(n)?;
        }
        let contacts = contacts.map_or(&[][..], |c| c.contacts());
        // RATTLE on the closed surfaces alone: a model without forces or constraints of its own.
        let constrained = model.constraint_counts() != (0, 0) || model.velocity_constraints().is_some();
        let holds = !model.as_lagrangian().is_forced() && !constrained;
        let scratch = Stepper::resume(model, StepperState::clone(stepper))?;
        let m = contacts.len();
        // The multipliers of every contact closed and stuck at once.
        let rows = m + contacts
            .iter()
            .filter_map(|c| c.friction.as_ref().map(|f| f.rows(n)))
            .sum::<usize>();
        let t0 = stepper.t();
        let mut resolver = Resolver {
            contacts,
            native: contacts.iter().map(|c| c.surface.native()).collect(),
            schedule,
            next_impulse: schedule.map_or(0, |s| s.impulses().partition_point(|b| b.t <= t0)),
            next_sample: schedule.map_or(0, |s| s.samples().partition_point(|&t| t <= t0)),
            counted: scratch.force_evaluations(),
            scratch,
            phi: vec![0.0; m],
            phi_start: vec![0.0; m],
            phi_end: vec![0.0; m],
            t: t0,
            q: stepper.q().to_vec(),
            p: stepper.p().to_vec(),
            piece_q: vec![0.0; n],
            piece_p: vec![0.0; n],
            contact_q: vec![0.0; n],
            contact_p: vec![0.0; n],
            normal: vec![0.0; n],
            v: vec![0.0; n],
            w: vec![0.0; n],
            zeros: vec![0.0; n],
            pending: Impacts::with_capacity(n, MAX_IMPACTS),
            blown: Impacts::with_capacity(n, schedule.map_or(0, |s| s.impulses().len())),
            discrete: (contacts.iter().any(|c| c.law == Law::Variational))
                .then(|| DiscreteEnergy::new(stepper.method(), n))
                .flatten(),
            closed: Vec::with_capacity(m),
            closed_start: Vec::with_capacity(m),
            hold: (m > 0 && holds)
                .then(|| Hold::new(stepper.method(), n, contacts))
                .flatten(),
            closed_then: Vec::with_capacity(m),
            lambda: vec![0.0; rows],
            lambda_end: vec![0.0; rows],
            released: Impacts::with_capacity(n, m),
            changes: Vec::with_capacity(2 * m),
            frictional: contacts.iter().any(|c| c.friction.is_some()),
            stuck: Vec::with_capacity(m),
            stuck_start: Vec::with_capacity(m),
            stuck_then: Vec::with_capacity(m),
            directions: vec![0.0; n * m],
            slip: vec![0.0; n],
            direction: vec![0.0; n],
            pending_work: Vec::with_capacity(MAX_IMPACTS),
            blown_work: Vec::with_capacity(schedule.map_or(0, |s| s.impulses().len())),
            released_work: Vec::with_capacity(m),
            piece_work: 0.0,
            step_work: 0.0,
            kept: Kept {
                at: None,
                from: vec![0.0; n],
                q: vec![0.0; n],
                p: vec![0.0; n],
            },
        };
        if resolver.frictional && resolver.hold.is_none() {
            return Err(Error::invalid(
                "contacts",
                format!(
                    "friction acts on held contacts, which {} hold on a model without forces or constraints of its \
                     own, not {}",
                    Hold::methods(),
                    stepper.method().info().name
                ),
            ));
        }
        let (step, time) = (stepper.steps(), stepper.t());
        evaluate(contacts, stepper.q(), &mut resolver.phi, step, time)?;
        resolver.close_resting((stepper.t(), stepper.q(), stepper.p()), step)?;
        Ok(resolver)
    }

    /// Whether the run saves the samples' states, and those alone.
    pub(in crate::integrators) fn sampling(&self) -> bool {
        self.schedule.is_some_and(Schedule::sampling)
    }

    /// How many samples the schedule holds.
    pub(in crate::integrators) fn samples(&self) -> usize {
        self.schedule.map_or(0, |s| s.samples().len())
    }

    /// A new run's start (a resumed run's times at its start are the first run's): the samples
    /// at its t0 taken, then the impulses there applied (the states just before and after each
    /// saved).
    pub(in crate::integrators) fn start<St: BorrowMut<StepperState>>(
        &mut self,
        stepper: &mut Stepper<M, St>,
        search: Option<&mut Search<'_, '_, M>>,
        traj: &mut Trajectory,
    ) -> Result<(), Error> {
        if let Some(schedule) = self.schedule {
            let t0 = stepper.t();
            self.next_impulse = schedule.impulses().partition_point(|b| b.t < t0);
            self.next_sample = schedule.samples().partition_point(|&t| t < t0);
        }
        self.take_samples(stepper, traj)?;
        self.blow_at_grid(stepper, search, traj)
    }

    /// Advances `stepper` by up to `n` steps, resolving the impacts of each (saved in `traj`:
    /// the impacts, and the states just before and after each), applying the schedule's
    /// impulses and taking its samples, and watching `search`'s events on the pieces. Returns
    /// the event whose terminal count was reached, the run stopping at the end of that step;
    /// None after the n steps. On failure the stepper is at the last good step.
    ///
    /// Without events the steps up to the next scheduled time are the method's own loop,
    /// checked against the contacts after each ([`Gaps`]) and stopped by the first that crosses
    /// one; with events, one at a time (the events need each step's start).
    pub(in crate::integrators) fn advance<St: BorrowMut<StepperState>, P: Poll>(
        &mut self,
        stepper: &mut Stepper<M, St>,
        n: usize,
        mut search: Option<&mut Search<'_, '_, M>>,
        traj: &mut Trajectory,
        poll: &mut P,
    ) -> Result<Option<usize>, Error> {
        let mut left = n;
        while left > 0 {
            let free = if search.is_none() && self.closed.is_empty() {
                self.free_steps(stepper, left)
            } else {
                0
            };
            if free > 0 {
                left -= self.advance_clear(stepper, free, traj, poll)?;
                continue;
            }
            let plain = if search.is_none() && !self.closed.is_empty() && !self.frictional {
                self.free_steps(stepper, left)
            } else {
                0
            };
            if plain > 0 {
                let taken = self.advance_held(stepper, plain, poll)?;
                left -= taken;
                if taken == plain {
                    continue;
                }
            }
            self.t = stepper.t();
            self.q.copy_from_slice(stepper.q());
            self.p.copy_from_slice(stepper.p());
            if let Some(search) = search.as_deref_mut() {
                search.start_step(stepper);
            }
            let first = traj.events.len();
            let crossed = if self.closed.is_empty() {
                stepper.advance(1, Counting(|steps| poll.poll(steps)))?;
                evaluate(self.contacts, stepper.q(), &mut self.phi_end, stepper.steps(), self.t)?;
                crosses(&self.phi, &self.phi_end)
            } else {
                // A held step, which the resolver takes: the step on the clock, its state set
                // at its end (`resolve`).
                stepper.tick(Counting(|steps| poll.poll(steps)))?;
                true
            };
            left -= 1;
            self.settle(stepper, crossed, search.as_deref_mut(), traj, first)?;
            if let Some(stop) = search.as_deref_mut().and_then(|s| s.count(&mut traj.events, first)) {
                return Ok(Some(stop));
            }
        }
        Ok(None)
    }

    /// How many of the next `n` steps end before the schedule's next time (impulse or sample):
    /// those the method's own loop may take.
    fn free_steps<St: Borrow<StepperState>>(&self, stepper: &Stepper<M, St>, n: usize) -> usize {
        let Some(schedule) = self.schedule else {
            return n;
        };
        let next = [
            schedule.impulses().get(self.next_impulse).map(|b| b.t),
            schedule.samples().get(self.next_sample).copied(),
        ];
        let Some(t_next) = next.into_iter().flatten().reduce(f64::min) else {
            return n;
        };
        let (start, t) = (stepper.steps(), stepper.t());
        // The estimate, then the clock's own times (tₙ₊ₖ < t_next for the k steps taken).
        let estimate = ((t_next - t) / stepper.dt()).floor();
        let mut k = if estimate > 0.0 { (estimate as usize).min(n) } else { 0 };
        while k > 0 && stepper.time_at(start + k) >= t_next {
            k -= 1;
        }
        while k < n && stepper.time_at(start + k + 1) < t_next {
            k += 1;
        }
        k
    }

    /// Up to `n` steps without events in the method's own loop, the first that crosses a
    /// contact settled as the one-at-a-time loop settles it: the steps taken.
    fn advance_clear<St: BorrowMut<StepperState>, P: Poll>(
        &mut self,
        stepper: &mut Stepper<M, St>,
        n: usize,
        traj: &mut Trajectory,
        poll: &mut P,
    ) -> Result<usize, Error> {
        let before = stepper.steps();
        let mut gaps = Gaps::new(self.contacts, &self.native, &mut self.phi, &mut self.phi_end);
        let start = (&mut self.t, &mut self.q[..], &mut self.p[..]);
        let stopped = stepper.advance_while(n, Counting(|steps| poll.poll(steps)), &mut gaps, start);
        let (swapped, stale, error) = (gaps.swapped, gaps.stale, gaps.error.take());
        if swapped {
            std::mem::swap(&mut self.phi, &mut self.phi_end);
        }
        let stopped = stopped?;
        let (step, time) = (stepper.steps(), self.t);
        if let Some(source) = error {
            return Err(Error::model(step, time, source));
        }
        if stale {
            // φ at the next step's start: the stopped step's start, or the state.
            let q = if stopped { &self.q[..] } else { stepper.q() };
            evaluate(self.contacts, q, &mut self.phi, step, time)?;
        }
        if stopped {
            self.settle(stepper, true, None, traj, traj.events.len())?;
        }
        Ok(stepper.steps() - before)
    }

    /// Up to `n` steps with the closed contacts (frictionless) held as they are, in the hold's
    /// own loop: each the held step from the last's end, kept where every closed contact still
    /// presses at its end and no open one is crossed. The first step that would release or
    /// cross a contact, or that fails, is not taken: the one-at-a-time loop redoes it
    /// ([`Resolver::resolve`]), from the same state to the same end. The steps taken.
    fn advance_held<St: BorrowMut<StepperState>, P: Poll>(
        &mut self,
        stepper: &mut Stepper<M, St>,
        n: usize,
        poll: &mut P,
    ) -> Result<usize, Error> {
        let (Some(hold), h) = (self.hold.as_mut(), stepper.dt()) else {
            return Ok(0);
        };
        let held = Held {
            contacts: self.contacts,
            closed: &self.closed,
            stuck: &self.stuck,
            directions: &self.directions,
        };
        let model = self.scratch.model().as_lagrangian();
        self.t = stepper.t();
        self.q.copy_from_slice(stepper.q());
        self.p.copy_from_slice(stepper.p());
        let mut taken = 0;
        let mut ticked = Ok(());
        while taken < n {
            let t = self.t;
            // φ of the open contacts alone: the closed ones' is needed only where the loop stops.
            let open = |j: &usize| !self.closed.contains(j);
            let kept = hold.step(model, held, (t, h), (&self.q, &self.p)).is_ok()
                && hold.pressing(model, held, t + h).unwrap_or(false)
                && (0..self.contacts.len()).filter(open).all(|j| {
                    gap(&self.contacts[j], None, &hold.q).is_ok_and(|phi| {
                        self.phi_end[j] = phi;
                        !crossing(self.phi[j], phi)
                    })
                });
            if !kept {
                break;
            }
            ticked = stepper.tick(Counting(|steps| poll.poll(steps)));
            if ticked.is_err() {
                break;
            }
            self.t = stepper.t();
            self.q.copy_from_slice(&hold.q);
            self.p.copy_from_slice(&hold.p);
            for j in (0..self.contacts.len()).filter(open) {
                self.phi[j] = self.phi_end[j];
            }
            taken += 1;
        }
        if taken > 0 {
            stepper.jump_to(&self.q, &self.p)?;
            for &j in &self.closed {
                self.phi[j] = gap(&self.contacts[j], None, &self.q).map_err(|source| Error::Model {
                    step: stepper.steps(),
                    time: self.t,
                    source,
                })?;
            }
        }
        ticked.map(|()| taken)
    }

    /// The step just taken by `stepper` from the kept start (t, q, p), with φ at its end in
    /// `phi_end`: redone in pieces if it `crossed` a contact or holds an impulse (its jumps,
    /// and the states just before and after each, saved in `traj`), `search`'s events located
    /// on it or its pieces (those from `first` on are the step's), its samples taken and the
    /// impulses at its end applied. On failure the stepper is at the step's start.
    fn settle<St: BorrowMut<StepperState>>(
        &mut self,
        stepper: &mut Stepper<M, St>,
        crossed: bool,
        mut search: Option<&mut Search<'_, '_, M>>,
        traj: &mut Trajectory,
        first: usize,
    ) -> Result<(), Error> {
        let (step, h) = (stepper.steps(), stepper.dt());
        let inside = self.impulse_inside(stepper.t()).is_some();
        // The energy the step's pieces and jumps put in: none unless it is resolved.
        self.step_work = 0.0;
        let resolved = if crossed || inside {
            match self.resolve(stepper, search.as_deref_mut(), &mut traj.events) {
                Ok(resolved) => resolved,
                Err(error) => {
                    // The run ends at the step's start, with none of the step's events, and
                    // the contacts closed there.
                    traj.events.truncate(first);
                    self.closed.clear();
                    self.closed.extend_from_slice(&self.closed_start);
                    self.stuck.clear();
                    self.stuck.extend_from_slice(&self.stuck_start);
                    stepper.rewind(&self.q, &self.p)?;
                    return Err(error);
                }
            }
        } else {
            false
        };
        if !resolved {
            if crossed {
                // The scratch's first piece crossed nothing after all: φ at the step's end.
                evaluate(self.contacts, stepper.q(), &mut self.phi_end, step, self.t)?;
            }
            std::mem::swap(&mut self.phi, &mut self.phi_end);
            if let Some(search) = search.as_deref_mut() {
                search.piece(step, (stepper.t(), stepper.q(), stepper.p()), h, &mut traj.events)?;
            }
        }
        // The samples from the step's jumps, before they are reported.
        self.take_samples(stepper, traj)?;
        if resolved {
            self.push_jumps(stepper, traj);
        }
        self.blow_at_grid(stepper, search, traj)
    }

    /// The time of the next impulse if it falls inside the step that ends at `t_end`.
    fn impulse_inside(&self, t_end: f64) -> Option<f64> {
        let impulses = self.schedule?.impulses();
        impulses.get(self.next_impulse).map(|b| b.t).filter(|&t| t < t_end)
    }

    /// The step's jumps saved, in order of time (the states just before and after each, unless
    /// the run saves its samples alone), and its impacts reported.
    fn push_jumps<St: Borrow<StepperState>>(&mut self, stepper: &Stepper<M, St>, traj: &mut Trajectory) {
        if !self.sampling() {
            let (a, b) = (&self.pending, &self.blown);
            let (mut i, mut k) = (0, 0);
            while i < a.len() || k < b.len() {
                let (jumps, row, [before, after]) = if k == b.len() || (i < a.len() && a.t[i] <= b.t[k]) {
                    i += 1;
                    (a, i - 1, self.pending_work[i - 1])
                } else {
                    k += 1;
                    (b, k - 1, self.blown_work[k - 1])
                };
                let (t, q) = (jumps.t[row], jumps.q_at(row));
                traj.push_state(t, (q, jumps.p_before_at(row)), stepper, self.step_work - before);
                traj.push_state(t, (q, jumps.p_after_at(row)), stepper, self.step_work - after);
            }
        }
        self.blown.clear();
        self.released.clear();
        self.changes.clear();
        self.pending_work.clear();
        self.blown_work.clear();
        self.released_work.clear();
        traj.impacts.append(&mut self.pending);
    }

    /// The impulses at the stepper's time, a point of the grid (the end of the step just taken,
    /// or a new run's t0): the jumps applied to its state, which is saved just before and after
    /// each (unless the run saves its samples alone); the events restarted there.
    fn blow_at_grid<St: BorrowMut<StepperState>>(
        &mut self,
        stepper: &mut Stepper<M, St>,
        search: Option<&mut Search<'_, '_, M>>,
        traj: &mut Trajectory,
    ) -> Result<(), Error> {
        let Some(schedule) = self.schedule else {
            return Ok(());
        };
        let (t, step) = (stepper.t(), stepper.steps());
        let first = self.next_impulse;
        while schedule.impulses().get(self.next_impulse).is_some_and(|b| b.t == t) {
            self.contact_q.copy_from_slice(stepper.q());
            self.contact_p.copy_from_slice(stepper.p());
            // Its own account: the step's (committed) is done with.
            self.step_work = 0.0;
            self.blow(self.next_impulse, step, t)?;
            self.after_jump(step, t)?;
            traj.impacts.switches.append(&mut self.pending.switches);
            let put = std::mem::take(&mut self.step_work);
            stepper.add_contact_work(put);
            if !self.sampling() {
                traj.push_state(t, (&self.contact_q, &self.contact_p), stepper, put);
                traj.push_state(t, (&self.contact_q, &self.piece_p), stepper, 0.0);
            }
            stepper.jump_to(&self.contact_q, &self.piece_p)?;
            self.next_impulse += 1;
        }
        if self.next_impulse > first {
            if let Some(search) = search {
                search.restart_piece(step, (t, stepper.q(), stepper.p()))?;
            }
        }
        Ok(())
    }

    /// The jump of impulse k at (q, p⁻) (the contact buffers) at time t: p⁺ = p⁻ + P(q) into
    /// `piece_p`, projected on the constraints of a constrained model (their workless impulse).
    fn blow(&mut self, k: usize, step: usize, t: f64) -> Result<(), Error> {
        let model_error = |source| Error::model(step, t, source);
        let impulse = &self.schedule.expect("a schedule blows").impulses()[k];
        impulse
            .blow
            .components(&self.contact_q, &mut self.v)
            .map_err(model_error)?;
        for (x, (a, b)) in self.piece_p.iter_mut().zip(self.contact_p.iter().zip(&self.v)) {
            *x = a + b;
        }
        let model = self.scratch.model();
        if let Some(projected) = model.project(&self.contact_q, &self.piece_p) {
            let (_, p) = projected?;
            self.piece_p.copy_from_slice(&p);
        }
        if !self.piece_p.iter().all(|x| x.is_finite()) {
            let source = format!("impulses[{k}] at t = {t} gives non-finite momenta").into();
            return Err(model_error(source));
        }
        // The energy the blow puts in: E(q, p⁺) − E(q, p⁻), where the model has an energy.
        let energy = |p: &[f64]| (model.energy(&self.contact_q, p, t).transpose()).map_err(model_error);
        if let (Some(before), Some(after)) = (energy(&self.contact_p)?, energy(&self.piece_p)?) {
            self.step_work += after.energy - before.energy;
        }
        Ok(())
    }

    /// The samples of the step just taken (those after its start, up to its end): each the
    /// partial step of the method to it from the last jump before it, or from the step's start;
    /// one at the step's end is its state. A sample at a jump's time is the state just before it.
    fn take_samples<St: Borrow<StepperState>>(
        &mut self,
        stepper: &Stepper<M, St>,
        traj: &mut Trajectory,
    ) -> Result<(), Error> {
        let Some(schedule) = self.schedule else {
            return Ok(());
        };
        let (t_end, step) = (stepper.t(), stepper.steps());
        while let Some(&ts) = schedule.samples().get(self.next_sample).filter(|&&ts| ts <= t_end) {
            self.next_sample += 1;
            if ts == t_end {
                traj.push_state(ts, (stepper.q(), stepper.p()), stepper, 0.0);
                continue;
            }
            // The last jump or release before ts (an impact before an impulse at its time), and
            // the energy put in up to it.
            let last = |jumps: &Impacts| jumps.t.iter().rposition(|&t| t < ts).map(|k| (jumps.t[k], k));
            let mut from: Option<(&Impacts, usize, f64, f64)> = None;
            let (pending, released, blown) = (&self.pending_work, &self.released_work, &self.blown_work);
            let offsets: [&dyn Fn(usize) -> f64; 3] = [&|k| pending[k][1], &|k| released[k], &|k| blown[k][1]];
            for (jumps, offset) in [&self.pending, &self.released, &self.blown].into_iter().zip(offsets) {
                if let Some((t, k)) = last(jumps) {
                    if from.is_none_or(|(_, _, t0, _)| t > t0) {
                        from = Some((jumps, k, t, offset(k)));
                    }
                }
            }
            let (ta, put) = match from {
                Some((jumps, k, _, put)) => {
                    self.piece_q.copy_from_slice(jumps.q_at(k));
                    self.piece_p.copy_from_slice(jumps.p_after_at(k));
                    (jumps.t[k], put)
                }
                None => {
                    self.piece_q.copy_from_slice(&self.q);
                    self.piece_p.copy_from_slice(&self.p);
                    (self.t, 0.0)
                }
            };
            // The contacts closed and stuck at ts: the step's changes from ts on undone.
            self.closed_then.clear();
            self.closed_then.extend_from_slice(&self.closed);
            self.stuck_then.clear();
            self.stuck_then.extend_from_slice(&self.stuck);
            for &(_, k, switch) in self.changes.iter().rev().take_while(|c| c.0 >= ts) {
                match switch {
                    Switch::Closed => self.closed_then.retain(|&j| j != k),
                    Switch::Released => insert(&mut self.closed_then, k),
                    Switch::Stuck => self.stuck_then.retain(|&j| j != k),
                    Switch::Slipped => insert(&mut self.stuck_then, k),
                }
            }
            std::mem::swap(&mut self.closed, &mut self.closed_then);
            std::mem::swap(&mut self.stuck, &mut self.stuck_then);
            let sampled = self.aim_piece(step, ta).and_then(|()| self.partial(step, ta, ts - ta));
            std::mem::swap(&mut self.closed, &mut self.closed_then);
            std::mem::swap(&mut self.stuck, &mut self.stuck_then);
            sampled?;
            let behind = self.step_work - (put + self.piece_work);
            traj.push_state(ts, (self.scratch.q(), self.scratch.p()), stepper, behind);
        }
        Ok(())
    }

    /// The step just taken by `stepper` from the kept start, redone in pieces: false (nothing
    /// changed) when its first piece on the scratch stepper crosses no contact after all
    /// (round-off at a grazing end), holds no impulse and no contact was held; true with the
    /// stepper set to the step's end state and its impacts in `pending`, its impulses in
    /// `blown`. A held step (some contact closed) is always redone: its pieces are the held
    /// steps of [`Hold`], each ended early at a lift-off.
    fn resolve<St: BorrowMut<StepperState>>(
        &mut self,
        stepper: &mut Stepper<M, St>,
        mut search: Option<&mut Search<'_, '_, M>>,
        occurrences: &mut Vec<Occurrence>,
    ) -> Result<bool, Error> {
        let (step, h, t_end) = (stepper.steps(), stepper.dt(), stepper.t());
        let (contacts, time) = (self.contacts, self.t);
        let contact_error = |reason: String| Error::Contact { step, time, reason };
        let held = !self.closed.is_empty();
        self.piece_q.copy_from_slice(&self.q);
        self.piece_p.copy_from_slice(&self.p);
        self.phi_start.copy_from_slice(&self.phi);
        self.pending.clear();
        self.blown.clear();
        self.released.clear();
        self.pending_work.clear();
        self.blown_work.clear();
        self.released_work.clear();
        self.changes.clear();
        self.closed_start.clear();
        self.closed_start.extend_from_slice(&self.closed);
        self.stuck_start.clear();
        self.stuck_start.extend_from_slice(&self.stuck);
        self.step_work = 0.0;
        self.aim_piece(step, self.t)?;
        let (mut ta, mut tau, mut last) = (self.t, h, None);
        let mut switches = 0;
        loop {
            if search.is_some() && !self.closed.is_empty() {
                return Err(contact_error(
                    "events are not located on the motion of a held contact yet: run without events while a body \
                     rests or slides on a contact (its closures and releases are reported with its impacts)"
                        .into(),
                ));
            }
            // The piece to the next impulse inside the step, or to the step's end, the first
            // contact it crosses and the first held contact it releases.
            let inside = self.impulse_inside(t_end);
            let piece = inside.map_or(tau, |t| t - ta);
            self.partial(step, ta, piece)?;
            evaluate(contacts, self.scratch.q(), &mut self.phi_end, step, self.t)?;
            let switch = self.friction_switch(step, (ta, piece))?;
            let release = self.lift_off(step, (ta, piece))?;
            let mut first: Option<(f64, usize)> = None;
            for (j, contact) in contacts.iter().enumerate() {
                let leaving = last == Some(j) || self.phi_start[j] <= 0.0;
                if self.closed.contains(&j) || !below(self.phi_end[j] - floor(self.phi_start[j], leaving), leaving) {
                    continue;
                }
                let s = self.locate(j, step, (ta, piece), leaving).map_err(|e| match e {
                    Located::Error(e) => e,
                    Located::Resting => contact_error(format!(
                        "a body leaving the contact {} crosses it again at once (a resting or grazing contact, \
                         such as e = 0 under a force pressing on it), which impacts cannot resolve; {}",
                        contact.name,
                        // A method that holds contacts missed this one's closing: its bounces
                        // outran the step.
                        if self.hold.is_some() {
                            "this method holds such a contact closed once its bounces die out within a step: a \
                             smaller step (dt) helps"
                                .to_string()
                        } else {
                            format!(
                                "{} hold such a contact closed on a model without forces or constraints of its own",
                                Hold::methods()
                            )
                        }
                    )),
                })?;
                if let Some(s) = s {
                    if first.is_none_or(|(s0, _)| s < s0) {
                        first = Some((s, j));
                    }
                }
            }
            let before = |s: f64| first.is_none_or(|(s0, _)| s < s0);
            if let Some((s, k)) = release.filter(|&(s, _)| before(s) && switch.is_none_or(|(s1, ..)| s <= s1)) {
                // Lift-off: the state there, the contact open from there on.
                self.partial(step, ta, s)?;
                self.step_work += self.piece_work;
                self.contact_q.copy_from_slice(self.scratch.q());
                self.contact_p.copy_from_slice(self.scratch.p());
                self.piece_p.copy_from_slice(self.scratch.p());
                let t = ta + s;
                self.open(k, step, t);
                self.released
                    .push(k, step, t, &self.contact_q, &self.contact_p, &self.contact_p);
                self.released_work.push(self.step_work);
                self.restart_piece(step, None, t)?;
                (ta, tau, last) = (t, tau - s, Some(k));
                continue;
            }
            if let Some((s, k, kind)) = switch.filter(|&(s, ..)| before(s)) {
                // Stick or slip: the state there, the contact's friction switched from there on.
                switches += 1;
                if switches > MAX_SWITCHES {
                    return Err(contact_error(format!(
                        "the friction of {} switched between sticking and sliding more than {MAX_SWITCHES} times in \
                         one step; shorten the step",
                        contacts[k].name
                    )));
                }
                self.partial(step, ta, s)?;
                self.step_work += self.piece_work;
                self.contact_q.copy_from_slice(self.scratch.q());
                self.contact_p.copy_from_slice(self.scratch.p());
                self.piece_p.copy_from_slice(self.scratch.p());
                let t = ta + s;
                self.switch_friction(k, kind, step, t)?;
                self.restart_piece(step, None, t)?;
                (ta, tau) = (t, tau - s);
                continue;
            }
            let (s, j) = match (first, inside) {
                (Some(first), _) => first,
                (None, Some(t_blow)) => {
                    // The piece reaches the impulse: the scratch holds (q, p⁻) there.
                    self.step_work += self.piece_work;
                    self.contact_q.copy_from_slice(self.scratch.q());
                    self.contact_p.copy_from_slice(self.scratch.p());
                    if let Some(search) = search.as_deref_mut() {
                        search.piece(step, (t_blow, &self.contact_q, &self.contact_p), piece, occurrences)?;
                    }
                    let (k, before) = (self.next_impulse, self.step_work);
                    self.blow(k, step, t_blow)?;
                    self.after_jump(step, t_blow)?;
                    self.blown
                        .push(k, step, t_blow, &self.contact_q, &self.contact_p, &self.piece_p);
                    self.blown_work.push([before, self.step_work]);
                    self.next_impulse += 1;
                    self.restart_piece(step, search.as_deref_mut(), t_blow)?;
                    (ta, tau, last) = (t_blow, tau - piece, None);
                    continue;
                }
                (None, None)
                    if !held && self.pending.is_empty() && self.blown.is_empty() && self.changes.is_empty() =>
                {
                    return Ok(false)
                }
                // The last piece ends the step: the scratch holds its end.
                (None, None) => {
                    self.step_work += self.piece_work;
                    break;
                }
            };
            if self.pending.len() == MAX_IMPACTS {
                return Err(contact_error(self.too_many_impacts()));
            }
            // The contact state (q̃, p⁻), the end of this piece.
            self.partial(step, ta, s)?;
            self.step_work += self.piece_work;
            self.contact_q.copy_from_slice(self.scratch.q());
            self.contact_p.copy_from_slice(self.scratch.p());
            let t_contact = ta + s;
            if let Some(search) = search.as_deref_mut() {
                search.piece(step, (t_contact, &self.contact_q, &self.contact_p), s, occurrences)?;
            }
            let (contact, before) = (&contacts[j], self.step_work);
            self.jump(j, step, (ta, s, tau - s), h)?;
            self.after_jump(step, t_contact)?;
            if !self.piece_p.iter().all(|x| x.is_finite()) {
                return Err(contact_error(format!(
                    "a non-finite state after the impact on {} at t = {t_contact}",
                    contact.name
                )));
            }
            self.pending
                .push(j, step, t_contact, &self.contact_q, &self.contact_p, &self.piece_p);
            self.pending_work.push([before, self.step_work]);
            self.restart_piece(step, search.as_deref_mut(), t_contact)?;
            (ta, tau, last) = (t_contact, tau - s, Some(j));
        }
        // The step's end: the last piece's, at tₙ₊₁.
        stepper.jump_to(self.scratch.q(), self.scratch.p())?;
        stepper.add_contact_work(self.step_work);
        std::mem::swap(&mut self.phi, &mut self.phi_end);
        if let Some(search) = search {
            search.piece(step, (stepper.t(), stepper.q(), stepper.p()), tau, occurrences)?;
        }
        Ok(true)
    }

    /// Why a step met more than [`MAX_IMPACTS`] impacts, and what helps: flights that still
    /// shrink geometrically (the last under half the first, and under 0.99 of the one before)
    /// accumulate at a finite time, as a body coming to rest does, which no step resolves;
    /// flights that do not (a chatter of equal ones) are a step too long for them.
    fn too_many_impacts(&self) -> String {
        let t = &self.pending.t;
        let k = t.len();
        let (first, last, before) = (t[1] - t[0], t[k - 1] - t[k - 2], t[k - 2] - t[k - 3]);
        let ratio = last / before;
        if !(last < 0.5 * first && ratio < 0.99) {
            return format!(
                "more than {MAX_IMPACTS} impacts in one step, in flights as short as {last:.3e}: shorten the step (dt)"
            );
        }
        // The geometric series of the last flights' ratio sums to where they accumulate.
        let limit = format!(" at t ≈ {:.6}", t[k - 1] + last * ratio / (1.0 - ratio));
        let hold = if self.hold.is_some() {
            "; this method holds a contact closed only where e < 1 and the body presses on it".to_string()
        } else {
            format!(
                ", or hold the contact: {} hold such a contact closed on a model without forces or constraints of its \
                 own, with e < 1",
                Hold::methods()
            )
        };
        format!(
            "more than {MAX_IMPACTS} impacts in one step, their flights shrinking to an accumulation{limit} (a body \
             coming to rest on a surface), which no step resolves: stop the run before it{hold}"
        )
    }

    /// The first lift-off in the piece of size τ from ta, with the scratch at its end: among
    /// the closed contacts whose multiplier λ is negative there, the earliest s where λ crosses
    /// 0 along the held partial steps (Illinois, to round-off), and the contact. None when
    /// every λ ≥ 0 at the piece's end.
    fn lift_off(&mut self, step: usize, (ta, tau): (f64, f64)) -> Result<Option<(f64, usize)>, Error> {
        let m = self.closed.len();
        if m == 0 {
            return Ok(None);
        }
        let mut lambda = std::mem::take(&mut self.lambda_end);
        self.multipliers(ta + tau, &mut lambda, step)?;
        let mut first: Option<(f64, usize)> = None;
        for (a, &end) in lambda.iter().enumerate().take(m) {
            if end >= 0.0 {
                continue;
            }
            let at_start = self.lambda_along(a, step, ta, 0.0)?;
            let s = if at_start <= 0.0 {
                0.0
            } else {
                let tolerance = 4.0 * f64::EPSILON * tau;
                illinois(
                    |s| self.lambda_along(a, step, ta, s),
                    (0.0, at_start),
                    (tau, end),
                    tolerance,
                )?
                .0
            };
            if first.is_none_or(|(s0, _)| s < s0) {
                first = Some((s, self.closed[a]));
            }
        }
        self.lambda_end = lambda;
        Ok(first)
    }

    /// λ of the a-th closed contact at the end of the held partial step of size s from the
    /// piece's start.
    fn lambda_along(&mut self, a: usize, step: usize, ta: f64, s: f64) -> Result<f64, Error> {
        self.partial(step, ta, s)?;
        let mut lambda = std::mem::take(&mut self.lambda);
        let result = self.multipliers(ta + s, &mut lambda, step);
        let value = lambda[a];
        self.lambda = lambda;
        result.map(|()| value)
    }

    /// The multipliers of the closed contacts at the scratch's state, at time t, into `out`:
    /// λ of each, then the force along each slip row of the stuck ones ([`Hold::multipliers`]).
    fn multipliers(&mut self, t: f64, out: &mut [f64], step: usize) -> Result<(), Error> {
        let time = self.t;
        let (hold, held, scratch) = self.holding();
        let state = (scratch.q(), scratch.p(), t);
        hold.multipliers(scratch.model().as_lagrangian(), held, state, out)
            .map(|_| ())
            .map_err(|source| run_error(source, step, time))
    }

    /// The held step, what it holds now, and the scratch stepper.
    fn holding(&mut self) -> (&mut Hold, Held<'_, 's>, &Stepper<M>) {
        let hold = self.hold.as_mut().expect("a contact closes only where it can be held");
        let held = Held {
            contacts: self.contacts,
            closed: &self.closed,
            stuck: &self.stuck,
            directions: &self.directions,
        };
        (hold, held, &self.scratch)
    }

    /// Contact k released at time t, at the state (`contact_q`, `piece_p`): at lift-off, or
    /// just after a jump that moves the body off its surface. A stuck contact's sticking ends
    /// with it (a change of its own, for the samples to undo).
    fn open(&mut self, k: usize, step: usize, t: f64) {
        if self.stuck.contains(&k) {
            self.stuck.retain(|&j| j != k);
            self.changes.push((t, k, Switch::Slipped));
        }
        self.closed.retain(|&j| j != k);
        self.switched(k, Switch::Released, step, (t, t));
    }

    /// Contact k's switch `kind` at time t, recorded for the samples to undo and reported at
    /// `reported` (t, or the limit of a Zeno series), at the state (`contact_q`, `piece_p`).
    fn switched(&mut self, k: usize, kind: Switch, step: usize, (t, reported): (f64, f64)) {
        self.changes.push((t, k, kind));
        self.pending
            .switches
            .push(k, step, reported, kind, (&self.contact_q, &self.piece_p));
    }

    /// The first friction switch in the piece of size τ from ta, with the scratch at its end
    /// (and left there): a stuck contact that slips where the force its slip rows need, |λ_t|,
    /// reaches μ_s N; a sliding one whose slip turns against its direction at the piece's
    /// start, where it stops (it sticks there if it can, [`Resolver::switch_friction`]). Each
    /// located by the Illinois method along the held partial steps, to round-off. None when
    /// neither happens in the piece.
    fn friction_switch(&mut self, step: usize, (ta, tau): (f64, f64)) -> Result<Option<(f64, usize, Switch)>, Error> {
        if !self.frictional || self.closed.is_empty() {
            return Ok(None);
        }
        let tolerance = 4.0 * f64::EPSILON * tau;
        let mut first: Option<(f64, usize, Switch)> = None;
        let mut searched = false;
        for a in 0..self.closed.len() {
            let j = self.closed[a];
            if self.contacts[j].friction.is_none() {
                continue;
            }
            let (kind, end) = if self.stuck.contains(&j) {
                (Switch::Slipped, -self.excess(j, step, ta + tau)?)
            } else {
                (Switch::Stuck, self.along(j, step, ta + tau)?)
            };
            if end >= 0.0 {
                continue;
            }
            searched = true;
            let mut value = |s: f64| -> Result<f64, Error> {
                self.partial(step, ta, s)?;
                match kind {
                    Switch::Slipped => Ok(-self.excess(j, step, ta + s)?),
                    _ => self.along(j, step, ta + s),
                }
            };
            let start = value(0.0)?;
            let s = if start <= 0.0 {
                if kind == Switch::Stuck {
                    // Stopped at the piece's start already: its direction came from there.
                    continue;
                }
                0.0
            } else {
                illinois(value, (0.0, start), (tau, end), tolerance)?.0
            };
            if first.is_none_or(|(s0, ..)| s < s0) {
                first = Some((s, j, kind));
            }
        }
        if searched {
            self.partial(step, ta, tau)?;
        }
        Ok(first)
    }

    /// The multipliers at the scratch's state at time t into `lambda` ([`Resolver::multipliers`]),
    /// stuck contact j's among them: its place among the closed (its λ) and its first slip row.
    fn stuck_multipliers(&mut self, j: usize, step: usize, t: f64) -> Result<(usize, usize), Error> {
        let n = self.scratch.q().len();
        let mut lambda = std::mem::take(&mut self.lambda);
        let result = self.multipliers(t, &mut lambda, step);
        self.lambda = lambda;
        result?;
        let a = self
            .closed
            .iter()
            .position(|&k| k == j)
            .expect("a stuck contact is closed");
        let mut row = self.closed.len();
        for &k in self.stuck.iter().take_while(|&&k| k != j) {
            row += self.contacts[k].friction.as_ref().map_or(0, |f| f.rows(n));
        }
        Ok((a, row))
    }

    /// |λ_t| − μ_s N of stuck contact j at the scratch's state at time t: the force its slip
    /// rows need beyond what friction can give (N = λ|∇φ|).
    fn excess(&mut self, j: usize, step: usize, t: f64) -> Result<f64, Error> {
        let (a, row) = self.stuck_multipliers(j, step, t)?;
        let friction = self.contacts[j]
            .friction
            .as_ref()
            .expect("a stuck contact has friction");
        let rows = friction.rows(self.normal.len());
        let tangential = self.lambda[row..row + rows].iter().map(|x| x * x).sum::<f64>().sqrt();
        let hold = self.hold.as_ref().expect("a contact closes only where it can be held");
        Ok(tangential - friction.static_coefficient * hold.normal_force(a, self.lambda[a]))
    }

    /// Contact k's friction switched at time t, at the state (`contact_q`, `piece_p`), which
    /// the scratch holds: slipped, or stopped sliding (`Switch::Stuck`), when it sticks if the
    /// force that holds its slip at 0 is within μ_s N (the slip's round-off then projected
    /// away), and slides on otherwise, from rest in a direction of its own
    /// ([`Resolver::aim`]). The state is kept for the samples after it.
    fn switch_friction(&mut self, k: usize, kind: Switch, step: usize, t: f64) -> Result<(), Error> {
        let switched = if kind == Switch::Slipped {
            self.stuck.retain(|&j| j != k);
            true
        } else {
            insert(&mut self.stuck, k);
            let sticks = self.excess(k, step, t)? <= 0.0;
            if sticks {
                self.project_piece(step, t)?;
            } else {
                self.stuck.retain(|&j| j != k);
            }
            sticks
        };
        if switched {
            self.switched(k, kind, step, (t, t));
        }
        self.released
            .push(k, step, t, &self.contact_q, &self.piece_p, &self.piece_p);
        self.released_work.push(self.step_work);
        Ok(())
    }

    /// Whether closed contact j, just closed at the scratch's state at time t, sticks: its slip
    /// round-off ([`Resolver::slip_size`]) and the force that holds it at 0 within μ_s N. It is
    /// then stuck.
    fn sticks(&mut self, j: usize, step: usize, t: f64) -> Result<bool, Error> {
        if self.contacts[j].friction.is_none() {
            return Ok(false);
        }
        if !self.slip_size(j, step, t)?.1 {
            return Ok(false);
        }
        insert(&mut self.stuck, j);
        if self.excess(j, step, t)? <= 0.0 {
            return Ok(true);
        }
        self.stuck.retain(|&k| k != j);
        Ok(false)
    }

    /// The sliding contacts' directions at the scratch's state at time t, a piece's start: each
    /// its slip's, Jᵀs/|s|; from rest (a slip of round-off), the way the force that would hold
    /// it points against, −Jᵀλ_t/|λ_t|.
    fn aim(&mut self, step: usize, t: f64) -> Result<(), Error> {
        let n = self.scratch.q().len();
        for a in 0..self.closed.len() {
            let j = self.closed[a];
            if self.contacts[j].friction.is_none() || self.stuck.contains(&j) {
                continue;
            }
            let time = self.t;
            let (size, round_off) = self.slip_size(j, step, t)?;
            let scale = if !round_off {
                size
            } else {
                insert(&mut self.stuck, j);
                let held = self.stuck_multipliers(j, step, t);
                self.stuck.retain(|&k| k != j);
                let (_, row) = held?;
                let Resolver {
                    hold,
                    scratch,
                    contacts,
                    lambda,
                    direction,
                    ..
                } = self;
                let hold = hold.as_mut().expect("a contact closes only where it can be held");
                let contact = &contacts[j];
                let friction = contact.friction.as_ref().expect("a sliding contact has friction");
                let x = &lambda[row..row + friction.rows(n)];
                hold.slip_force((contact, friction), scratch.q(), x, direction)
                    .map_err(|source| Error::model(step, time, source))?;
                -x.iter().map(|y| y * y).sum::<f64>().sqrt()
            };
            let target = &mut self.directions[j * n..(j + 1) * n];
            for (d, x) in target.iter_mut().zip(&self.direction) {
                *d = if scale == 0.0 { 0.0 } else { x / scale };
            }
        }
        Ok(())
    }

    /// `piece_p` made tangent to the closed contacts at `contact_q` and free of the stuck
    /// ones' slip, at time t ([`Hold::project`]); the energy that takes (their impulses, a
    /// plastic impact and friction's) into the step's account, ½Δp·(q̇⁺ + q̇⁻), exact for the
    /// held models' T = ½pᵀM⁻¹p.
    fn project_piece(&mut self, step: usize, t: f64) -> Result<(), Error> {
        let time = self.t;
        // Lent out while the held step is borrowed with the rest (moves, no copies).
        let (q, mut p) = (std::mem::take(&mut self.contact_q), std::mem::take(&mut self.piece_p));
        let (mut v, mut w) = (std::mem::take(&mut self.v), std::mem::take(&mut self.w));
        let (hold, held, scratch) = self.holding();
        hold.q.copy_from_slice(&q);
        hold.p.copy_from_slice(&p);
        let model = scratch.model().as_lagrangian();
        let projected = hold.project(model, held, t);
        let velocities = model
            .velocity(&q, &p, t, &mut v)
            .and_then(|()| model.velocity(&q, &hold.p, t, &mut w));
        let change = 0.5 * (0..p.len()).map(|i| (hold.p[i] - p[i]) * (v[i] + w[i])).sum::<f64>();
        p.copy_from_slice(&hold.p);
        (self.contact_q, self.piece_p, self.v, self.w) = (q, p, v, w);
        projected.map_err(|source| run_error(source, step, time))?;
        velocities.map_err(|source| Error::model(step, time, source))?;
        self.step_work += change;
        Ok(())
    }

    /// The slip of sliding contact j at the scratch's state at time t along its direction at
    /// the piece's start: negative once it has turned against it.
    fn along(&mut self, j: usize, step: usize, t: f64) -> Result<f64, Error> {
        let n = self.scratch.q().len();
        self.slip_at(j, step, t)?;
        Ok(dot(&self.direction, &self.directions[j * n..(j + 1) * n]))
    }

    /// The slip s = Jq̇ of contact j at the scratch's state at time t into `slip`, Jᵀs into
    /// `direction`: its size |s|, and that of J's entries, max |J|.
    fn slip_at(&mut self, j: usize, step: usize, t: f64) -> Result<(f64, f64), Error> {
        let time = self.t;
        let Resolver {
            hold,
            scratch,
            contacts,
            slip,
            direction,
            ..
        } = self;
        let hold = hold.as_mut().expect("a contact closes only where it can be held");
        let contact = &contacts[j];
        let friction = contact.friction.as_ref().expect("a sliding contact has friction");
        let (q, p) = (scratch.q(), scratch.p());
        let scale = hold
            .slip(
                scratch.model().as_lagrangian(),
                (contact, friction),
                (q, p, t),
                (slip, direction),
            )
            .map_err(|source| Error::model(step, time, source))?;
        let size = slip[..friction.rows(q.len())].iter().map(|x| x * x).sum::<f64>().sqrt();
        Ok((size, scale))
    }

    /// Contact j's slip at the scratch's state at time t ([`Resolver::slip_at`]): its size,
    /// and whether that is round-off, within 10³ε|J|∞(|q̇|∞ + h|M⁻¹∂L/∂q|∞) (a slip that the
    /// step's acceleration would reverse).
    fn slip_size(&mut self, j: usize, step: usize, t: f64) -> Result<(f64, bool), Error> {
        let (size, scale) = self.slip_at(j, step, t)?;
        let (time, h) = (self.t, self.scratch.dt());
        let Resolver {
            scratch, v, w, zeros, ..
        } = self;
        let model = scratch.model().as_lagrangian();
        let (q, p) = (scratch.q(), scratch.p());
        let model_error = |source| Error::model(step, time, source);
        model.velocity(q, p, t, v).map_err(model_error)?;
        let speed = amax(v);
        model.dl_dq(q, zeros, t, w).map_err(model_error)?;
        model.velocity(q, w, t, v).map_err(model_error)?;
        Ok((size, size <= 1e3 * f64::EPSILON * scale * (speed + h * amax(v))))
    }

    /// After a jump at time t to (q̃, p⁺) (`contact_q`, `piece_p`) with contacts closed: those
    /// the jump moves off their surface released, the stuck ones it sets slipping slipped (a
    /// jump has no friction: a ball struck while it rolls slides), and p⁺ made tangent to the
    /// others (their impulse, which keeps a body on a surface it presses on).
    fn after_jump(&mut self, step: usize, t: f64) -> Result<(), Error> {
        if self.closed.is_empty() {
            return Ok(());
        }
        let time = self.t;
        let model_error = |source| Error::model(step, time, source);
        let model = self.scratch.model().as_lagrangian();
        model
            .velocity(&self.contact_q, &self.contact_p, t, &mut self.w)
            .map_err(model_error)?;
        model
            .velocity(&self.contact_q, &self.piece_p, t, &mut self.v)
            .map_err(model_error)?;
        // The jump's round-off is that of the speeds it joins: a contact closed by it keeps a
        // normal velocity of order ε|q̇⁻| (all of q̇⁺ on a body that moved along the normal alone).
        let speed = amax(&self.v).max(amax(&self.w));
        let mut a = 0;
        while a < self.closed.len() {
            let k = self.closed[a];
            self.contacts[k]
                .surface
                .gradient(&self.contact_q, &mut self.normal)
                .map_err(model_error)?;
            let normal_velocity = dot(&self.normal, &self.v);
            if normal_velocity > 1e3 * f64::EPSILON * amax(&self.normal) * speed {
                self.open(k, step, t);
            } else {
                a += 1;
            }
        }
        if self.closed.is_empty() {
            return Ok(());
        }
        if !self.stuck.is_empty() {
            let h = self.scratch.dt();
            self.scratch.restart(t, &self.contact_q, &self.piece_p, h);
            let mut a = 0;
            while a < self.stuck.len() {
                let k = self.stuck[a];
                if !self.slip_size(k, step, t)?.1 {
                    self.stuck.remove(a);
                    self.switched(k, Switch::Slipped, step, (t, t));
                } else {
                    a += 1;
                }
            }
        }
        self.project_piece(step, t)
    }

    /// The contacts a body rests on at the state (t, q, p), closed: on the surface to
    /// round-off (|φ| and the normal velocity's reach in a step, |∇φ·q̇|h, within
    /// [`round_off`]) and pressing on it (λ ≥ 0); those with friction stuck where they stick
    /// ([`Resolver::sticks`]). A run's held states are such, so a run resumed holds what it
    /// held.
    fn close_resting(&mut self, (t, q, p): (f64, &[f64], &[f64]), step: usize) -> Result<(), Error> {
        if self.hold.is_none() {
            return Ok(());
        }
        let model_error = |source| Error::model(step, t, source);
        let h = self.scratch.dt();
        self.scratch
            .model()
            .as_lagrangian()
            .velocity(q, p, t, &mut self.v)
            .map_err(model_error)?;
        for j in 0..self.contacts.len() {
            self.contacts[j]
                .surface
                .gradient(q, &mut self.normal)
                .map_err(model_error)?;
            let tolerance = round_off(&self.normal, q);
            let reach = dot(&self.normal, &self.v) * h;
            if self.phi[j].abs() > tolerance || reach.abs() > tolerance {
                continue;
            }
            self.closed.push(j);
            self.scratch.restart(t, q, p, h);
            let mut lambda = std::mem::take(&mut self.lambda);
            let pressed = self
                .multipliers(t, &mut lambda, step)
                .map(|()| lambda[self.closed.len() - 1] >= 0.0);
            self.lambda = lambda;
            if !pressed? {
                self.closed.pop();
            }
        }
        // Stuck where their slip is at rest and friction can hold it.
        for a in 0..self.closed.len() {
            self.sticks(self.closed[a], step, t)?;
        }
        Ok(())
    }

    /// The next piece from the jump at t, (q̃, p⁺) in the contact and piece buffers: its start
    /// kept, φ and the events evaluated there.
    fn restart_piece(&mut self, step: usize, search: Option<&mut Search<'_, '_, M>>, t: f64) -> Result<(), Error> {
        if let Some(search) = search {
            search.restart_piece(step, (t, &self.contact_q, &self.piece_p))?;
        }
        self.piece_q.copy_from_slice(&self.contact_q);
        evaluate(self.contacts, &self.piece_q, &mut self.phi_start, step, self.t)?;
        self.aim_piece(step, t)
    }

    /// The sliding contacts' directions at the piece's start (`piece_q`, `piece_p`) at time t
    /// ([`Resolver::aim`]).
    fn aim_piece(&mut self, step: usize, t: f64) -> Result<(), Error> {
        if self.frictional && !self.closed.is_empty() {
            self.scratch.restart(t, &self.piece_q, &self.piece_p, self.scratch.dt());
            self.aim(step, t)?;
        }
        Ok(())
    }

    /// The jump on contact j at (q̃, p⁻) (the contact buffers), at the end of the piece of size s
    /// from ta with `rest` of the step after it: p⁺ into `piece_p`. The contact closes there
    /// ([`Resolver::closes`]) when the rest of its bounces would last less than the step h.
    fn jump(&mut self, j: usize, step: usize, (ta, s, rest): (f64, f64, f64), h: f64) -> Result<(), Error> {
        let contacts = self.contacts;
        let contact = &contacts[j];
        let (t, time) = (ta + s, self.t);
        let model_error = |source| Error::model(step, time, source);
        let model = self.scratch.model();
        let (q, p) = (&self.contact_q[..], &self.contact_p[..]);
        contact.surface.gradient(q, &mut self.normal).map_err(model_error)?;
        // On a constrained model, the part of ∇φ the constraints let act: the surface's impulse
        // comes with the constraints' workless one that keeps the momenta on them, which adds up
        // to ∇φ projected M-orthogonally (the projection's affine part cancels).
        for (x, (a, b)) in self.v.iter_mut().zip(p.iter().zip(&self.normal)) {
            *x = a + b;
        }
        if let Some(projected) = model.project(q, &self.v) {
            let (_, with) = projected?;
            let (_, without) = model.project(q, p).expect("a constrained model projects")?;
            for (x, (a, b)) in self.normal.iter_mut().zip(with.iter().zip(&without)) {
                *x = a - b;
            }
        }
        let vectors = (&mut self.v[..], &mut self.w[..], &self.zeros[..]);
        let reflected = reflect::reflection(
            model.as_lagrangian(),
            (t, q, p),
            &self.normal,
            contact.restitution,
            vectors,
        )
        .map_err(model_error)?;
        let reflection = reflected.lambda;
        // For e < 1, and beside a held contact, both laws take Newton's law, the reflection.
        // The energy account takes each law's own loss: none for e = 1 (the variational law's
        // change of E is the method's error, its E_d kept), Newton's law's otherwise.
        let variational = contact.law == Law::Variational && contact.restitution == 1.0 && self.closed.is_empty();
        let lambda = if variational && rest > 0.0 {
            let (lambda, found) = self.variational(step, (ta, s, rest), reflection)?;
            self.pending.grazing += usize::from(!found);
            lambda
        } else {
            reflection
        };
        let mut loss = reflected.loss(contact.restitution);
        for (x, (a, b)) in self.piece_p.iter_mut().zip(self.contact_p.iter().zip(&self.normal)) {
            *x = a + lambda * b;
        }
        if let Some(t_rest) = self.closes(j, step, t, (reflection, h))? {
            // The whole normal velocity gone: the Zeno series' losses summed.
            loss = reflected.loss(0.0);
            insert(&mut self.closed, j);
            self.switched(j, Switch::Closed, step, (t, t_rest));
            self.scratch.restart(t, &self.contact_q, &self.piece_p, h);
            if self.sticks(j, step, t)? {
                self.project_piece(step, t)?;
                self.switched(j, Switch::Stuck, step, (t, t_rest));
            }
        }
        self.step_work += loss;
        Ok(())
    }

    /// Whether contact j closes at its impact at time t, reflected with the multiplier
    /// `reflection` (the normal, ∇φ, in `normal`): the body pressing on the surface once its
    /// normal velocity is gone (λ > 0), and the Zeno series of the rebounds, flights of
    /// 2v⁺/|a|, 2ev⁺/|a|, … under the normal acceleration a = −λ∇φᵀM⁻¹∇φ, summing to
    /// T∞ = 2v⁺/(|a|(1 − e)) ≤ h (at once for v⁺ = 0). Then the momenta lose their normal
    /// velocity (`piece_p`: the reflection with e = 0) and the contact is held from t: the
    /// series' limit t + T∞, when the body comes to rest on the surface, is returned.
    fn closes(&mut self, j: usize, step: usize, t: f64, (reflection, h): (f64, f64)) -> Result<Option<f64>, Error> {
        let e = self.contacts[j].restitution;
        // Elastic contacts close only on an arrival without normal velocity.
        if self.hold.is_none() || (e == 1.0 && reflection != 0.0) {
            return Ok(None);
        }
        let time = self.t;
        let model_error = |source| Error::model(step, time, source);
        // p with the normal velocity gone, λ/(1 + e) along ∇φ; v⁺ = −e∇φ·q̇⁻ = eλ nᵀM⁻¹n/(1 + e).
        for (x, (a, b)) in self.w.iter_mut().zip(self.contact_p.iter().zip(&self.normal)) {
            *x = a + reflection / (1.0 + e) * b;
        }
        let model = self.scratch.model().as_lagrangian();
        model
            .velocity(&self.contact_q, &self.normal, t, &mut self.v)
            .map_err(model_error)?;
        let metric_plus = dot(&self.normal, &self.v);
        model
            .velocity(&self.contact_q, &self.zeros, t, &mut self.v)
            .map_err(model_error)?;
        let metric = metric_plus - dot(&self.normal, &self.v);
        let rebound = e * reflection * metric / (1.0 + e);
        insert(&mut self.closed, j);
        let a = self.closed.iter().position(|&k| k == j).expect("just inserted");
        self.scratch.restart(t, &self.contact_q, &self.w, h);
        let mut lambda = std::mem::take(&mut self.lambda);
        let pressed = self.multipliers(t, &mut lambda, step).map(|()| lambda[a]);
        self.lambda = lambda;
        self.closed.retain(|&k| k != j);
        let pressed = pressed?;
        if pressed.is_nan() || pressed <= 0.0 {
            return Ok(None);
        }
        let tail = if rebound == 0.0 {
            0.0
        } else if e < 1.0 {
            2.0 * rebound / (pressed * metric * (1.0 - e))
        } else {
            return Ok(None);
        };
        if tail.is_nan() || tail > h {
            return Ok(None);
        }
        self.piece_p.copy_from_slice(&self.w);
        Ok(Some(t + tail))
    }

    /// λ of the variational law ([`variational::multiplier`]) for the jump at the end of the
    /// piece of size s from ta, from the reflection's λ: E_d of the piece after the jump, to
    /// the step's end `rest` later, equal to E_d of the piece before. Leaves `piece_q` at q̃.
    fn variational(
        &mut self,
        step: usize,
        (ta, s, rest): (f64, f64, f64),
        reflection: f64,
    ) -> Result<(f64, bool), Error> {
        let time = self.t;
        let model_error = |source| Error::model(step, time, source);
        let Resolver {
            scratch,
            discrete,
            piece_q,
            piece_p,
            contact_q,
            contact_p,
            normal,
            v,
            ..
        } = self;
        let Some(discrete) = discrete.as_mut() else {
            return Ok((reflection, false));
        };
        let t = ta + s;
        let before = (&piece_q[..], &piece_p[..]);
        let target = discrete
            .energy(scratch.model(), ta, s, before, (contact_q, contact_p))
            .map_err(|e| e.at(step, time))?;
        scratch
            .model()
            .as_lagrangian()
            .velocity(contact_q, contact_p, t, v)
            .map_err(model_error)?;
        let scale = contact_p.iter().zip(v.iter()).map(|(a, b)| a * b).sum::<f64>();
        piece_q.copy_from_slice(contact_q);
        let mut last = f64::NAN;
        let after = |lambda: f64| {
            last = lambda;
            for (x, (a, b)) in piece_p.iter_mut().zip(contact_p.iter().zip(normal.iter())) {
                *x = a + lambda * b;
            }
            scratch.restart(t, piece_q, piece_p, rest);
            scratch.step().map_err(|e| e.at(step, time))?;
            let end = (scratch.q(), scratch.p());
            discrete
                .energy(scratch.model(), t, rest, (piece_q, piece_p), end)
                .map_err(|e| e.at(step, time))
        };
        let found = variational::multiplier(after, reflection, target, scale)?;
        // The scratch holds the piece after the jump for the λ taken: the next piece's first step.
        if last == found.0 {
            self.keep(t, rest);
        }
        Ok(found)
    }

    /// The s ∈ (0, τ] where φⱼ along the piece from (ta, piece_q, piece_p) falls through 0,
    /// by Newton's method in the bracket ([`newton`]) to round-off. A piece that starts above the surface
    /// brackets it by its ends (φⱼ falls through 0 once in a step short against the path's
    /// curvature); one leaving it (`leaving`: it starts on that surface and only φⱼ < 0 counts)
    /// is bracketed by samples ([`Resolver::leaving_bracket`]). None when no sample is below
    /// (round-off at the piece's end).
    fn locate(&mut self, j: usize, step: usize, (ta, tau): (f64, f64), leaving: bool) -> Result<Option<f64>, Located> {
        let floor = floor(self.phi_start[j], leaving);
        let start = (0.0, self.phi_start[j] - floor);
        let ((a, b), guess) = if leaving {
            match self.leaving_bracket(j, step, (ta, tau), start, floor)? {
                Some(bracket) => (bracket, None),
                None => return Ok(None),
            }
        } else {
            // The partial steps' q(s) leaves with the velocity q̇ at the piece's start.
            let (model, time) = (self.scratch.model().as_lagrangian(), self.t);
            let vectors = (&mut self.normal[..], &mut self.v[..]);
            let rate = phi_rate(&self.contacts[j], model, (ta, &self.piece_q, &self.piece_p), vectors)
                .map_err(|source| Error::model(step, time, source))?;
            let end = (tau, self.phi_end[j]);
            ((start, end), Some(quadratic_root(start.1, rate, end)))
        };
        let tolerance = 4.0 * f64::EPSILON * tau;
        let mut least = f64::INFINITY;
        let (s, _) = newton(
            |s| {
                let (phi, rate) = self.phi_rate_along(j, step, ta, s)?;
                // The nearest so far, which the contact state will be.
                if (phi - floor).abs() < least {
                    least = (phi - floor).abs();
                    self.keep(ta, s);
                }
                Ok::<_, Error>((phi - floor, rate))
            },
            a,
            b,
            guess,
            tolerance,
        )?;
        Ok(Some(s))
    }

    /// φⱼ and its rate ∇φⱼ·q̇ at the end of the partial step of size s from the piece's start:
    /// the rate of the flow through that state, within the method's error of the partial
    /// steps' own rate in s, which is what [`newton`] needs.
    fn phi_rate_along(&mut self, j: usize, step: usize, ta: f64, s: f64) -> Result<(f64, f64), Error> {
        let phi = self.phi_along(j, step, ta, s)?;
        let (model, time) = (self.scratch.model().as_lagrangian(), self.t);
        let state = (ta + s, self.scratch.q(), self.scratch.p());
        let rate = phi_rate(&self.contacts[j], model, state, (&mut self.normal, &mut self.v))
            .map_err(|source| Error::model(step, time, source))?;
        Ok((phi, rate))
    }

    /// The bracket of a crossing of φⱼ − `floor` (`start` its value at s = 0) on a piece
    /// leaving the surface: eight samples over (0, τ], refined towards 0 up to four times while
    /// the first is already below; a body below at every one crosses again at once
    /// ([`Located::Resting`]). None when no sample is below.
    fn leaving_bracket(
        &mut self,
        j: usize,
        step: usize,
        (ta, tau): (f64, f64),
        start: (f64, f64),
        floor: f64,
    ) -> Result<Option<Bracket>, Located> {
        let mut hi = tau;
        for _ in 0..4 {
            let mut previous = start;
            let mut found = None;
            for k in 1..=8 {
                let x = hi * k as f64 / 8.0;
                let v = self.phi_along(j, step, ta, x)? - floor;
                if below(v, true) {
                    found = Some((k, x, v));
                    break;
                }
                previous = (x, v);
            }
            let Some((k, x, v)) = found else {
                return Ok(None);
            };
            if k > 1 {
                return Ok(Some((previous, (x, v))));
            }
            hi = x;
        }
        Err(Located::Resting)
    }

    /// Keeps the scratch's end as that of the free partial step of size s from ta and the
    /// piece's start, for [`Resolver::partial`] to take again.
    fn keep(&mut self, ta: f64, s: f64) {
        if self.closed.is_empty() {
            let Kept { at, from, q, p } = &mut self.kept;
            *at = Some((ta, s));
            from.copy_from_slice(&self.piece_p);
            q.copy_from_slice(self.scratch.q());
            p.copy_from_slice(self.scratch.p());
        }
    }

    /// φⱼ at the end of the partial step of size s from the piece's start.
    fn phi_along(&mut self, j: usize, step: usize, ta: f64, s: f64) -> Result<f64, Error> {
        self.partial(step, ta, s)?;
        let surface = &self.contacts[j].surface;
        surface.phi(self.scratch.q()).map_err(|source| Error::Model {
            step,
            time: self.t,
            source,
        })
    }

    /// The scratch stepper at the end of the method's step of size s (0: none) from the
    /// piece's start at ta; an error names the run's step and its start.
    fn partial(&mut self, step: usize, ta: f64, s: f64) -> Result<(), Error> {
        self.piece_work = 0.0;
        let Kept { at, from, q, p } = &self.kept;
        if s > 0.0 && self.closed.is_empty() && *at == Some((ta, s)) && *from == self.piece_p {
            self.scratch.restart(ta + s, q, p, s);
            return Ok(());
        }
        if let (Some(hold), false) = (self.hold.as_mut(), self.closed.is_empty() || s == 0.0) {
            // The held step, its end set on the scratch as a free piece's would be.
            let held = Held {
                contacts: self.contacts,
                closed: &self.closed,
                stuck: &self.stuck,
                directions: &self.directions,
            };
            let model = self.scratch.model().as_lagrangian();
            hold.step(model, held, (ta, s), (&self.piece_q, &self.piece_p))
                .map_err(|source| run_error(source, step, self.t))?;
            self.piece_work = hold.work;
            self.scratch.restart(ta + s, &hold.q, &hold.p, s);
            return Ok(());
        }
        self.scratch
            .restart(ta, &self.piece_q, &self.piece_p, if s > 0.0 { s } else { 1.0 });
        if s > 0.0 {
            self.scratch.step().map_err(|e| e.at(step, self.t))?;
        }
        Ok(())
    }

    /// Force evaluations of the partial steps.
    pub(in crate::integrators) fn force_evaluations(&self) -> u64 {
        self.scratch.force_evaluations() - self.counted
    }
}

/// Two points (s, φ − floor) on either side of a crossing.
type Bracket = ((f64, f64), (f64, f64));

/// Why a crossing was not located.
enum Located {
    Error(Error),
    /// Below the surface at every sample of a piece leaving it.
    Resting,
}

impl From<Error> for Located {
    fn from(e: Error) -> Self {
        Located::Error(e)
    }
}

/// ∇φ·q̇ of `contact` at the state (t, q, p), with ∇φ and q̇ left in `normal` and `v`.
fn phi_rate(
    contact: &Contact<'_>,
    model: &dyn Lagrangian,
    (t, q, p): (f64, &[f64], &[f64]),
    (normal, v): (&mut [f64], &mut [f64]),
) -> Result<f64, ModelError> {
    contact.surface.gradient(q, normal)?;
    model.velocity(q, p, t, v)?;
    Ok(dot(normal, v))
}

/// The root in (0, τ) of the quadratic through φ(0) = φ₀ > 0 with φ′(0) = r₀ and φ(τ) = φ₁ ≤ 0
/// (NaN where round-off leaves it none): the crossing of a flight whose φ is quadratic in
/// time (a straight chord of a circle, a parabola over a wall) to round-off, in the form
/// 2φ₀/(√(r₀² − 4cφ₀) − r₀), which does not cancel.
fn quadratic_root(phi0: f64, r0: f64, (tau, phi1): (f64, f64)) -> f64 {
    let c = (phi1 - phi0 - r0 * tau) / (tau * tau);
    2.0 * phi0 / ((r0 * r0 - 4.0 * c * phi0).sqrt() - r0)
}

/// The level a piece's φ must fall below to cross again: 0, or φ at its start for a piece that
/// starts a little past the surface (a contact state located to round-off on its far side),
/// so that a piece leaving it, however short, is not taken for a crossing.
fn floor(phi_start: f64, leaving: bool) -> f64 {
    if leaving {
        phi_start.min(0.0)
    } else {
        0.0
    }
}

/// Whether φ at a piece's end is past the surface: φ < 0, or φ = 0 on a piece that did not
/// start on it (a crossing ends at 0 or below, as events count it).
fn below(phi: f64, leaving: bool) -> bool {
    phi < 0.0 || (phi <= 0.0 && !leaving)
}

/// Whether a step from φ at its start to φ at its end crosses a contact.
fn crosses(phi_start: &[f64], phi_end: &[f64]) -> bool {
    phi_start.iter().zip(phi_end).any(|(&start, &end)| crossing(start, end))
}

/// Whether a step from φ = `start` to φ = `end` crosses the contact (one it starts on or past,
/// it leaves: only φ < 0 past the start's counts).
#[inline(always)]
fn crossing(start: f64, end: f64) -> bool {
    let leaving = start <= 0.0;
    below(end - floor(start, leaving), leaving)
}

/// φ of every contact at q into `phi`; a surface's error names the run's step and time.
fn evaluate(contacts: &[Contact<'_>], q: &[f64], phi: &mut [f64], step: usize, time: f64) -> Result<(), Error> {
    for (c, phi) in contacts.iter().zip(phi) {
        *phi = gap(c, None, q).map_err(|source| Error::model(step, time, source))?;
    }
    Ok(())
}

/// φ of contact `c` at q (through `native`, its surface if native, without dispatch); a
/// non-finite φ is an error.
#[inline(always)]
fn gap(c: &Contact<'_>, native: Option<&NativeSurface>, q: &[f64]) -> Result<f64, ModelError> {
    let phi = match native {
        Some(surface) => surface.value(q),
        None => c.surface.phi(q)?,
    };
    if !phi.is_finite() {
        return Err(format!("contact {} returned a non-finite φ = {phi}", c.name).into());
    }
    Ok(phi)
}

/// φ of a run's contacts, checked at the end of each step the method's own loop takes
/// ([`crate::integrators::Dynamics::advance_while`]): a step is clear when it crosses no
/// contact, by the test the one-at-a-time loop judges a step by; φ at its end is then the next
/// step's start. A failing φ stops the steps as a crossing does, its error kept for the run.
///
/// While every φ at a step's start is above its surface (φ > 0, the body in flight), the step
/// crosses a contact exactly where some φ at its end is ≤ 0, whatever the values at its start:
/// then, for native surfaces, φ is tested and not kept (`above`), and the resolver evaluates it
/// again where it needs it (`stale`). So a contact never hit costs a run its φ and a comparison
/// a step, inlined, and all else is out of the loop (1.03× the run without it, verlet on the
/// ball, `benches/impacts.py`).
pub struct Gaps<'g, 's> {
    contacts: &'g [Contact<'s>],
    /// Each contact's surface, if native.
    native: &'g [Option<&'g NativeSurface>],
    /// φ at the state (the next step's start), and at a step's end: the resolver's, swapped
    /// (`swapped`) rather than copied after a clear step.
    phi: &'g mut [f64],
    phi_end: &'g mut [f64],
    swapped: bool,
    /// Flight mode: every φ at the next step's start is > 0, and `phi` is not kept.
    above: bool,
    /// `phi` may not hold φ at the next step's start (flight mode was entered): the resolver
    /// evaluates it again.
    stale: bool,
    error: Option<ModelError>,
}

impl<'g, 's> Gaps<'g, 's> {
    /// The gaps of `contacts` with φ at the state in `phi`.
    fn new(
        contacts: &'g [Contact<'s>],
        native: &'g [Option<&'g NativeSurface>],
        phi: &'g mut [f64],
        phi_end: &'g mut [f64],
    ) -> Self {
        let above = in_flight(native, phi);
        Gaps {
            contacts,
            native,
            phi,
            phi_end,
            swapped: false,
            above,
            stale: above,
            error: None,
        }
    }

    /// Whether every φ at q is positive and finite (`above`: the surfaces are native).
    #[inline(always)]
    fn flying(&self, q: &[f64]) -> bool {
        let mut flying = true;
        for surface in self.native.iter().flatten() {
            let phi = surface.value(q);
            // Positive and finite (NaN fails both).
            flying &= phi > 0.0 && phi <= f64::MAX;
        }
        flying
    }

    /// [`Clear::clear`] but for a flight's clear step: out of line, so that the loop of a
    /// flight stays as tight as an unwatched one.
    #[cold]
    #[inline(never)]
    fn judge(&mut self, q: &[f64]) -> bool {
        let contacts = self.contacts.iter().zip(self.native);
        if self.above {
            // A crossing, or an error: φ at the end, for the resolver, and the step stops.
            self.above = false;
            for ((c, native), end) in contacts.zip(self.phi_end.iter_mut()) {
                match gap(c, *native, q) {
                    Ok(phi) => *end = phi,
                    Err(error) => {
                        self.error = Some(error);
                        break;
                    }
                }
            }
            return false;
        }
        let mut crossed = false;
        for ((c, native), (start, end)) in contacts.zip(self.phi.iter().zip(self.phi_end.iter_mut())) {
            *end = match gap(c, *native, q) {
                Ok(phi) => phi,
                Err(error) => {
                    self.error = Some(error);
                    return false;
                }
            };
            crossed |= crossing(*start, *end);
        }
        if crossed {
            return false;
        }
        std::mem::swap(&mut self.phi, &mut self.phi_end);
        self.swapped = !self.swapped;
        if in_flight(self.native, self.phi) {
            (self.above, self.stale) = (true, true);
        }
        true
    }
}

impl Clear for Gaps<'_, '_> {
    /// Whether a step ending at q crosses no contact, each φ evaluated (finite); φ at q is
    /// then the next step's start.
    #[inline(always)]
    fn clear(&mut self, q: &[f64], _: &[f64]) -> bool {
        (self.above && self.flying(q)) || self.judge(q)
    }
}

/// Whether the flight test of [`Gaps`] applies from φ at a step's start: every surface native,
/// every φ > 0.
fn in_flight(native: &[Option<&NativeSurface>], phi: &[f64]) -> bool {
    native.iter().all(Option::is_some) && phi.iter().all(|&phi| phi > 0.0)
}

/// Inserts contact k into the ordered set `closed`.
fn insert(closed: &mut Vec<usize>, k: usize) {
    if let Err(at) = closed.binary_search(&k) {
        closed.insert(at, k);
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn amax(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |a, y| a.max(y.abs()))
}
