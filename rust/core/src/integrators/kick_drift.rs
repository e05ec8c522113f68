use super::{Increment, Splitting, StepStart};
use crate::model::MechanicalSystem;
use crate::ModelError;

/// A kick–drift splitting method ([`Splitting`]) for H = ½pᵀM⁻¹p + V(q):
///
/// p ← p − a₀h∇V(q); then for i = 1..s: q ← q + bᵢhM⁻¹p, p ← p − aᵢh∇V(q).
///
/// A zero kick evaluates no force: an ABA method (a₀ = aₛ = 0) opens its step with a drift.
/// The force at the end of a BAB step is kept for the first kick of the next (first same as
/// last), so a Verlet composition of s stages costs s force evaluations a step.
#[derive(Clone, Debug)]
pub struct KickDrift {
    kicks: Vec<f64>,
    drifts: Vec<f64>,
    q: Vec<f64>,
    p: Vec<f64>,
    force: Vec<f64>,
    force_cached: bool,
    evaluations: u64,
}

impl KickDrift {
    /// The integrator of `splitting` for n coordinates.
    pub fn new(splitting: &Splitting, n: usize) -> Self {
        KickDrift {
            kicks: splitting.kicks().to_vec(),
            drifts: splitting.drifts().to_vec(),
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

    fn evaluate<S: MechanicalSystem + ?Sized>(&mut self, sys: &S) -> Result<(), ModelError> {
        self.evaluations += 1;
        let r = sys.gradient(&self.q, &mut self.force);
        // A failed evaluation leaves no stale force behind.
        self.force_cached = r.is_ok();
        r
    }

    pub(super) fn increment<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), ModelError> {
        let StepStart { h, q, p, .. } = *start;
        let Increment { dq, dp } = increment;
        if self.kicks[0] == 0.0 {
            // ABA: the first drift moves with the step's own momenta; no force is needed.
            dq.fill(0.0);
            dp.fill(0.0);
            self.p.copy_from_slice(p);
        } else {
            if !self.force_cached {
                self.q.copy_from_slice(q);
                self.evaluate(sys)?;
            }
            // The first kick writes δp (and clears δq, which the drifts add to); each later
            // one adds to it.
            let a = self.kicks[0] * h;
            kick(a, &self.force, p, dp, &mut self.p, Some(dq));
        }
        for i in 0..self.drifts.len() {
            sys.mass().drift(self.drifts[i] * h, &self.p, q, dq, &mut self.q);
            let a = self.kicks[i + 1] * h;
            if a == 0.0 {
                self.force_cached = false;
                continue;
            }
            self.evaluate(sys)?;
            kick(a, &self.force, p, dp, &mut self.p, None);
        }
        Ok(())
    }
}

/// δp ← δp − a·f (δp ← −a·f, and δq ← 0, when `first` holds δq), fused with the momenta
/// p̃ = p + δp the next drift needs. Indexed over slices cut to one length, so that the bounds
/// checks fold away (a four-way zip costs more instructions than the arithmetic here).
#[inline(always)]
fn kick(a: f64, force: &[f64], p: &[f64], dp: &mut [f64], stage: &mut [f64], first: Option<&mut [f64]>) {
    let n = p.len();
    let (force, dp, stage) = (&force[..n], &mut dp[..n], &mut stage[..n]);
    match first {
        Some(dq) => {
            let dq = &mut dq[..n];
            for i in 0..n {
                dp[i] = -a * force[i];
                stage[i] = p[i] + dp[i];
                dq[i] = 0.0;
            }
        }
        None => {
            for i in 0..n {
                dp[i] -= a * force[i];
                stage[i] = p[i] + dp[i];
            }
        }
    }
}
