//! A symmetric composition of a [`Del`] step: Ψ_h = Φ_{γₛh} ∘ … ∘ Φ_{γ₁h} (HLW V.3), of
//! order 4 by Yoshida's triple jump when Φ is symmetric of order 2.

use serde::{Deserialize, Serialize};

use super::{Constraints, Del, StepEquations};
use crate::integrators::{Increment, StepError, StepStart};
use crate::model::Lagrangian;
use crate::solve::NewtonOptions;

/// The steps of fractions γ₁, …, γₛ (Σγᵢ = 1, γᵢ = γₛ₊₁₋ᵢ) of one scheme, each stage with its
/// own solver, so that its predictor extrapolates steps of its own size from one composed step
/// to the next. Every stage ends on the constraints, as the step does.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Composed<Sc> {
    gamma: Vec<f64>,
    stages: Vec<Del<Sc>>,
    q_stage: Vec<f64>,
    p_stage: Vec<f64>,
    dq_stage: Vec<f64>,
    dp_stage: Vec<f64>,
}

impl<Sc: StepEquations + Clone> Composed<Sc> {
    /// `scheme` composed with the fractions `gamma`, for n coordinates.
    pub fn new(scheme: Sc, gamma: Vec<f64>, n: usize, options: NewtonOptions) -> Self {
        Composed {
            stages: gamma.iter().map(|_| Del::new(scheme.clone(), n, options)).collect(),
            gamma,
            q_stage: vec![0.0; n],
            p_stage: vec![0.0; n],
            dq_stage: vec![0.0; n],
            dp_stage: vec![0.0; n],
        }
    }

    /// Evaluations of the step's equations so far, over the stages.
    pub fn evaluations(&self) -> u64 {
        self.stages.iter().map(Del::evaluations).sum()
    }

    /// Newton iterations so far, over the stages.
    pub fn iterations(&self) -> u64 {
        self.stages.iter().map(Del::iterations).sum()
    }

    /// The energy put in so far: the generalized forces' work, less Σ∂L_d/∂t.
    pub fn work(&self) -> f64 {
        self.stages.iter().map(Del::work).sum()
    }

    /// Sizes every stage's buffers for m constraints, `holonomic` of them holonomic.
    pub(in crate::integrators) fn size_for(&mut self, n: usize, m: usize, holonomic: usize) {
        self.stages.iter_mut().for_each(|s| s.size_for(n, m, holonomic));
    }

    /// The options of the stages' Newton iteration.
    pub(in crate::integrators) fn options(&self) -> NewtonOptions {
        self.stages[0].options()
    }

    pub(in crate::integrators) fn reset(&mut self) {
        self.stages.iter_mut().for_each(Del::reset);
    }

    /// One composed step's increments from `start`: the stages' increments summed.
    pub(in crate::integrators) fn increment<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        constraints: Constraints<'_>,
        start: StepStart<'_>,
        out: Increment<'_>,
    ) -> Result<(), StepError> {
        let Increment { dq, dp } = out;
        dq.fill(0.0);
        dp.fill(0.0);
        let mut t = start.t;
        for (del, gamma) in self.stages.iter_mut().zip(&self.gamma) {
            for ((qs, ps), ((q, p), (d, e))) in self
                .q_stage
                .iter_mut()
                .zip(self.p_stage.iter_mut())
                .zip(start.q.iter().zip(start.p).zip(dq.iter().zip(dp.iter())))
            {
                *qs = q + d;
                *ps = p + e;
            }
            // The constraint matrix a stage cached at its last end is not where it starts now.
            del.multipliers.cached = false;
            let stage = StepStart {
                t,
                h: gamma * start.h,
                q: &self.q_stage,
                p: &self.p_stage,
            };
            let increment = Increment {
                dq: &mut self.dq_stage,
                dp: &mut self.dp_stage,
            };
            del.increment(sys, constraints, stage, increment)?;
            dq.iter_mut().zip(&self.dq_stage).for_each(|(d, s)| *d += s);
            dp.iter_mut().zip(&self.dp_stage).for_each(|(d, s)| *d += s);
            t += gamma * start.h;
        }
        Ok(())
    }
}
