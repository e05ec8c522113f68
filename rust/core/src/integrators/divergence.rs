//! How a run tells a divergence from a bounded error: the stability limit at its first state
//! ([`beyond_limit`]), the energy watch that stops a run whose error grows ([`EnergyWatch`]),
//! and the advice a divergence carries.

use serde::{Deserialize, Serialize};

use super::{Dynamics, Method, Stepper};
use crate::model::{EnergyTerms, Rest, Scale};
use crate::solve::difference;
use crate::solve::newton::norm;
use crate::{Error, ModelError};

/// A step beyond the method's stability limit on the model's fastest mode: h·ω_max, the limit
/// h_ω on q̈ = −ω²q, and ω_max.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeyondLimit {
    pub h_omega: f64,
    pub limit: f64,
    pub omega: f64,
}

/// Whether a step `dt` of `method` at (q, t) is beyond its stability limit, ω_max the fastest
/// frequency of the small oscillations there from at most `iterations` of Lanczos
/// ([`Rest::fastest`]): the one test of the check before a run and of a divergence's diagnosis.
/// None within the limit, for a method without a finite one (unconditionally stable, or with
/// none on an oscillator) and for a model with velocity constraints.
///
/// # Errors
/// The model's own.
pub fn beyond_limit<S: Dynamics + ?Sized>(
    sys: &S,
    (method, dt): (Method, f64),
    (q, t): (&[f64], f64),
    iterations: usize,
) -> Result<Option<BeyondLimit>, ModelError> {
    let limit = method.info().h_omega_max;
    if !(limit.is_finite() && limit > 0.0) || sys.velocity_constraints().is_some() {
        return Ok(None);
    }
    let omega = Rest::new(sys.as_lagrangian(), sys.holonomic(), q, t)?
        .fastest(iterations)?
        .omega;
    Ok((dt * omega > limit).then_some(BeyondLimit {
        h_omega: dt * omega,
        limit,
        omega,
    }))
}

/// A divergence with its likely cause named: h·ω_max at the run's first state beyond the
/// method's stability limit ([`beyond_limit`]). Other errors, and divergences within the limit
/// (or where the frequency does not evaluate), as they are.
pub(super) fn diagnosed<S: Dynamics + ?Sized>(
    error: Error,
    sys: &S,
    (method, dt): (Method, f64),
    (q, t): (Vec<f64>, f64),
) -> Error {
    let Error::Divergence { step, time, reason } = error else {
        return error;
    };
    let reason = match beyond_limit(sys, (method, dt), (&q, t), Rest::AFTER_FAILURE) {
        Ok(Some(BeyondLimit { h_omega, limit, omega })) => format!(
            "{reason}; h·ω_max = {h_omega:.4} at the run's first state (t = {t}) is beyond {}'s stability limit {limit} \
             (ω_max = {omega:.6e}, the fastest frequency of the small oscillations there): take dt below {:.6e} \
             (varmech.suggest_dt)",
            method.info().name,
            limit / omega
        ),
        _ => reason,
    };
    Error::Divergence { step, time, reason }
}

/// The run's energy check: E − W against its value at the start, judged by a running [`Scale`].
/// An error beyond `tolerance` × the scale stops the run at once where the step is beyond the
/// method's stability limit at the run's first state ([`beyond_limit`]; explicit Euler's, 0, at
/// every step): a blow-up foretold, which the check before the run warned of. Within the limit
/// it stops the run only where it grows, or the state does ([`Growth`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct EnergyWatch {
    initial: f64,
    scale: Scale,
    tolerance: f64,
    growth: Growth,
    /// The size of the state, max |qᵢ|, judged as the error is: an orbit thrown out of its well, or
    /// a pendulum thrown over its top, has an error that jumps once and stays, and a state that
    /// grows from then on.
    spread: Growth,
    /// Whether the step is beyond the limit, once an error has passed the scale: asked then
    /// (Lanczos on the first state, as a divergence's diagnosis does), once a run.
    beyond: Option<bool>,
}

/// Whether an energy error grows: the error at the n-th check (saved state) is at least
/// [`Growth::FACTOR`] times the largest at the checks up to P, the largest power of two ≤ n/2
/// (the run then at most half as long), from check [`Growth::FIRST`] on.
///
/// Why growth, not size, within the stability limit: a stable step of a symplectic method
/// conserves a modified energy H̃ = H + O(hᵖ) (Hairer, Lubich & Wanner, GNI IX.8), so its error
/// E − E₀ is an offset that stays bounded however large it is: on q̈ = −ω²q Verlet's H/H̃ reaches
/// 1/(1 − (hω/2)²), 50 at 0.99 of its limit, many times the mean kinetic energy. The offset
/// swings with the angle the step turns a mode by, slowly near a limit (at 0.99 of it: in 11
/// steps for Verlet, 62 for kahan_li8, 99 for blanes_moan6; a mode far from its limit carries
/// an offset far below the scale), rising from zero at the start over half that. A baseline of
/// 32 checks spans that rise, so from check 64 on a bounded offset no longer doubles in a
/// doubling of the run. An error that grows geometrically (a mode that turns unstable along a
/// nonlinear run), or drifts or diffuses at least linearly, doubles in every doubling of the
/// run, and is stopped within a doubling of passing `max_energy_error` × the scale. An offset
/// that varies more slowly than the run has been long (a step yet closer to the limit, saved
/// states that alias a near-limit oscillation) reads as growth; an error that jumps once and
/// stays (an orbit thrown out of its well at one pericentre) does not, but the state it leaves
/// grows, and the same test of max |qᵢ| stops it. The maxima at powers of two keep the test to four numbers, carried in the checkpoint
/// so that a resumed run is judged as one run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
struct Growth {
    /// Checks so far (the initial state is check 0, with error 0).
    checks: u64,
    /// The largest |error| over every check.
    largest: f64,
    /// The largest |error| up to check 2ᵏ, 2ᵏ ≤ checks < 2ᵏ⁺¹, and up to check 2ᵏ⁻¹.
    at_power: f64,
    baseline: f64,
}

impl Growth {
    /// How much an error must grow in a doubling of the run.
    const FACTOR: f64 = 2.0;
    /// The first check judged: the baseline then spans 32 checks, a bounded offset's rise.
    const FIRST: u64 = 64;

    /// Adds the next check's |error|; whether it grows.
    fn grows(&mut self, error: f64) -> bool {
        // Saturating: a crafted checkpoint's count must not overflow.
        self.checks = self.checks.saturating_add(1);
        self.largest = self.largest.max(error);
        if self.checks.is_power_of_two() {
            self.baseline = self.at_power;
            self.at_power = self.largest;
        }
        self.checks >= Self::FIRST && error >= Self::FACTOR * self.baseline
    }
}

impl EnergyWatch {
    /// None for a model without an energy (L depends on t); an error when the initial energy
    /// does not evaluate or is not finite.
    pub(super) fn new<S, M>(sys: &S, stepper: &Stepper<M>, tolerance: f64) -> Option<Result<Self, Error>>
    where
        S: Dynamics + ?Sized,
        M: std::ops::Deref<Target: Dynamics>,
    {
        let (step, time) = (0, stepper.t());
        let terms = match sys.energy(stepper.q(), stepper.p(), time)? {
            Ok(terms) => terms,
            Err(source) => return Some(Err(Error::model(step, time, source))),
        };
        if !terms.energy.is_finite() {
            let reason = not_finite(&terms);
            return Some(Err(Error::Divergence { step, time, reason }));
        }
        let mut watch = EnergyWatch {
            initial: terms.energy - stepper.work(),
            scale: Scale::default(),
            tolerance,
            growth: Growth::default(),
            spread: Growth {
                largest: norm(stepper.q()),
                ..Growth::default()
            },
            beyond: None,
        };
        watch.push(&terms, stepper.work());
        Some(Ok(watch))
    }

    pub(super) fn set_tolerance(&mut self, tolerance: f64) {
        self.tolerance = tolerance;
    }

    fn push(&mut self, terms: &EnergyTerms, work: f64) {
        self.scale.push(terms.kinetic, terms.size() + work.abs());
    }

    /// The error that ends the run at the stepper's state, if any; `first` is the run's first
    /// state (q, t), where the stability limit is judged.
    pub(super) fn check<S, M>(
        &mut self,
        sys: &S,
        stepper: &Stepper<M>,
        first: (&[f64], f64),
        reflects: bool,
    ) -> Option<Error>
    where
        S: Dynamics + ?Sized,
        M: std::ops::Deref<Target: Dynamics>,
    {
        let (step, time, work) = (stepper.steps(), stepper.t(), stepper.work());
        let terms = match sys.energy(stepper.q(), stepper.p(), time)? {
            Ok(terms) => terms,
            Err(source) => return Some(Error::model(step, time, source)),
        };
        self.push(&terms, work);
        let error = terms.energy - work - self.initial;
        if !error.is_finite() {
            let reason = not_finite(&terms);
            return Some(Error::Divergence { step, time, reason });
        }
        let (baseline, spread) = (self.growth.baseline, self.spread.baseline);
        let size = norm(stepper.q());
        let grows = self.growth.grows(error.abs());
        let spreads = self.spread.grows(size);
        if !self.scale.fails(error, step as u64, self.tolerance) {
            return None;
        }
        let (method, dt) = (stepper.method(), stepper.dt());
        let beyond = *self.beyond.get_or_insert_with(|| {
            method.info().h_omega_max == 0.0
                || matches!(beyond_limit(sys, (method, dt), first, Rest::AFTER_FAILURE), Ok(Some(_)))
        });
        if !(beyond || grows || spreads) {
            return None;
        }
        let scale = self.scale.scale();
        let growing = if beyond {
            String::new()
        } else if grows {
            format!(", and growing: it was at most {baseline:.3e} while the run was half as long")
        } else {
            format!(
                ", and the state growing: max |qᵢ| = {size:.3e}, at most {spread:.3e} while the run was half as long"
            )
        };
        let advice = differences_advice(sys, (stepper.q(), stepper.p(), time), first.0, error.abs())
            .unwrap_or_else(|| step_advice(method, reflects));
        let reason = format!(
            "energy error {:.3e} is {:.3e} times the energy scale {scale:.3e} (the mean kinetic energy), \
             beyond max_energy_error = {:.3e}{growing}; {advice}",
            error.abs(),
            error.abs() / scale,
            self.tolerance,
        );
        Some(Error::Divergence { step, time, reason })
    }
}

/// The advice for an energy error that the rounding of derivatives taken by differences
/// accounts for: their noise in the forces at (q, p, t), times the motion from the run's first
/// state `first`, at least `error` (a motion far below the differences' step, as at amplitudes
/// of 1e-100, loses its forces to rounding). None where derivatives are exact, or the noise
/// accounts for less: then the step is to blame.
fn differences_advice<S: Dynamics + ?Sized>(
    sys: &S,
    (q, p, t): (&[f64], &[f64], f64),
    first: &[f64],
    error: f64,
) -> Option<String> {
    let model = sys.as_lagrangian();
    let (mut v, mut forces) = (vec![0.0; q.len()], vec![0.0; q.len()]);
    difference::take_noise();
    model.velocity(q, p, t, &mut v).ok()?;
    model.gradients(q, &v, t, &mut forces, &mut vec![0.0; q.len()]).ok()?;
    let noise = difference::take_noise();
    let motion = q.iter().zip(first).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    (noise * motion >= error).then(|| {
        format!(
            "the error is within the rounding of the derivatives taken by differences (forces to ±{noise:.1e} \
             over a motion of {motion:.1e}), which a smaller step does not lower: supply the model's \
             derivatives, or scale its coordinates to order 1"
        )
    })
}

/// What helps an energy error that a step too coarse accounts for, in a run that reflects
/// impacts by Newton's law (`reflects`) or not. A method that is not symplectic conserves no
/// modified energy: its error grows along any run, so a smaller step only slows it (a run k
/// times as long needs a step k times smaller at order 1), and a symplectic method bounds it. A
/// symplectic one that is not symmetric (symplectic Euler) has a modified energy odd in p, at
/// first order (H̃ = H − (h/2)q̇·∇V + O(h²)): a reflection of p moves it by O(h), with the same
/// sign at every impact, a drift of order 1; a symmetric method's is even in p, and the
/// variational law keeps the discrete energy across the impact.
fn step_advice(method: Method, reflects: bool) -> String {
    let info = method.info();
    if info.symplectic && (info.symmetric || !reflects) {
        return "reduce dt".into();
    }
    if info.symplectic {
        return format!(
            "reduce dt ({} is not symmetric: each impact reflected by Newton's law moves its modified energy by \
             O(h), alike at every one, a drift that falls at order 1), or take a symmetric method, whose energy \
             stays bounded across impacts: verlet, or law=\"variational\"",
            info.name
        );
    }
    format!(
        "reduce dt ({} is not symplectic: its energy error grows along the run, slower at a smaller step, by \
         order {}), or take a symplectic method, whose error stays bounded: verlet (rattle on a constrained model)",
        info.name, info.order
    )
}

fn not_finite(terms: &EnergyTerms) -> String {
    format!(
        "the energy is not finite (E = {}, T = {}, V = {}): the model's energy does not evaluate there",
        terms.energy, terms.kinetic, terms.potential
    )
}
