//! The DEL step of a two-point rule on N ≤ 4 coordinates, without constraints or forces, in a
//! loop of fixed-size arrays: [`Del::increment`]'s arithmetic in its order (the same bits,
//! tests/rust/bits.rs), with the state, the unknowns, F and the LU factors on the stack and
//! every length known to the compiler. On a double pendulum the general step's runtime lengths,
//! calls and buffers cost more than the model's own arithmetic (issue 15).

use super::{correct, finite_jacobian, rounding, segment, Constraints, Del, Equations, TwoPoint, REASONS};
use crate::discrete::{DiscreteLagrangian, Workspace};
use crate::integrators::clear::Clear;
use crate::integrators::del::StepEquations;
use crate::integrators::stepper::{array, Phase};
use crate::integrators::{StepError, StepStart};
use crate::model::Lagrangian;
use crate::solve::difference;
use crate::solve::lu::{factorise, substitute};
use crate::solve::newton::{norm, Diagnosis, Judgement, NewtonProblem, Progress};
use crate::Error;

impl<R: DiscreteLagrangian> Del<TwoPoint<R>> {
    /// The unconstrained step's equations at the unknowns `x`, counted in `evaluations`: for
    /// the Jacobian where the model gives no second derivatives, and a failure's diagnosis
    /// (started from `guess`).
    fn unconstrained<'a, S: Lagrangian + ?Sized>(
        &'a mut self,
        sys: &'a S,
        start: StepStart<'a>,
        (x, guess): (&'a mut [f64], Option<&'a [f64]>),
        evaluations: &'a mut u64,
    ) -> Equations<'a, TwoPoint<R>, S> {
        Equations {
            scheme: &mut self.scheme,
            sys,
            constraints: Constraints::None,
            start,
            m: 0,
            multipliers: &mut self.multipliers,
            block: &mut self.block,
            x,
            guess,
            plus: &mut self.plus,
            minus: &mut self.minus,
            evaluations,
        }
    }

    /// The iteration at its cap above the estimated floor: converged (Ok) at the floor
    /// measured about x (ws restored at x after), as [`crate::solve::newton::Newton::solve`]
    /// judges it, else its failure diagnosed. Out of line: the rare path's code would crowd
    /// the loop's registers and cost every step (6% of a double pendulum's instructions).
    #[cold]
    #[inline(never)]
    fn at_cap<S: Lagrangian + ?Sized, const N: usize>(
        &mut self,
        sys: &S,
        start: StepStart<'_>,
        (x, ws): (&mut [f64; N], &mut Workspace<[f64; N]>),
        cap: Cap<'_, N>,
        evaluations: &mut u64,
    ) -> Result<(), StepError> {
        let (r, residual) = cap.residual;
        let (mut plus, mut minus) = ([0.0; N], [0.0; N]);
        let sizes = (norm(x), norm(start.q));
        let noise = difference::measured_noise(r, (&mut plus, &mut minus), sizes, |shift, out| {
            *evaluations += 1;
            let at: [f64; N] = std::array::from_fn(|i| x[i] + shift);
            self.scheme.equations_in(ws, sys, start, &at, out)
        })?;
        let equations = &mut self.unconstrained(sys, start, (x, None), evaluations);
        if Progress::at_measured_floor(equations, residual, noise)? {
            return Ok(());
        }
        let equations = &mut self.unconstrained(sys, start, (x, Some(cap.guess)), evaluations);
        let diagnosis = cap.progress.diagnosis().confirmed(equations)?;
        Err(StepError::Convergence {
            residual,
            iterations: self.options.max_iterations,
            reason: REASONS.not_converged,
            advice: diagnosis.advice(&REASONS),
        })
    }

    /// Whether [`Del::run`] takes the next steps of `sys`: no constraints and no forces, and
    /// the run's first step made (which judges the continuum limit's determinant sign).
    pub(in crate::integrators) fn runs_fixed<S: Lagrangian + ?Sized>(&self, sys: &S) -> bool {
        self.m == 0 && self.continuum_sign != 0.0 && !sys.is_forced()
    }

    /// `steps` steps of N coordinates, as [`Del::increment`] makes them when
    /// [`Del::runs_fixed`] holds. The Jacobian is [`Equations`]' own (exact, or by differences
    /// for a model without second derivatives), factorised on the stack.
    pub(in crate::integrators) fn run<S: Lagrangian + ?Sized, const N: usize, C: Clear + ?Sized>(
        &mut self,
        sys: &S,
        phase: Phase<'_>,
        steps: usize,
        clear: &mut C,
    ) -> Result<bool, Error> {
        let h = phase.clock.h;
        let (mut last, mut before_last, mut history) =
            (array(&self.last_dq), array(&self.before_last_dq), self.history);
        // The last step's unknowns, F and factorised Jacobian, kept for the Newton workspace.
        let (lu, pivots) = self.newton.factors::<N>();
        let mut kept = (
            array(&self.x),
            array(self.newton.residual_mut()),
            lu,
            pivots,
            self.newton.jacobian_sign(),
        );
        // Counts in locals, written back once.
        let (mut evaluations, mut iterations) = (self.evaluations, 0);
        let options = self.options;
        // Extrapolates the last two increments (second order), the last one, or rest.
        let predictor = |last: &[f64; N], before_last: &[f64; N], history: usize| -> [f64; N] {
            std::array::from_fn(|i| match history {
                0 => 0.0,
                1 => last[i],
                _ => 2.0 * last[i] - before_last[i],
            })
        };
        let increment = |t: f64, q: &[f64; N], p: &[f64; N], dq: &mut [f64; N], dp: &mut [f64; N]| {
            let start = StepStart { t, h, q, p };
            // The differences' rounding from this step's evaluations alone (Progress::noise).
            difference::take_noise();
            // The Newton iteration's values are the closure's own, so that they may stay in
            // registers: through memory, scalar stores feeding vector loads stall.
            let mut x = predictor(&last, &before_last, history);
            let (mut r, mut lu, mut pivots, mut sign) = ([0.0; N], [[0.0; N]; N], [0; N], 0.0);
            let mut ws = Workspace::<[f64; N]>::default();
            evaluations += 1;
            self.scheme.equations_in(&mut ws, sys, start, &x, &mut r)?;
            let mut residual = norm(&r);
            if !residual.is_finite() {
                return Err(StepError::NonFinite {
                    reason: REASONS.non_finite_start,
                });
            }
            let mut progress = Progress::new();
            let mut iteration = 0;
            loop {
                if iteration == options.max_iterations {
                    let guess = predictor(&last, &before_last, history);
                    let at_cap = Cap {
                        residual: (&r, residual),
                        progress: &progress,
                        guess: &guess,
                    };
                    self.at_cap(sys, start, (&mut x, &mut ws), at_cap, &mut evaluations)?;
                    break;
                }
                iteration += 1;
                self.newton.poll_interrupt()?;
                let fresh = progress.fresh();
                if fresh {
                    let exact =
                        self.scheme
                            .quadrature()
                            .jacobian_into(sys, segment(&start, &x), lu.as_flattened_mut(), N)?;
                    if exact {
                        finite_jacobian(lu.as_flattened())?;
                    } else {
                        let mut jacobian = std::mem::take(self.newton.jacobian_mut());
                        let differenced = self
                            .unconstrained(sys, start, (&mut x, None), &mut evaluations)
                            .jacobian(&mut jacobian);
                        *self.newton.jacobian_mut() = jacobian;
                        differenced?;
                        lu.as_flattened_mut()
                            .copy_from_slice(self.newton.jacobian_mut().as_slice());
                    }
                    progress.jacobian(lu.as_flattened(), N);
                    sign = factorise(lu.as_flattened_mut(), &mut pivots, N).ok_or_else(|| StepError::Convergence {
                        residual,
                        iterations: iteration - 1,
                        reason: REASONS.singular,
                        advice: Diagnosis::Singular.advice(&REASONS),
                    })?;
                }
                iterations += 1;
                substitute(lu.as_flattened(), &pivots, &mut r, N);
                let correction = correct(&mut x, &r, 0, h);
                let judgement = progress.judge(fresh, correction, options.tolerance, true);
                if judgement != Judgement::Iterating {
                    ws.keep_dl_dt();
                }
                evaluations += 1;
                self.scheme.equations_in(&mut ws, sys, start, &x, &mut r)?;
                residual = norm(&r);
                if !(correction.size.is_finite() && residual.is_finite()) {
                    return Err(StepError::NonFinite {
                        reason: REASONS.non_finite,
                    });
                }
                let converged = match judgement {
                    Judgement::Converged => true,
                    Judgement::Stalled => {
                        Progress::at_floor(residual, progress.noise(rounding(p), correction, norm(q)))
                    }
                    Judgement::Iterating => false,
                };
                if converged {
                    break;
                }
            }
            self.same_branch(sign)?;
            evaluations += 1;
            // No force here, but L may depend on t: its ∂L_d/∂t is the energy the step puts in.
            self.work += self.scheme.momentum_change_in(&mut ws, sys, start, &x, &r, dp)?;
            *dq = x;
            (before_last, last) = (last, x);
            history = (history + 1).min(2);
            kept = (x, r, lu, pivots, sign);
            Ok(())
        };
        let result = phase.run::<N, _, C>(steps, increment, clear);
        self.last_dq.copy_from_slice(&last);
        self.before_last_dq.copy_from_slice(&before_last);
        self.history = history;
        self.evaluations = evaluations;
        let (x, r, lu, pivots, sign) = kept;
        self.x.copy_from_slice(&x);
        self.newton.keep(&r, lu.as_flattened(), &pivots, sign, iterations);
        result
    }
}

/// What [`Del::at_cap`] judges: F at x and its norm, the iteration's course, and the step's
/// predictor (where a diagnosis starts).
struct Cap<'a, const N: usize> {
    residual: (&'a [f64; N], f64),
    progress: &'a Progress,
    guess: &'a [f64; N],
}
