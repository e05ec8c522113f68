//! The saved states of a run, and a run that stopped early.

use std::borrow::Cow;
use std::ops::Deref;

use super::{Dynamics, Impacts, Occurrence, Stepper};
use crate::Error;

/// The saved states of a run: row k is (`t[k]`, `q[k]`, `p[k]`); q and p are stored row-major.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    pub dim: usize,
    pub t: Vec<f64>,
    pub q: Vec<f64>,
    pub p: Vec<f64>,
    /// Steps completed.
    pub steps: usize,
    /// Force evaluations made (see [`super::Integrator::force_evaluations`]).
    pub force_evaluations: u64,
    /// Newton iterations made (implicit methods).
    pub newton_iterations: u64,
    /// Newton iterations made up to each saved state (cumulative; empty for the methods that
    /// solve no equations, rather than zeros): their differences give the iterations per step
    /// between saves.
    pub newton: Vec<u64>,
    /// Work done by non-conservative forces up to each saved state (forced systems; empty
    /// without forces, rather than zeros): the energy balance E(t) − E(0) − W(t) is the discrete
    /// Lagrange–d'Alembert check.
    pub work: Vec<f64>,
    /// The [`super::Checkpoint`] of the last state, as bytes ([`super::Checkpoint::to_bytes`]):
    /// [`super::resume`] goes on from it. Empty for a run that failed before its first state.
    pub checkpoint: Vec<u8>,
    /// The located event crossings, in order of time ([`super::integrate_watching`]).
    pub events: Vec<Occurrence>,
    /// The event whose terminal count stopped the run, if one did.
    pub terminated_by: Option<usize>,
    /// The impacts on the run's contacts ([`super::integrate_watching`]), in order of time; the
    /// saved states hold the state just before and just after each (one time, two rows).
    pub impacts: Impacts,
}

impl Trajectory {
    /// Number of saved states.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// q at saved state k.
    pub fn q_at(&self, k: usize) -> &[f64] {
        &self.q[k * self.dim..(k + 1) * self.dim]
    }

    /// p at saved state k.
    pub fn p_at(&self, k: usize) -> &[f64] {
        &self.p[k * self.dim..(k + 1) * self.dim]
    }

    /// Newton iterations up to each saved state, zeros (made now) when the run solved no equations.
    pub fn newton_at_saves(&self) -> Cow<'_, [u64]> {
        Self::or_zeros(&self.newton, self.len())
    }

    /// Work of the non-conservative forces up to each saved state, zeros (made now) without forces.
    pub fn work_at_saves(&self) -> Cow<'_, [f64]> {
        Self::or_zeros(&self.work, self.len())
    }

    fn or_zeros<T: Clone + Default>(column: &[T], len: usize) -> Cow<'_, [T]> {
        if column.is_empty() {
            Cow::Owned(vec![T::default(); len])
        } else {
            Cow::Borrowed(column)
        }
    }

    /// Saves the stepper's state as the state at time `t`.
    pub(super) fn push<M>(&mut self, t: f64, stepper: &Stepper<M>)
    where
        M: Deref<Target: Dynamics>,
    {
        self.t.push(t);
        self.newton.extend(stepper.newton());
        self.work.extend(stepper.forced_work());
        self.q.extend_from_slice(stepper.q());
        self.p.extend_from_slice(stepper.p());
    }

    /// Saves (q, p) as the state at time `t`, with the stepper's Newton count and work less
    /// `behind`, the energy put in after that state: a state inside a step (just before or
    /// after an impact, a sample).
    pub(super) fn push_state<M, St>(&mut self, t: f64, (q, p): (&[f64], &[f64]), stepper: &Stepper<M, St>, behind: f64)
    where
        M: Deref<Target: Dynamics>,
        St: std::borrow::Borrow<super::StepperState>,
    {
        self.t.push(t);
        self.newton.extend(stepper.newton());
        self.work.extend(stepper.forced_work().map(|w| w - behind));
        self.q.extend_from_slice(q);
        self.p.extend_from_slice(p);
    }

    /// Records the stepper's counts: the steps completed and the work they took.
    pub(super) fn count<M>(&mut self, stepper: &Stepper<M>)
    where
        M: Deref<Target: Dynamics>,
    {
        self.steps = stepper.steps();
        self.force_evaluations = stepper.force_evaluations();
        self.newton_iterations = stepper.newton_iterations();
    }
}

/// A run that stopped early: why, and every state saved up to the last good step.
#[derive(Debug)]
pub struct Failure {
    pub error: Error,
    pub partial: Trajectory,
}
