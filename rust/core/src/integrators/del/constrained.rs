//! The constrained DEL equations (Marsden & West 2001, §3.4): the multipliers λ of g(q₁) = 0
//! among the unknowns, and the momentum put on the hidden constraint G(q₁)q̇ = 0 by μ.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::{nonholonomic, Constraints, StepEquations};
use crate::integrators::{Increment, StepError, StepStart};
use crate::model::{HolonomicConstraints, Lagrangian};
use crate::solve::difference::{central_jacobian, Evaluations};
use crate::solve::newton::{Correction, Newton, NewtonOptions, NewtonProblem, Reasons, Rules};
use crate::ModelError;

/// F(x) for x = (λ, s): the scheme's equations in s with (h/2)G(q₀)ᵀλ taken from the last
/// block (the one holding p₀), then the discrete constraint on δq, the last n of s: g(q₀ + δq)
/// for holonomic constraints, A(q̃)δq + h b(q̃) for velocity ones
/// ([`nonholonomic::discrete_constraint`]), both for mixed ones (G stacked over A in G(q₀)).
// Inlined into Newton's iteration, whose chain of dependent evaluations a call would lengthen.
#[inline(always)]
pub(super) fn constrained_equations<Sc: StepEquations, S: Lagrangian + ?Sized>(
    scheme: &mut Sc,
    sys: &S,
    constraints: Constraints<'_>,
    mp: &mut Multipliers,
    start: StepStart<'_>,
    x: &[f64],
    out: &mut [f64],
) -> Result<(), ModelError> {
    if let Constraints::None = constraints {
        return scheme.equations(sys, start, x, out);
    }
    let (n, m) = (start.q.len(), mp.g0.nrows());
    let (lambda, s) = x.split_at(m);
    let u = s.len();
    scheme.equations(sys, start, s, &mut out[..u])?;
    for (j, o) in out[u - n..u].iter_mut().enumerate() {
        *o -= 0.5 * start.h * (0..m).map(|k| mp.g0[(k, j)] * lambda[k]).sum::<f64>();
    }
    let dq = &s[u - n..];
    let (holonomic, velocity) = out[u..].split_at_mut(constraints.holonomic_count());
    match constraints {
        Constraints::Velocity(c, at) => {
            nonholonomic::discrete_constraint((c, at), mp, (start.q, start.h), dq, velocity)
        }
        Constraints::Holonomic(g) => position_constraint(g, mp, start.q, dq, holonomic),
        Constraints::Mixed(g, c, at) => {
            position_constraint(g, mp, start.q, dq, holonomic)?;
            nonholonomic::discrete_constraint((c, at), mp, (start.q, start.h), dq, velocity)
        }
        Constraints::None => Ok(()),
    }
}

/// g(q₀ + δq) into `out`, q₁ = q₀ + δq into `mp.q1`.
fn position_constraint(
    g: &dyn HolonomicConstraints,
    mp: &mut Multipliers,
    q0: &[f64],
    dq: &[f64],
    out: &mut [f64],
) -> Result<(), ModelError> {
    for ((q1, q), d) in mp.q1.iter_mut().zip(q0).zip(dq) {
        *q1 = q + d;
    }
    g.residual(&mp.q1, out)
}

/// The two blocks of a stacked constraint matrix [G; A] of mixed constraints, where each set
/// writes its own ([`Constraints::matrix`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct Parts {
    pub holonomic: DMatrix<f64>,
    pub velocity: DMatrix<f64>,
}

/// The buffers of the constrained step: G(q₀) and G(q₁) (or A, or [G; A] for mixed
/// constraints, with its blocks), q₁ and p₁, and μ's Newton iteration; for velocity
/// constraints also q̄, A(q̄), ∂A/∂qᵢ and the affine term's b(q̄), ∂b/∂qᵢ and b(q₁).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct Multipliers {
    /// G at the step's start; the last step's G(q₁) once a step is taken (first same as last).
    pub g0: DMatrix<f64>,
    pub cached: bool,
    g1: DMatrix<f64>,
    pub parts: Parts,
    pub q1: Vec<f64>,
    pub midpoint: Vec<f64>,
    pub a_mid: DMatrix<f64>,
    pub da: DMatrix<f64>,
    pub b_mid: Vec<f64>,
    pub db: Vec<f64>,
    b1: Vec<f64>,
    p1: Vec<f64>,
    v: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    mu: Vec<f64>,
    newton: Newton,
}

impl Multipliers {
    /// The buffers for m constraints on n coordinates, the first `holonomic` of them holonomic.
    pub fn new(n: usize, m: usize, holonomic: usize) -> Self {
        let velocity = m - holonomic;
        Multipliers {
            g0: DMatrix::zeros(m, n),
            cached: false,
            g1: DMatrix::zeros(m, n),
            parts: Parts {
                holonomic: DMatrix::zeros(holonomic, n),
                velocity: DMatrix::zeros(velocity, n),
            },
            q1: vec![0.0; n],
            midpoint: vec![0.0; n],
            a_mid: DMatrix::zeros(velocity, n),
            da: DMatrix::zeros(velocity, n),
            b_mid: vec![0.0; velocity],
            db: vec![0.0; velocity],
            b1: vec![0.0; m],
            p1: vec![0.0; n],
            v: vec![0.0; n],
            plus: vec![0.0; m],
            minus: vec![0.0; m],
            mu: vec![0.0; m],
            newton: Newton::new(m),
        }
    }

    /// Number of holonomic constraints the buffers are sized for.
    pub fn holonomic(&self) -> usize {
        self.parts.holonomic.nrows()
    }

    /// p₁ = p₀ + δp − (h/2)G(q₁)ᵀμ with G(q₁)q̇(q₁, p₁) + b(q₁) = 0 (G the constraints' Jacobian,
    /// or the matrix A of velocity constraints, [`Constraints::matrix`]; b = 0 but for affine
    /// velocity constraints, [`Constraints::offset`]): Newton's method on μ, its
    /// Jacobian −(h/2)G(q₁)(∂q̇/∂p)G(q₁)ᵀ from central differences of the inverse Legendre
    /// transform (exact in one step when L is quadratic in q̇); δp takes the projection.
    pub fn project_momentum<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        c: Constraints<'_>,
        start: StepStart<'_>,
        step: &mut Increment<'_>,
        options: &NewtonOptions,
    ) -> Result<(), StepError> {
        let StepStart { q, p, h, .. } = start;
        for ((x, q), d) in self.q1.iter_mut().zip(q).zip(step.dq.iter()) {
            *x = q + d;
        }
        c.matrix(&self.q1, &mut self.g1, &mut self.parts)?;
        c.offset(&self.q1, &mut self.b1)?;
        self.mu.fill(0.0);
        let mut problem = OntoHiddenConstraint {
            tangent: Tangent {
                sys,
                g1: &self.g1,
                b1: &self.b1,
                q1: &self.q1,
                p,
                dp: step.dp,
                t1: start.t + h,
                h,
            },
            mu: &mut self.mu,
            p1: &mut self.p1,
            v: &mut self.v,
            plus: &mut self.plus,
            minus: &mut self.minus,
            scale: p.iter().fold(1.0_f64, |a, x| a.max(x.abs())),
            speed: 1.0,
        };
        let rules = Rules { simplified: false };
        self.newton.solve(&mut problem, options, rules)?;
        let m = self.mu.len();
        for (j, d) in step.dp.iter_mut().enumerate() {
            *d -= 0.5 * h * (0..m).map(|k| self.g1[(k, j)] * self.mu[k]).sum::<f64>();
        }
        std::mem::swap(&mut self.g0, &mut self.g1);
        self.cached = true;
        Ok(())
    }
}

/// r(μ) = G(q₁)q̇(q₁, p₁(μ)) + b(q₁), p₁(μ) = p₀ + δp − (h/2)G(q₁)ᵀμ, the inverse Legendre
/// transform q̇ taken at t₁ = t + h.
struct Tangent<'a, S: ?Sized> {
    sys: &'a S,
    g1: &'a DMatrix<f64>,
    b1: &'a [f64],
    q1: &'a [f64],
    p: &'a [f64],
    dp: &'a [f64],
    t1: f64,
    h: f64,
}

impl<S: Lagrangian + ?Sized> Tangent<'_, S> {
    /// Writes r(μ) into `out`, and p₁(μ) and q̇ into `p1` and `v`.
    fn evaluate(&self, mu: &[f64], p1: &mut [f64], v: &mut [f64], out: &mut [f64]) -> Result<(), ModelError> {
        let (g1, m) = (self.g1, mu.len());
        for (j, x) in p1.iter_mut().enumerate() {
            *x = self.p[j] + self.dp[j] - 0.5 * self.h * (0..m).map(|k| g1[(k, j)] * mu[k]).sum::<f64>();
        }
        self.sys.velocity(self.q1, p1, self.t1, v)?;
        for (k, o) in out.iter_mut().enumerate() {
            *o = g1.row(k).iter().zip(v.iter()).map(|(a, b)| a * b).sum::<f64>() + self.b1[k];
        }
        Ok(())
    }
}

/// r(μ) = 0, solved to round-off in the velocity: ‖r‖∞ ≤ 4ε·max(‖q̇‖∞, |b(q₁)|∞, the size of
/// r's terms, 1).
struct OntoHiddenConstraint<'a, S: ?Sized> {
    tangent: Tangent<'a, S>,
    mu: &'a mut [f64],
    p1: &'a mut [f64],
    v: &'a mut [f64],
    plus: &'a mut [f64],
    minus: &'a mut [f64],
    /// max(‖p₀‖∞, 1), the least size μ's difference steps are relative to.
    scale: f64,
    /// max(‖q̇‖∞, |b(q₁)|∞, maxₖ Σⱼ|G_kj q̇ⱼ| + |b_k|, 1) at the last residual.
    speed: f64,
}

impl<S: Lagrangian + ?Sized> NewtonProblem for OntoHiddenConstraint<'_, S> {
    const REASONS: Reasons = Reasons {
        singular: "G(q₁)(∂q̇/∂p)G(q₁)ᵀ is singular: the constraints are not independent here",
        non_finite_start: "the velocity on the hidden constraint G(q₁)q̇ = 0 is non-finite",
        non_finite: "the momenta on the hidden constraint G(q₁)q̇ = 0 became non-finite",
        not_converged: "the momenta could not be put on the hidden constraint G(q₁)q̇ = 0",
        outside: "the step's momenta end too far from the hidden constraint for Newton's iteration: a \
                  smaller step (dt) brings them nearer",
    };

    fn residual(&mut self, r: &mut [f64]) -> Result<(), StepError> {
        self.tangent.evaluate(self.mu, self.p1, self.v, r)?;
        // The size of r's terms, Σⱼ|G_kj q̇ⱼ| + |b_k|: its rounding error, which a stall at
        // round-off reaches, is a few ε of it (the ball on a turntable stalls at 9.4e-16).
        let (g1, b1, v) = (self.tangent.g1, self.tangent.b1, &*self.v);
        let terms = (0..g1.nrows())
            .map(|k| g1.row(k).iter().zip(v).map(|(a, x)| (a * x).abs()).sum::<f64>() + b1[k].abs())
            .fold(0.0_f64, f64::max);
        self.speed = v.iter().chain(b1).fold(terms.max(1.0), |a, x| a.max(x.abs()));
        Ok(())
    }

    fn jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<(), StepError> {
        let (tangent, p1, v, scale) = (&self.tangent, &mut *self.p1, &mut *self.v, self.scale);
        let at = Evaluations {
            plus: &mut *self.plus,
            minus: &mut *self.minus,
        };
        let r = |mu: &[f64], out: &mut [f64]| tangent.evaluate(mu, p1, v, out);
        central_jacobian(r, self.mu, |_, mu| mu.abs().max(scale), at, jac)?;
        Ok(())
    }

    /// Converged on the residual alone (scale 0).
    fn correct(&mut self, delta: &[f64]) -> Correction {
        let mut size = 0.0_f64;
        for (mu, d) in self.mu.iter_mut().zip(delta) {
            *mu -= d;
            size = size.max(d.abs());
        }
        Correction { size, scale: 0.0 }
    }

    fn solved(&self, residual: f64) -> bool {
        residual <= self.noise()
    }

    fn noise(&self) -> f64 {
        4.0 * f64::EPSILON * self.speed
    }
}
