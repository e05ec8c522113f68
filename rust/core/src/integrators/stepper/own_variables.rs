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
use crate::model::NBody;
use crate::Error;

impl StepperState {
    /// `steps` steps of the method's own variables (the stepper polls for interrupts between
    /// such calls, and synchronises (q, p) after the last); None for a method without
    /// variables of its own.
    pub(super) fn advance_own(&mut self, model: &NBody, steps: usize) -> Option<Result<(), Error>> {
        let StepperState {
            integrator,
            clock,
            steps: done,
            compensated,
            q,
            p,
            ..
        } = self;
        let own = integrator.own_variables()?;
        for _ in 0..steps {
            if let Err(e) = own.step(model, q, p, clock.h, *compensated) {
                return Some(Err(e.at(*done + 1, clock.at(*done))));
            }
            *done += 1;
        }
        Some(Ok(()))
    }

    /// Writes (q, p) from the method's own variables, as of the last good step, if it keeps
    /// any.
    pub(super) fn synchronise(&mut self) {
        if let Some(own) = self.integrator.own_variables() {
            own.synchronise(&mut self.q, &mut self.p);
        }
    }
}
