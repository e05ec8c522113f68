//! Contacts held closed: their multipliers, the lift-off where one crosses 0, what a jump does
//! to them, the contacts a state rests on, and the events located on a held piece.

use std::ops::Deref;

use super::gaps::evaluate;
use super::{amax, dot, Resolver};
use crate::integrators::events::{PieceSteps, Search};
use crate::integrators::jumps::hold::{Held, Hold};
use crate::integrators::jumps::round_off;
use crate::integrators::jumps::unsolved::run_error;
use crate::integrators::Switch;
use crate::integrators::{Dynamics, Occurrence, Stepper};
use crate::solve::bracket::illinois;
use crate::Error;

impl<'c, 's, M: Deref<Target: Dynamics>> Resolver<'c, 's, M> {
    /// The first lift-off in the piece of size τ from ta, with the scratch at its end: among
    /// the closed contacts whose multiplier λ is negative there, the earliest s where λ crosses
    /// 0 along the held partial steps (Illinois, to round-off), and the contact. None when
    /// every λ ≥ 0 at the piece's end.
    pub(super) fn lift_off(&mut self, step: usize, (ta, tau): (f64, f64)) -> Result<Option<(f64, usize)>, Error> {
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
    pub(super) fn lambda_along(&mut self, a: usize, step: usize, ta: f64, s: f64) -> Result<f64, Error> {
        self.partial(step, ta, s)?;
        let mut lambda = std::mem::take(&mut self.lambda);
        let result = self.multipliers(ta + s, &mut lambda, step);
        let value = lambda[a];
        self.lambda = lambda;
        result.map(|()| value)
    }

    /// The multipliers of the closed contacts at the scratch's state, at time t, into `out`:
    /// λ of each, then the force along each slip row of the stuck ones ([`Hold::multipliers`]).
    pub(super) fn multipliers(&mut self, t: f64, out: &mut [f64], step: usize) -> Result<(), Error> {
        let time = self.t;
        let (hold, held, scratch) = self.holding();
        let state = (scratch.q(), scratch.p(), t);
        hold.multipliers(scratch.model().as_lagrangian(), held, state, out)
            .map(|_| ())
            .map_err(|source| run_error(source, step, time))
    }

    /// The held step, what it holds now, and the scratch stepper.
    pub(super) fn holding(&mut self) -> (&mut Hold, Held<'_, 's>, &Stepper<M>) {
        let hold = self.hold.as_mut().expect("a contact closes only where it can be held");
        let held = held!(self);
        (hold, held, &self.scratch)
    }

    /// Contact k released at time t, at the state (`contact_q`, `piece_p`): at lift-off, or
    /// just after a jump that moves the body off its surface. A stuck contact's sticking ends
    /// with it (a change of its own, for the samples to undo).
    pub(super) fn open(&mut self, k: usize, step: usize, t: f64) {
        if self.stuck.contains(&k) {
            self.stuck.retain(|&j| j != k);
            self.changes.push((t, k, Switch::Slipped));
        }
        self.closed.retain(|&j| j != k);
        self.switched(k, Switch::Released, step, (t, t));
    }

    /// Contact k's switch `kind` at time t, recorded for the samples to undo and reported at
    /// `reported` (t, or the limit of a Zeno series), at the state (`contact_q`, `piece_p`).
    pub(super) fn switched(&mut self, k: usize, kind: Switch, step: usize, (t, reported): (f64, f64)) {
        self.changes.push((t, k, kind));
        self.pending
            .switches
            .push(k, step, reported, kind, (&self.contact_q, &self.piece_p));
    }

    /// Closed contact k lifted off at time t, at the state (q, p) in the contact buffers: open
    /// from there on, the state kept for the samples after it.
    pub(super) fn release(&mut self, k: usize, step: usize, t: f64) {
        self.piece_p.copy_from_slice(&self.contact_p);
        self.open(k, step, t);
        self.released
            .push(k, step, t, &self.contact_q, &self.contact_p, &self.contact_p);
        self.released_work.push(self.step_work);
    }

    /// After a jump at time t to (q̃, p⁺) (`contact_q`, `piece_p`) with contacts closed: those
    /// the jump moves off their surface released, the stuck ones it sets slipping slipped (a
    /// jump has no friction: a ball struck while it rolls slides), and p⁺ made tangent to the
    /// others (their impulse, which keeps a body on a surface it presses on).
    pub(super) fn after_jump(&mut self, step: usize, t: f64) -> Result<(), Error> {
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
    pub(super) fn close_resting(&mut self, (t, q, p): (f64, &[f64], &[f64]), step: usize) -> Result<(), Error> {
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
    pub(super) fn restart_piece(
        &mut self,
        step: usize,
        search: Option<&mut Search<'_, '_, M>>,
        t: f64,
    ) -> Result<(), Error> {
        if let Some(search) = search {
            search.restart_piece(step, (t, &self.contact_q, &self.piece_p))?;
        }
        self.piece_q.copy_from_slice(&self.contact_q);
        evaluate(self.contacts, &self.piece_q, &mut self.phi_start, step, self.t)?;
        self.aim_piece(step, t)
    }

    /// The sliding contacts' directions at the piece's start (`piece_q`, `piece_p`) at time t
    /// ([`Resolver::aim`]).
    pub(super) fn aim_piece(&mut self, step: usize, t: f64) -> Result<(), Error> {
        if self.frictional && !self.closed.is_empty() {
            self.scratch.restart(t, &self.piece_q, &self.piece_p, self.scratch.dt());
            self.aim(step, t)?;
        }
        Ok(())
    }

    /// `search`'s crossings on the piece of size s from ta, which ends at `end`: located on
    /// the held steps while a contact is closed (the scratch then redone to the piece's end,
    /// which the loop goes on from), else on the search's own partial steps of the method.
    pub(super) fn watch_piece(
        &mut self,
        search: &mut Search<'_, '_, M>,
        step: usize,
        (ta, s): (f64, f64),
        end: (f64, &[f64], &[f64]),
        occurrences: &mut Vec<Occurrence>,
    ) -> Result<(), Error> {
        if self.closed.is_empty() {
            return search.piece(step, end, s, occurrences);
        }
        let mut held = HeldSteps {
            resolver: self,
            ta,
            taken: false,
        };
        search.piece_on(step, end, s, occurrences, Some(&mut held))?;
        if held.taken {
            self.partial(step, ta, s)?;
        }
        Ok(())
    }
}

/// A held piece from (ta, `piece_q`, `piece_p`): its partial steps are the resolver's held
/// steps, on which a search locates its crossings.
struct HeldSteps<'r, 'c, 's, M> {
    resolver: &'r mut Resolver<'c, 's, M>,
    ta: f64,
    /// Whether a step was taken, leaving the scratch elsewhere.
    taken: bool,
}

impl<M: Deref<Target: Dynamics>> PieceSteps for HeldSteps<'_, '_, '_, M> {
    fn state_at(&mut self, step: usize, tau: f64) -> Result<(&[f64], &[f64]), Error> {
        self.taken = true;
        self.resolver.partial(step, self.ta, tau)?;
        Ok((self.resolver.scratch.q(), self.resolver.scratch.p()))
    }
}
