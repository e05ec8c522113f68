use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::checkpoint::derived::{same, Reached};
use super::{Increment, StepError, StepStart};
use crate::error::SHAKE_UNCONVERGED;
use crate::model::{HolonomicConstraints, MechanicalSystem};
use crate::solve::interrupt::{check_interrupt, InterruptPoll};
use crate::solve::lu::{lu_in_place, lu_solve};
use crate::solve::newton::{Correction, Diagnosis, Newton, NewtonOptions, NewtonProblem, Reasons, Rules};
use crate::ModelError;

/// RATTLE (Andersen 1983; HLW VII.1.4) for H = ½pᵀM⁻¹p + V(q) on g(q) = 0:
///
/// p½ = p₀ − (h/2)(∇V(q₀) + G(q₀)ᵀλ),   q₁ = q₀ + hM⁻¹p½,   g(q₁) = 0,
/// p₁ = p½ − (h/2)(∇V(q₁) + G(q₁)ᵀμ),   G(q₁)M⁻¹p₁ = 0.
///
/// Symmetric, symplectic on the constraint manifold, order 2: the variational integrator of
/// the trapezoidal L_d with the constraints. λ is found by Newton's method with the exact
/// Jacobian −(h²/2)G(q₁)M⁻¹G(q₀)ᵀ, to the Newton tolerance; μ from the linear hidden
/// constraint. SHAKE (Ryckaert, Ciccotti & Berendsen 1977) solves g(q₁) = 0 one constraint at
/// a time until |g|∞ ≤ tolerance and keeps p₁ = p½ − (h/2)∇V(q₁), off the hidden constraint.
/// Compositions apply the step with the fractions γ of a symmetric composition.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Rattle {
    shake: bool,
    gamma: Vec<f64>,
    options: NewtonOptions,
    /// ∇V and G at the step's start; at its end once it is taken (first same as last).
    grad0: Vec<f64>,
    grad1: Vec<f64>,
    jac0: DMatrix<f64>,
    jac1: DMatrix<f64>,
    cached: bool,
    /// M⁻¹G(q₀)ᵀ (n × m), and a row of G as a contiguous vector.
    minv_jac0t: DMatrix<f64>,
    minv_jac1t: DMatrix<f64>,
    row: Vec<f64>,
    column: Vec<f64>,
    half: Vec<f64>,
    q1: Vec<f64>,
    q_stage: Vec<f64>,
    p_stage: Vec<f64>,
    dq_stage: Vec<f64>,
    dp_stage: Vec<f64>,
    lambda: Vec<f64>,
    newton: Newton,
    /// g(q₁) for SHAKE; μ for RATTLE's projection, with G(q₁)M⁻¹G(q₁)ᵀ and its LU factors.
    g: DVector<f64>,
    gram: DMatrix<f64>,
    pivots: Vec<usize>,
    evaluations: u64,
    /// SHAKE's sweeps.
    sweeps: u64,
    /// When SHAKE checks for interrupts between sweeps.
    // Wall-clock pacing, not state: a restored state starts a fresh one.
    #[serde(skip)]
    interrupt: InterruptPoll,
    /// The tangent map's copy of the buffers, made at its first use; not state.
    #[serde(skip)]
    scratch: Option<Box<Rattle>>,
}

impl Rattle {
    /// RATTLE (or SHAKE) composed with the fractions `gamma` (`[1.0]` for the plain step), for
    /// n coordinates and m constraints.
    pub fn new(shake: bool, gamma: Vec<f64>, options: NewtonOptions, n: usize, m: usize) -> Self {
        Rattle {
            shake,
            gamma,
            options,
            grad0: vec![0.0; n],
            grad1: vec![0.0; n],
            jac0: DMatrix::zeros(m, n),
            jac1: DMatrix::zeros(m, n),
            cached: false,
            minv_jac0t: DMatrix::zeros(n, m),
            minv_jac1t: DMatrix::zeros(n, m),
            row: vec![0.0; n],
            column: vec![0.0; n],
            half: vec![0.0; n],
            q1: vec![0.0; n],
            q_stage: vec![0.0; n],
            p_stage: vec![0.0; n],
            dq_stage: vec![0.0; n],
            dp_stage: vec![0.0; n],
            lambda: vec![0.0; m],
            newton: Newton::new(m),
            g: DVector::zeros(m),
            gram: DMatrix::zeros(m, m),
            pivots: vec![0; m],
            evaluations: 0,
            sweeps: 0,
            interrupt: InterruptPoll::new(),
            scratch: None,
        }
    }

    /// Sizes the buffers for m constraints (allocating only when m changes).
    pub(super) fn size_for(&mut self, m: usize) {
        let n = self.q1.len();
        if self.lambda.len() != m {
            *self = Rattle::new(self.shake, std::mem::take(&mut self.gamma), self.options, n, m);
        }
    }

    /// Gradient evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Newton (RATTLE) or sweep (SHAKE) iterations so far.
    pub fn iterations(&self) -> u64 {
        self.newton.iterations() + self.sweeps
    }

    /// The options of the Newton iteration.
    pub(super) fn options(&self) -> NewtonOptions {
        self.options
    }

    pub(super) fn reset(&mut self) {
        self.cached = false;
    }

    /// Why a decoded step's cache is not its own (see `checkpoint/derived.rs`), if it is not:
    /// ∇V and G at its last step's end q₁, evaluated again there, q₁ the state's q to
    /// round-off.
    pub(super) fn misfit(
        &self,
        sys: &dyn MechanicalSystem,
        constraints: &dyn HolonomicConstraints,
        at: &Reached<'_>,
    ) -> Option<String> {
        if !self.cached {
            return None;
        }
        if !at.holds(&self.q1) {
            return Some(
                "its last step's end, where its force and constraint Jacobian were cached, is not at its state's q"
                    .to_string(),
            );
        }
        let (mut grad, mut jac) = (vec![0.0; self.grad0.len()], self.jac0.clone());
        let evaluated = sys.gradient(&self.q1, &mut grad).is_ok() && constraints.jacobian(&self.q1, &mut jac).is_ok();
        (!(evaluated && same(&grad, &self.grad0) && same(jac.as_slice(), self.jac0.as_slice())))
            .then(|| "its cached force or constraint Jacobian is not the model's at its last step's end".to_string())
    }

    /// One composed step's increments from (q, p) (the system is autonomous: t is not read).
    pub(super) fn increment<S, C>(
        &mut self,
        sys: &S,
        constraints: &C,
        start: StepStart<'_>,
        out: Increment<'_>,
    ) -> Result<(), StepError>
    where
        S: MechanicalSystem + ?Sized,
        C: HolonomicConstraints + ?Sized,
    {
        let StepStart { q, p, h, .. } = start;
        let Increment { dq, dp } = out;
        dq.fill(0.0);
        dp.fill(0.0);
        for stage in 0..self.gamma.len() {
            for (((qs, ps), (q, p)), (dq, dp)) in self
                .q_stage
                .iter_mut()
                .zip(self.p_stage.iter_mut())
                .zip(q.iter().zip(p))
                .zip(dq.iter().zip(dp.iter()))
            {
                *qs = q + dq;
                *ps = p + dp;
            }
            // The stage's start is lent to the step, which writes every other buffer.
            let (q_stage, p_stage) = (std::mem::take(&mut self.q_stage), std::mem::take(&mut self.p_stage));
            let result = self.step(sys, constraints, &q_stage, &p_stage, self.gamma[stage] * h);
            (self.q_stage, self.p_stage) = (q_stage, p_stage);
            result?;
            for (d, s) in dq.iter_mut().zip(&self.dq_stage) {
                *d += s;
            }
            for (d, s) in dp.iter_mut().zip(&self.dp_stage) {
                *d += s;
            }
        }
        Ok(())
    }

    /// M⁻¹Gᵀ (n × m) of G (m × n), column by column.
    fn minv_transpose<S: MechanicalSystem + ?Sized>(
        sys: &S,
        jac: &DMatrix<f64>,
        row: &mut [f64],
        column: &mut [f64],
        out: &mut DMatrix<f64>,
    ) {
        for k in 0..jac.nrows() {
            row.iter_mut().zip(jac.row(k).iter()).for_each(|(r, g)| *r = *g);
            sys.mass().velocity(row, column);
            out.column_mut(k).copy_from_slice(column);
        }
    }

    /// One RATTLE (or SHAKE) step of size h from (q0, p0) into (dq_stage, dp_stage).
    fn step<S, C>(&mut self, sys: &S, constraints: &C, q0: &[f64], p0: &[f64], h: f64) -> Result<(), StepError>
    where
        S: MechanicalSystem + ?Sized,
        C: HolonomicConstraints + ?Sized,
    {
        self.begin(sys, constraints, q0, p0, h)?;
        let scale = q0.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        // The predictor is the last step's λ (a force, smooth in time); 0 after a reset.
        if !self.cached {
            self.lambda.fill(0.0);
        }
        if self.shake {
            position(q0, h, &self.column, &self.minv_jac0t, &self.lambda, &mut self.q1);
            self.shake(constraints, h)?;
        } else {
            let mut multipliers = PositionConstraint {
                constraints,
                q0,
                h,
                drift: &self.column,
                minv_jac0t: &self.minv_jac0t,
                jac1: &mut self.jac1,
                lambda: &mut self.lambda,
                q1: &mut self.q1,
                scale,
            };
            let rules = Rules { simplified: false };
            self.newton.solve(&mut multipliers, &self.options, rules)?;
        }
        self.end(sys, constraints, q0, p0, h)
    }

    /// The step's start: ∇V and G at q₀ (kept from the last step's end where it ended there),
    /// M⁻¹G₀ᵀ, and the unconstrained drift M⁻¹(p₀ − (h/2)∇V₀) in `column`.
    fn begin<S, C>(&mut self, sys: &S, constraints: &C, q0: &[f64], p0: &[f64], h: f64) -> Result<(), StepError>
    where
        S: MechanicalSystem + ?Sized,
        C: HolonomicConstraints + ?Sized,
    {
        if !self.cached {
            sys.gradient(q0, &mut self.grad0)?;
            constraints.jacobian(q0, &mut self.jac0)?;
            self.evaluations += 1;
        }
        Self::minv_transpose(sys, &self.jac0, &mut self.row, &mut self.column, &mut self.minv_jac0t);
        // The unconstrained drift q̃ = q₀ + hM⁻¹(p₀ − (h/2)∇V₀); then q₁ = q̃ − (h²/2)M⁻¹G₀ᵀλ.
        for ((hf, p), g) in self.half.iter_mut().zip(p0).zip(&self.grad0) {
            *hf = p - 0.5 * h * g;
        }
        sys.mass().velocity(&self.half, &mut self.column);
        Ok(())
    }

    /// The step's end from its multipliers λ: (dq_stage, dp_stage), with μ putting p₁ on the
    /// hidden constraint (RATTLE), and ∇V, G at q₁ kept for the next step.
    fn end<S, C>(&mut self, sys: &S, constraints: &C, q0: &[f64], p0: &[f64], h: f64) -> Result<(), StepError>
    where
        S: MechanicalSystem + ?Sized,
        C: HolonomicConstraints + ?Sized,
    {
        // δp = −(h/2)(∇V₀ + G₀ᵀλ) so far, p½ = p₀ + δp, δq = hM⁻¹p½.
        for (j, (d, hf)) in self.dp_stage.iter_mut().zip(self.half.iter_mut()).enumerate() {
            *d = -0.5
                * h
                * (self.grad0[j]
                    + (0..self.lambda.len())
                        .map(|k| self.jac0[(k, j)] * self.lambda[k])
                        .sum::<f64>());
            *hf = p0[j] + *d;
        }
        sys.mass().velocity(&self.half, &mut self.column);
        for (d, v) in self.dq_stage.iter_mut().zip(&self.column) {
            *d = h * v;
        }
        for (x, (q, d)) in self.q1.iter_mut().zip(q0.iter().zip(&self.dq_stage)) {
            *x = q + d;
        }
        sys.gradient(&self.q1, &mut self.grad1)?;
        constraints.jacobian(&self.q1, &mut self.jac1)?;
        self.evaluations += 1;
        // p̂ = p½ − (h/2)∇V₁; RATTLE projects it: p₁ = p̂ − (h/2)G₁ᵀμ with G₁M⁻¹p₁ = 0.
        for ((hf, d), g) in self.half.iter_mut().zip(self.dp_stage.iter_mut()).zip(&self.grad1) {
            *hf -= 0.5 * h * g;
            *d -= 0.5 * h * g;
        }
        let m = self.lambda.len();
        // μ goes to `g`, and is 0 for SHAKE, which does not project the momenta.
        self.g.fill(0.0);
        if !self.shake && m > 0 {
            Self::minv_transpose(sys, &self.jac1, &mut self.row, &mut self.column, &mut self.minv_jac1t);
            product(&mut self.gram, 0.5 * h, &self.jac1, &self.minv_jac1t);
            sys.mass().velocity(&self.half, &mut self.column);
            for k in 0..m {
                self.g[k] = self.jac1.row(k).iter().zip(&self.column).map(|(a, b)| a * b).sum();
            }
            if lu_in_place(&mut self.gram, &mut self.pivots).is_none() {
                return Err(StepError::Convergence {
                    residual: self.g.amax(),
                    iterations: 0,
                    reason: "G(q₁)M⁻¹G(q₁)ᵀ is singular: the constraints are not independent here",
                    advice: Diagnosis::Singular.advice(&PositionConstraint::<C>::REASONS),
                });
            }
            lu_solve(&self.gram, &self.pivots, self.g.as_mut_slice());
        }
        // δp = p₁ − p₀ as the sum of the kicks, free of cancellation.
        for (j, d) in self.dp_stage.iter_mut().enumerate() {
            *d -= 0.5 * h * (0..m).map(|k| self.jac1[(k, j)] * self.g[k]).sum::<f64>();
        }
        std::mem::swap(&mut self.grad0, &mut self.grad1);
        std::mem::swap(&mut self.jac0, &mut self.jac1);
        self.cached = true;
        Ok(())
    }

    /// The plain RATTLE step's map at multipliers λ = `x` from `start`, for its tangent map: the
    /// position constraints g(q₁(λ)) into `out[..m]`, then the end q₁ and p₁ (n each), from a
    /// scratch copy of the step's buffers (the step's own cache stays as it is).
    pub(super) fn step_map<S, C>(
        &mut self,
        (sys, constraints): (&S, &C),
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError>
    where
        S: MechanicalSystem + ?Sized,
        C: HolonomicConstraints + ?Sized,
    {
        let (n, m) = (start.q.len(), x.len());
        let scratch = self
            .scratch
            .get_or_insert_with(|| Box::new(Rattle::new(false, vec![1.0], self.options, n, m)));
        scratch.cached = false;
        let (q0, p0, h) = (start.q, start.p, start.h);
        let step = |s: &mut Rattle| -> Result<(), StepError> {
            s.begin(sys, constraints, q0, p0, h)?;
            s.lambda.copy_from_slice(x);
            s.end(sys, constraints, q0, p0, h)
        };
        step(scratch).map_err(|e| -> ModelError {
            match e {
                StepError::Model(source) => source,
                StepError::Convergence { reason, .. } => reason.into(),
                _ => "the tangent map: RATTLE's step from a nearby state failed".into(),
            }
        })?;
        let (g, end) = out.split_at_mut(m);
        let (q1, p1) = end.split_at_mut(n);
        q1.iter_mut()
            .zip(q0.iter().zip(&scratch.dq_stage))
            .for_each(|(a, (q, d))| *a = q + d);
        p1.iter_mut()
            .zip(p0.iter().zip(&scratch.dp_stage))
            .for_each(|(a, (p, d))| *a = p + d);
        constraints.residual(q1, g)
    }

    /// The last step's multipliers λ (the plain RATTLE step's, for its tangent map).
    pub(super) fn multipliers(&self) -> &[f64] {
        &self.lambda
    }

    /// SHAKE: sweeps until |g(q₁)|∞ ≤ tolerance, at most `max_iterations` of them (the residual
    /// after the last judged too, so that no failure reports a residual within tolerance). A
    /// failure whose sweeps were still bringing the residual down (the last one to its smallest
    /// yet, below the residual halfway) wants more of them; one whose residual no longer fell
    /// (it grew, or wandered) has a step that moves the constraints beyond SHAKE's linearization
    /// at q₀, which a smaller step mends, as at hω of order 1 on a pendulum, where 10⁴ sweeps
    /// fail as 50 do.
    fn shake<C: HolonomicConstraints + ?Sized>(&mut self, constraints: &C, h: f64) -> Result<(), StepError> {
        let mut sweeps = 0;
        let (mut halfway, mut smallest) = (f64::INFINITY, f64::INFINITY);
        loop {
            if self.interrupt.due() {
                check_interrupt().map_err(StepError::Interrupted)?;
            }
            constraints.residual(&self.q1, self.g.as_mut_slice())?;
            let residual = self.g.amax();
            if !residual.is_finite() {
                return Err(StepError::NonFinite {
                    reason: "the constraints became non-finite",
                });
            }
            if residual <= self.options.tolerance {
                return Ok(());
            }
            if sweeps == self.options.max_iterations / 2 {
                halfway = residual;
            }
            if sweeps == self.options.max_iterations {
                let falling = residual < halfway && residual <= smallest;
                return Err(StepError::Convergence {
                    residual,
                    iterations: sweeps,
                    reason: SHAKE_UNCONVERGED,
                    advice: if falling {
                        // SHAKE's sweeps converge linearly at a rate the constraints' coupling sets, not h.
                        "more sweeps help (newton_max_iterations), or rattle, whose Newton iteration converges \
                         quadratically"
                    } else {
                        "the sweeps no longer brought the residual down: the step moves the constraints too far \
                         from their linearization at its start; a smaller step (dt) helps, or rattle"
                    },
                });
            }
            smallest = smallest.min(residual);
            sweeps += 1;
            self.sweeps += 1;
            // The sweep moves q₁ with each multiplier it changes.
            self.shake_sweep(constraints, h)?;
        }
    }

    /// One SHAKE sweep: each constraint in turn, λₖ −= gₖ(q₁)/(−(h²/2)Gₖ(q₁)·M⁻¹Gₖ(q₀)ᵀ), with
    /// q₁ moved after each.
    fn shake_sweep<C: HolonomicConstraints + ?Sized>(&mut self, constraints: &C, h: f64) -> Result<(), StepError> {
        let c = 0.5 * h * h;
        for k in 0..self.lambda.len() {
            constraints.jacobian(&self.q1, &mut self.jac1)?;
            constraints.residual(&self.q1, self.g.as_mut_slice())?;
            let slope: f64 = -c
                * (0..self.q1.len())
                    .map(|i| self.jac1[(k, i)] * self.minv_jac0t[(i, k)])
                    .sum::<f64>();
            let delta = self.g[k] / slope;
            self.lambda[k] -= delta;
            for i in 0..self.q1.len() {
                self.q1[i] += c * self.minv_jac0t[(i, k)] * delta;
            }
        }
        Ok(())
    }
}

/// out = αAB, a column at a time. Not `gemm`: nalgebra hands products of dynamic matrices
/// larger than 5 × 5 to matrixmultiply, which allocates its packing buffers on every call
/// (three times a step on a chain of eight links). The sums are `gemm`'s own below that
/// size, term by term in the same order, so small systems step bit for bit as before. Terms
/// with a zero factor of B are skipped: B is M⁻¹Gᵀ, and a constraint moves few coordinates
/// (four of a chain's 2N), which makes this as fast as matrixmultiply on long chains.
fn product(out: &mut DMatrix<f64>, alpha: f64, a: &DMatrix<f64>, b: &DMatrix<f64>) {
    let (m, n) = a.shape();
    let (a, b, out) = (a.as_slice(), b.as_slice(), out.as_mut_slice());
    for (column, b) in out.chunks_exact_mut(m).zip(b.chunks_exact(n)) {
        column.fill(0.0);
        for (a, &factor) in a.chunks_exact(m).zip(b) {
            if factor == 0.0 {
                continue;
            }
            for (y, &x) in column.iter_mut().zip(a) {
                *y += alpha * x * factor;
            }
        }
    }
}

/// q₁ = q₀ + h·q̇ − (h²/2)M⁻¹G(q₀)ᵀλ, q̇ = M⁻¹(p₀ − (h/2)∇V₀) the unconstrained drift.
fn position(q0: &[f64], h: f64, drift: &[f64], minv_jac0t: &DMatrix<f64>, lambda: &[f64], q1: &mut [f64]) {
    let c = 0.5 * h * h;
    for (i, x) in q1.iter_mut().enumerate() {
        *x = q0[i] + h * drift[i] - c * (0..lambda.len()).map(|k| minv_jac0t[(i, k)] * lambda[k]).sum::<f64>();
    }
}

/// g(q₁(λ)) = 0 for RATTLE's multipliers λ, with the exact Jacobian −(h²/2)G(q₁)M⁻¹G(q₀)ᵀ.
struct PositionConstraint<'a, C: ?Sized> {
    constraints: &'a C,
    q0: &'a [f64],
    h: f64,
    /// M⁻¹(p₀ − (h/2)∇V₀).
    drift: &'a [f64],
    minv_jac0t: &'a DMatrix<f64>,
    jac1: &'a mut DMatrix<f64>,
    lambda: &'a mut [f64],
    q1: &'a mut [f64],
    /// max(‖q₀‖∞, 1), the scale of the corrections of q₁.
    scale: f64,
}

impl<C: HolonomicConstraints + ?Sized> NewtonProblem for PositionConstraint<'_, C> {
    const REASONS: Reasons = Reasons {
        singular: "G(q₁)M⁻¹G(q₀)ᵀ is singular: the constraints are not independent here",
        non_finite_start: "the constraints became non-finite",
        non_finite: "the constraints became non-finite",
        not_converged: "RATTLE's Newton iteration for the multipliers did not converge",
        outside: "the step's drift ends too far from the constraints for Newton's iteration: a smaller step \
                  (dt) brings it nearer",
    };

    fn residual(&mut self, r: &mut [f64]) -> Result<(), StepError> {
        position(self.q0, self.h, self.drift, self.minv_jac0t, self.lambda, self.q1);
        Ok(self.constraints.residual(self.q1, r)?)
    }

    fn jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<(), StepError> {
        self.constraints.jacobian(self.q1, self.jac1)?;
        product(jac, -0.5 * self.h * self.h, self.jac1, self.minv_jac0t);
        Ok(())
    }

    /// The correction measured as the move of q₁, (h²/2)M⁻¹G(q₀)ᵀδλ, against max(‖q₀‖∞, 1).
    fn correct(&mut self, delta: &[f64]) -> Correction {
        let c = 0.5 * self.h * self.h;
        for (l, d) in self.lambda.iter_mut().zip(delta) {
            *l -= d;
        }
        let mut size = 0.0_f64;
        for i in 0..self.q1.len() {
            let shift: f64 = (0..delta.len()).map(|k| self.minv_jac0t[(i, k)] * delta[k]).sum();
            size = size.max((c * shift).abs());
        }
        Correction {
            size,
            scale: self.scale,
        }
    }

    /// The constraints hold to round-off.
    fn solved(&self, residual: f64) -> bool {
        residual <= self.noise()
    }

    fn noise(&self) -> f64 {
        4.0 * f64::EPSILON
    }
}
