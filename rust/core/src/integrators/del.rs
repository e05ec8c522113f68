use nalgebra::{DMatrix, DVector};

use super::StepError;
use crate::discrete::{DiscreteLagrangian, Workspace};
use crate::model::finite_difference::NOISE_FLOOR;
use crate::model::Lagrangian;
use crate::ModelError;

/// Options of the Newton iteration that solves the discrete Euler–Lagrange equations.
///
/// The iteration stops when ‖δ‖∞ ≤ tolerance·(1 + ‖q₁‖∞), or when a Newton step with a freshly
/// computed Jacobian no longer halves a correction that is already below √ε (the equations'
/// own accuracy when derivatives come from differences).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    /// Stop when the correction satisfies ‖δ‖∞ ≤ tolerance·(1 + ‖q₁‖∞).
    pub tolerance: f64,
    /// Give up (a convergence error) after this many iterations.
    pub max_iterations: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            tolerance: 1e-14,
            max_iterations: 50,
        }
    }
}

/// The variational integrator of a discrete Lagrangian L_d in position–momentum form: from
/// (q₀, p₀), solve p₀ + D₁L_d(q₀, q₁) + f_d⁻ = 0 for q₁ by Newton's method, then
/// p₁ = D₂L_d(q₀, q₁) + f_d⁺ (the forced DEL equations of the discrete Lagrange–d'Alembert
/// principle; f_d^± = (h/2)f(q̄, v, t + h/2) at the midpoint q̄ = q₀ + δq/2, v = δq/h, and zero
/// for unforced systems). The work of the forces, f(q̄, v)·δq a step, is accumulated.
///
/// The unknown is the increment δq = q₁ − q₀, and p₁ − p₀ is formed as D₁L_d + D₂L_d minus the
/// final residual, so that both increments keep their own relative precision for the
/// compensated summation of the driver (HLW VIII.5): round-off then does not grow with |q| and
/// |p|, and Noether momenta stay conserved to round-off.
///
/// The Jacobian ∂D₁L_d/∂q₁ comes from central differences of D₁L_d, is factorised once a step
/// and kept while the iteration contracts by at least half per step (simplified Newton),
/// refreshed otherwise. The predictor extrapolates the last two increments.
#[derive(Clone, Debug)]
pub struct Del<R> {
    rule: R,
    options: NewtonOptions,
    ws: Workspace,
    dq: Vec<f64>,
    residual: DVector<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    jacobian: DMatrix<f64>,
    pivots: Vec<usize>,
    last_dq: Vec<f64>,
    before_last_dq: Vec<f64>,
    /// How many previous increments the predictor has (0, 1 or 2).
    history: usize,
    evaluations: u64,
    iterations: u64,
    forcing: Forcing,
    work: f64,
}

/// The generalized force at a step's midpoint, f(q₀ + δq/2, δq/h, t + h/2), with its buffers.
#[derive(Clone, Debug)]
struct Forcing {
    mid: Vec<f64>,
    vel: Vec<f64>,
    f: Vec<f64>,
}

impl Forcing {
    fn evaluate<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        dq: &[f64],
        t: f64,
        h: f64,
    ) -> Result<&[f64], ModelError> {
        for (((m, v), q), d) in self.mid.iter_mut().zip(self.vel.iter_mut()).zip(q0).zip(dq) {
            *m = q + 0.5 * d;
            *v = d / h;
        }
        sys.force(&self.mid, &self.vel, t + 0.5 * h, &mut self.f)?;
        Ok(&self.f)
    }
}

/// Writes D₁L_d(q₀, q₀ + δq) + f_d⁻ into `out`: the left side of the forced DEL equations, less p₀.
#[allow(clippy::too_many_arguments)]
fn equations<R: DiscreteLagrangian, S: Lagrangian + ?Sized>(
    rule: &R,
    sys: &S,
    q0: &[f64],
    dq: &[f64],
    t: f64,
    h: f64,
    out: &mut [f64],
    ws: &mut Workspace,
    forcing: &mut Forcing,
) -> Result<(), ModelError> {
    rule.d1(sys, q0, dq, t, h, out, ws)?;
    if sys.is_forced() {
        let f = forcing.evaluate(sys, q0, dq, t, h)?;
        out.iter_mut().zip(f).for_each(|(o, f)| *o += 0.5 * h * f);
    }
    Ok(())
}

impl<R: DiscreteLagrangian> Del<R> {
    pub fn new(rule: R, n: usize, options: NewtonOptions) -> Self {
        Del {
            rule,
            options,
            ws: Workspace::new(n),
            dq: vec![0.0; n],
            residual: DVector::zeros(n),
            plus: vec![0.0; n],
            minus: vec![0.0; n],
            jacobian: DMatrix::zeros(n, n),
            pivots: vec![0; n],
            last_dq: vec![0.0; n],
            before_last_dq: vec![0.0; n],
            history: 0,
            evaluations: 0,
            iterations: 0,
            forcing: Forcing {
                mid: vec![0.0; n],
                vel: vec![0.0; n],
                f: vec![0.0; n],
            },
            work: 0.0,
        }
    }

    /// The work done by the generalized forces so far, Σ f(q̄, v)·δq.
    pub fn work(&self) -> f64 {
        self.work
    }

    /// Evaluations of D₁L_d or D₂L_d made so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Newton iterations made so far.
    pub fn iterations(&self) -> u64 {
        self.iterations
    }

    pub(super) fn reset(&mut self) {
        self.history = 0;
    }

    /// residual = p₀ + D₁L_d(q₀, q₀ + δq) + f_d⁻; returns ‖residual‖∞.
    fn residual<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        p0: &[f64],
        t: f64,
        h: f64,
    ) -> Result<f64, StepError> {
        self.evaluations += 1;
        equations(
            &self.rule,
            sys,
            q0,
            &self.dq,
            t,
            h,
            self.residual.as_mut_slice(),
            &mut self.ws,
            &mut self.forcing,
        )?;
        let mut norm = 0.0_f64;
        for (r, p) in self.residual.iter_mut().zip(p0) {
            *r += p;
            norm = norm.max(r.abs());
        }
        Ok(norm)
    }

    /// ∂(D₁L_d + f_d⁻)/∂q₁ at q₁ = q₀ + δq by central differences, factorised in place.
    fn factorise_jacobian<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        t: f64,
        h: f64,
    ) -> Result<bool, StepError> {
        let cbrt_eps = f64::EPSILON.cbrt();
        for j in 0..self.dq.len() {
            let d = self.dq[j];
            let e = cbrt_eps * (q0[j] + d).abs().max(1.0);
            self.dq[j] = d + e;
            equations(
                &self.rule,
                sys,
                q0,
                &self.dq,
                t,
                h,
                &mut self.plus,
                &mut self.ws,
                &mut self.forcing,
            )?;
            self.dq[j] = d - e;
            equations(
                &self.rule,
                sys,
                q0,
                &self.dq,
                t,
                h,
                &mut self.minus,
                &mut self.ws,
                &mut self.forcing,
            )?;
            self.dq[j] = d;
            self.evaluations += 2;
            for (i, (a, b)) in self.plus.iter().zip(&self.minus).enumerate() {
                self.jacobian[(i, j)] = (a - b) / (2.0 * e);
            }
        }
        Ok(lu_in_place(&mut self.jacobian, &mut self.pivots))
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn increment<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        q: &[f64],
        p: &[f64],
        h: f64,
        dq: &mut [f64],
        dp: &mut [f64],
    ) -> Result<(), StepError> {
        // Predictor: extrapolate the last two increments (second order), the last one, or rest.
        for ((x, d1), d0) in self.dq.iter_mut().zip(&self.last_dq).zip(&self.before_last_dq) {
            *x = match self.history {
                0 => 0.0,
                1 => *d1,
                _ => 2.0 * d1 - d0,
            };
        }
        let mut residual = self.residual(sys, q, p, t, h)?;
        if !residual.is_finite() {
            return Err(StepError::NonFinite {
                reason: "the implicit equations are non-finite at the predictor",
            });
        }
        // Simplified Newton: the factorised Jacobian is kept while the corrections shrink by at
        // least half an iteration, and refreshed otherwise.
        let mut keep_jacobian = false;
        let mut last_correction = f64::INFINITY;
        for iteration in 1..=self.options.max_iterations {
            let fresh = !keep_jacobian;
            if fresh && !self.factorise_jacobian(sys, q, t, h)? {
                let reason = "the Jacobian ∂D₁L_d/∂q₁ is singular";
                return Err(StepError::Convergence {
                    residual,
                    iterations: iteration - 1,
                    reason,
                });
            }
            self.iterations += 1;
            lu_solve(&self.jacobian, &self.pivots, &mut self.residual);
            let mut correction = 0.0_f64;
            let mut scale = 1.0_f64;
            for ((x, d), q0) in self.dq.iter_mut().zip(self.residual.iter()).zip(q) {
                *x -= d;
                correction = correction.max(d.abs());
                scale = scale.max((q0 + *x).abs());
            }
            residual = self.residual(sys, q, p, t, h)?;
            if !(correction.is_finite() && residual.is_finite()) {
                let reason = "the implicit equations became non-finite (Newton's method or the solution diverged)";
                return Err(StepError::NonFinite { reason });
            }
            let contracting = correction <= 0.5 * last_correction;
            // Converged: at the tolerance, or at the noise floor of the equations (derivatives
            // by differences are accurate to about 1e-10), where even a fresh Newton step no
            // longer contracts.
            let at_floor = fresh && !contracting && correction <= NOISE_FLOOR * scale;
            if correction <= self.options.tolerance * scale || at_floor {
                return self.finish(sys, t, q, h, dq, dp);
            }
            keep_jacobian = contracting;
            last_correction = correction;
        }
        let reason = "Newton's method did not converge";
        Err(StepError::Convergence {
            residual,
            iterations: self.options.max_iterations,
            reason,
        })
    }

    /// The increments once δq is found: p₁ − p₀ = D₁L_d + D₂L_d + f_d⁻ + f_d⁺ − residual, since
    /// the last residual evaluation left p₀ + D₁L_d + f_d⁻ in `self.residual`.
    #[allow(clippy::too_many_arguments)]
    fn finish<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        q: &[f64],
        h: f64,
        dq: &mut [f64],
        dp: &mut [f64],
    ) -> Result<(), StepError> {
        self.evaluations += 1;
        self.rule.momentum_change(sys, q, &self.dq, t, h, dp, &mut self.ws)?;
        for (d, r) in dp.iter_mut().zip(self.residual.iter()) {
            *d -= r;
        }
        if sys.is_forced() {
            // f_d⁻ + f_d⁺ = h·f(q̄, v); the work of the step, f·δq.
            let f = self.forcing.evaluate(sys, q, &self.dq, t, h)?;
            let mut work = 0.0;
            for ((d, f), x) in dp.iter_mut().zip(f).zip(&self.dq) {
                *d += h * f;
                work += f * x;
            }
            self.work += work;
        }
        dq.copy_from_slice(&self.dq);
        std::mem::swap(&mut self.before_last_dq, &mut self.last_dq);
        self.last_dq.copy_from_slice(dq);
        self.history = (self.history + 1).min(2);
        Ok(())
    }
}

/// LU factorisation with partial pivoting, in place (L below the diagonal with unit diagonal,
/// U on and above it); `pivots[i]` is the row swapped into row i. Returns false for a singular
/// matrix. Written out because nalgebra's `LU` allocates its permutation on every
/// factorisation, and the Newton loop must not allocate.
fn lu_in_place(a: &mut DMatrix<f64>, pivots: &mut [usize]) -> bool {
    let n = a.nrows();
    for k in 0..n {
        let piv = k + a.view_range(k.., k).iamax();
        pivots[k] = piv;
        if a[(piv, k)] == 0.0 {
            return false;
        }
        a.swap_rows(k, piv);
        let inv = 1.0 / a[(k, k)];
        for i in k + 1..n {
            a[(i, k)] *= inv;
            let l = a[(i, k)];
            for j in k + 1..n {
                a[(i, j)] -= l * a[(k, j)];
            }
        }
    }
    true
}

/// Solves A x = b in place with the factors of [`lu_in_place`].
fn lu_solve(lu: &DMatrix<f64>, pivots: &[usize], b: &mut DVector<f64>) {
    for (k, &piv) in pivots.iter().enumerate() {
        b.swap_rows(k, piv);
    }
    lu.solve_lower_triangular_with_diag_mut(b, 1.0);
    lu.solve_upper_triangular_mut(b);
}
