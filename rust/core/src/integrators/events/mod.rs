//! Events: functions g(t, q, p) whose sign changes the run watches, located inside the step by
//! the method's own partial step (the semantics of scipy's `solve_ivp(events=)`).
//!
//! - [`EventFunctions`]: the functions, all evaluated at once into a slice;
//! - [`EventSpec`]: each one's name, direction and terminal count;
//! - [`Detector`]: the functions with their specs, which a run given them
//!   ([`super::integrate_watching`]) checks after every step, locating each crossing;
//! - [`NativeEvent`]: the built-in functions, evaluated without leaving Rust;
//! - [`Occurrence`]: a located crossing, a state of the integrator.

mod detector;
mod native;

pub use detector::Detector;
pub(in crate::integrators) use detector::{PieceSteps, Search};
pub use native::NativeEvent;

use super::Dynamics;
use crate::ModelError;

/// Event functions g₁ … g_m of the state: a run records where each changes sign.
pub trait EventFunctions {
    /// The number m of functions.
    fn len(&self) -> usize;

    /// Whether there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Called once at the initial state (t₀, q₀, p₀) of a run, before any evaluation (e.g. to
    /// take the initial energy). By default nothing.
    fn start(&mut self, _model: &dyn Dynamics, _t: f64, _q: &[f64], _p: &[f64]) -> Result<(), ModelError> {
        Ok(())
    }

    /// Writes gᵢ(t, q, p) into `g[i]`, i < m. `model` gives the velocities q̇(q, p, t), the
    /// energy and the forces of constraint where a function needs them.
    fn evaluate(&mut self, model: &dyn Dynamics, t: f64, q: &[f64], p: &[f64], g: &mut [f64])
        -> Result<(), ModelError>;
}

/// A borrowed set of functions is one: a stepper keeps its functions between calls, lending
/// them to each call's [`Detector`].
impl<E: EventFunctions + ?Sized> EventFunctions for &mut E {
    fn len(&self) -> usize {
        (**self).len()
    }

    fn start(&mut self, model: &dyn Dynamics, t: f64, q: &[f64], p: &[f64]) -> Result<(), ModelError> {
        (**self).start(model, t, q, p)
    }

    fn evaluate(
        &mut self,
        model: &dyn Dynamics,
        t: f64,
        q: &[f64],
        p: &[f64],
        g: &mut [f64],
    ) -> Result<(), ModelError> {
        (**self).evaluate(model, t, q, p, g)
    }
}

/// How an event is watched: a crossing is a step from gₙ ≠ 0 to gₙ₊₁ of the other sign or 0.
#[derive(Clone, Debug, PartialEq)]
pub struct EventSpec {
    /// Named in errors and in the terminating event's message.
    pub name: String,
    /// +1: only crossings where g increases (from − to +); −1: where it decreases; 0: both.
    pub direction: i8,
    /// Stop the run after this many occurrences (at the end of the step of the last one); 0:
    /// never.
    pub terminal: usize,
}

impl EventSpec {
    /// Counts `found` (one call's crossings, of these specs in order) toward the terminal
    /// counts, for the next call of a stepper going on: a count reached becomes 0, never
    /// again, as for a run gone on from.
    pub fn carry(specs: &mut [EventSpec], found: &[Occurrence]) {
        for o in found {
            let terminal = &mut specs[o.event].terminal;
            *terminal = terminal.saturating_sub(1);
        }
    }
}

/// A located crossing of event `event`, during step `step` (counted from 1): the state
/// (t, q, p) of one step of size τ = t − tₙ₋₁ ∈ (0, h] of the run's method from the state
/// (q_start, p_start) before the step, with gₑᵥₑₙₜ = 0 to round-off.
///
/// The start is kept because a run stopped by a terminal event ends after the step of the
/// crossing, and the partial step (q_start, p_start) → (q, p) is then known whole only here: an
/// impact's variational collision integrator needs the discrete energy of that partial step,
/// which for an implicit rule cannot be had from its end alone without solving it backwards.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Occurrence {
    pub event: usize,
    pub step: usize,
    pub t: f64,
    pub q: Vec<f64>,
    pub p: Vec<f64>,
    pub q_start: Vec<f64>,
    pub p_start: Vec<f64>,
}
