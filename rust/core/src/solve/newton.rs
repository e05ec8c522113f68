//! Newton's method for the implicit equations of every layer: the step equations of the
//! variational integrators, RATTLE's multipliers, the momentum projection onto the hidden
//! constraint, the inverse Legendre transform, the Routhian's cyclic velocities and the
//! projection onto the constraints.
//!
//! One iteration x ← x − J⁻¹F(x), with J factorised in place ([`super::lu`]) and, as an option,
//! kept while the corrections at least halve (simplified Newton). It stops on the increment,
//! ‖δ‖ ≤ tolerance·scale, when the problem declares F small enough, at the iteration cap, or at
//! the noise floor of the equations: where a Newton step with a fresh Jacobian no longer halves
//! the corrections (a stall) and F is within the noise its evaluation carries
//! ([`NewtonProblem::noise`]), x is as converged as F's evaluation allows ([`Progress`]).

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::difference;
use super::interrupt::{check_interrupt, InterruptPoll};
use super::lu::{lu_in_place, lu_solve};
use crate::error::StepError;
use crate::{Error, ModelError};

mod diagnosis;
pub(crate) mod plain;

pub(crate) use diagnosis::Reasons;
pub use diagnosis::{degenerate, Diagnosis};

/// Options of a Newton iteration.
///
/// The implicit integrators stop when ‖δ‖∞ ≤ tolerance·‖x‖∞, x the unknowns as increments from
/// q₀ (the step's δq, and the Galerkin control points' offsets), or at the noise floor of the
/// equations (their own accuracy, as when derivatives come from differences: see
/// `Progress`). The scale is the increment,
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

/// How an iteration refreshes its Jacobian.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rules {
    /// Keep the factorised Jacobian while the corrections at least halve (simplified Newton),
    /// refresh it otherwise; false: a fresh Jacobian every iteration.
    pub simplified: bool,
}

/// The size of a Newton correction and the scale the tolerance is relative to: converged when
/// size ≤ tolerance·scale (a scale of 0 leaves convergence to [`NewtonProblem::solved`] and the
/// noise floor).
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

    /// Returns x to where the iteration started, before a failure is diagnosed there
    /// ([`Diagnosis::confirmed`]): differences of F check J near the start, which a smaller step
    /// moves, and not at a far iterate of a diverged course, where a difference step relative to
    /// x spans F's curvature (and rounding of F's large values swamps them). Default: x stays
    /// at the last iterate.
    fn restart(&mut self) {}

    /// Whether the model's ∂²L/∂q̇² is nearly singular at the problem's state ([`degenerate`]):
    /// asked only to diagnose a failure. Default: not known to be.
    fn degenerate(&mut self) -> Result<bool, StepError> {
        Ok(false)
    }

    /// Whether the Jacobian the problem supplies agrees with differences of F at the current x
    /// (a model's second derivatives need not be those of its first): asked only to diagnose a
    /// failure, after [`NewtonProblem::restart`]. Default: it does (a Jacobian by differences of
    /// F agrees by construction).
    fn jacobian_agrees(&mut self) -> Result<bool, StepError> {
        Ok(true)
    }

    /// F's rounding about x measured ([`difference::measured_noise`]; F(x) = `f0`, x left as it
    /// was), for a stall above the estimated floor. Default: nothing measured.
    fn measured_noise(&mut self, _f0: &[f64]) -> Result<f64, StepError> {
        Ok(0.0)
    }

    /// Applies x ← x − δ (or the problem's own update along δ) and measures the correction.
    fn correct(&mut self, delta: &[f64]) -> Correction;

    /// The rounding of F's terms at the last [`NewtonProblem::residual`], in the max norm,
    /// where the problem knows them (the iteration adds the rounding of its terms where F is
    /// linear in x, and of the derivatives taken by differences for F,
    /// [`difference::take_noise`]). Newton's corrections fall no further than J⁻¹ of F's noise.
    fn noise(&self) -> f64;

    /// The size of what the unknowns are added to before F is evaluated (q₀ for a step's
    /// increments), or of the unknowns themselves where the corrections are measured relative to
    /// them (q̇ for the inverse Legendre transform): its rounding moves them by a few ε of it,
    /// and F by ‖J‖ times that. Default: nothing.
    fn offset(&self) -> f64 {
        0.0
    }

    /// Whether F, of norm ‖F‖∞ = `residual`, is small enough to stop at (checked at the start
    /// and after every correction). Default: never, the increment decides.
    fn solved(&self, _residual: f64) -> bool {
        false
    }

    /// Told before the evaluation of F at which the iteration may end (its correction
    /// converged, or stalled), for a problem that takes more than F from that evaluation (the
    /// DEL step: ∂L/∂t for the energy balance, which the others need not compute). Default:
    /// nothing.
    fn finishing(&mut self) {}
}

/// What an iteration's latest correction says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Judgement {
    /// Within the tolerance, or below the normal numbers.
    Converged,
    /// A correction made with a fresh Jacobian that did not halve the smallest so far: at the
    /// noise floor of F, or failing; F's noise decides ([`Progress::at_floor`]).
    Stalled,
    /// Neither: iterate on.
    Iterating,
}

/// How far F may lie above its estimated noise at a stall and count as converged: the
/// estimate bounds each difference's rounding, and a sum of several (a step's quadrature nodes)
/// adds theirs.
const NOISE_MARGIN: f64 = 4.0;

/// How closely corrections must repeat to be a cycle: Newton's map returning to where it was
/// (about a jump of F, which no iterate crosses to a root) repeats them to the rounding of the
/// iterates, or approaches the cycle geometrically; an iteration wandering outside its region
/// repeats no size to a part in a thousand twice running.
const CYCLE: f64 = 1e-3;

/// An iteration's progress, by the sizes of its corrections: whether the next step factorises
/// a fresh Jacobian, when to stop, and why it failed. Shared by [`Newton::solve`] and the
/// fixed-size DEL step, which must decide alike.
///
/// The noise floor: F evaluated in floating point (its derivatives by differences, a sum of
/// large terms, points rounded) is F plus noise of some size σ, and Newton's corrections fall
/// no further than J⁻¹σ. Where a correction made with a fresh Jacobian does not halve the
/// smallest so far (a stall), the iteration has converged if ‖F‖ is within [`NOISE_MARGIN`]σ at
/// the new iterate ([`Progress::noise`] estimates σ); a stall far above it is a failure to come
/// (of the model's smoothness, or its Jacobian). The noise of differences is not random but in
/// steps, flat or in line over several corrections, so it is bounded from the values differenced
/// rather than sampled (Moré and Wild's estimate, "Estimating computational noise", SIAM J. Sci.
/// Comput. 33, 2011, sees none along a line).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Progress {
    keep_jacobian: bool,
    first: f64,
    last: f64,
    smallest: f64,
    /// The ratio of the last two corrections made with fresh Jacobians, the ratio before it,
    /// and the last size made with one.
    fresh_ratio: f64,
    fresh_ratio_before: f64,
    last_fresh: f64,
    /// The second correction over the first, made with the first Jacobian where it is kept:
    /// Deuflhard's contraction θ₀ at the start.
    start_ratio: f64,
    stalls: usize,
    corrections: usize,
    /// ‖J‖∞ of the last fresh Jacobian: with the unknowns' size, the size of F's terms.
    jacobian_norm: f64,
}

impl Progress {
    pub fn new() -> Self {
        Progress {
            keep_jacobian: false,
            first: f64::INFINITY,
            last: f64::INFINITY,
            smallest: f64::INFINITY,
            fresh_ratio: f64::INFINITY,
            fresh_ratio_before: f64::INFINITY,
            last_fresh: f64::INFINITY,
            start_ratio: f64::NAN,
            stalls: 0,
            corrections: 0,
            jacobian_norm: 0.0,
        }
    }

    /// Whether the next Newton step factorises a fresh Jacobian.
    #[inline(always)]
    pub fn fresh(&self) -> bool {
        !self.keep_jacobian
    }

    /// Judges `correction`, made with a fresh Jacobian or a kept one, against `tolerance`; the
    /// Jacobian is kept (with `simplified`) while the corrections halve.
    #[inline(always)]
    pub fn judge(&mut self, fresh: bool, correction: Correction, tolerance: f64, simplified: bool) -> Judgement {
        let size = correction.size;
        match self.corrections {
            0 => self.first = size,
            1 => self.start_ratio = size / self.first,
            _ => {}
        }
        let stalled = fresh && size > 0.5 * self.smallest;
        self.corrections += 1;
        if fresh {
            self.fresh_ratio_before = self.fresh_ratio;
            self.fresh_ratio = size / self.last_fresh;
            self.last_fresh = size;
        }
        self.smallest = self.smallest.min(size);
        // A subnormal correction has no relative precision left to gain: the unknowns have
        // decayed below the smallest normal number (a motion damped to rest).
        if size <= tolerance * correction.scale || size < f64::MIN_POSITIVE {
            return Judgement::Converged;
        }
        self.keep_jacobian = simplified && size <= 0.5 * self.last;
        self.last = size;
        if stalled {
            self.stalls += 1;
            return Judgement::Stalled;
        }
        Judgement::Iterating
    }

    /// Records a fresh Jacobian, `jac` (n × n, column-major), before it is factorised.
    #[inline(always)]
    pub fn jacobian(&mut self, jac: &[f64], n: usize) {
        self.jacobian_norm = (0..n).fold(0.0_f64, |m, i| m.max((0..n).map(|j| jac[i + j * n].abs()).sum()));
    }

    /// F's noise σ near the last iterate: `rounding`, what the problem knows of its terms'
    /// ([`NewtonProblem::noise`]); the rounding of the derivatives taken by differences since
    /// the last call ([`difference::take_noise`]); and a few ε of ‖J‖∞ times the unknowns' size
    /// (`correction.scale`: F's terms where F is linear in x) and what they are added to
    /// (`offset`, [`NewtonProblem::offset`]).
    #[inline(always)]
    pub fn noise(&self, rounding: f64, correction: Correction, offset: f64) -> f64 {
        rounding + difference::take_noise() + 4.0 * f64::EPSILON * self.jacobian_norm * (correction.scale + offset)
    }

    /// Whether a stalled iteration, ‖F‖∞ = `residual` at its new iterate and F's noise `noise`
    /// ([`Progress::noise`]), has converged.
    #[inline(always)]
    pub fn at_floor(residual: f64, noise: f64) -> bool {
        residual <= NOISE_MARGIN * noise
    }

    /// Whether an iteration at its cap, ‖F‖∞ = `residual`, is converged at the noise measured
    /// about it ([`NewtonProblem::measured_noise`]): at that floor, and not where ∂²L/∂q̇² is
    /// nearly singular ([`NewtonProblem::degenerate`]), whose F varies on every scale a
    /// measurement takes, as rounding does.
    pub fn at_measured_floor<P: NewtonProblem>(problem: &mut P, residual: f64, noise: f64) -> Result<bool, StepError> {
        Ok(Progress::at_floor(residual, noise) && !problem.degenerate()?)
    }

    /// Why the iteration failed, having reached its cap: by the course of its corrections,
    /// the last two made with fresh Jacobians in ratio θ, and the first two in ratio θ₀.
    ///
    /// Deuflhard's contraction θ₀ = ‖Δx₁‖/‖Δx₀‖ (Newton Methods for Nonlinear Problems,
    /// Springer 2004) estimates h₀/2, h₀ = ω‖Δx₀‖ the Kantorovich quantity of the start, which
    /// falls with ‖Δx₀‖, so with the step; Newton converges from where h₀ < 2, θ₀ < 1. A course
    /// that did not contract at its start began outside that region, whatever it did after (a
    /// wander that settles far from the root); one that contracted and then stalled met F's
    /// lack of a root or of smoothness.
    pub fn diagnosis(&self) -> Diagnosis {
        let ratio = self.fresh_ratio;
        let same = |r: f64| (0.95..=1.05).contains(&r);
        let repeats = |r: f64| (r - 1.0).abs() <= CYCLE;
        if self.corrections < 2 {
            // Too few to tell.
            Diagnosis::Cap
        } else if repeats(ratio) && repeats(self.fresh_ratio_before) {
            // The same correction again and again: a cycle about a point where F jumps.
            Diagnosis::Cycle
        } else if self.start_ratio >= 1.0 {
            // No contraction from the start: outside Newton's region.
            Diagnosis::Diverged
        } else if same(ratio) && same(self.fresh_ratio_before) {
            // Contracted, then about the same size again and again: no root nearby, or flat.
            Diagnosis::Stalled
        } else if self.last > self.first / 16.0 {
            // No headway: wandering, or growing, far from a root.
            Diagnosis::Diverged
        } else if ratio <= 0.1 || self.last < 0.1 * self.last_fresh {
            // Still falling fast (quadratically, or on a kept Jacobian).
            Diagnosis::Cap
        } else if ratio < 0.95 {
            // Falling, but at a steady rate θ: J⁻¹ times the true Jacobian is not the identity.
            Diagnosis::Linear
        } else {
            Diagnosis::Stalled
        }
    }
}

/// What a converged iteration reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Solution {
    /// Newton steps made (linear solves).
    pub iterations: usize,
    /// ‖F‖∞ at the solution.
    pub residual: f64,
    /// F's noise there ([`Progress::noise`]).
    pub noise: f64,
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
        // A solve inside another's F (a Routhian's cyclic velocities, a step's q̇(q, p)) keeps
        // the differences the outer F took before it, and adds its own solution's noise.
        let outer = difference::take_noise();
        let solution = self.iterate(problem, options, rules);
        let own = solution.as_ref().map_or(0.0, |s| s.noise);
        difference::record(outer.max(own));
        solution
    }

    /// [`Newton::solve`]'s iteration.
    fn iterate<P: NewtonProblem>(
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
                noise: problem.noise() + difference::take_noise(),
            });
        }
        let mut progress = Progress::new();
        for iteration in 1..=options.max_iterations {
            self.poll_interrupt()?;
            let fresh = progress.fresh();
            if fresh {
                problem.jacobian(&mut self.jacobian)?;
                progress.jacobian(self.jacobian.as_slice(), self.jacobian.nrows());
                self.sign = match lu_in_place(&mut self.jacobian, &mut self.pivots) {
                    Some(sign) => sign,
                    None => {
                        return Err(StepError::Convergence {
                            residual,
                            iterations: iteration - 1,
                            reason: reasons.singular,
                            advice: Diagnosis::Singular.advice(&reasons),
                        })
                    }
                };
            }
            self.iterations += 1;
            lu_solve(&self.jacobian, &self.pivots, self.residual.as_mut_slice());
            let correction = problem.correct(self.residual.as_slice());
            let judgement = progress.judge(fresh, correction, options.tolerance, rules.simplified);
            if judgement != Judgement::Iterating {
                problem.finishing();
            }
            problem.residual(self.residual.as_mut_slice())?;
            residual = norm(self.residual.as_slice());
            if !(correction.size.is_finite() && residual.is_finite()) {
                return Err(StepError::NonFinite {
                    reason: reasons.non_finite,
                });
            }
            let noise = match judgement {
                Judgement::Iterating => None,
                _ => Some(progress.noise(problem.noise(), correction, problem.offset())),
            };
            let converged = match (judgement, noise) {
                (Judgement::Converged, _) => true,
                (Judgement::Stalled, Some(noise)) => Progress::at_floor(residual, noise),
                _ => false,
            };
            if converged || problem.solved(residual) {
                return Ok(Solution {
                    iterations: iteration,
                    residual,
                    noise: noise.unwrap_or_else(|| progress.noise(problem.noise(), correction, problem.offset())),
                });
            }
        }
        self.at_cap(problem, residual, &progress, options.max_iterations)
    }

    /// The iteration at its cap above the estimated floor (an iteration wandering in noise the
    /// estimate misses reads as a stall, a cycle or a slow fall): converged at the floor
    /// measured about it, else its failure diagnosed. Out of line: the rare path's code would
    /// crowd the iteration's loop and cost every solve.
    #[cold]
    #[inline(never)]
    fn at_cap<P: NewtonProblem>(
        &mut self,
        problem: &mut P,
        residual: f64,
        progress: &Progress,
        iterations: usize,
    ) -> Result<Solution, StepError> {
        let noise = problem.measured_noise(self.residual.as_slice())?;
        if Progress::at_measured_floor(problem, residual, noise)? {
            return Ok(Solution {
                iterations,
                residual,
                noise,
            });
        }
        Err(StepError::Convergence {
            residual,
            iterations,
            reason: P::REASONS.not_converged,
            advice: progress.diagnosis().confirmed(problem)?.advice(&P::REASONS),
        })
    }
}

/// A failed iteration as the model layer reports it: the model's own errors unchanged, and a
/// failure of the solve itself whole, so that the run reports it typed ([`Error::model`]).
///
/// [`Error::model`]: crate::Error::model
pub(crate) fn model_error(e: StepError) -> ModelError {
    match e {
        StepError::Model(e) | StepError::Interrupted(e) => e,
        StepError::Method(e) => e.to_string().into(),
        e => Box::new(e),
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::DMatrix;

    use super::{difference, Correction, Diagnosis, Newton, NewtonOptions, NewtonProblem, Progress, Reasons, Rules};
    use crate::error::StepError;

    /// The diagnosis of a course of corrections, each made with a fresh Jacobian or a kept one
    /// as the simplified iteration decides, none converging.
    fn diagnosed(sizes: impl IntoIterator<Item = f64>) -> Diagnosis {
        let mut progress = Progress::new();
        for size in sizes {
            let fresh = progress.fresh();
            progress.judge(fresh, Correction { size, scale: 0.0 }, 1e-14, true);
        }
        progress.diagnosis()
    }

    #[test]
    fn a_cycle_about_a_jump_is_a_kink_whatever_its_start() {
        // V = 5|q| from rest at its kink: x = 0 → −a → a → −a …, corrections a, 2a, 2a, …
        // (θ₀ = 2: the start never contracted, but the iteration repeats itself).
        let a = 2.5e-6;
        assert_eq!(diagnosed([a].into_iter().chain([2.0 * a; 20])), Diagnosis::Cycle);
    }

    #[test]
    fn a_start_that_never_contracted_is_outside_newtons_region_however_the_course_ends() {
        // Issue 64's stall at ‖F‖ = 0.19 on a circle: a first correction of 112, then one 4 750
        // times larger, halving back to about 1 and wandering there; the last two ratios
        // within 5 % of 1 read as a kink.
        let halving = (0..18).map(|k| 5.3e5 * 0.5_f64.powi(k));
        let wander = [1.72, 0.9965, 1.011, 0.983];
        let course = [111.7].into_iter().chain(halving).chain(wander);
        assert_eq!(diagnosed(course), Diagnosis::Diverged);
    }

    #[test]
    fn a_course_that_contracted_is_told_by_how_it_ends() {
        // Quadratic convergence to 1e-4 of the first correction, then about the same size again.
        let stall = (0..10).map(|k| if k % 2 == 0 { 1.02e-4 } else { 0.99e-4 });
        assert_eq!(
            diagnosed([1.0, 1e-2, 1e-4].into_iter().chain(stall)),
            Diagnosis::Stalled
        );
        assert_eq!(diagnosed((0..30).map(|k| (2.0_f64 / 3.0).powi(k))), Diagnosis::Linear);
        assert_eq!(diagnosed([1.0, 1e-3, 1e-6]), Diagnosis::Cap);
    }

    /// F(x) = atan x with J = `gain`/(1 + x²) (1: exact), whose Newton iteration converges to
    /// 0 from |x₀| < 1.39 and diverges from beyond.
    struct Atan {
        x: f64,
        guess: f64,
        gain: f64,
    }

    impl NewtonProblem for Atan {
        const REASONS: Reasons = Reasons {
            singular: "singular",
            non_finite_start: "non-finite start",
            non_finite: "non-finite",
            not_converged: "not converged",
            outside: "outside",
        };

        fn residual(&mut self, r: &mut [f64]) -> Result<(), StepError> {
            r[0] = self.x.atan();
            Ok(())
        }

        fn jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<(), StepError> {
            jac[(0, 0)] = self.gain / (1.0 + self.x * self.x);
            Ok(())
        }

        fn restart(&mut self) {
            self.x = self.guess;
        }

        fn jacobian_agrees(&mut self) -> Result<bool, StepError> {
            let x = self.x;
            let h = difference::step(difference::unit(0, x));
            let differenced = ((x + h).atan() - (x - h).atan()) / (2.0 * h);
            let exact = self.gain / (1.0 + x * x);
            Ok((exact - differenced).abs() <= 1e-4 * differenced.abs())
        }

        /// Measured as a step's increments are: absolute, against |x|.
        fn correct(&mut self, delta: &[f64]) -> Correction {
            self.x -= delta[0];
            Correction {
                size: delta[0].abs(),
                scale: self.x.abs(),
            }
        }

        fn noise(&self) -> f64 {
            0.0
        }
    }

    /// The advice of Newton's failure on [`Atan`] from x₀ within `cap` iterations.
    fn atan_advice(x0: f64, gain: f64, cap: usize) -> &'static str {
        let mut problem = Atan { x: x0, guess: x0, gain };
        let options = NewtonOptions {
            max_iterations: cap,
            ..NewtonOptions::default()
        };
        match Newton::new(1).solve(&mut problem, &options, Rules { simplified: false }) {
            Err(StepError::Convergence { advice, .. }) => advice,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_diverged_course_checks_its_jacobian_at_the_start_where_differences_are_a_check() {
        // From x₀ = 2 the iterates grow to −2.3e10 in five corrections, where atan(x ± h)
        // differ by a few units in the last place of π/2: J would disagree there. At x₀ it
        // agrees.
        assert_eq!(atan_advice(2.0, 1.0, 5), Atan::REASONS.outside);
        // A Jacobian 0.4 of the true one grows by 1.5 from any start: it disagrees at the start.
        assert_eq!(atan_advice(0.01, 0.4, 8), Diagnosis::Linear.advice(&Atan::REASONS));
    }

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
