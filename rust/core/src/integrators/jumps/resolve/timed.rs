//! The schedule inside a step: its impulses, each a jump of the momenta at a given time, and its
//! samples (`t_eval`), each a partial step from the last jump before it.

use std::borrow::{Borrow, BorrowMut};
use std::ops::Deref;

use super::{insert, Resolver};
use crate::integrators::events::Search;
use crate::integrators::{Dynamics, Stepper, StepperState, Trajectory};
use crate::integrators::{Impacts, Switch};
use crate::Error;

impl<'c, 's, M: Deref<Target: Dynamics>> Resolver<'c, 's, M> {
    /// The time of the next impulse if it falls inside the step that ends at `t_end`.
    pub(super) fn impulse_inside(&self, t_end: f64) -> Option<f64> {
        let impulses = self.schedule?.impulses();
        impulses.get(self.next_impulse).map(|b| b.t).filter(|&t| t < t_end)
    }

    /// The step's jumps saved, in order of time (the states just before and after each, unless
    /// the run saves its samples alone), and its impacts reported.
    pub(super) fn push_jumps<St: Borrow<StepperState>>(&mut self, stepper: &Stepper<M, St>, traj: &mut Trajectory) {
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
        self.forget_jumps();
        traj.impacts.append(&mut self.pending);
    }

    /// Forgets a step's impulses, releases and switches and the work of its jumps (not its
    /// impacts, `pending`): once they are saved, or before a step's resolution.
    pub(super) fn forget_jumps(&mut self) {
        self.blown.clear();
        self.released.clear();
        self.changes.clear();
        self.pending_work.clear();
        self.blown_work.clear();
        self.released_work.clear();
    }

    /// The impulses at the stepper's time, a point of the grid (the end of the step just taken,
    /// or a new run's t0): the jumps applied to its state, which is saved just before and after
    /// each (unless the run saves its samples alone); the events restarted there.
    pub(super) fn blow_at_grid<St: BorrowMut<StepperState>>(
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
    pub(super) fn blow(&mut self, k: usize, step: usize, t: f64) -> Result<(), Error> {
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
    pub(super) fn take_samples<St: Borrow<StepperState>>(
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

    /// The schedule's next impulse at (q, p⁻) (the contact buffers) at time t, inside a step:
    /// its jump ([`Resolver::blow`]) and what it does to the closed contacts, p⁺ into
    /// `piece_p`, kept for the step's saved states.
    pub(super) fn impulse(&mut self, step: usize, t: f64) -> Result<(), Error> {
        let (k, before) = (self.next_impulse, self.step_work);
        self.blow(k, step, t)?;
        self.after_jump(step, t)?;
        self.blown
            .push(k, step, t, &self.contact_q, &self.contact_p, &self.piece_p);
        self.blown_work.push([before, self.step_work]);
        self.next_impulse += 1;
        Ok(())
    }
}
