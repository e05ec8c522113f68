//! The variational law: the variational collision integrator of Fetecau, Marsden, Ortiz & West
//! (2003), "Nonsmooth Lagrangian mechanics and variational collision integrators", SIAM J. Appl.
//! Dyn. Syst. 2, 381–416.

use super::{Impact, Jump};
use crate::integrators::{Dynamics, Feature, Method};
use crate::solve::secant::secant;
use crate::Error;

/// Why the law does not fit `method` on `model`, if it does not: it needs the method's discrete
/// energy ([`Feature::DiscreteEnergy`]) and a conservative, autonomous, unconstrained model
/// (the energy balance is E_d's alone).
pub(super) fn misfit(model: &dyn Dynamics, method: Method) -> Option<String> {
    if !method.supports(Feature::DiscreteEnergy) {
        return Some(format!(
            "the variational collision integrator needs a kick–drift method, a two-point rule or a Galerkin rule, \
             whose steps have a discrete energy ({}), not {}; give the contact law reflect or use such a method",
            Method::names(|m| m.supports(Feature::DiscreteEnergy)).join(", "),
            method.info().name
        ));
    }
    let lagrangian = model.as_lagrangian();
    let constrained = model.constraint_counts() != (0, 0) || model.velocity_constraints().is_some();
    if lagrangian.is_forced() || lagrangian.is_time_dependent() || constrained {
        return Some(
            "the variational collision integrator keeps the discrete energy, which needs a conservative, \
             autonomous, unconstrained model; give the contact law reflect"
                .into(),
        );
    }
    None
}

/// The jump of an elastic impact with E_d kept ([`multiplier`]); Newton's law (the reflection)
/// for e < 1, beside a held contact and at a step's end. Its loss is Newton's: none for e = 1
/// (the change of E is the method's error, E_d kept).
pub(super) fn jump(impact: &mut dyn Impact) -> Result<Jump, Error> {
    let (newton, e) = impact.newton();
    let mut jump = Jump {
        lambda: newton.lambda,
        loss: newton.loss(e),
        restitution: e,
        grazing: false,
    };
    if e < 1.0 || impact.newton_only() {
        return Ok(jump);
    }
    let Some((target, scale)) = impact.discrete_energy()? else {
        jump.grazing = true;
        return Ok(jump);
    };
    let (lambda, found) = multiplier(
        |lambda| impact.discrete_energy_after(lambda),
        newton.lambda,
        target,
        scale,
    )?;
    (jump.lambda, jump.grazing) = (lambda, !found);
    Ok(jump)
}

/// λ with the discrete energy of the piece after the jump, `after(λ)`, equal to `target`, that of
/// the piece before: the contact point and the fraction of the step then make the action of the
/// two pieces stationary, D₂L_d(q_k, q̃, τ₁) + D₁L_d(q̃, q_{k+1}, τ₂) = λ∇φ(q̃) and
/// E_d(q_k, q̃, τ₁) = E_d(q̃, q_{k+1}, τ₂), so the step across the impact is symplectic. Solved by
/// secants ([`secant`]) from the reflection's λ `exact`, O(τ²) away; `(exact, false)` where
/// there is no root near it (a grazing impact, |∇φ·q̇| of order τ). `scale` sizes the energies'
/// round-off.
fn multiplier(
    mut after: impl FnMut(f64) -> Result<f64, Error>,
    exact: f64,
    target: f64,
    scale: f64,
) -> Result<(f64, bool), Error> {
    // An implicit rule's E_d(λ), from a Newton solve, can stall a few ulps from the root, where
    // the secant sees no slope.
    // A λ whose E_d is within that noise of the target is the root as far as E_d can tell:
    // no further secant could tell a better one (the billiard's, where the laws coincide, is
    // the reflection's at once).
    let noise = 16.0 * f64::EPSILON * (target.abs() + scale.abs());
    let f0 = after(exact)? - target;
    if f0.abs() <= noise {
        return Ok((exact, true));
    }
    let energy = |lam| Ok::<_, Error>(after(lam)? - target);
    let root = secant(energy, (exact, f0), exact * (1.0 + 1e-6), noise, 40)?;
    let (lo, hi) = if exact > 0.0 {
        (0.5 * exact, 1.5 * exact)
    } else {
        (1.5 * exact, 0.5 * exact)
    };
    Ok(match root {
        Some(lam) if (lo..=hi).contains(&lam) => (lam, true),
        _ => (exact, false),
    })
}
