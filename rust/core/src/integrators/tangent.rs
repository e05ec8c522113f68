//! The tangent map DΨ_h of a step: the step's linearization, applied to tangent vectors
//! (δq, δp), for the variational equations of chaos indicators (Lyapunov spectra, MEGNO).
//!
//! - A kick–drift step is a composition of shears, so its tangent map is one too, exactly: a
//!   drift q ← q + bhM⁻¹p maps δq ← δq + bhM⁻¹δp, a kick p ← p − ah∇V(q) maps
//!   δp ← δp − ahH(q)δq with H = ∂²V/∂q² at the kick's point. With H symmetric each factor has
//!   determinant 1 and is symplectic, so the tangent map is, to round-off, whatever H's
//!   accuracy: a differenced H is symmetrized.
//! - An implicit (DEL, forced Lagrange–d'Alembert) step solves F(x; q₀, p₀) = 0 for its unknowns
//!   x and ends at q₁ = q₀ + δq, p₁ = P(x; q₀, p₀). At the solution, by the implicit function
//!   theorem, δx = −F_x⁻¹(F_q₀δq₀ + F_p₀δp₀), so that
//!
//!   DΨ_h = [I 0; P_q₀ P_p₀] + [E; P_x]·(−F_x⁻¹[F_q₀ F_p₀]),   E picking δq out of δx:
//!
//!   the step's own equations differentiated at their solution (central differences of (F, P)
//!   in (x, q₀, p₀), error about ε^⅔), not differences of whole steps, which would carry
//!   Newton's tolerance. It holds for every rule's equations alike (midpoint, trapezoid,
//!   Galerkin) and for forces: a damped step's volume change det DΨ_h comes out as the step
//!   makes it.

use nalgebra::DMatrix;

use super::{Del, Dynamics, Integrator, Method, ModelKind, Splitting, StepEquations, StepStart};
use crate::model::{Lagrangian, MechanicalSystem};
use crate::solve::difference::{central_jacobian, unit, Evaluations};
use crate::solve::lu::{lu_in_place, lu_solve};
use crate::{Error, ModelError};

/// The tangent map of one method's step on a model, with its buffers: carrying vectors
/// ([`super::Stepper::step_with_tangent`]) allocates nothing once the first step has sized
/// them.
#[derive(Clone, Debug)]
pub struct Tangent {
    map: Map,
    /// The step's start (t, q₀, p₀), kept before the stepper moves on.
    t: f64,
    q: Vec<f64>,
    p: Vec<f64>,
}

#[derive(Clone, Debug)]
enum Map {
    Shears(Shears),
    Implicit(Implicit),
}

impl Tangent {
    /// The tangent map of `method`'s step on `model`: the explicit kick–drift methods on a
    /// separable model, the implicit midpoint, trapezoid and Galerkin rules on an unconstrained
    /// Lagrangian (forced or not). Refused, naming the argument: another method, a kick–drift
    /// method on a model that is not separable, constraints, and delayed forces (the step then
    /// depends on the run's past, so it is no map of (q, p) alone).
    pub fn new<S: Dynamics + ?Sized>(method: Method, model: &S) -> Result<Tangent, Error> {
        let n = model.dim();
        let map = if let Some(splitting) = Splitting::of(method) {
            if model.as_mechanical().is_none() {
                let reason = format!(
                    "the tangent map of {} (a kick–drift step) needs a separable model, L = ½q̇ᵀMq̇ − V(q); \
                     this one is not: take midpoint, trapezoid, galerkin4 or galerkin6, whose implicit \
                     steps have one for any L",
                    method.info().name
                );
                return Err(Error::invalid("model", reason));
            }
            Map::Shears(Shears::new(splitting, n))
        } else if matches!(
            method,
            Method::Midpoint | Method::Trapezoid | Method::Galerkin4 | Method::Galerkin6
        ) {
            if !matches!(
                model.kind(),
                ModelKind::Separable | ModelKind::Lagrangian | ModelKind::Gravitational
            ) {
                let reason = "has constraints: the tangent map here is that of an unconstrained step in (q, p), \
                              and a constrained step's maps the constraint manifold's tangent space";
                return Err(Error::invalid("model", reason));
            }
            if !model.as_lagrangian().delays().is_empty() {
                let reason = "has delayed forces: its step depends on the run's past as well as on (q, p), so \
                              it has no tangent map in (q, p) alone";
                return Err(Error::invalid("model", reason));
            }
            Map::Implicit(Implicit::default())
        } else {
            return Err(Error::invalid(
                "method",
                format!(
                    "{} has no tangent map here: the kick–drift methods (verlet, yoshida4, blanes_moan4, \
                     aba864, …) and the implicit rules (midpoint, trapezoid, galerkin4, galerkin6) have one",
                    method.info().name
                ),
            ));
        };
        Ok(Tangent {
            map,
            t: 0.0,
            q: vec![0.0; n],
            p: vec![0.0; n],
        })
    }

    /// Evaluations the tangent map made: of ∇V and H (a differenced H counts its 2n gradients)
    /// for a kick–drift step, of the step's equations and end momentum for an implicit one.
    pub fn evaluations(&self) -> u64 {
        match &self.map {
            Map::Shears(s) => s.evaluations,
            Map::Implicit(s) => s.evaluations,
        }
    }

    /// Keeps the start (t, q₀, p₀) of the step about to be taken.
    pub(super) fn begin(&mut self, t: f64, q: &[f64], p: &[f64]) {
        self.t = t;
        self.q.copy_from_slice(q);
        self.p.copy_from_slice(p);
    }

    /// Applies DΨ_h of the step of size h just taken by `integrator` on `model` from the start
    /// kept by [`Tangent::begin`] to its end q₁ (`end`) to the tangent vectors in `x`, in place:
    /// column j of the 2n × k column-major `x` is (δq, δp).
    pub(super) fn apply(
        &mut self,
        model: &dyn Dynamics,
        integrator: &mut Integrator,
        (h, end): (f64, &[f64]),
        x: &mut [f64],
    ) -> Result<(), ModelError> {
        let start = StepStart {
            t: self.t,
            h,
            q: &self.q,
            p: &self.p,
        };
        match &mut self.map {
            Map::Shears(s) => {
                let sys = model
                    .as_mechanical()
                    .expect("a separable model, checked by Tangent::new");
                s.apply(sys, start, end, x)
            }
            Map::Implicit(s) => {
                let del = integrator
                    .step_map()
                    .expect("an implicit method, checked by Tangent::new");
                s.linearize(del, model.as_lagrangian(), start)?;
                s.apply(x);
                Ok(())
            }
        }
    }
}

/// A kick–drift step's tangent map: its shears replayed from the step's start, with the stage's
/// (q, p), its velocity, the force at it and H there, and the q that H was taken at.
#[derive(Clone, Debug)]
struct Shears {
    splitting: Splitting,
    n: usize,
    q: Vec<f64>,
    p: Vec<f64>,
    v: Vec<f64>,
    force: Vec<f64>,
    hessian: DMatrix<f64>,
    hessian_at: Option<Vec<f64>>,
    /// A tangent vector's δp through M⁻¹, and the gradients a differenced H takes.
    velocity: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    /// Evaluations of ∇V and of H (exact or differenced) made.
    evaluations: u64,
}

impl Shears {
    fn new(splitting: Splitting, n: usize) -> Self {
        let buffer = || vec![0.0; n];
        Shears {
            splitting,
            n,
            q: buffer(),
            p: buffer(),
            v: buffer(),
            force: buffer(),
            hessian: DMatrix::zeros(n, n),
            hessian_at: None,
            velocity: buffer(),
            plus: buffer(),
            minus: buffer(),
            evaluations: 0,
        }
    }

    /// The stages replayed from `start`, so that each kick's H is taken where that kick acts;
    /// a last kick after a drift acts at the step's end q₁, `end` (the replay's last q but for
    /// round-off), where the next step's first kick takes the same H again.
    fn apply<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        start: StepStart<'_>,
        end: &[f64],
        x: &mut [f64],
    ) -> Result<(), ModelError> {
        let (n, mass, h) = (self.n, sys.mass(), start.h);
        self.q.copy_from_slice(start.q);
        self.p.copy_from_slice(start.p);
        let last = self.splitting.kicks().len() - 1;
        for i in 0..=last {
            let a = self.splitting.kicks()[i];
            if i > 0 {
                let b = self.splitting.drifts()[i - 1] * h;
                if i == last {
                    self.q.copy_from_slice(end);
                } else {
                    mass.velocity(&self.p, &mut self.v);
                    self.q.iter_mut().zip(&self.v).for_each(|(q, v)| *q += b * v);
                }
                for column in x.chunks_exact_mut(2 * n) {
                    let (dq, dp) = column.split_at_mut(n);
                    mass.velocity(dp, &mut self.velocity);
                    dq.iter_mut().zip(&self.velocity).for_each(|(d, v)| *d += b * v);
                }
            }
            if a == 0.0 {
                continue;
            }
            let a = a * h;
            self.hessian(sys)?;
            // H is symmetric: its column r, contiguous, is its row r.
            let hessian = self.hessian.as_slice();
            for column in x.chunks_exact_mut(2 * n) {
                let (dq, dp) = column.split_at_mut(n);
                for (d, row) in dp.iter_mut().zip(hessian.chunks_exact(n)) {
                    *d -= a * row.iter().zip(dq.iter()).map(|(h, x)| h * x).sum::<f64>();
                }
            }
            // The stage momenta, for the drifts after this kick but the last, which ends at q₁.
            if i + 1 < last {
                self.evaluations += 1;
                sys.gradient(&self.q, &mut self.force)?;
                self.p.iter_mut().zip(&self.force).for_each(|(p, f)| *p -= a * f);
            }
        }
        Ok(())
    }

    /// H = ∂²V/∂q² at the stage's q: the one kept where it was taken at that q (a kick at the
    /// end of one step and the start of the next), else the model's own, or central differences
    /// of ∇V ([`central_jacobian`]), symmetrized.
    fn hessian<S: MechanicalSystem + ?Sized>(&mut self, sys: &S) -> Result<(), ModelError> {
        if self.hessian_at.as_deref() == Some(&self.q[..]) {
            return Ok(());
        }
        // Forgotten until it is whole, so that a failed evaluation is not kept.
        let mut at = self.hessian_at.take().unwrap_or_else(|| vec![0.0; self.n]);
        self.evaluate_hessian(sys)?;
        at.copy_from_slice(&self.q);
        self.hessian_at = Some(at);
        Ok(())
    }

    fn evaluate_hessian<S: MechanicalSystem + ?Sized>(&mut self, sys: &S) -> Result<(), ModelError> {
        self.evaluations += 1;
        if let Some(exact) = sys.hessian(&self.q, self.hessian.as_mut_slice()) {
            return exact;
        }
        let at = Evaluations {
            plus: &mut self.plus,
            minus: &mut self.minus,
        };
        central_jacobian(|q, out| sys.gradient(q, out), &mut self.q, unit, at, &mut self.hessian)?;
        self.evaluations += 2 * self.n as u64 - 1;
        for i in 0..self.n {
            for j in 0..i {
                let mean = 0.5 * (self.hessian[(i, j)] + self.hessian[(j, i)]);
                self.hessian[(i, j)] = mean;
                self.hessian[(j, i)] = mean;
            }
        }
        Ok(())
    }
}

/// An implicit step's map as its tangent map linearizes it: [`Del::step_map`] and the solution
/// its Newton iteration left.
pub(super) trait StepMap {
    fn solution(&self) -> &[f64];

    fn step_map(
        &mut self,
        sys: &dyn Lagrangian,
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError>;
}

impl<Sc: StepEquations> StepMap for Del<Sc> {
    fn solution(&self) -> &[f64] {
        Del::solution(self)
    }

    fn step_map(
        &mut self,
        sys: &dyn Lagrangian,
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        Del::step_map(self, sys, start, x, out)
    }
}

/// The tangent map of an implicit step, with its buffers (sized at the first step: u unknowns,
/// n coordinates): z = (x, q₀, p₀), the Jacobian of (F, P) in z, F_x's factors, Y = F_x⁻¹[F_q₀ F_p₀]
/// and DΨ_h itself.
#[derive(Clone, Debug, Default)]
struct Implicit {
    z: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    jacobian: DMatrix<f64>,
    lu: DMatrix<f64>,
    pivots: Vec<usize>,
    y: DMatrix<f64>,
    map: DMatrix<f64>,
    column: Vec<f64>,
    /// Evaluations of the step's map (F and P together).
    evaluations: u64,
}

impl Implicit {
    fn size(&mut self, u: usize, n: usize) {
        if self.z.len() == u + 2 * n && self.map.nrows() == 2 * n {
            return;
        }
        *self = Implicit {
            z: vec![0.0; u + 2 * n],
            plus: vec![0.0; u + n],
            minus: vec![0.0; u + n],
            jacobian: DMatrix::zeros(u + n, u + 2 * n),
            lu: DMatrix::zeros(u, u),
            pivots: vec![0; u],
            y: DMatrix::zeros(u, 2 * n),
            map: DMatrix::zeros(2 * n, 2 * n),
            column: vec![0.0; 2 * n],
            evaluations: self.evaluations,
        };
    }

    /// DΨ_h of the step from `start` whose solution `del` holds.
    fn linearize(
        &mut self,
        del: &mut dyn StepMap,
        sys: &dyn Lagrangian,
        start: StepStart<'_>,
    ) -> Result<(), ModelError> {
        let n = start.q.len();
        let u = del.solution().len();
        self.size(u, n);
        self.z[..u].copy_from_slice(del.solution());
        self.z[u..u + n].copy_from_slice(start.q);
        self.z[u + n..].copy_from_slice(start.p);
        let (t, h) = (start.t, start.h);
        let evaluations = &mut self.evaluations;
        let map = |z: &[f64], out: &mut [f64]| {
            *evaluations += 1;
            let (x, state) = z.split_at(u);
            let (q, p) = state.split_at(n);
            del.step_map(sys, StepStart { t, h, q, p }, x, out)
        };
        // The unknowns are increments of size about h·q̇: their steps are relative to h at least,
        // so that the rule's 1/h in q̇ = δq/h keeps the difference's error at ε^⅔.
        let size = |j: usize, x: f64| if j < u { x.abs().max(h) } else { unit(j, x) };
        let at = Evaluations {
            plus: &mut self.plus,
            minus: &mut self.minus,
        };
        central_jacobian(map, &mut self.z, size, at, &mut self.jacobian)?;
        self.lu.copy_from(&self.jacobian.view((0, 0), (u, u)));
        if lu_in_place(&mut self.lu, &mut self.pivots).is_none() {
            return Err("the tangent map: the step's Jacobian ∂F/∂x is singular at its solution".into());
        }
        self.y.copy_from(&self.jacobian.view((0, u), (u, 2 * n)));
        for mut column in self.y.column_iter_mut() {
            lu_solve(&self.lu, &self.pivots, column.as_mut_slice());
        }
        // δq₁ = δq₀ + δx's last n, δp₁ = P_z₀δz₀ + P_x δx, δx = −Y δz₀.
        for c in 0..2 * n {
            for i in 0..n {
                let identity = if i == c { 1.0 } else { 0.0 };
                self.map[(i, c)] = identity - self.y[(u - n + i, c)];
                let through: f64 = (0..u).map(|j| self.jacobian[(u + i, j)] * self.y[(j, c)]).sum();
                self.map[(n + i, c)] = self.jacobian[(u + i, u + c)] - through;
            }
        }
        Ok(())
    }

    /// x ← DΨ_h x, column by column.
    fn apply(&mut self, x: &mut [f64]) {
        let dim = self.map.nrows();
        for column in x.chunks_exact_mut(dim) {
            for (i, out) in self.column.iter_mut().enumerate() {
                *out = (0..dim).map(|j| self.map[(i, j)] * column[j]).sum();
            }
            column.copy_from_slice(&self.column);
        }
    }
}
