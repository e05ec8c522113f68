//! Newton's method for the implicit equations of every layer: the step equations of the
//! variational integrators, RATTLE's multipliers, the momentum projection onto the hidden
//! constraint, the inverse Legendre transform, the Routhian's cyclic velocities and the
//! projection onto the constraints.
//!
//! One iteration x ← x − J⁻¹F(x), with J factorised in place ([`super::lu`]) and, as an option,
//! kept while the corrections at least halve (simplified Newton). It stops on the increment,
//! ‖δ‖ ≤ tolerance·scale, at the noise floor of the equations, when the problem declares F
//! small enough, or at the iteration cap.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::difference::NOISE_FLOOR;
use super::interrupt::{check_interrupt, InterruptPoll};
use super::lu::{lu_in_place, lu_solve};
use crate::error::StepError;
use crate::{Error, ModelError};

/// Options of a Newton iteration.
///
/// The implicit integrators stop when ‖δ‖∞ ≤ tolerance·‖x‖∞, x the unknowns as increments from
/// q₀ (the step's δq, and the Galerkin control points' offsets), or when a Newton step with a
/// freshly computed Jacobian no longer halves a correction that is already below √ε‖x‖∞ (the
/// equations' own accuracy when derivatives come from differences). The scale is the increment,
/// not the position: the discrete velocity δq/h, and so p₁, carries the increment's relative
/// precision, which a scale of ‖q‖∞ would give away as a cyclic angle grows. The other
/// iterations measure their corrections their own way (RATTLE: the move of q₁ against ‖q₀‖∞).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NewtonOptions {
    /// Stop when the correction satisfies ‖δ‖ ≤ tolerance·scale (the problem's measure).
    pub tolerance: f64,
    /// Give up (a convergence error) after this many iterations.
    pub max_iterations: usize,
}

impl NewtonOptions {
    /// The largest iteration cap. Newton's method converges in a handful of iterations or not
    /// at all (the default cap is 50); a cap beyond ten thousand only turns a failure into an
    /// apparent hang, and a cap near 2⁶³ into a real one.
    pub const MAX_ITERATIONS: usize = 10_000;

    /// Checks tolerance > 0 finite and 1 ≤ max_iterations ≤ [`Self::MAX_ITERATIONS`]; the
    /// errors name the arguments `newton_tolerance` and `newton_max_iterations`.
    pub fn check(&self) -> Result<(), Error> {
        let NewtonOptions {
            tolerance,
            max_iterations,
        } = *self;
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(Error::invalid(
                "newton_tolerance",
                format!("must be finite and positive, got {tolerance}"),
            ));
        }
        if !(1..=Self::MAX_ITERATIONS).contains(&max_iterations) {
            return Err(Error::invalid(
                "newton_max_iterations",
                format!("must be from 1 to {}, got {max_iterations}", Self::MAX_ITERATIONS),
            ));
        }
        Ok(())
    }
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            tolerance: 1e-14,
            max_iterations: 50,
        }
    }
}

/// How an iteration refreshes its Jacobian and when it may stop short of the tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rules {
    /// Keep the factorised Jacobian while the corrections at least halve (simplified Newton),
    /// refresh it otherwise; false: a fresh Jacobian every iteration.
    pub simplified: bool,
    /// Also stop at the noise floor: when a step with a fresh Jacobian no longer halves the
    /// smallest correction so far, and that correction is below [`NOISE_FLOOR`]·scale.
    pub noise_floor: bool,
}

/// The size of a Newton correction and the scale the tolerance is relative to: converged when
/// size ≤ tolerance·scale (a scale of 0 leaves convergence to [`NewtonProblem::solved`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Correction {
    pub size: f64,
    pub scale: f64,
}

impl Correction {
    /// x ← x − δ, measured relative to each entry: size maxᵢ |δᵢ|/max(|xᵢ|, 1), scale 1.
    pub fn relative(x: &mut [f64], delta: &[f64]) -> Self {
        let mut size = 0.0_f64;
        for (x, d) in x.iter_mut().zip(delta) {
            *x -= d;
            size = size.max(d.abs() / x.abs().max(1.0));
        }
        Correction { size, scale: 1.0 }
    }
}

/// Why an iteration failed, in the words of its problem.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Reasons {
    /// The Jacobian is singular.
    pub singular: &'static str,
    /// F is non-finite at the starting guess.
    pub non_finite_start: &'static str,
    /// A correction or F became non-finite.
    pub non_finite: &'static str,
    /// The iteration cap was reached.
    pub not_converged: &'static str,
}

/// The equations F(x) = 0 of one Newton iteration. The problem keeps its unknowns x (the
/// iteration only sees F, its Jacobian and the corrections), so that it may apply a correction
/// as it must (the projection onto g(q) = 0 moves q along M⁻¹Gᵀ).
pub(crate) trait NewtonProblem {
    /// The messages of the failures.
    const REASONS: Reasons;

    /// Writes F(x) into `r`.
    fn residual(&mut self, r: &mut [f64]) -> Result<(), StepError>;

    /// Writes ∂F/∂x into `jac` (it is factorised in place afterwards).
    fn jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<(), StepError>;

    /// Applies x ← x − δ (or the problem's own update along δ) and measures the correction.
    fn correct(&mut self, delta: &[f64]) -> Correction;

    /// Whether F, of norm ‖F‖∞ = `residual`, is small enough to stop at (checked at the start
    /// and after every correction). Default: never, the increment decides.
    fn solved(&self, _residual: f64) -> bool {
        false
    }

    /// Told before the evaluation of F at which the iteration ends (its correction converged),
    /// for a problem that takes more than F from that evaluation (the DEL step: ∂L/∂t for the
    /// energy balance, which the others need not compute). Default: nothing.
    fn finishing(&mut self) {}
}

/// An iteration's progress, by the sizes of its corrections: whether the next step factorises
/// a fresh Jacobian, and when to stop ([`Rules`]). Shared by [`Newton::solve`] and the
/// fixed-size DEL step, which must decide alike.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Progress {
    keep_jacobian: bool,
    last: f64,
    smallest: f64,
}

impl Progress {
    pub fn new() -> Self {
        Progress {
            keep_jacobian: false,
            last: f64::INFINITY,
            smallest: f64::INFINITY,
        }
    }

    /// Whether the next Newton step factorises a fresh Jacobian.
    #[inline(always)]
    pub fn fresh(&self) -> bool {
        !self.keep_jacobian
    }

    /// Whether the iteration has converged after `correction`, made with a fresh Jacobian or
    /// a kept one: on the increment, or at the noise floor of the equations (round-off, or
    /// derivatives by differences), where even a fresh Newton step no longer halves the
    /// smallest correction so far, or below the normal numbers. If not, the Jacobian is kept while the corrections halve.
    #[inline(always)]
    pub fn converged(&mut self, fresh: bool, correction: Correction, tolerance: f64, rules: Rules) -> bool {
        let at_floor = rules.noise_floor
            && fresh
            && correction.size > 0.5 * self.smallest
            && correction.size <= NOISE_FLOOR * correction.scale;
        self.smallest = self.smallest.min(correction.size);
        // A subnormal correction has no relative precision left to gain: the unknowns have
        // decayed below the smallest normal number (a motion damped to rest).
        let underflow = correction.size < f64::MIN_POSITIVE;
        if correction.size <= tolerance * correction.scale || at_floor || underflow {
            return true;
        }
        self.keep_jacobian = rules.simplified && correction.size <= 0.5 * self.last;
        self.last = correction.size;
        false
    }
}

/// What a converged iteration reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Solution {
    /// Newton steps made (linear solves).
    pub iterations: usize,
    /// ‖F‖∞ at the solution.
    pub residual: f64,
}

/// The buffers of Newton's method for m equations: F, its Jacobian and LU factors; sized once,
/// so that the iteration allocates nothing.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(crate) struct Newton {
    residual: DVector<f64>,
    jacobian: DMatrix<f64>,
    pivots: Vec<usize>,
    /// sign det of the last factorised Jacobian.
    sign: f64,
    /// Newton steps made over the workspace's life.
    iterations: u64,
    /// When to check for interrupts between iterations (kept over solves: most take a few).
    // Wall-clock pacing, not state: a restored state starts a fresh one.
    #[serde(skip)]
    interrupt: InterruptPoll,
}

/// ‖r‖∞.
#[inline(always)]
pub(crate) fn norm(r: &[f64]) -> f64 {
    r.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

impl Newton {
    pub fn new(m: usize) -> Self {
        Newton {
            residual: DVector::zeros(m),
            jacobian: DMatrix::zeros(m, m),
            pivots: vec![0; m],
            sign: 0.0,
            iterations: 0,
            interrupt: InterruptPoll::new(),
        }
    }

    /// Resizes the buffers for m equations, keeping the count of iterations.
    pub fn resize(&mut self, m: usize) {
        *self = Newton {
            iterations: self.iterations,
            ..Newton::new(m)
        };
    }

    /// Newton steps made so far, over every solve.
    pub fn iterations(&self) -> u64 {
        self.iterations
    }

    /// F at the last iterate, for a caller that completes it.
    pub fn residual_mut(&mut self) -> &mut [f64] {
        self.residual.as_mut_slice()
    }

    /// sign det J of the last factorised Jacobian.
    pub fn jacobian_sign(&self) -> f64 {
        self.sign
    }

    /// The buffer of the Jacobian, for an iteration run outside [`Newton::solve`] (the
    /// fixed-size DEL step), which also keeps its results here with [`Newton::keep`].
    pub fn jacobian_mut(&mut self) -> &mut DMatrix<f64> {
        &mut self.jacobian
    }

    /// The last factorised Jacobian (column-major) and its pivots, for N equations, so that an
    /// iteration run outside [`Newton::solve`] starts from what it left.
    pub fn factors<const N: usize>(&self) -> ([[f64; N]; N], [usize; N]) {
        let lu = std::array::from_fn(|c| std::array::from_fn(|r| self.jacobian[(r, c)]));
        (lu, std::array::from_fn(|i| self.pivots[i]))
    }

    /// Records what an iteration run outside [`Newton::solve`] left: F at its last iterate,
    /// the last factorised Jacobian (column-major) with its pivots and determinant sign, and
    /// its Newton steps.
    pub fn keep(&mut self, residual: &[f64], lu: &[f64], pivots: &[usize], sign: f64, iterations: u64) {
        self.residual.copy_from_slice(residual);
        self.jacobian.copy_from_slice(lu);
        self.pivots.copy_from_slice(pivots);
        self.sign = sign;
        self.iterations += iterations;
    }

    /// Checks for Ctrl-C when due.
    #[inline(always)]
    pub fn poll_interrupt(&mut self) -> Result<(), StepError> {
        if self.interrupt.due() {
            check_interrupt().map_err(StepError::Interrupted)?;
        }
        Ok(())
    }

    /// Solves F(x) = 0 from the problem's current x.
    pub fn solve<P: NewtonProblem>(
        &mut self,
        problem: &mut P,
        options: &NewtonOptions,
        rules: Rules,
    ) -> Result<Solution, StepError> {
        let reasons = P::REASONS;
        problem.residual(self.residual.as_mut_slice())?;
        let mut residual = norm(self.residual.as_slice());
        if !residual.is_finite() {
            return Err(StepError::NonFinite {
                reason: reasons.non_finite_start,
            });
        }
        if problem.solved(residual) {
            return Ok(Solution {
                iterations: 0,
                residual,
            });
        }
        let mut progress = Progress::new();
        for iteration in 1..=options.max_iterations {
            self.poll_interrupt()?;
            let fresh = progress.fresh();
            if fresh {
                problem.jacobian(&mut self.jacobian)?;
                self.sign = match lu_in_place(&mut self.jacobian, &mut self.pivots) {
                    Some(sign) => sign,
                    None => {
                        return Err(StepError::Convergence {
                            residual,
                            iterations: iteration - 1,
                            reason: reasons.singular,
                        })
                    }
                };
            }
            self.iterations += 1;
            lu_solve(&self.jacobian, &self.pivots, self.residual.as_mut_slice());
            let correction = problem.correct(self.residual.as_slice());
            let converged = progress.converged(fresh, correction, options.tolerance, rules);
            if converged {
                problem.finishing();
            }
            problem.residual(self.residual.as_mut_slice())?;
            residual = norm(self.residual.as_slice());
            if !(correction.size.is_finite() && residual.is_finite()) {
                return Err(StepError::NonFinite {
                    reason: reasons.non_finite,
                });
            }
            if converged || problem.solved(residual) {
                return Ok(Solution {
                    iterations: iteration,
                    residual,
                });
            }
        }
        Err(StepError::Convergence {
            residual,
            iterations: options.max_iterations,
            reason: reasons.not_converged,
        })
    }
}

/// A failed iteration as the model layer reports it.
pub(crate) fn model_error(e: StepError) -> ModelError {
    match e {
        StepError::Model(e) | StepError::Interrupted(e) => e,
        StepError::Convergence { reason, .. }
        | StepError::NonFinite { reason }
        | StepError::SpuriousBranch { reason } => reason.into(),
        StepError::Method(e) => e.to_string().into(),
    }
}

#[cfg(test)]
mod tests {
    use super::NewtonOptions;

    #[test]
    fn the_iteration_cap_is_bounded_and_named() {
        let cap = |max_iterations| NewtonOptions {
            max_iterations,
            ..NewtonOptions::default()
        };
        assert!(cap(NewtonOptions::MAX_ITERATIONS).check().is_ok());
        for bad in [0, NewtonOptions::MAX_ITERATIONS + 1, usize::MAX] {
            let err = cap(bad).check().unwrap_err().to_string();
            assert!(err.starts_with("newton_max_iterations:"), "{err}");
        }
    }
}
