//! Coulomb friction on the held contacts: the switches between sticking and sliding, located
//! along the held partial steps, and the sliding contacts' directions.

use std::ops::Deref;

use super::{amax, dot, insert, Resolver};
use crate::integrators::jumps::unsolved::run_error;
use crate::integrators::Dynamics;
use crate::integrators::Switch;
use crate::solve::bracket::illinois;
use crate::Error;

impl<'c, 's, M: Deref<Target: Dynamics>> Resolver<'c, 's, M> {
    /// The first friction switch in the piece of size τ from ta, with the scratch at its end
    /// (and left there): a stuck contact that slips where the force its slip rows need, |λ_t|,
    /// reaches μ_s N; a sliding one whose slip turns against its direction at the piece's
    /// start, where it stops (it sticks there if it can, [`Resolver::switch_friction`]). Each
    /// located by the Illinois method along the held partial steps, to round-off. None when
    /// neither happens in the piece.
    pub(super) fn friction_switch(
        &mut self,
        step: usize,
        (ta, tau): (f64, f64),
    ) -> Result<Option<(f64, usize, Switch)>, Error> {
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
    pub(super) fn stuck_multipliers(&mut self, j: usize, step: usize, t: f64) -> Result<(usize, usize), Error> {
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
    pub(super) fn excess(&mut self, j: usize, step: usize, t: f64) -> Result<f64, Error> {
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
    pub(super) fn switch_friction(&mut self, k: usize, kind: Switch, step: usize, t: f64) -> Result<(), Error> {
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
    pub(super) fn sticks(&mut self, j: usize, step: usize, t: f64) -> Result<bool, Error> {
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
    pub(super) fn aim(&mut self, step: usize, t: f64) -> Result<(), Error> {
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
    pub(super) fn project_piece(&mut self, step: usize, t: f64) -> Result<(), Error> {
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
    pub(super) fn along(&mut self, j: usize, step: usize, t: f64) -> Result<f64, Error> {
        let n = self.scratch.q().len();
        self.slip_at(j, step, t)?;
        Ok(dot(&self.direction, &self.directions[j * n..(j + 1) * n]))
    }

    /// The slip s = Jq̇ of contact j at the scratch's state at time t into `slip`, Jᵀs into
    /// `direction`: its size |s|, and that of J's entries, max |J|.
    pub(super) fn slip_at(&mut self, j: usize, step: usize, t: f64) -> Result<(f64, f64), Error> {
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
    pub(super) fn slip_size(&mut self, j: usize, step: usize, t: f64) -> Result<(f64, bool), Error> {
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
}
