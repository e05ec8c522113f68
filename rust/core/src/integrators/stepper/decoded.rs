//! The checks of a decoded state (a checkpoint's): its shape against the state its method has
//! on the model, and the values its method derives (`checkpoint/derived.rs`).

use super::{Clock, StepperState};
use crate::integrators::checkpoint::{derived, shape::shape};
use crate::integrators::{Dynamics, Integrator, Options};

impl StepperState {
    /// Why a decoded state (a checkpoint's, which its CRC does not protect against a crafted
    /// file) cannot be stepped on `model`, if it cannot: every length, matrix size, variant
    /// and count in it is compared with the state its method has on `model`, fresh or after a
    /// step (the constrained methods size their buffers at the first step), every pivot must
    /// index its vector, and the state, clock and options must be finite and in range. The
    /// caller has checked the dimension and that the method integrates the model's kind.
    pub(in crate::integrators) fn misfit<S: Dynamics + ?Sized>(&self, model: &S) -> Option<String> {
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
        let (fresh, stepped) = self.templates(model);
        let (found, fresh, stepped) = (shape(self), shape(&fresh), shape(&stepped));
        if found == fresh || found == stepped {
            return None;
        }
        let (at, expected) = found
            .iter()
            .zip(&stepped)
            .find(|(a, b)| a != b)
            .map_or_else(|| (None, None), |(a, b)| (Some(a), Some(b)));
        Some(match (at, expected) {
            (Some(a), Some(b)) => format!(
                "its state does not fit this model and its method {}: {a} where they have {b}",
                self.method().info().name
            ),
            _ => format!(
                "its state does not fit this model and its method {}: {} parts where they have {}",
                self.method().info().name,
                found.len(),
                stepped.len()
            ),
        })
    }

    /// The states of this one's method, clock and options on `model`, fresh and after a step
    /// (its buffers sized, its history kept), of zeros: the templates a decoded state is
    /// checked against.
    fn templates<S: Dynamics + ?Sized>(&self, model: &S) -> (StepperState, StepperState) {
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

    /// Why a decoded state's derived values (its method's constants and caches) are not what
    /// its method computes on `model`, if they are not (see `checkpoint/derived.rs`); for a
    /// state whose shape [`StepperState::misfit`] has checked.
    pub(in crate::integrators) fn derived_misfit<S: Dynamics + ?Sized>(&self, model: &S) -> Option<String> {
        derived::misfit(self, &self.templates(model).1, model)
    }

    /// The integrator, for the checks of a decoded state.
    pub(in crate::integrators) fn integrator(&self) -> &Integrator {
        &self.integrator
    }
}
