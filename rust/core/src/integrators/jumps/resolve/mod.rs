//! The jumps' resolution: a step that ends with some φ < 0, or that holds an impulse's time,
//! redone in pieces on a scratch stepper by one piece loop ([`Resolver::resolve`]). Each piece is
//! a partial step of the method from its start (the held step where contacts are closed); the
//! earliest occurrence in it ([`Resolver::earliest`]) is found, the piece redone to it, the
//! occurrence applied there and the next piece started from it, up to [`MAX_IMPACTS`] impacts
//! in the step. The occurrences, a file each:
//!
//! - `impact.rs`: a contact crossed, located to round-off, and its law's jump;
//! - `held.rs`: a held contact's lift-off, and what a jump does to the held contacts;
//! - `stick_slip.rs`: a held contact's friction switching between sticking and sliding;
//! - `timed.rs`: the schedule's impulses, and its samples (partial steps from the last jump);
//! - `gaps.rs`: φ of the contacts at a state (the check after each step of the method's own
//!   loop is [`Gaps`], integrators/clear.rs).

use std::borrow::{Borrow, BorrowMut};
use std::ops::Deref;

use super::hold::{Held, Hold};
use super::unsolved::run_error;
use super::{Contact, Contacts, Law, Schedule, MAX_IMPACTS};
use crate::integrators::events::Search;
use crate::integrators::DiscreteEnergy;
use crate::integrators::{Counting, Dynamics, Occurrence, Poll, Stepper, StepperState, Trajectory};
use crate::integrators::{Impacts, NativeSurface, Surface, Switch};
use crate::Error;

/// What the resolver `$r` holds now, a [`Held`] of its contacts, the closed and stuck ones and
/// their slip directions: a macro, so that it borrows those fields alone, beside the held step
/// (`hold`, borrowed mutably with it).
macro_rules! held {
    ($r:expr) => {
        Held {
            contacts: $r.contacts,
            closed: &$r.closed,
            stuck: &$r.stuck,
            directions: &$r.directions,
        }
    };
}

mod gaps;
mod held;
mod impact;
mod stick_slip;
mod timed;

use crate::integrators::clear::{crosses, crossing, gap, Gaps};
use gaps::evaluate;

/// A run's resolver: the contacts and the schedule, the scratch stepper of the partial steps
/// (a copy of the run's stepper) and every buffer of the resolution, made once per run.
pub(in crate::integrators) struct Resolver<'c, 's, M> {
    contacts: &'c [Contact<'s>],
    /// Each contact's surface and name, and its surface if native ([`Gaps`]).
    surfaces: Vec<(&'c (dyn Surface + 's), &'c str)>,
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
            surfaces: contacts.iter().map(|c| (&*c.surface, c.name.as_str())).collect(),
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
            discrete: (contacts.iter().any(|c| c.law.needs_discrete_energy()))
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
        let mut gaps = Gaps::new(&self.surfaces, &self.native, &mut self.phi, &mut self.phi_end);
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
        let held = held!(self);
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
                    gap(self.surfaces[j], None, &hold.q).is_ok_and(|phi| {
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
                self.phi[j] = gap(self.surfaces[j], None, &self.q).map_err(|source| Error::Model {
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
        let held = !self.closed.is_empty();
        self.piece_q.copy_from_slice(&self.q);
        self.piece_p.copy_from_slice(&self.p);
        self.phi_start.copy_from_slice(&self.phi);
        self.pending.clear();
        self.forget_jumps();
        self.closed_start.clear();
        self.closed_start.extend_from_slice(&self.closed);
        self.stuck_start.clear();
        self.stuck_start.extend_from_slice(&self.stuck);
        self.step_work = 0.0;
        self.aim_piece(step, self.t)?;
        let (mut ta, mut tau, mut last) = (self.t, h, None);
        let mut switches = 0;
        loop {
            // The piece to the next impulse inside the step, or to the step's end, and the
            // earliest occurrence in it.
            let inside = self.impulse_inside(t_end);
            let piece = inside.map_or(tau, |t| t - ta);
            self.partial(step, ta, piece)?;
            let Some((s, next)) = self.earliest(step, (ta, piece), last, inside.is_some())? else {
                if !held && self.pending.is_empty() && self.blown.is_empty() && self.changes.is_empty() {
                    return Ok(false);
                }
                // The last piece ends the step: the scratch holds its end.
                self.step_work += self.piece_work;
                break;
            };
            match next {
                Next::Impact(_) if self.pending.len() == MAX_IMPACTS => {
                    return Err(self.contact_error(step, self.too_many_impacts()));
                }
                Next::Switch(k, _) => {
                    switches += 1;
                    if switches > MAX_SWITCHES {
                        return Err(self.contact_error(
                            step,
                            format!(
                                "the friction of {} switched between sticking and sliding more than {MAX_SWITCHES} \
                                 times in one step; shorten the step",
                                self.contacts[k].name
                            ),
                        ));
                    }
                }
                _ => {}
            }
            // The state there, just before the occurrence: the piece redone to it (an impulse
            // ends the piece, which the scratch holds).
            if !matches!(next, Next::Impulse) {
                self.partial(step, ta, s)?;
            }
            self.step_work += self.piece_work;
            self.contact_q.copy_from_slice(self.scratch.q());
            self.contact_p.copy_from_slice(self.scratch.p());
            let t = ta + s;
            if let Some(search) = search.as_deref_mut() {
                // The end's buffers lent out while the piece's steps are the resolver's.
                let (q, p) = (std::mem::take(&mut self.contact_q), std::mem::take(&mut self.contact_p));
                let watched = self.watch_piece(search, step, (ta, s), (t, &q, &p), occurrences);
                (self.contact_q, self.contact_p) = (q, p);
                watched?;
            }
            last = match next {
                Next::Release(k) => {
                    self.release(k, step, t);
                    Some(k)
                }
                Next::Switch(k, kind) => {
                    self.piece_p.copy_from_slice(&self.contact_p);
                    self.switch_friction(k, kind, step, t)?;
                    last
                }
                Next::Impulse => {
                    self.impulse(step, t)?;
                    None
                }
                Next::Impact(j) => {
                    self.impact(j, step, (ta, s, tau - s), h)?;
                    Some(j)
                }
            };
            self.restart_piece(step, search.as_deref_mut(), t)?;
            (ta, tau) = (t, tau - s);
        }
        // The step's end: the last piece's, at tₙ₊₁.
        stepper.jump_to(self.scratch.q(), self.scratch.p())?;
        stepper.add_contact_work(self.step_work);
        std::mem::swap(&mut self.phi, &mut self.phi_end);
        if let Some(search) = search {
            self.watch_piece(
                search,
                step,
                (ta, tau),
                (stepper.t(), stepper.q(), stepper.p()),
                occurrences,
            )?;
        }
        Ok(true)
    }

    /// The earliest occurrence in the piece of size τ from ta, with the scratch at its end, and
    /// where: a lift-off, a friction switch, a contact crossed (the last jump's, `last`, one the
    /// piece leaves), or the impulse that ends the piece (`impulse`). A tie goes to the
    /// crossing, then the lift-off. None when the piece ends the step.
    fn earliest(
        &mut self,
        step: usize,
        (ta, tau): (f64, f64),
        last: Option<usize>,
        impulse: bool,
    ) -> Result<Option<(f64, Next)>, Error> {
        evaluate(self.contacts, self.scratch.q(), &mut self.phi_end, step, self.t)?;
        let switch = self.friction_switch(step, (ta, tau))?;
        let release = self.lift_off(step, (ta, tau))?;
        let first = self.first_crossing(step, (ta, tau), last)?;
        let before = |s: f64| first.is_none_or(|(s0, _)| s < s0);
        if let Some((s, k)) = release.filter(|&(s, _)| before(s) && switch.is_none_or(|(s1, ..)| s <= s1)) {
            return Ok(Some((s, Next::Release(k))));
        }
        if let Some((s, k, kind)) = switch.filter(|&(s, ..)| before(s)) {
            return Ok(Some((s, Next::Switch(k, kind))));
        }
        Ok(match first {
            Some((s, j)) => Some((s, Next::Impact(j))),
            None => impulse.then_some((tau, Next::Impulse)),
        })
    }

    /// A contact error at the run's step, from the step's start.
    fn contact_error(&self, step: usize, reason: String) -> Error {
        Error::Contact {
            step,
            time: self.t,
            reason,
        }
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
            let held = held!(self);
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

    /// Whether a contact's law is Newton's ([`Law::Reflect`]).
    pub(in crate::integrators) fn reflects(&self) -> bool {
        self.contacts.iter().any(|c| c.law == Law::Reflect)
    }

    /// Force evaluations of the partial steps.
    pub(in crate::integrators) fn force_evaluations(&self) -> u64 {
        self.scratch.force_evaluations() - self.counted
    }
}

/// What happens first in a piece ([`Resolver::earliest`]), which the piece loop applies.
#[derive(Clone, Copy)]
enum Next {
    /// Closed contact k lifts off.
    Release(usize),
    /// Closed contact k's friction switches.
    Switch(usize, Switch),
    /// The schedule's next impulse, which ends the piece.
    Impulse,
    /// An impact on contact j.
    Impact(usize),
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
