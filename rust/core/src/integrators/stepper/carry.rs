//! The stepper's one loop of steps, generic over what a step carries besides (q, p)
//! ([`Carry`]): nothing, the contacts' gaps checked at each step's end, or tangent vectors
//! carried by each step's tangent map.
//!
//! A model kind's [`Dynamics::advance`] picks how its steps run: a separable system's
//! kick–drift methods and a Lagrangian's two-point rules on up to 4 coordinates in their own
//! loops of fixed-size arrays (the driver's costs, not the physics, dominate such small steps),
//! every other case one step at a time ([`StepperState::one_at_a_time`]). A check that needs only the
//! step's end (a [`Clear`]) runs inside either loop; one that needs the step's solution (an
//! implicit step's tangent map reads it from the integrator) runs in the one-at-a-time loop.

use super::StepperState;
use crate::integrators::clear::{Always, Clear, Gaps};
use crate::integrators::tangent::{self, Tangent};
use crate::integrators::{Dynamics, General};
use crate::model::{Lagrangian, MechanicalSystem};
use crate::Error;

/// What the steps of [`Dynamics::advance`] carry besides (q, p). They stop after the first
/// step that crosses a contact ([`Gaps`]), or that takes a tangent vector's component past
/// the bound; `advance` is true then, with that step kept.
pub enum Carry<'a, 'g, 's> {
    /// Nothing: every step is taken.
    Nothing,
    /// The contacts' gaps φ, checked at the end of every step.
    Gaps(&'a mut Gaps<'g, 's>),
    /// Tangent vectors `x` (2n × k, column-major) carried by each step's map, and the bound.
    Tangent(&'a mut Tangent, &'a mut [f64], f64),
}

/// What the one-at-a-time loop does about each step: `begin` before it, `end` after it (true:
/// stop there). Every [`Clear`] is one; so are tangent vectors whose map reads the step's
/// solution from the integrator ([`Vectors`]).
trait EachStep {
    fn begin(&mut self, _state: &StepperState) {}

    fn end(&mut self, model: &dyn Dynamics, state: &mut StepperState) -> Result<bool, Error>;
}

impl<C: Clear + ?Sized> EachStep for C {
    #[inline(always)]
    fn end(&mut self, _: &dyn Dynamics, state: &mut StepperState) -> Result<bool, Error> {
        Ok(!self.clear(&state.q, &state.p))
    }
}

/// Tangent vectors carried by each step's map ([`Tangent::apply`]), from the step's start.
struct Vectors<'a> {
    tangent: &'a mut Tangent,
    x: &'a mut [f64],
    large: f64,
}

impl EachStep for Vectors<'_> {
    fn begin(&mut self, state: &StepperState) {
        self.tangent.begin(state.t(), &state.q, &state.p);
    }

    fn end(&mut self, model: &dyn Dynamics, state: &mut StepperState) -> Result<bool, Error> {
        let (step, time) = (state.steps, state.clock.at(state.steps - 1));
        self.tangent
            .apply(model, &mut state.integrator, (state.clock.h, &state.q), self.x)
            .map_err(|source| Error::model(step, time, source))?;
        Ok(tangent::past(self.x, self.large))
    }
}

impl StepperState {
    /// `steps` steps of `model` one at a time, carrying `carry`: the loop of a model kind
    /// without one of its own, and of the cases the kinds' own loops leave.
    pub(in crate::integrators) fn steps_carrying<S: Dynamics + ?Sized>(
        &mut self,
        model: &S,
        steps: usize,
        carry: Carry<'_, '_, '_>,
    ) -> Result<bool, Error> {
        match carry {
            Carry::Nothing => self.one_at_a_time(model, steps, &mut Always),
            Carry::Gaps(gaps) => self.one_at_a_time(model, steps, gaps),
            Carry::Tangent(tangent, x, large) => self.one_at_a_time(model, steps, &mut Vectors { tangent, x, large }),
        }
    }

    /// The one-at-a-time loop: steps of `model`, each between `each`'s begin and end, stopping
    /// after the first whose end stops it (true then), with its start in (q_next, p_next),
    /// where a step's swap leaves it. A method with its own variables takes each step in its
    /// own loop, (q, p) synchronised after it.
    fn one_at_a_time<S, C>(&mut self, model: &S, steps: usize, each: &mut C) -> Result<bool, Error>
    where
        S: Dynamics + ?Sized,
        C: EachStep + ?Sized,
    {
        let own = self.integrator.own_variables().is_some();
        for _ in 0..steps {
            each.begin(self);
            if own {
                self.q_next.copy_from_slice(&self.q);
                self.p_next.copy_from_slice(&self.p);
                let result = model.advance(self, 1, Carry::Nothing);
                self.synchronise();
                result?;
            } else {
                self.step(model)?;
            }
            if each.end(model.as_dynamics(), self)? {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// `steps` steps of a separable system carrying `carry`: the methods with their own
    /// variables on them (`own_variables.rs`); a kick–drift step's tangent map as the check at
    /// each step's end ([`tangent::Carried`]) of its loop; every other case as
    /// [`StepperState::separable`] takes it.
    pub(in crate::integrators) fn advance_separable<S: MechanicalSystem>(
        &mut self,
        sys: &S,
        steps: usize,
        carry: Carry<'_, '_, '_>,
    ) -> Result<bool, Error> {
        match carry {
            Carry::Nothing => {
                if let Some(result) = sys.as_nbody().and_then(|nbody| self.advance_own(nbody, steps)) {
                    return result.map(|()| false);
                }
                self.separable(sys, steps, &mut Always)
            }
            Carry::Gaps(gaps) => self.separable(sys, steps, gaps),
            Carry::Tangent(tangent, x, large) => {
                let h = self.clock.h;
                let Some(mut carried) = tangent.carried(sys, h, (&self.q, &self.p), &mut *x, large) else {
                    return self.one_at_a_time(sys, steps, &mut Vectors { tangent, x, large });
                };
                let stopped = self.separable(sys, steps, &mut carried)?;
                match carried.failed.take() {
                    // The step whose map failed is kept, as a step of the stepper's own keeps it.
                    Some(source) => Err(Error::Model {
                        step: self.steps,
                        time: self.clock.at(self.steps - 1),
                        source,
                    }),
                    None => Ok(stopped),
                }
            }
        }
    }

    /// Steps of a separable system, stopping after the first whose end is not `clear` (true
    /// then): the kick–drift methods on up to 4 coordinates in a loop of fixed-size arrays
    /// ([`crate::integrators::KickDrift::run`]), every other case one at a time.
    fn separable<S, C>(&mut self, sys: &S, steps: usize, clear: &mut C) -> Result<bool, Error>
    where
        S: MechanicalSystem,
        C: Clear + ?Sized,
    {
        let (integrator, phase) = self.phase();
        if let Some(kick_drift) = integrator.kick_drift() {
            match phase.q.len() {
                1 => return kick_drift.run::<S, 1, C>(sys, phase, steps, clear),
                2 => return kick_drift.run::<S, 2, C>(sys, phase, steps, clear),
                3 => return kick_drift.run::<S, 3, C>(sys, phase, steps, clear),
                4 => return kick_drift.run::<S, 4, C>(sys, phase, steps, clear),
                _ => {}
            }
        }
        self.one_at_a_time(sys, steps, clear)
    }

    /// `steps` steps of a general Lagrangian carrying `carry`, as
    /// [`StepperState::lagrangian`] takes them; tangent vectors one step at a time (an
    /// implicit step's map reads the step's solution).
    pub(in crate::integrators) fn advance_lagrangian<L: Lagrangian>(
        &mut self,
        sys: &L,
        steps: usize,
        carry: Carry<'_, '_, '_>,
    ) -> Result<bool, Error> {
        match carry {
            Carry::Nothing => self.lagrangian(sys, steps, &mut Always),
            Carry::Gaps(gaps) => self.lagrangian(sys, steps, gaps),
            vectors @ Carry::Tangent(..) => self.steps_carrying(&General(sys), steps, vectors),
        }
    }

    /// Steps of a general Lagrangian, stopping after the first whose end is not `clear` (true
    /// then): the two-point DEL methods on up to 4 coordinates in their loop of fixed-size
    /// arrays ([`crate::integrators::Del::run`]), every other case one at a time.
    fn lagrangian<L, C>(&mut self, sys: &L, steps: usize, clear: &mut C) -> Result<bool, Error>
    where
        L: Lagrangian,
        C: Clear + ?Sized,
    {
        let mut left = steps;
        while left > 0 {
            let (integrator, phase) = self.phase();
            let n = phase.q.len();
            let fixed = match n {
                1 => integrator.run_two_point::<L, 1, C>(sys, phase, left, clear),
                2 => integrator.run_two_point::<L, 2, C>(sys, phase, left, clear),
                3 => integrator.run_two_point::<L, 3, C>(sys, phase, left, clear),
                4 => integrator.run_two_point::<L, 4, C>(sys, phase, left, clear),
                _ => None,
            };
            if let Some(result) = fixed {
                return result;
            }
            self.step(&General(sys))?;
            left -= 1;
            if !clear.clear(&self.q, &self.p) {
                return Ok(true);
            }
            // Only a run's first step makes the loop apply (it judges the continuum limit's
            // sign): once past it, a case the loop does not take steps on without asking.
            if left < steps - 1 {
                return self.one_at_a_time(&General(sys), left, clear);
            }
        }
        Ok(false)
    }
}
