//! The step loop of a method that keeps its own variables between steps (the Wisdom–Holman
//! methods: corrected Jacobi coordinates, as WHFast with `safe_mode = 0`).
//!
//! Such a method advances its inner variables w by one step at a time from the stepper's
//! (q, p), which stay its synchronised image: the method reads (q, p) only when w is not valid
//! (the first step, after [`super::Stepper::reset`], on another h or model) and writes them,
//! from a copy of w, once the steps asked for are done or one fails. So the steps are the same
//! whether the state is read after every step or once, and taking the stepper apart
//! ([`super::Stepper::into_state`]) keeps w with the state: the steps resume bit for bit.

use super::StepperState;
use crate::integrators::Dynamics;
use crate::{Error, ModelError};

impl StepperState {
    /// `n` steps of the method's own variables, `poll` called when due as in
    /// [`super::Stepper::advance`], then (q, p) synchronised to the last good step.
    pub(super) fn advance_own<S, P>(&mut self, model: &S, n: usize, mut poll: P) -> Result<(), Error>
    where
        S: Dynamics + ?Sized,
        P: FnMut() -> Result<(), ModelError>,
    {
        let Some(nbody) = model.as_nbody() else {
            return Err(self.method().refusal(model.kind()));
        };
        let mut result = Ok(());
        for _ in 0..n {
            let (step, time) = (self.steps + 1, self.t());
            if self.interrupt.due() {
                if let Err(source) = poll() {
                    result = Err(Error::Interrupted { step, time, source });
                    break;
                }
            }
            let stepped = match self.integrator.own_variables() {
                Some(own) => own.step(nbody, &self.q, &self.p, self.clock.h, self.compensated),
                None => return Err(self.method().refusal(model.kind())),
            };
            if let Err(e) = stepped {
                result = Err(e.at(step, time));
                break;
            }
            self.steps = step;
        }
        if let Some(own) = self.integrator.own_variables() {
            own.synchronise(&mut self.q, &mut self.p);
        }
        result
    }
}
