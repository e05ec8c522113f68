use nalgebra::{DMatrix, DVector};

use super::StepError;
use crate::discrete::{DiscreteLagrangian, Workspace};
use crate::linalg::{lu_in_place, lu_solve};
use crate::model::finite_difference::NOISE_FLOOR;
use crate::model::{Hessians, HolonomicConstraints, Lagrangian};
use crate::ModelError;

/// Options of the Newton iteration that solves the discrete Euler–Lagrange equations.
///
/// The iteration stops when ‖δ‖∞ ≤ tolerance·‖x‖∞, x the unknowns as increments from q₀ (the
/// step's δq, and the Galerkin control points' offsets), or when a Newton step with a freshly
/// computed Jacobian no longer halves a correction that is already below √ε‖x‖∞ (the
/// equations' own accuracy when derivatives come from differences). The scale is the increment,
/// not the position: the discrete velocity δq/h, and so p₁, carries the increment's relative
/// precision, which a scale of ‖q‖∞ would give away as a cyclic angle grows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    /// Stop when the correction satisfies ‖δ‖∞ ≤ tolerance·‖x‖∞ (x the increments).
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

/// The implicit equations of one step of a variational integrator. The unknowns x are the
/// increments from q₀ of every point the step solves for, n at a time; the last n are
/// δq = q₁ − q₀. Solving for increments keeps their own relative precision for the driver's
/// compensated summation (HLW VIII.5).
pub trait StepEquations {
    /// Number of unknowns for n coordinates.
    fn unknowns(&self, n: usize) -> usize;

    /// Writes F(x) into `out`; F = 0 at the step's solution.
    #[allow(clippy::too_many_arguments)]
    fn equations<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        p0: &[f64],
        t: f64,
        h: f64,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError>;

    /// Writes p₁ − p₀ at the solution x (F(x) = `residual`) into `dp`, in a form free of
    /// cancellation, and returns the work of the non-conservative forces over the step.
    #[allow(clippy::too_many_arguments)]
    fn momentum_change<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        t: f64,
        h: f64,
        x: &[f64],
        residual: &[f64],
        dp: &mut [f64],
    ) -> Result<f64, ModelError>;

    /// The predictor of all unknowns from a predicted increment δq.
    fn predict(&self, dq: &[f64], x: &mut [f64]);

    /// The quadrature that defines the scheme's L_d.
    fn quadrature(&mut self) -> &mut Quadrature;
}

/// L_d = h Σᵢ bᵢ L(q(cᵢh), q̇(cᵢh), t + cᵢh) along the polynomial q(τh) = Σⱼ ℓⱼ(τ)Qⱼ of degree
/// s through the control points Q₀ = q₀, Q₁, …, Q_s = q₁ at τ = j/s. A step's equations are
/// ∂L_d/∂Qⱼ for the slots j = 1, …, s−1 and then 0, its unknowns the increments Q₁ − q₀, …,
/// Q_s − q₀. Degree 1 gives the two-point rules (midpoint: c = ½; trapezoid: c = 0, 1).
#[derive(Clone, Debug)]
pub struct Quadrature {
    s: usize,
    nodes: Vec<f64>,
    weights: Vec<f64>,
    /// ℓⱼ(cᵢ) and ℓⱼ'(cᵢ), row i, column j = 0..=s.
    basis: Vec<Vec<f64>>,
    slopes: Vec<Vec<f64>>,
    /// sign det K, K = (Σᵢ bᵢℓⱼ'(cᵢ)ℓₖ'(cᵢ)) over the slots j and the unknowns k: the
    /// Jacobian of the equations tends to (1/h)·K ⊗ ∂²L/∂q̇² as h → 0.
    k_sign: f64,
    pos: Vec<f64>,
    vel: Vec<f64>,
    hessians: Hessians,
}

impl Quadrature {
    fn new(s: usize, nodes: &[f64], weights: &[f64], n: usize) -> Self {
        let d: Vec<f64> = (0..=s).map(|j| j as f64 / s as f64).collect();
        let ell = |j: usize, x: f64| {
            (0..=s)
                .filter(|&m| m != j)
                .map(|m| (x - d[m]) / (d[j] - d[m]))
                .product::<f64>()
        };
        let slope = |j: usize, x: f64| {
            (0..=s)
                .filter(|&k| k != j)
                .map(|k| {
                    (0..=s)
                        .filter(|&m| m != j && m != k)
                        .map(|m| (x - d[m]) / (d[j] - d[m]))
                        .product::<f64>()
                        / (d[j] - d[k])
                })
                .sum::<f64>()
        };
        let basis = nodes.iter().map(|&c| (0..=s).map(|j| ell(j, c)).collect()).collect();
        let slopes: Vec<Vec<f64>> = nodes.iter().map(|&c| (0..=s).map(|j| slope(j, c)).collect()).collect();
        let slot = |r: usize| if r + 1 < s { r + 1 } else { 0 };
        let k = DMatrix::from_fn(s, s, |r, c| {
            (0..nodes.len())
                .map(|i| weights[i] * slopes[i][slot(r)] * slopes[i][c + 1])
                .sum::<f64>()
        });
        Quadrature {
            s,
            nodes: nodes.to_vec(),
            weights: weights.to_vec(),
            basis,
            slopes,
            k_sign: k.determinant().signum(),
            pos: vec![0.0; n],
            vel: vec![0.0; n],
            hessians: Hessians::zeros(n),
        }
    }

    /// The slot of the r-th block of equations: Q₁, …, Q_{s−1}, then Q₀.
    fn slot(&self, r: usize) -> usize {
        if r + 1 < self.s {
            r + 1
        } else {
            0
        }
    }

    /// `pos` = q(cᵢh) and `vel` = q̇(cᵢh) for the control increments x.
    fn node_state(&mut self, i: usize, q0: &[f64], h: f64, x: &[f64]) {
        let n = q0.len();
        for a in 0..n {
            let (mut pos, mut vel) = (0.0, 0.0);
            for j in 1..=self.s {
                let xj = x[(j - 1) * n + a];
                pos += self.basis[i][j] * xj;
                vel += self.slopes[i][j] * xj;
            }
            self.pos[a] = q0[a] + pos;
            self.vel[a] = vel / h;
        }
    }

    /// The sign of det ∂F/∂x as h → 0: sign(det K)ⁿ·sign(det ∂²L/∂q̇²)ˢ.
    fn continuum_sign(&self, n: usize, hessian_sign: f64) -> f64 {
        self.k_sign.powi(n as i32) * hessian_sign.powi(self.s as i32)
    }

    /// Writes ∂F/∂x into `jac` from the model's exact second derivatives at the nodes,
    ///
    /// ∂F_r/∂Qₖ = Σᵢ bᵢ[hℓⱼℓₖ L_qq + ℓⱼℓₖ' L_qq̇ + ℓⱼ'ℓₖ L_q̇q + ℓⱼ'ℓₖ' L_q̇q̇/h](cᵢ), j = slot(r),
    ///
    /// and returns true; false when the model supplies none.
    #[allow(clippy::too_many_arguments)]
    fn jacobian<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        t: f64,
        h: f64,
        x: &[f64],
        jac: &mut DMatrix<f64>,
    ) -> Result<bool, ModelError> {
        let n = q0.len();
        jac.fill(0.0);
        for i in 0..self.nodes.len() {
            self.node_state(i, q0, h, x);
            if !sys.hessians(&self.pos, &self.vel, t + self.nodes[i] * h, &mut self.hessians)? {
                return Ok(false);
            }
            let (b, hs) = (self.weights[i], &self.hessians);
            for r in 0..self.s {
                let j = self.slot(r);
                let (lj, dj) = (self.basis[i][j], self.slopes[i][j]);
                for c in 0..self.s {
                    let (lk, dk) = (self.basis[i][c + 1], self.slopes[i][c + 1]);
                    let (qq, qv, vq, vv) = (b * h * lj * lk, b * lj * dk, b * dj * lk, b * dj * dk / h);
                    for a in 0..n {
                        for e in 0..n {
                            jac[(r * n + a, c * n + e)] +=
                                qq * hs.qq[(a, e)] + qv * hs.qv[(a, e)] + vq * hs.qv[(e, a)] + vv * hs.vv[(a, e)];
                        }
                    }
                }
            }
        }
        Ok(true)
    }
}

/// The generalized force at a step's midpoint, f(q₀ + δq/2, δq/h, t + h/2), with its buffers.
#[derive(Clone, Debug)]
struct Forcing {
    mid: Vec<f64>,
    vel: Vec<f64>,
    f: Vec<f64>,
}

impl Forcing {
    fn new(n: usize) -> Self {
        Forcing {
            mid: vec![0.0; n],
            vel: vec![0.0; n],
            f: vec![0.0; n],
        }
    }

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

/// The variational integrator of a two-point discrete Lagrangian (midpoint, trapezoid) with
/// forcing: F(δq) = p₀ + D₁L_d(q₀, q₀ + δq) + f_d⁻, then p₁ = D₂L_d + f_d⁺ (the forced DEL
/// equations of the discrete Lagrange–d'Alembert principle, f_d^± = (h/2)f(q̄, v, t + h/2) at
/// the midpoint). The work of the forces is f(q̄, v)·δq a step.
#[derive(Clone, Debug)]
pub struct TwoPoint<R> {
    rule: R,
    ws: Workspace,
    forcing: Forcing,
    quadrature: Quadrature,
}

impl<R: DiscreteLagrangian> TwoPoint<R> {
    pub fn new(rule: R, n: usize) -> Self {
        let (nodes, weights) = rule.quadrature();
        TwoPoint {
            quadrature: Quadrature::new(1, nodes, weights, n),
            rule,
            ws: Workspace::new(n),
            forcing: Forcing::new(n),
        }
    }
}

impl<R: DiscreteLagrangian> StepEquations for TwoPoint<R> {
    fn unknowns(&self, n: usize) -> usize {
        n
    }

    fn equations<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        p0: &[f64],
        t: f64,
        h: f64,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        self.rule.d1(sys, q0, x, t, h, out, &mut self.ws)?;
        out.iter_mut().zip(p0).for_each(|(o, p)| *o += p);
        if sys.is_forced() {
            let f = self.forcing.evaluate(sys, q0, x, t, h)?;
            out.iter_mut().zip(f).for_each(|(o, f)| *o += 0.5 * h * f);
        }
        Ok(())
    }

    /// p₁ − p₀ = D₁L_d + D₂L_d + h·f(q̄, v) − F, since F = p₀ + D₁L_d + f_d⁻.
    fn momentum_change<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        t: f64,
        h: f64,
        x: &[f64],
        residual: &[f64],
        dp: &mut [f64],
    ) -> Result<f64, ModelError> {
        self.rule.momentum_change(sys, q0, x, t, h, dp, &mut self.ws)?;
        dp.iter_mut().zip(residual).for_each(|(d, r)| *d -= r);
        if !sys.is_forced() {
            return Ok(0.0);
        }
        let f = self.forcing.evaluate(sys, q0, x, t, h)?;
        let mut work = 0.0;
        for ((d, f), x) in dp.iter_mut().zip(f).zip(x) {
            *d += h * f;
            work += f * x;
        }
        Ok(work)
    }

    fn predict(&self, dq: &[f64], x: &mut [f64]) {
        x.copy_from_slice(dq);
    }

    fn quadrature(&mut self) -> &mut Quadrature {
        &mut self.quadrature
    }
}

/// The Galerkin variational integrator of degree s with s-point Gauss–Legendre quadrature
/// (Marsden & West 2001, §2.6; order 2s): q(τh) = Σⱼ ℓⱼ(τ)Qⱼ through the control points
/// Q₀ = q₀, Q₁, …, Q_s = q₁ at τ = j/s, and L_d = h Σᵢ bᵢ L(q(cᵢh), q̇(cᵢh), t + cᵢh), made
/// stationary in the interior points. With ∂L_d/∂Qⱼ = Σᵢ bᵢ[hℓⱼ(cᵢ)∂L/∂q + ℓⱼ'(cᵢ)∂L/∂q̇]:
///
/// F = (∂L_d/∂Q₁, …, ∂L_d/∂Q_{s−1}, p₀ + ∂L_d/∂Q₀),   p₁ = ∂L_d/∂Q_s,
///
/// and since Σⱼ ℓⱼ = 1, Σⱼ ℓⱼ' = 0, p₁ − p₀ = hΣᵢ bᵢ ∂L/∂q(cᵢ) − ΣF. A force f adds to ∂L/∂q
/// at every node (forced DEL equations), and its work over the step is hΣᵢ bᵢ f(cᵢ)·q̇(cᵢ).
#[derive(Clone, Debug)]
pub struct Galerkin {
    quadrature: Quadrature,
    lq: Vec<Vec<f64>>,
    lv: Vec<Vec<f64>>,
    f: Vec<f64>,
    /// h Σᵢ bᵢ f(cᵢ)·q̇(cᵢ) at the last evaluation: the forces' work over the step.
    work: f64,
}

impl Galerkin {
    /// Degree s = 2 (order 4) or 3 (order 6).
    pub fn new(s: usize, n: usize) -> Self {
        let (nodes, weights) = match s {
            2 => {
                let d = 3f64.sqrt() / 6.0;
                (vec![0.5 - d, 0.5 + d], vec![0.5, 0.5])
            }
            3 => {
                let d = 15f64.sqrt() / 10.0;
                (vec![0.5 - d, 0.5, 0.5 + d], vec![5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0])
            }
            _ => panic!("Galerkin integrators of degree 2 and 3 only"),
        };
        Galerkin {
            quadrature: Quadrature::new(s, &nodes, &weights, n),
            lq: vec![vec![0.0; n]; s],
            lv: vec![vec![0.0; n]; s],
            f: vec![0.0; n],
            work: 0.0,
        }
    }

    /// ∂L/∂q + f and ∂L/∂q̇ at every quadrature node, for the control increments x (Q₀ = q₀).
    /// A force f enters where ∂L/∂q does: the discrete Lagrange–d'Alembert principle adds the
    /// virtual work h Σᵢ bᵢ f(cᵢ)·δq(cᵢh) to δL_d, and δq(cᵢh) = Σⱼ ℓⱼ(cᵢ)δQⱼ.
    fn derivatives<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        t: f64,
        h: f64,
        x: &[f64],
    ) -> Result<(), ModelError> {
        let quad = &mut self.quadrature;
        self.work = 0.0;
        for i in 0..quad.s {
            quad.node_state(i, q0, h, x);
            let ti = t + quad.nodes[i] * h;
            sys.dl_dq(&quad.pos, &quad.vel, ti, &mut self.lq[i])?;
            sys.dl_dv(&quad.pos, &quad.vel, ti, &mut self.lv[i])?;
            if sys.is_forced() {
                sys.force(&quad.pos, &quad.vel, ti, &mut self.f)?;
                let mut power = 0.0;
                for ((lq, f), v) in self.lq[i].iter_mut().zip(&self.f).zip(&quad.vel) {
                    *lq += f;
                    power += f * v;
                }
                self.work += h * quad.weights[i] * power;
            }
        }
        Ok(())
    }

    /// out = ∂L_d/∂Qⱼ = Σᵢ bᵢ[hℓⱼ(cᵢ)∂L/∂q + ℓⱼ'(cᵢ)∂L/∂q̇].
    fn slot(&self, j: usize, h: f64, out: &mut [f64]) {
        let quad = &self.quadrature;
        out.fill(0.0);
        for i in 0..quad.s {
            let (a, b) = (
                quad.weights[i] * h * quad.basis[i][j],
                quad.weights[i] * quad.slopes[i][j],
            );
            for ((o, lq), lv) in out.iter_mut().zip(&self.lq[i]).zip(&self.lv[i]) {
                *o += a * lq + b * lv;
            }
        }
    }
}

impl StepEquations for Galerkin {
    fn unknowns(&self, n: usize) -> usize {
        self.quadrature.s * n
    }

    fn equations<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        p0: &[f64],
        t: f64,
        h: f64,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        let n = q0.len();
        self.derivatives(sys, q0, t, h, x)?;
        for j in 1..self.quadrature.s {
            self.slot(j, h, &mut out[(j - 1) * n..j * n]);
        }
        let last = &mut out[(self.quadrature.s - 1) * n..];
        self.slot(0, h, last);
        last.iter_mut().zip(p0).for_each(|(o, p)| *o += p);
        Ok(())
    }

    fn momentum_change<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q0: &[f64],
        t: f64,
        h: f64,
        x: &[f64],
        residual: &[f64],
        dp: &mut [f64],
    ) -> Result<f64, ModelError> {
        let n = q0.len();
        self.derivatives(sys, q0, t, h, x)?;
        dp.fill(0.0);
        for (lq, b) in self.lq.iter().zip(&self.quadrature.weights) {
            dp.iter_mut().zip(lq).for_each(|(d, lq)| *d += h * b * lq);
        }
        for block in residual.chunks_exact(n) {
            dp.iter_mut().zip(block).for_each(|(d, r)| *d -= r);
        }
        Ok(self.work)
    }

    /// The control points along the predicted increment: Qⱼ − q₀ = (j/s)·δq.
    fn predict(&self, dq: &[f64], x: &mut [f64]) {
        let n = dq.len();
        let s = self.quadrature.s;
        for j in 1..=s {
            let w = j as f64 / s as f64;
            x[(j - 1) * n..j * n].iter_mut().zip(dq).for_each(|(x, d)| *x = w * d);
        }
    }

    fn quadrature(&mut self) -> &mut Quadrature {
        &mut self.quadrature
    }
}

/// A variational integrator that solves its step's implicit equations (a [`StepEquations`]) by
/// Newton's method.
///
/// The Jacobian comes from central differences of the equations, is factorised and kept while
/// the iteration contracts by at least half per step (simplified Newton), refreshed otherwise.
/// The predictor extrapolates the last two increments. p₁ − p₀ is formed by the scheme free
/// of cancellation, so that Noether momenta stay conserved to round-off.
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
#[derive(Clone, Debug)]
pub struct Del<Sc> {
    scheme: Sc,
    options: NewtonOptions,
    /// Number of constraints m; the unknowns are (λ, the scheme's).
    m: usize,
    multipliers: Multipliers,
    x: Vec<f64>,
    residual: DVector<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    jacobian: DMatrix<f64>,
    pivots: Vec<usize>,
    /// sign det of the last factorised Jacobian.
    jacobian_sign: f64,
    /// sign det ∂F/∂x as h → 0 at the run's first state; 0 until computed.
    continuum_sign: f64,
    hessian: DMatrix<f64>,
    velocity: Vec<f64>,
    predicted: Vec<f64>,
    last_dq: Vec<f64>,
    before_last_dq: Vec<f64>,
    /// How many previous increments the predictor has (0, 1 or 2).
    history: usize,
    evaluations: u64,
    iterations: u64,
    work: f64,
}

/// The buffers of the constrained step: G(q₀) and G(q₁), q₁ and p₁, and μ's Newton iteration.
#[derive(Clone, Debug)]
struct Multipliers {
    /// G at the step's start; the last step's G(q₁) once a step is taken (first same as last).
    g0: DMatrix<f64>,
    cached: bool,
    g1: DMatrix<f64>,
    q1: Vec<f64>,
    p1: Vec<f64>,
    v: Vec<f64>,
    r: DVector<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    mu: Vec<f64>,
    jacobian: DMatrix<f64>,
    pivots: Vec<usize>,
}

impl Multipliers {
    fn new(n: usize, m: usize) -> Self {
        Multipliers {
            g0: DMatrix::zeros(m, n),
            cached: false,
            g1: DMatrix::zeros(m, n),
            q1: vec![0.0; n],
            p1: vec![0.0; n],
            v: vec![0.0; n],
            r: DVector::zeros(m),
            plus: vec![0.0; m],
            minus: vec![0.0; m],
            mu: vec![0.0; m],
            jacobian: DMatrix::zeros(m, m),
            pivots: vec![0; m],
        }
    }
}

/// F(x) for x = (λ, s): the scheme's equations in s with (h/2)G(q₀)ᵀλ taken from the last
/// block (the one holding p₀), then g(q₀ + δq) with δq the last n of s.
#[allow(clippy::too_many_arguments)]
fn constrained_equations<Sc: StepEquations, S: Lagrangian + ?Sized>(
    scheme: &mut Sc,
    sys: &S,
    constraints: Option<(&dyn HolonomicConstraints, &DMatrix<f64>, &mut [f64])>,
    q0: &[f64],
    p0: &[f64],
    t: f64,
    h: f64,
    x: &[f64],
    out: &mut [f64],
) -> Result<(), ModelError> {
    let Some((c, g0, q1)) = constraints else {
        return scheme.equations(sys, q0, p0, t, h, x, out);
    };
    let (n, m) = (q0.len(), g0.nrows());
    let (lambda, s) = x.split_at(m);
    let u = s.len();
    scheme.equations(sys, q0, p0, t, h, s, &mut out[..u])?;
    for (j, o) in out[u - n..u].iter_mut().enumerate() {
        *o -= 0.5 * h * (0..m).map(|k| g0[(k, j)] * lambda[k]).sum::<f64>();
    }
    for ((q1, q), d) in q1.iter_mut().zip(q0).zip(&s[u - n..]) {
        *q1 = q + d;
    }
    c.residual(q1, &mut out[u..])
}

impl<Sc: StepEquations> Del<Sc> {
    pub fn new(scheme: Sc, n: usize, options: NewtonOptions) -> Self {
        let m = scheme.unknowns(n);
        Del {
            scheme,
            options,
            m: 0,
            multipliers: Multipliers::new(n, 0),
            x: vec![0.0; m],
            residual: DVector::zeros(m),
            plus: vec![0.0; m],
            minus: vec![0.0; m],
            jacobian: DMatrix::zeros(m, m),
            pivots: vec![0; m],
            jacobian_sign: 0.0,
            continuum_sign: 0.0,
            hessian: DMatrix::zeros(n, n),
            velocity: vec![0.0; n],
            predicted: vec![0.0; n],
            last_dq: vec![0.0; n],
            before_last_dq: vec![0.0; n],
            history: 0,
            evaluations: 0,
            iterations: 0,
            work: 0.0,
        }
    }

    /// Evaluations of the step's equations so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Newton iterations made so far.
    pub fn iterations(&self) -> u64 {
        self.iterations
    }

    /// The work done by the generalized forces so far.
    pub fn work(&self) -> f64 {
        self.work
    }

    pub(super) fn reset(&mut self) {
        self.history = 0;
        self.continuum_sign = 0.0;
        self.x[..self.m].fill(0.0);
        self.multipliers.cached = false;
    }

    /// Sizes the buffers for m constraints (allocating only when m changes).
    fn size_for(&mut self, n: usize, m: usize) {
        if m == self.m {
            return;
        }
        let total = self.scheme.unknowns(n) + m;
        self.m = m;
        self.multipliers = Multipliers::new(n, m);
        self.x = vec![0.0; total];
        self.residual = DVector::zeros(total);
        self.plus = vec![0.0; total];
        self.minus = vec![0.0; total];
        self.jacobian = DMatrix::zeros(total, total);
        self.pivots = vec![0; total];
    }

    /// sign det ∂²L/∂q̇² at (q, q̇(q, p), t), by central differences of ∂L/∂q̇: the regularity
    /// of L, against which the DEL Jacobian's sign is judged.
    fn hessian_sign<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        q: &[f64],
        p: &[f64],
        t: f64,
    ) -> Result<f64, StepError> {
        let n = q.len();
        sys.velocity(q, p, t, &mut self.velocity)?;
        for j in 0..n {
            let v = self.velocity[j];
            let e = f64::EPSILON.cbrt() * v.abs().max(1.0);
            self.velocity[j] = v + e;
            sys.dl_dv(q, &self.velocity, t, &mut self.plus[..n])?;
            self.velocity[j] = v - e;
            sys.dl_dv(q, &self.velocity, t, &mut self.minus[..n])?;
            self.velocity[j] = v;
            for i in 0..n {
                self.hessian[(i, j)] = (self.plus[i] - self.minus[i]) / (2.0 * e);
            }
        }
        let mut pivots = std::mem::take(&mut self.pivots);
        let sign = lu_in_place(&mut self.hessian, &mut pivots[..n]);
        self.pivots = pivots;
        sign.ok_or_else(|| {
            StepError::Model("∂²L/∂q̇² is singular at the initial state: the Lagrangian is not regular".into())
        })
    }

    /// residual = F(x); returns ‖residual‖∞.
    #[allow(clippy::too_many_arguments)]
    fn residual<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        constraints: Option<&dyn HolonomicConstraints>,
        q0: &[f64],
        p0: &[f64],
        t: f64,
        h: f64,
    ) -> Result<f64, StepError> {
        self.evaluations += 1;
        let mp = &mut self.multipliers;
        let c = constraints.map(|c| (c, &mp.g0, mp.q1.as_mut_slice()));
        constrained_equations(
            &mut self.scheme,
            sys,
            c,
            q0,
            p0,
            t,
            h,
            &self.x,
            self.residual.as_mut_slice(),
        )?;
        Ok(self.residual.iter().fold(0.0_f64, |m, r| m.max(r.abs())))
    }

    /// ∂F/∂x from the model's second derivatives where it supplies them and no force acts (the
    /// forces' derivatives are not supplied), by central differences otherwise; factorised in
    /// place.
    #[allow(clippy::too_many_arguments)]
    fn factorise_jacobian<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        constraints: Option<&dyn HolonomicConstraints>,
        q0: &[f64],
        p0: &[f64],
        t: f64,
        h: f64,
    ) -> Result<bool, StepError> {
        let exact = !sys.is_forced()
            && constraints.is_none()
            && self
                .scheme
                .quadrature()
                .jacobian(sys, q0, t, h, &self.x, &mut self.jacobian)?;
        let cbrt_eps = f64::EPSILON.cbrt();
        let (n, m) = (q0.len(), self.m);
        for j in (0..self.x.len()).filter(|_| !exact) {
            let d = self.x[j];
            let base = if j < m { 0.0 } else { q0[(j - m) % n] };
            let e = cbrt_eps * (base + d).abs().max(1.0);
            let mp = &mut self.multipliers;
            self.x[j] = d + e;
            let c = constraints.map(|c| (c, &mp.g0, mp.q1.as_mut_slice()));
            constrained_equations(&mut self.scheme, sys, c, q0, p0, t, h, &self.x, &mut self.plus)?;
            self.x[j] = d - e;
            let c = constraints.map(|c| (c, &mp.g0, mp.q1.as_mut_slice()));
            constrained_equations(&mut self.scheme, sys, c, q0, p0, t, h, &self.x, &mut self.minus)?;
            self.x[j] = d;
            self.evaluations += 2;
            for (i, (a, b)) in self.plus.iter().zip(&self.minus).enumerate() {
                self.jacobian[(i, j)] = (a - b) / (2.0 * e);
            }
        }
        if !self.jacobian.iter().all(|x| x.is_finite()) {
            let reason = "the Jacobian of the step's equations is non-finite: the solution is blowing up";
            return Err(StepError::NonFinite { reason });
        }
        match lu_in_place(&mut self.jacobian, &mut self.pivots) {
            Some(sign) => {
                self.jacobian_sign = sign;
                Ok(true)
            }
            None => Ok(false),
        }
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn increment<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        constraints: Option<&dyn HolonomicConstraints>,
        t: f64,
        q: &[f64],
        p: &[f64],
        h: f64,
        dq: &mut [f64],
        dp: &mut [f64],
    ) -> Result<(), StepError> {
        let n = q.len();
        self.size_for(n, constraints.map_or(0, |c| c.count()));
        let m = self.m;
        if let Some(c) = constraints {
            if !self.multipliers.cached {
                c.jacobian(q, &mut self.multipliers.g0)?;
            }
        }
        if self.continuum_sign == 0.0 {
            let hessian_sign = self.hessian_sign(sys, q, p, t)?;
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
        let mut residual = self.residual(sys, constraints, q, p, t, h)?;
        if !residual.is_finite() {
            return Err(StepError::NonFinite {
                reason: "the implicit equations are non-finite at the predictor",
            });
        }
        // Simplified Newton: the factorised Jacobian is kept while the corrections shrink by at
        // least half an iteration, and refreshed otherwise.
        let mut keep_jacobian = false;
        let mut last_correction = f64::INFINITY;
        let mut smallest = f64::INFINITY;
        for iteration in 1..=self.options.max_iterations {
            let fresh = !keep_jacobian;
            if fresh && !self.factorise_jacobian(sys, constraints, q, p, t, h)? {
                let reason = "the Jacobian of the step's equations is singular";
                return Err(StepError::Convergence {
                    residual,
                    iterations: iteration - 1,
                    reason,
                });
            }
            self.iterations += 1;
            lu_solve(&self.jacobian, &self.pivots, &mut self.residual);
            let mut correction = 0.0_f64;
            let mut scale = 0.0_f64;
            for (j, (x, d)) in self.x.iter_mut().zip(self.residual.iter()).enumerate() {
                *x -= d;
                // A multiplier moves q₁ by about (h²/2)M⁻¹Gᵀλ: its correction counts at that size.
                let weight = if j < m { 0.5 * h * h } else { 1.0 };
                correction = correction.max(weight * d.abs());
                scale = scale.max(weight * x.abs());
            }
            residual = self.residual(sys, constraints, q, p, t, h)?;
            if !(correction.is_finite() && residual.is_finite()) {
                let reason = "the implicit equations became non-finite (Newton's method or the solution diverged)";
                return Err(StepError::NonFinite { reason });
            }
            let contracting = correction <= 0.5 * last_correction;
            // Converged: at the tolerance, or at the noise floor of the equations (round-off,
            // or derivatives by differences, accurate to about 1e-10), where even a fresh
            // Newton step no longer halves the smallest correction so far.
            let at_floor = fresh && correction > 0.5 * smallest && correction <= NOISE_FLOOR * scale;
            smallest = smallest.min(correction);
            if correction <= self.options.tolerance * scale || at_floor {
                // The fold test knows the unconstrained equations' continuum limit only.
                if m == 0 && self.jacobian_sign != self.continuum_sign {
                    return Err(StepError::SpuriousBranch {
                        reason: "the step's solution lies beyond a fold of the discrete Euler–Lagrange map \
                                 (the Jacobian's determinant changed sign from its continuum limit), where \
                                 the equations have several solutions and Newton's may be spurious",
                    });
                }
                return self.finish(sys, constraints, t, q, p, h, dq, dp);
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

    /// The increments once the step is solved.
    #[allow(clippy::too_many_arguments)]
    fn finish<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        constraints: Option<&dyn HolonomicConstraints>,
        t: f64,
        q: &[f64],
        p: &[f64],
        h: f64,
        dq: &mut [f64],
        dp: &mut [f64],
    ) -> Result<(), StepError> {
        self.evaluations += 1;
        let (n, m) = (q.len(), self.m);
        let u = self.x.len() - m;
        // The scheme's own residual: its last block holds (h/2)G(q₀)ᵀλ at the solution.
        for j in (0..n).filter(|_| m > 0) {
            let force: f64 = (0..m).map(|k| self.multipliers.g0[(k, j)] * self.x[k]).sum();
            self.residual[u - n + j] += 0.5 * h * force;
        }
        self.work += self
            .scheme
            .momentum_change(sys, q, t, h, &self.x[m..], &self.residual.as_slice()[..u], dp)?;
        dq.copy_from_slice(&self.x[self.x.len() - n..]);
        if let Some(c) = constraints {
            self.project_momentum(sys, c, t + h, q, p, h, dq, dp)?;
        }
        std::mem::swap(&mut self.before_last_dq, &mut self.last_dq);
        self.last_dq.copy_from_slice(dq);
        self.history = (self.history + 1).min(2);
        Ok(())
    }

    /// p₁ = p₀ + δp − (h/2)G(q₁)ᵀμ with G(q₁)q̇(q₁, p₁) = 0: Newton's method on μ, its
    /// Jacobian −(h/2)G(q₁)(∂q̇/∂p)G(q₁)ᵀ from central differences of the inverse Legendre
    /// transform (exact in one step when L is quadratic in q̇); δp takes the projection.
    #[allow(clippy::too_many_arguments)]
    fn project_momentum<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        c: &dyn HolonomicConstraints,
        t1: f64,
        q: &[f64],
        p: &[f64],
        h: f64,
        dq: &[f64],
        dp: &mut [f64],
    ) -> Result<(), StepError> {
        let mp = &mut self.multipliers;
        let m = mp.mu.len();
        for ((x, q), d) in mp.q1.iter_mut().zip(q).zip(dq) {
            *x = q + d;
        }
        c.jacobian(&mp.q1, &mut mp.g1)?;
        mp.mu.fill(0.0);
        // r(μ) = G(q₁)q̇(q₁, p₀ + δp − (h/2)G(q₁)ᵀμ).
        let tangent = |mu: &[f64], mp_p1: &mut [f64], v: &mut [f64], out: &mut [f64], g1: &DMatrix<f64>, q1: &[f64]| {
            for (j, x) in mp_p1.iter_mut().enumerate() {
                *x = p[j] + dp[j] - 0.5 * h * (0..m).map(|k| g1[(k, j)] * mu[k]).sum::<f64>();
            }
            sys.velocity(q1, mp_p1, t1, v)?;
            for (k, o) in out.iter_mut().enumerate() {
                *o = g1.row(k).iter().zip(v.iter()).map(|(a, b)| a * b).sum();
            }
            Ok::<(), ModelError>(())
        };
        let scale = p.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
        let mut converged = false;
        for _ in 0..self.options.max_iterations {
            tangent(&mp.mu, &mut mp.p1, &mut mp.v, mp.r.as_mut_slice(), &mp.g1, &mp.q1)?;
            let speed = mp.v.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
            if mp.r.amax() <= 4.0 * f64::EPSILON * speed {
                converged = true;
                break;
            }
            for k in 0..m {
                let e = f64::EPSILON.cbrt() * mp.mu[k].abs().max(scale);
                let mu = mp.mu[k];
                mp.mu[k] = mu + e;
                tangent(&mp.mu, &mut mp.p1, &mut mp.v, &mut mp.plus, &mp.g1, &mp.q1)?;
                mp.mu[k] = mu - e;
                tangent(&mp.mu, &mut mp.p1, &mut mp.v, &mut mp.minus, &mp.g1, &mp.q1)?;
                mp.mu[k] = mu;
                for i in 0..m {
                    mp.jacobian[(i, k)] = (mp.plus[i] - mp.minus[i]) / (2.0 * e);
                }
            }
            if lu_in_place(&mut mp.jacobian, &mut mp.pivots).is_none() {
                return Err(StepError::Convergence {
                    residual: mp.r.amax(),
                    iterations: 0,
                    reason: "G(q₁)(∂q̇/∂p)G(q₁)ᵀ is singular: the constraints are not independent here",
                });
            }
            lu_solve(&mp.jacobian, &mp.pivots, &mut mp.r);
            mp.mu.iter_mut().zip(mp.r.iter()).for_each(|(mu, d)| *mu -= d);
        }
        if !converged {
            return Err(StepError::Convergence {
                residual: mp.r.amax(),
                iterations: self.options.max_iterations,
                reason: "the momenta could not be put on the hidden constraint G(q₁)q̇ = 0",
            });
        }
        for (j, d) in dp.iter_mut().enumerate() {
            *d -= 0.5 * h * (0..m).map(|k| mp.g1[(k, j)] * mp.mu[k]).sum::<f64>();
        }
        std::mem::swap(&mut mp.g0, &mut mp.g1);
        mp.cached = true;
        Ok(())
    }
}
