use super::checkpoint::derived::{same, Reached};
use super::clear::Clear;
use super::stepper::{array, Phase};
use super::{Increment, Splitting, StepError, StepStart};
use crate::model::MechanicalSystem;
use crate::{Error, ModelError};
use serde::{Deserialize, Serialize};

/// A kick–drift splitting method ([`Splitting`]) for H = ½pᵀM⁻¹p + V(q):
///
/// p ← p − a₀h∇V(q); then for i = 1..s: q ← q + bᵢhM⁻¹p, p ← p − aᵢh∇V(q).
///
/// A zero kick evaluates no force: an ABA method (a₀ = aₛ = 0) opens its step with a drift.
/// The force at the end of a BAB step is kept for the first kick of the next (first same as
/// last), so a Verlet composition of s stages costs s force evaluations a step.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct KickDrift {
    /// The fractions in the order the step applies them: a₀, b₁, a₁, …, bₛ, aₛ.
    fractions: Vec<f64>,
    /// The fractions times the step h they were computed for.
    scaled: Vec<f64>,
    scaled_for: f64,
    q: Vec<f64>,
    p: Vec<f64>,
    force: Vec<f64>,
    force_cached: bool,
    evaluations: u64,
}

impl KickDrift {
    /// The integrator of `splitting` for n coordinates.
    pub fn new(splitting: &Splitting, n: usize) -> Self {
        let (kicks, drifts) = (splitting.kicks(), splitting.drifts());
        let pairs = drifts.iter().zip(&kicks[1..]).flat_map(|(b, a)| [*b, *a]);
        let fractions: Vec<f64> = std::iter::once(kicks[0]).chain(pairs).collect();
        KickDrift {
            scaled: vec![0.0; fractions.len()],
            scaled_for: f64::NAN,
            fractions,
            q: vec![0.0; n],
            p: vec![0.0; n],
            force: vec![0.0; n],
            force_cached: false,
            evaluations: 0,
        }
    }

    pub(super) fn reset(&mut self) {
        self.force_cached = false;
    }

    pub(super) fn force_evaluations(&self) -> u64 {
        self.evaluations
    }

    pub(super) fn increment<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), ModelError> {
        let StepStart { h, q, p, .. } = *start;
        let Increment { dq, dp } = increment;
        self.scale(h);
        let stage = Stage {
            q: &mut self.q,
            p: &mut self.p,
            force: &mut self.force,
        };
        let counts = Counts {
            cached: &mut self.force_cached,
            evaluations: &mut self.evaluations,
        };
        sequence(sys, &self.scaled, q, p, dq, dp, stage, counts)
    }

    /// Why a decoded step's derived values are not its own (see `checkpoint/derived.rs`), if
    /// they are not: its fractions times the step it was last scaled for, and the force it
    /// cached, ∇V at its last stage, which lies at the state's q to round-off.
    pub(super) fn misfit(&self, sys: &dyn MechanicalSystem, at: &Reached<'_>) -> Option<String> {
        let h = self.scaled_for;
        let scaled = |(s, f): (&f64, &f64)| s.to_bits() == (f * h).to_bits();
        if !h.is_nan() && !self.scaled.iter().zip(&self.fractions).all(scaled) {
            return Some(format!(
                "its stage coefficients times the step, {:?}, are not its fractions times dt = {h:?}",
                self.scaled
            ));
        }
        if !self.force_cached {
            return None;
        }
        if !at.holds(&self.q) {
            return Some("the last stage of its step, where its force was cached, is not at its state's q".to_string());
        }
        let mut force = vec![0.0; self.force.len()];
        (sys.gradient(&self.q, &mut force).is_err() || !same(&force, &self.force))
            .then(|| "its cached force is not the model's ∇V at its step's last stage".to_string())
    }

    /// The fractions times h, once per step size.
    fn scale(&mut self, h: f64) {
        if self.scaled_for != h {
            for (x, f) in self.scaled.iter_mut().zip(&self.fractions) {
                *x = f * h;
            }
            self.scaled_for = h;
        }
    }

    /// `steps` steps of N coordinates with the state in fixed-size arrays, one loop with no
    /// dispatch, the step's arithmetic that of [`KickDrift::increment`] and of the stepper,
    /// so that the results agree bit for bit. Called by the stepper for small separable
    /// systems ([`StepperState`](super::StepperState)), stopping after a step whose end is
    /// not `clear` ([`Phase::run`]).
    pub(super) fn run<S: MechanicalSystem + ?Sized, const N: usize, C: Clear + ?Sized>(
        &mut self,
        sys: &S,
        state: Phase<'_>,
        steps: usize,
        clear: &mut C,
    ) -> Result<bool, Error> {
        self.scale(state.clock.h);
        let (mut stage_q, mut stage_p, mut force) = (array::<N>(&self.q), array::<N>(&self.p), array::<N>(&self.force));
        // Counts in locals, written back once: through the pointers they would cost stores.
        let (mut cached, mut evaluations) = (self.force_cached, self.evaluations);
        let scaled = &self.scaled;
        let increment = |_: f64, q: &[f64; N], p: &[f64; N], dq: &mut [f64; N], dp: &mut [f64; N]| {
            let stage = Stage {
                q: &mut stage_q,
                p: &mut stage_p,
                force: &mut force,
            };
            let counts = Counts {
                cached: &mut cached,
                evaluations: &mut evaluations,
            };
            Ok::<_, StepError>(sequence(sys, scaled, q, p, dq, dp, stage, counts)?)
        };
        let result = state.run::<N, _, C>(steps, increment, clear);
        (self.force_cached, self.evaluations) = (cached, evaluations);
        self.q.copy_from_slice(&stage_q);
        self.p.copy_from_slice(&stage_p);
        self.force.copy_from_slice(&force);
        result
    }
}

/// The stage positions and momenta a sequence moves through, and the force at the last stage.
struct Stage<'a> {
    q: &'a mut [f64],
    p: &'a mut [f64],
    force: &'a mut [f64],
}

/// Whether `Stage::force` holds ∇V at the step's start, and the evaluations made.
struct Counts<'a> {
    cached: &'a mut bool,
    evaluations: &'a mut u64,
}

impl Counts<'_> {
    /// force = ∇V(q), counted.
    #[inline(always)]
    fn evaluate<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        q: &[f64],
        force: &mut [f64],
    ) -> Result<(), ModelError> {
        *self.evaluations += 1;
        let r = sys.gradient(q, force);
        // A failed evaluation leaves no stale force behind.
        *self.cached = r.is_ok();
        r
    }
}

/// The increments (δq, δp) of one step from (q, p), with `scaled` = a₀h, b₁h, a₁h, …, bₛh, aₛh.
/// Written once for both the stepper's step and the fixed-size loop; inlined, so that the
/// latter's lengths are known.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn sequence<S: MechanicalSystem + ?Sized>(
    sys: &S,
    scaled: &[f64],
    q: &[f64],
    p: &[f64],
    dq: &mut [f64],
    dp: &mut [f64],
    stage: Stage<'_>,
    mut counts: Counts<'_>,
) -> Result<(), ModelError> {
    let Stage {
        q: stage_q,
        p: stage_p,
        force,
    } = stage;
    if scaled[0] == 0.0 {
        // ABA: the first drift moves with the step's own momenta; no force is needed.
        dq.fill(0.0);
        dp.fill(0.0);
        stage_p.copy_from_slice(p);
    } else {
        if !*counts.cached {
            stage_q.copy_from_slice(q);
            counts.evaluate(sys, stage_q, force)?;
        }
        // The first kick writes δp (and clears δq, which the drifts add to); each later one
        // adds to it, and the last leaves the stage momenta, which no drift reads.
        kick(scaled[0], force, p, dp, Some(stage_p), Some(dq));
    }
    let stages = scaled.len() / 2;
    for i in 0..stages {
        sys.mass().drift(scaled[2 * i + 1], stage_p, q, dq, stage_q);
        let a = scaled[2 * i + 2];
        if a == 0.0 {
            *counts.cached = false;
            continue;
        }
        counts.evaluate(sys, stage_q, force)?;
        let stage = (i + 1 < stages).then_some(&mut *stage_p);
        kick(a, force, p, dp, stage, None);
    }
    Ok(())
}

/// δp ← δp − a·f (δp ← −a·f, and δq ← 0, when `first` holds δq), fused with the momenta
/// p̃ = p + δp the next drift needs, if any. Indexed over slices cut to one length, so that the
/// bounds checks fold away (a four-way zip costs more instructions than the arithmetic here).
#[inline(always)]
fn kick(a: f64, force: &[f64], p: &[f64], dp: &mut [f64], stage: Option<&mut [f64]>, first: Option<&mut [f64]>) {
    let n = p.len();
    let (force, dp) = (&force[..n], &mut dp[..n]);
    if let Some(dq) = first {
        let dq = &mut dq[..n];
        for i in 0..n {
            dp[i] = -a * force[i];
            dq[i] = 0.0;
        }
    } else {
        for i in 0..n {
            dp[i] -= a * force[i];
        }
    }
    if let Some(stage) = stage {
        let stage = &mut stage[..n];
        for i in 0..n {
            stage[i] = p[i] + dp[i];
        }
    }
}
