//! A decoded state's derived values, recomputed and compared: what a method computes from its
//! coefficients, the step and the model rather than carries from step to step. A CRC does not
//! stop an edited checkpoint, and these values steer the run that goes on (an edited stage
//! coefficient or cached force would, silently).
//!
//! Checked here, to the bit: the constants ([`shape::constants`]: a splitting's fractions, a
//! composition's γ, a quadrature's nodes, weights and basis, a delayed force's lags) against a
//! fresh state of the method and model; and each method's own derived values
//! ([`Integrator::derived_misfit`]): a kick–drift step's fractions times its step, and the
//! caches of first same as last (∇V at a kick–drift step's last stage, ∇V and G at a RATTLE
//! step's end, the constraint matrix at a DEL step's end) evaluated again where they were
//! taken, that point within round-off of the state's q; the Wisdom–Holman method's Jacobi
//! masses against the model's, and its inner variables against the (q, p) they synchronise to.
//! The run's own state, (t, q, p), the compensated-summation carries, the Newton and
//! multiplier predictors, the counts and a delayed force's history, is what a checkpoint
//! carries: it is checked finite and, through the fingerprint, against the model (an edit of
//! (t, q, p) that the model's L, ∂L/∂q, ∂L/∂q̇ and forces do not see, a cyclic coordinate's,
//! is not detectable).

use super::shape;
use crate::integrators::{Dynamics, Integrator, StepperState};

/// Why `state`'s derived values (its method's constants and caches) are not those of its
/// method on `model`, if they are not; for a state whose shape [`shape::misfit`] has checked.
pub(in crate::integrators) fn misfit<S: Dynamics + ?Sized>(state: &StepperState, model: &S) -> Option<String> {
    let template = state.templates(model).1;
    let (found, expected) = (shape::constants(state), shape::constants(&template));
    if found != expected {
        let differs = found.iter().zip(&expected).find(|(a, b)| a != b);
        return Some(match differs {
            Some((a, b)) => format!("its method's constant {a} differs from the method's own, {b}"),
            None => "its method's constants differ from the method's own".to_string(),
        });
    }
    let (q, p, t, h) = (state.q(), state.p(), state.t(), state.dt());
    let mut v = vec![0.0; q.len()];
    if model.as_lagrangian().velocity(q, p, t, &mut v).is_err() {
        v.fill(0.0);
    }
    let reach: Vec<f64> = v.iter().map(|v| (h * v).abs()).collect();
    Integrator::derived_misfit(
        state.integrator(),
        model.as_dynamics(),
        &Reached { q, p, reach: &reach },
    )
}

/// The state's (q, p), and how far a step moves each coordinate, |h q̇ᵢ|: a cache taken at a
/// step's last stage lies at qₙ + δq, which the compensated sum rounds to the state's q.
pub(in crate::integrators) struct Reached<'a> {
    pub q: &'a [f64],
    pub p: &'a [f64],
    reach: &'a [f64],
}

impl Reached<'_> {
    /// Whether `x` is the state's q to round-off: |xᵢ − qᵢ| ≤ 10⁻⁶(|qᵢ| + |xᵢ| + |hq̇ᵢ|), a bound
    /// far above the few ulps of qₙ that tell them apart (qₙ = q − δq, |δq| about |hq̇|), and
    /// far below a changed value.
    pub fn holds(&self, x: &[f64]) -> bool {
        x.len() == self.q.len()
            && (x.iter().zip(self.q).zip(self.reach)).all(|((x, q), r)| (x - q).abs() <= 1e-6 * (q.abs() + x.abs() + r))
    }
}

/// Whether two vectors hold the same bits.
pub(in crate::integrators) fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(a, b)| a.to_bits() == b.to_bits())
}
