//! What the checks of a decoded state (a checkpoint's, `checkpoint/shape.rs` and
//! `checkpoint/derived.rs`) read of it: its values in range, and the templates of its method
//! on the model that its shape is compared with.

use super::{Clock, StepperState};
use crate::integrators::{Dynamics, Integrator, Options};

impl StepperState {
    /// Why a decoded state's values (a checkpoint's, which its CRC does not protect against a
    /// crafted file) cannot be stepped, if they cannot: the state, clock and options must be
    /// finite and in range. Its shape is checked against [`StepperState::templates`]
    /// (`checkpoint/shape.rs`).
    pub(in crate::integrators) fn values_misfit(&self) -> Option<String> {
        let vectors = [("q", &self.q), ("p", &self.p), ("eq", &self.eq), ("ep", &self.ep)];
        if let Some((name, _)) = vectors.iter().find(|(_, x)| !x.iter().all(|v| v.is_finite())) {
            return Some(format!("its state's {name} is not finite"));
        }
        let Clock { t0, n0, h } = self.clock;
        if !(t0.is_finite() && h.is_finite() && h > 0.0 && n0 <= self.steps && self.t().is_finite()) {
            return Some(format!(
                "its clock (t0 = {t0}, dt = {h}, set at step {n0} of {}) is not a valid one",
                self.steps
            ));
        }
        if let Err(e) = self.integrator.newton_options().unwrap_or_default().check() {
            return Some(format!("its Newton options are not valid ({e})"));
        }
        None
    }

    /// The states of this one's method, clock and options on `model`, fresh and after a step
    /// (its buffers sized, its history kept), of zeros: the templates a decoded state is
    /// checked against.
    pub(in crate::integrators) fn templates<S: Dynamics + ?Sized>(&self, model: &S) -> (StepperState, StepperState) {
        let options = Options {
            t0: self.clock.t0,
            compensated: self.compensated,
            newton: self.integrator.newton_options().unwrap_or_default(),
            ..Options::new(self.clock.h, 0)
        };
        // Of the model's size: the state's own vectors are what is checked.
        let zeros = vec![0.0; model.dim()];
        let fresh = StepperState::fresh(self.method(), &zeros, &zeros, &options);
        let mut stepped = fresh.clone();
        let (m, holonomic) = model.constraint_counts();
        stepped.integrator.prepare(model.dim(), m, holonomic);
        stepped
            .integrator
            .keep_history(model.dim(), model.as_lagrangian(), self.clock.h);
        (fresh, stepped)
    }

    /// The integrator, for the checks of a decoded state.
    pub(in crate::integrators) fn integrator(&self) -> &Integrator {
        &self.integrator
    }
}
