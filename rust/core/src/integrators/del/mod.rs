//! The discrete Euler–Lagrange (DEL) equations of one step, solved by Newton's method: the
//! solver [`Del`], the equations of the two-point rules ([`TwoPoint`]) and of the Galerkin
//! integrators, and the constrained DEL equations.

use serde::{Deserialize, Serialize};
mod composed;
mod constrained;
mod fixed;
mod galerkin;
mod history;
mod nonholonomic;
mod two_point;

pub use composed::Composed;
pub(in crate::integrators) use nonholonomic::DiscreteConstraint;

pub(in crate::integrators) use history::check_delays;
pub use two_point::TwoPoint;

use nalgebra::DMatrix;

use super::checkpoint::derived::{same, Reached};
use super::{Dynamics, Increment, StepError, StepStart};
use crate::discrete::Quadrature;
use crate::discrete::Segment;
use crate::model::{HolonomicConstraints, Lagrangian, VelocityConstraints};
use crate::solve::difference::{self, central_jacobian, Evaluations};
use crate::solve::lu::lu_in_place;
use crate::solve::newton::{degenerate, norm, Correction, Newton, NewtonProblem, Reasons, Rules};
use crate::solve::NewtonOptions;
use crate::ModelError;
use constrained::{constrained_equations, Multipliers, Parts};

/// The implicit equations of one step of a variational integrator. The unknowns x are the
/// increments from q₀ of every point the step solves for, n at a time; the last n are
/// δq = q₁ − q₀. Solving for increments keeps their own relative precision for the driver's
/// compensated summation (HLW VIII.5).
pub trait StepEquations {
    /// Number of unknowns for n coordinates.
    fn unknowns(&self, n: usize) -> usize;

    /// Writes F(x) into `out`; F = 0 at the step's solution.
    fn equations<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError>;

    /// Writes p₁ − p₀ at the solution x (F(x) = `residual`) into `dp`, in a form free of
    /// cancellation, and returns the work of the non-conservative forces over the step.
    fn momentum_change<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        start: StepStart<'_>,
        x: &[f64],
        residual: &[f64],
        dp: &mut [f64],
    ) -> Result<f64, ModelError>;

    /// The predictor of all unknowns from a predicted increment δq.
    fn predict(&self, dq: &[f64], x: &mut [f64]);

    /// The quadrature that defines the scheme's L_d.
    fn quadrature(&mut self) -> &mut Quadrature;

    /// Told before the evaluation of F at which Newton's iteration ends
    /// (`NewtonProblem::finishing`). Default: nothing.
    fn finishing(&mut self) {}
}

/// The discrete Lagrangian's segment of a step whose unknowns are `x`.
fn segment<'a>(start: &StepStart<'a>, x: &'a [f64]) -> Segment<'a> {
    Segment {
        q0: start.q,
        dq: x,
        t: start.t,
        h: start.h,
    }
}

/// The constraints a step holds to.
#[derive(Clone, Copy)]
pub(in crate::integrators) enum Constraints<'a> {
    None,
    /// g(q) = 0: the constrained DEL equations.
    Holonomic(&'a dyn HolonomicConstraints),
    /// A(q)q̇ = 0: the discrete Lagrange–d'Alembert equations, with the discrete constraint
    /// where it says (at the midpoint, reversible, unless a method asks otherwise).
    Velocity(&'a dyn VelocityConstraints, DiscreteConstraint),
    /// g(q) = 0 and A(q)q̇ + b(q) = 0 together: the discrete Lagrange–d'Alembert equations
    /// with both sets of multipliers, the holonomic rows first (g(q₁) = 0, then the velocity
    /// constraints' discrete constraint), the constraint matrix stacked [G; A].
    Mixed(
        &'a dyn HolonomicConstraints,
        &'a dyn VelocityConstraints,
        DiscreteConstraint,
    ),
}

impl Constraints<'_> {
    /// Writes the constraint matrix at q into `out`: G(q) = ∂g/∂q, A(q), or [G(q); A(q)]
    /// (assembled in `parts`); nothing without constraints.
    fn matrix(&self, q: &[f64], out: &mut DMatrix<f64>, parts: &mut Parts) -> Result<(), ModelError> {
        match self {
            Constraints::None => Ok(()),
            Constraints::Holonomic(c) => c.jacobian(q, out),
            Constraints::Velocity(c, _) => c.matrix(q, out),
            Constraints::Mixed(g, a, _) => {
                let k = g.count();
                g.jacobian(q, &mut parts.holonomic)?;
                a.matrix(q, &mut parts.velocity)?;
                out.rows_mut(0, k).copy_from(&parts.holonomic);
                out.rows_mut(k, a.count()).copy_from(&parts.velocity);
                Ok(())
            }
        }
    }

    /// Writes the affine term b(q) of velocity constraints A(q)q̇ + b(q) = 0 into `out`: 0 for
    /// holonomic (their hidden constraint is G(q)q̇ = 0) and linear velocity constraints, and
    /// for the holonomic rows of mixed ones.
    fn offset(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        match self {
            Constraints::Velocity(c, _) => c.offset(q, out),
            Constraints::Mixed(g, c, _) => {
                let (holonomic, velocity) = out.split_at_mut(g.count());
                holonomic.fill(0.0);
                c.offset(q, velocity)
            }
            Constraints::None | Constraints::Holonomic(_) => {
                out.fill(0.0);
                Ok(())
            }
        }
    }

    /// Number of constraints m (of both kinds).
    fn count(&self) -> usize {
        match self {
            Constraints::None => 0,
            Constraints::Holonomic(c) => c.count(),
            Constraints::Velocity(c, _) => c.count(),
            Constraints::Mixed(g, c, _) => g.count() + c.count(),
        }
    }

    /// Number of holonomic constraints among them.
    fn holonomic_count(&self) -> usize {
        match self {
            Constraints::Holonomic(c) | Constraints::Mixed(c, _, _) => c.count(),
            Constraints::None | Constraints::Velocity(..) => 0,
        }
    }
}

/// A variational integrator that solves its step's implicit equations (a [`StepEquations`]) by
/// Newton's method.
///
/// The Jacobian comes from the model's exact second derivatives or from central differences of
/// the equations, is factorised and kept while the iteration contracts by at least half per
/// step (simplified Newton), refreshed otherwise. The iteration stops on the increment (see
/// [`NewtonOptions`]) or at the noise floor of the equations. The predictor extrapolates the
/// last two increments. p₁ − p₀ is formed by the scheme free of cancellation, so that Noether
/// momenta stay conserved to round-off.
/// On up to 4 coordinates, without constraints or forces, the stepper runs the two-point rules'
/// steps in a loop of fixed-size arrays (`Del::run`, in `fixed.rs`): the same arithmetic and bits.
///
///
/// A step whose Jacobian at the solution has the opposite determinant sign to the continuum
/// limit ([`Quadrature`]) has crossed a fold of the DEL map: beyond it the
/// equations have several solutions (for the midpoint rule once h²λ/4 > 1 for an unstable
/// eigenvalue λ of −M⁻¹∂²L/∂q², e.g. h ≥ 2 at the top of the pendulum) and Newton may settle
/// on a spurious one. Such a step is refused as [`StepError::SpuriousBranch`].
///
/// With holonomic constraints g(q) = 0 (m of them) the unknowns grow by multipliers λ, and the
/// step solves the constrained DEL equations (Marsden & West 2001, §3.4; RATTLE for separable
/// systems and the trapezoidal L_d):
///
/// p₀ + D₁L_d(q₀, q₁) − (h/2)G(q₀)ᵀλ = 0,   g(q₁) = 0,   p₁ = D₂L_d(q₀, q₁) − (h/2)G(q₁)ᵀμ,
///
/// with μ such that the velocity q̇(q₁, p₁) of the inverse Legendre transform is tangent,
/// G(q₁)q̇ = 0 (Newton's method on μ, from differences of the Legendre transform).
///
/// With velocity constraints A(q)q̇ = 0 (nonholonomic; m of them) and the midpoint rule, the
/// step solves a reversible discrete Lagrange–d'Alembert (DLA) system in position–momentum form,
/// with the discrete constraint at the midpoint as McLachlan & Perlmutter (2006) impose it for
/// their reversible integrators, and the constraint forces shared by the step's ends as RATTLE
/// shares them:
///
/// p₀ + D₁L_d(q₀, q₁) − (h/2)A(q₀)ᵀλ = 0,   A(q̄)(q₁ − q₀) + h b(q̄) = 0,   q̄ = (q₀ + q₁)/2,
/// p₁ = D₂L_d(q₀, q₁) − (h/2)A(q₁)ᵀμ,   A(q₁)q̇(q₁, p₁) + b(q₁) = 0,
///
/// b the affine term of affine constraints A(q)q̇ + b(q) = 0 (0 for linear ones).
///
/// It is symmetric: from (q₁, p₁) with −h it steps back to (q₀, p₀), λ and μ trading places
/// (the discrete constraint changes sign as a whole under δq ↦ −δq, h ↦ −h, b included), so
/// reversible systems keep a bounded energy error. Affine constraints are not reversible
/// under p ↦ −p alone (the moving surface does not reverse): the turntable's ball is
/// reversible under p ↦ −p with a mirror of the plane, which turns the table back. Forces A(q̄)ᵀλ at the midpoint on both
/// halves would be symmetric too, but would leave A(q₁)q̇₁ = O(h²); with μ the momenta stay on
/// the constraint to round-off at every step, as the constrained DEL equations keep them on
/// the hidden one. Where A = G is the derivative of holonomic constraints the two methods
/// differ only in the discrete constraint (A(q̄)δq = 0 here, g(q₁) = 0 there). (The paper's
/// text was not at hand when this was written: the midpoint discrete constraint follows its
/// abstract and the issue; the placement of the forces is this method's own choice, for the
/// round-off constraint residuals, and its reversibility is checked by the bounded energy of
/// the sleigh and the disk in the tests.)
///
/// With holonomic constraints g(q) = 0 beside the velocity constraints (a rolling body whose
/// contact is held on a surface; [`crate::model::Mixed`]) the step takes both sets of
/// multipliers, the forces (h/2)[G; A]ᵀλ at q₀ and (h/2)[G; A]ᵀμ at q₁ of the stacked
/// constraint matrix:
///
/// p₀ + D₁L_d(q₀, q₁) − (h/2)\[G; A\](q₀)ᵀλ = 0,   g(q₁) = 0,   A(q̄)(q₁ − q₀) + h b(q̄) = 0,
/// p₁ = D₂L_d(q₀, q₁) − (h/2)\[G; A\](q₁)ᵀμ,   \[G; A\](q₁)q̇(q₁, p₁) + [0; b(q₁)] = 0,
///
/// the constrained DEL equations (RATTLE's discrete constraint g(q₁) = 0) and the reversible
/// DLA step at once: as symmetric as each, so that [`super::Method::Dla4`] composes it to
/// order 4 (measured in tests/rust/mixed_constraints.rs, with the closed form of a skate on an
/// incline).
///
/// With the discrete constraint at the step's start instead, A(q₀)(q₁ − q₀) = 0
/// ([`super::Method::CortesMartinez`]), the step is Cortés & Martínez's (2001) discrete
/// Lagrange–d'Alembert integrator: its DEL equations in (qₖ₋₁, qₖ, qₖ₊₁) are
/// D₂L_d + D₁L_d = (h/2)A(qₖ)ᵀ(μₖ + λₖ), the one force at qₖ split between two steps, so
/// putting pₖ on the constraint moves no position. It is not symmetric (order 1): the contrast
/// McLachlan & Perlmutter (2006) draw, whose energy drifts on reversible systems where the
/// reversible step's stays bounded (measured in tests/rust/nonholonomic_variants.rs).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Del<Sc> {
    scheme: Sc,
    options: NewtonOptions,
    /// Number of constraints m; the unknowns are (λ, the scheme's).
    m: usize,
    multipliers: Multipliers,
    x: Vec<f64>,
    /// x at the step's start (the predictor), where a failure is diagnosed
    /// ([`NewtonProblem::restart`]); scratch, refilled every step.
    #[serde(skip)]
    guess: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    newton: Newton,
    /// sign det ∂F/∂x as h → 0 at the run's first state; 0 until computed.
    continuum_sign: f64,
    hessian: DMatrix<f64>,
    hessian_pivots: Vec<usize>,
    /// The scheme's own Jacobian (u × u), for the exact Jacobian with velocity constraints.
    block: DMatrix<f64>,
    velocity: Vec<f64>,
    predicted: Vec<f64>,
    last_dq: Vec<f64>,
    before_last_dq: Vec<f64>,
    /// How many previous increments the predictor has (0, 1 or 2).
    history: usize,
    evaluations: u64,
    work: f64,
}

impl<Sc: StepEquations> Del<Sc> {
    pub fn new(scheme: Sc, n: usize, options: NewtonOptions) -> Self {
        let m = scheme.unknowns(n);
        Del {
            scheme,
            options,
            m: 0,
            multipliers: Multipliers::new(n, 0, 0),
            x: vec![0.0; m],
            guess: Vec::new(),
            plus: vec![0.0; m],
            minus: vec![0.0; m],
            newton: Newton::new(m),
            continuum_sign: 0.0,
            hessian: DMatrix::zeros(n, n),
            hessian_pivots: vec![0; n],
            block: DMatrix::zeros(m, m),
            velocity: vec![0.0; n],
            predicted: vec![0.0; n],
            last_dq: vec![0.0; n],
            before_last_dq: vec![0.0; n],
            history: 0,
            evaluations: 0,
            work: 0.0,
        }
    }

    /// Evaluations of the step's equations so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Newton iterations made so far.
    pub fn iterations(&self) -> u64 {
        self.newton.iterations()
    }

    /// The energy put in so far: the generalized forces' work, less Σ∂L_d/∂t.
    pub fn work(&self) -> f64 {
        self.work
    }

    /// The options of the Newton iteration.
    pub(in crate::integrators) fn options(&self) -> NewtonOptions {
        self.options
    }

    /// Why a decoded step's derived values are not its own (see `checkpoint/derived.rs`), if
    /// they are not: its continuum sign ±1 (0 before the run's first step), and the constraint
    /// matrix it cached at its last step's end q₁ (first same as last), evaluated again there,
    /// q₁ the state's q to round-off.
    pub(in crate::integrators) fn misfit(&self, model: &dyn Dynamics, at: &Reached<'_>) -> Option<String> {
        if ![-1.0, 0.0, 1.0].contains(&self.continuum_sign) {
            return Some(format!("its continuum sign is {:?}, not ±1 or 0", self.continuum_sign));
        }
        let mp = &self.multipliers;
        let constraints = match (model.holonomic(), model.velocity_constraints()) {
            _ if !mp.cached || mp.g0.nrows() == 0 => return None,
            (Some(g), Some(a)) => Constraints::Mixed(g, a, DiscreteConstraint::Midpoint),
            (Some(g), None) => Constraints::Holonomic(g),
            (None, Some(a)) => Constraints::Velocity(a, DiscreteConstraint::Midpoint),
            (None, None) => return None,
        };
        if !at.holds(&mp.q1) {
            return Some(
                "its last step's end, where its constraint matrix was cached, is not at its state's q".to_string(),
            );
        }
        let (mut matrix, mut parts) = (mp.g0.clone(), mp.parts.clone());
        let evaluated = constraints.matrix(&mp.q1, &mut matrix, &mut parts).is_ok();
        (!(evaluated && same(matrix.as_slice(), mp.g0.as_slice())))
            .then(|| "its cached constraint matrix is not the model's at its last step's end".to_string())
    }

    pub(in crate::integrators) fn reset(&mut self) {
        self.history = 0;
        self.continuum_sign = 0.0;
        self.x[..self.m].fill(0.0);
        self.multipliers.cached = false;
    }

    /// Sizes the buffers for m constraints, `holonomic` of them holonomic (allocating only
    /// when they change).
    pub(in crate::integrators) fn size_for(&mut self, n: usize, m: usize, holonomic: usize) {
        if m == self.m && holonomic == self.multipliers.holonomic() {
            return;
        }
        let total = self.scheme.unknowns(n) + m;
        self.m = m;
        self.multipliers = Multipliers::new(n, m, holonomic);
        self.block = DMatrix::zeros(total - m, total - m);
        self.x = vec![0.0; total];
        self.plus = vec![0.0; total];
        self.minus = vec![0.0; total];
        self.newton.resize(total);
    }

    /// sign det ∂²L/∂q̇² at (q, q̇(q, p), t), by central differences of ∂L/∂q̇: the regularity
    /// of L, against which the DEL Jacobian's sign is judged.
    fn hessian_sign<S: Lagrangian + ?Sized>(&mut self, sys: &S, start: StepStart<'_>) -> Result<f64, StepError> {
        let StepStart { t, q, p, .. } = start;
        let n = q.len();
        sys.velocity(q, p, t, &mut self.velocity)?;
        let at = Evaluations {
            plus: &mut self.plus[..n],
            minus: &mut self.minus[..n],
        };
        let dl_dv = |v: &[f64], out: &mut [f64]| sys.dl_dv(q, v, t, out);
        central_jacobian(dl_dv, &mut self.velocity, difference::unit, at, &mut self.hessian)?;
        lu_in_place(&mut self.hessian, &mut self.hessian_pivots).ok_or_else(|| {
            StepError::Model("∂²L/∂q̇² is singular at the initial state: the Lagrangian is not regular".into())
        })
    }

    /// The increments of one step from `start`, on the constraints if any.
    pub(in crate::integrators) fn increment<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        constraints: Constraints<'_>,
        start: StepStart<'_>,
        out: Increment<'_>,
    ) -> Result<(), StepError> {
        let n = start.q.len();
        self.size_for(n, constraints.count(), constraints.holonomic_count());
        let m = self.m;
        if !self.multipliers.cached {
            let Multipliers { g0, parts, .. } = &mut self.multipliers;
            constraints.matrix(start.q, g0, parts)?;
        }
        if self.continuum_sign == 0.0 {
            let hessian_sign = self.hessian_sign(sys, start)?;
            self.continuum_sign = self.scheme.quadrature().continuum_sign(n, hessian_sign);
        }
        // Predictor: extrapolate the last two increments (second order), the last one, or rest.
        for ((x, d1), d0) in self.predicted.iter_mut().zip(&self.last_dq).zip(&self.before_last_dq) {
            *x = match self.history {
                0 => 0.0,
                1 => *d1,
                _ => 2.0 * d1 - d0,
            };
        }
        // The multipliers keep the last step's values: a force, smooth in time.
        self.scheme.predict(&self.predicted, &mut self.x[m..]);
        self.guess.clear();
        self.guess.extend_from_slice(&self.x);
        let mut equations = Equations {
            scheme: &mut self.scheme,
            sys,
            constraints,
            start,
            m,
            multipliers: &mut self.multipliers,
            block: &mut self.block,
            x: &mut self.x,
            guess: Some(&self.guess),
            plus: &mut self.plus,
            minus: &mut self.minus,
            evaluations: &mut self.evaluations,
        };
        self.newton
            .solve(&mut equations, &self.options, Rules { simplified: true })?;
        // The fold test knows the unconstrained equations' continuum limit only.
        if m == 0 {
            self.same_branch(self.newton.jacobian_sign())?;
        }
        self.finish(sys, constraints, start, out)
    }

    /// The unknowns of the last unconstrained step, as Newton's method left them at its
    /// solution: the increments from q₀ of every point the step solved for, δq last.
    pub(in crate::integrators) fn solution(&self) -> &[f64] {
        &self.x[self.m..]
    }

    /// The unconstrained step's map at unknowns `x` from `start`, without the run's
    /// bookkeeping (work, predictor, history): its equations F(x) into `out[..u]`, then its end
    /// q₁ = q₀ + δq and p₁ = p₀ + δp (n each). At the solution F = 0, and the linearization of
    /// (F, q₁, p₁) in (x, q₀, p₀) gives the step's tangent map ([`crate::integrators::Tangent`]).
    pub(in crate::integrators) fn step_map<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        let n = start.q.len();
        let (residual, end) = out.split_at_mut(x.len());
        let (q1, p1) = end.split_at_mut(n);
        self.scheme.equations(sys, start, x, residual)?;
        self.scheme.momentum_change(sys, start, x, residual, p1)?;
        p1.iter_mut().zip(start.p).for_each(|(p1, p0)| *p1 += p0);
        let dq = &x[x.len() - n..];
        q1.iter_mut()
            .zip(start.q.iter().zip(dq))
            .for_each(|(q1, (q0, d))| *q1 = q0 + d);
        Ok(())
    }

    /// Refuses a solution whose Jacobian's determinant has the sign `sign`, opposite to the
    /// continuum limit's: beyond a fold of the DEL map.
    #[inline(always)]
    fn same_branch(&self, sign: f64) -> Result<(), StepError> {
        if sign != self.continuum_sign {
            return Err(StepError::SpuriousBranch {
                reason: "the step's solution lies beyond a fold of the discrete Euler–Lagrange map \
                         (the Jacobian's determinant changed sign from its continuum limit), where \
                         the equations have several solutions and Newton's may be spurious",
            });
        }
        Ok(())
    }

    /// The increments once the step is solved.
    fn finish<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        constraints: Constraints<'_>,
        start: StepStart<'_>,
        mut out: Increment<'_>,
    ) -> Result<(), StepError> {
        self.evaluations += 1;
        let (n, m) = (start.q.len(), self.m);
        let u = self.x.len() - m;
        let residual = self.newton.residual_mut();
        // The scheme's own residual: its last block holds (h/2)G(q₀)ᵀλ at the solution.
        for j in (0..n).filter(|_| m > 0) {
            let force: f64 = (0..m).map(|k| self.multipliers.g0[(k, j)] * self.x[k]).sum();
            residual[u - n + j] += 0.5 * start.h * force;
        }
        self.work += self
            .scheme
            .momentum_change(sys, start, &self.x[m..], &residual[..u], out.dp)?;
        crate::solve::copy(out.dq, &self.x[self.x.len() - n..]);
        if m > 0 {
            self.multipliers
                .project_momentum(sys, constraints, start, &mut out, &self.options)?;
        }
        std::mem::swap(&mut self.before_last_dq, &mut self.last_dq);
        crate::solve::copy(&mut self.last_dq, out.dq);
        self.history = (self.history + 1).min(2);
        Ok(())
    }
}

/// A step's equations F(x) = 0 as Newton's method sees them: x = (λ, the scheme's unknowns).
struct Equations<'a, Sc, S: ?Sized> {
    scheme: &'a mut Sc,
    sys: &'a S,
    constraints: Constraints<'a>,
    start: StepStart<'a>,
    /// Number of constraints.
    m: usize,
    multipliers: &'a mut Multipliers,
    block: &'a mut DMatrix<f64>,
    x: &'a mut [f64],
    /// x where the iteration started, for a failure's diagnosis.
    guess: Option<&'a [f64]>,
    plus: &'a mut [f64],
    minus: &'a mut [f64],
    evaluations: &'a mut u64,
}

/// Why a step's Newton iteration failed.
const REASONS: Reasons = Reasons {
    singular: "the Jacobian of the step's equations is singular (∂²L/∂q̇² is not invertible here, or the \
               step lies at a fold of the discrete map, which a smaller step avoids)",
    non_finite_start: "the implicit equations are non-finite at the predictor",
    non_finite: "the implicit equations became non-finite (Newton's method or the solution diverged)",
    not_converged: "Newton's method did not converge",
    outside: "the step's predictor lies outside the region where Newton's iteration converges: a smaller step \
              (dt) brings it closer",
};

impl<Sc: StepEquations, S: Lagrangian + ?Sized> NewtonProblem for Equations<'_, Sc, S> {
    const REASONS: Reasons = REASONS;

    fn residual(&mut self, r: &mut [f64]) -> Result<(), StepError> {
        *self.evaluations += 1;
        let mp = &mut *self.multipliers;
        Ok(constrained_equations(
            self.scheme,
            self.sys,
            self.constraints,
            mp,
            self.start,
            self.x,
            r,
        )?)
    }

    fn noise(&self) -> f64 {
        rounding(self.start.p)
    }

    /// About x, by steps relative to ‖x‖∞ + ‖q₀‖∞ (F is evaluated at q₀ + x); x and the
    /// scheme's caches left at x. A rare path, before a failure: x is copied.
    fn measured_noise(&mut self, f0: &[f64]) -> Result<f64, StepError> {
        let x0 = self.x.to_vec();
        let (mut plus, mut minus) = (vec![0.0; f0.len()], vec![0.0; f0.len()]);
        let sizes = (norm(&x0), self.offset());
        let noise = difference::measured_noise(f0, (&mut plus, &mut minus), sizes, |shift, out| {
            for (x, a) in self.x.iter_mut().zip(&x0) {
                *x = a + shift;
            }
            self.residual(out)
        });
        self.x.copy_from_slice(&x0);
        noise
    }

    fn offset(&self) -> f64 {
        norm(self.start.q)
    }

    /// ∂F/∂x from the model's second derivatives where it supplies them and no force acts (the
    /// forces' derivatives are not supplied), with ∂A/∂q for velocity constraints; by central
    /// differences otherwise (and with holonomic constraints, alone or mixed), each unknown's step relative to
    /// the position it moves (λ: to itself).
    fn jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<(), StepError> {
        if !self.exact_jacobian(jac)? {
            self.differenced_jacobian(jac)?;
        }
        finite_jacobian(jac.as_slice())
    }

    /// Back to the predictor.
    fn restart(&mut self) {
        if let Some(guess) = self.guess {
            self.x.copy_from_slice(guess);
        }
    }

    /// ∂²L/∂q̇² at q₀ and the step's velocity δq/h, by differences of ∂L/∂q̇.
    fn degenerate(&mut self) -> Result<bool, StepError> {
        let Self { sys, start, x, .. } = self;
        let n = start.q.len();
        let mut v: Vec<f64> = x[x.len() - n..].iter().map(|d| d / start.h).collect();
        let (mut mass, mut plus, mut minus) = (DMatrix::zeros(n, n), vec![0.0; n], vec![0.0; n]);
        let at = Evaluations {
            plus: &mut plus,
            minus: &mut minus,
        };
        let dl_dv = |v: &[f64], out: &mut [f64]| sys.dl_dv(start.q, v, start.t, out);
        central_jacobian(dl_dv, &mut v, difference::unit, at, &mut mass)?;
        Ok(degenerate(&mass))
    }

    /// The exact Jacobian, where there is one, against differences of F (10⁻⁴ relative in the
    /// max norm: the differences are good to about 10⁻⁸).
    fn jacobian_agrees(&mut self) -> Result<bool, StepError> {
        let u = self.x.len();
        let (mut exact, mut differenced) = (DMatrix::zeros(u, u), DMatrix::zeros(u, u));
        if !self.exact_jacobian(&mut exact)? {
            return Ok(true);
        }
        self.differenced_jacobian(&mut differenced)?;
        Ok((&exact - &differenced).amax() <= 1e-4 * differenced.amax())
    }

    fn correct(&mut self, delta: &[f64]) -> Correction {
        correct(self.x, delta, self.m, self.start.h)
    }

    fn finishing(&mut self) {
        self.scheme.finishing();
    }
}

/// The rounding of a step's equations F = p₀ + D₁L_d + …: a few ε of their terms, of the size
/// of p₀ ([`NewtonProblem::noise`]).
#[inline(always)]
fn rounding(p0: &[f64]) -> f64 {
    4.0 * f64::EPSILON * norm(p0)
}

impl<Sc: StepEquations, S: Lagrangian + ?Sized> Equations<'_, Sc, S> {
    /// Writes ∂F/∂x from the model's second derivatives and returns true, where it supplies
    /// them and no force acts (the forces' derivatives are not supplied), with ∂A/∂q for
    /// velocity constraints; false otherwise (and with holonomic constraints, alone or mixed).
    fn exact_jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<bool, ModelError> {
        let (sys, constraints, start, m) = (self.sys, self.constraints, self.start, self.m);
        if sys.is_forced() {
            return Ok(false);
        }
        Ok(match constraints {
            Constraints::None => self.scheme.quadrature().jacobian(sys, segment(&start, self.x), jac)?,
            Constraints::Velocity(c, at) => {
                self.scheme
                    .quadrature()
                    .jacobian(sys, segment(&start, &self.x[m..]), self.block)?
                    && nonholonomic::jacobian((c, at), self.multipliers, self.block, (start.q, start.h), self.x, jac)
                        .map(|_| true)?
            }
            Constraints::Holonomic(_) | Constraints::Mixed(..) => false,
        })
    }

    /// ∂F/∂x by central differences, each unknown's step relative to the position it moves
    /// (λ: to itself).
    fn differenced_jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let Equations {
            scheme,
            sys,
            constraints,
            start,
            m,
            multipliers,
            x,
            plus,
            minus,
            evaluations,
            ..
        } = self;
        let (sys, constraints, start, m) = (*sys, *constraints, *start, *m);
        let n = start.q.len();
        let equations = |x: &[f64], out: &mut [f64]| {
            **evaluations += 1;
            constrained_equations(&mut **scheme, sys, constraints, multipliers, start, x, out)
        };
        let size = |j: usize, d: f64| {
            let base = if j < m { 0.0 } else { start.q[(j - m) % n] };
            (base + d).abs().max(1.0)
        };
        central_jacobian(equations, x, size, Evaluations { plus, minus }, jac)
    }
}

/// Refuses a non-finite Jacobian.
#[inline(always)]
fn finite_jacobian(jac: &[f64]) -> Result<(), StepError> {
    if !jac.iter().all(|x| x.is_finite()) {
        let reason = "the Jacobian of the step's equations is non-finite: the solution is blowing up";
        return Err(StepError::NonFinite { reason });
    }
    Ok(())
}

/// x ← x − δ for the unknowns x = (λ, the scheme's) of m multipliers, measured in the max norm.
#[inline(always)]
fn correct(x: &mut [f64], delta: &[f64], m: usize, h: f64) -> Correction {
    let (mut size, mut scale) = (0.0_f64, 0.0_f64);
    for (j, (x, d)) in x.iter_mut().zip(delta).enumerate() {
        *x -= d;
        // A multiplier moves q₁ by about (h²/2)M⁻¹Gᵀλ: its correction counts at that size.
        let weight = if j < m { 0.5 * h * h } else { 1.0 };
        size = size.max(weight * d.abs());
        scale = scale.max(weight * x.abs());
    }
    Correction { size, scale }
}
