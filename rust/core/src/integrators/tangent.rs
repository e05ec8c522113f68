//! The tangent map DΨ_h of a step: the step's linearization, applied to tangent vectors
//! (δq, δp), for the variational equations of chaos indicators (Lyapunov spectra, MEGNO).
//!
//! - A kick–drift step is a composition of shears, so its tangent map is one too, exactly: a
//!   drift q ← q + bhM⁻¹p maps δq ← δq + bhM⁻¹δp, a kick p ← p − ah∇V(q) maps
//!   δp ← δp − ahH(q)δq with H = ∂²V/∂q² at the kick's point. With H symmetric each factor has
//!   determinant 1 and is symplectic, so the tangent map is, to round-off, whatever H's
//!   accuracy: a differenced H is symmetrized.
//! - An implicit step (DEL, forced Lagrange–d'Alembert, RATTLE) solves F(x; z₀) = 0 for its
//!   unknowns x (increments, or RATTLE's multipliers λ) from z₀ = (q₀, p₀) and ends at
//!   E(x; z₀) = (q₁, p₁). At the solution, by the implicit function theorem,
//!   δx = −F_x⁻¹F_z₀δz₀, so that
//!
//!   DΨ_h = E_z₀ − E_x F_x⁻¹F_z₀:
//!
//!   the step's own equations differentiated at their solution (central differences of (F, E)
//!   in (x, z₀), error about ε^⅔), not differences of whole steps, which would carry Newton's
//!   tolerance. It holds for every rule's equations alike (midpoint, trapezoid, Galerkin) and
//!   for forces: a damped step's volume change det DΨ_h comes out as the step makes it. RATTLE's
//!   step maps every (q₀, p₀) onto the constraint manifold, so DΨ_h maps every vector into its
//!   tangent space there (and its rank is 2(n − m)).

use nalgebra::DMatrix;

use super::clear::Clear;
use super::{
    one_of, Del, Dynamics, Feature, Integrator, Method, ModelKind, Rattle, Splitting, StepEquations, StepStart,
};
use crate::model::{Mass, MechanicalSystem};
use crate::solve::difference::{central_jacobian, unit, Evaluations};
use crate::solve::lu::{lu_in_place, lu_solve};
use crate::solve::sized;
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
    /// Lagrangian (forced or not), RATTLE on a separable model with holonomic constraints.
    /// Refused, naming the argument: another method (SHAKE, RATTLE's compositions), a kick–drift
    /// method on a model that is not separable, other constraints, and delayed forces (the step
    /// then depends on the run's past, so it is no map of (q, p) alone).
    pub fn new<S: Dynamics + ?Sized>(method: Method, model: &S) -> Result<Tangent, Error> {
        let n = model.dim();
        let with_map = |kind: Option<ModelKind>| {
            one_of(&Method::names(|m| {
                m.supports(Feature::TangentMap) && kind.is_none_or(|kind| kind.admits(m))
            }))
        };
        if !method.supports(Feature::TangentMap) {
            let reason = format!(
                "{} has no tangent map here; use a kick–drift method, an implicit rule or RATTLE: {}",
                method.info().name,
                with_map(None)
            );
            return Err(Error::invalid("method", reason));
        }
        let map = if let Some(splitting) = Splitting::of(method) {
            // A constrained model's system is separable too, but its steps are RATTLE's.
            if model.as_mechanical().is_none() || model.holonomic().is_some() {
                let reason = format!(
                    "the tangent map of {} (a kick–drift step) needs a separable model, L = ½q̇ᵀMq̇ − V(q); \
                     this one is not: take {}, whose implicit steps have one for any L",
                    method.info().name,
                    with_map(Some(ModelKind::Lagrangian))
                );
                return Err(Error::invalid("model", reason));
            }
            Map::Shears(Shears::new(splitting, n))
        } else if method == Method::Rattle {
            // RATTLE integrates separable models on holonomic constraints alone: the method
            // check refuses the others, naming the method.
            method.check(model.kind())?;
            Map::Implicit(Implicit::default())
        } else {
            // The implicit rules.
            if !matches!(
                model.kind(),
                ModelKind::Separable | ModelKind::Lagrangian | ModelKind::Gravitational
            ) {
                let reason = format!(
                    "has constraints: the implicit rules' tangent map here is that of an unconstrained step; on \
                     holonomic constraints of a separable model, that of {} maps the constraint manifold's \
                     tangent space",
                    with_map(Some(ModelKind::ConstrainedSeparable))
                );
                return Err(Error::invalid("model", reason));
            }
            if !model.as_lagrangian().delays().is_empty() {
                let reason = "has delayed forces: its step depends on the run's past as well as on (q, p), so \
                              it has no tangent map in (q, p) alone";
                return Err(Error::invalid("model", reason));
            }
            Map::Implicit(Implicit::default())
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

    /// The vectors `x` carried through steps of size h of a kick–drift method on `sys` from
    /// (q, p), each step's shears applied at the check ([`Clear`]) at its end inside the
    /// method's own loop; None for an implicit step's map, which needs the step's solution
    /// from its integrator (the loop holds it).
    pub(super) fn carried<'a, S: MechanicalSystem + ?Sized>(
        &'a mut self,
        sys: &'a S,
        h: f64,
        (q, p): (&[f64], &[f64]),
        x: &'a mut [f64],
        large: f64,
    ) -> Option<Carried<'a, S>> {
        let Map::Shears(shears) = &mut self.map else {
            return None;
        };
        self.q.copy_from_slice(q);
        self.p.copy_from_slice(p);
        Some(Carried {
            sys,
            shears,
            h,
            start: (&mut self.q, &mut self.p),
            x,
            large,
            failed: None,
        })
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
                s.apply(sys, h, (&self.q, &self.p), end, x)
            }
            Map::Implicit(s) => {
                let step = integrator
                    .step_map()
                    .expect("an implicit method, checked by Tangent::new");
                s.linearize(step, model, start)?;
                s.apply(x);
                Ok(())
            }
        }
    }
}

/// Tangent vectors carried by a kick–drift step's shears as the check at each step's end
/// ([`Clear`]): the step clear once its map has carried them and none is past `large`; its
/// map's failure kept in `failed`, the loop stopped.
pub(super) struct Carried<'a, S: ?Sized> {
    sys: &'a S,
    shears: &'a mut Shears,
    h: f64,
    /// The step's start (q₀, p₀): the last step's end.
    start: (&'a mut Vec<f64>, &'a mut Vec<f64>),
    x: &'a mut [f64],
    large: f64,
    pub(super) failed: Option<ModelError>,
}

impl<S: MechanicalSystem + ?Sized> Clear for Carried<'_, S> {
    // Inlined into the method's loop, where q and p are arrays: their copies then unroll.
    #[inline(always)]
    fn clear(&mut self, q: &[f64], p: &[f64]) -> bool {
        let (q0, p0) = (&mut *self.start.0, &mut *self.start.1);
        if let Err(e) = self.shears.apply(self.sys, self.h, (q0, p0), q, self.x) {
            self.failed = Some(e);
            return false;
        }
        q0.copy_from_slice(q);
        p0.copy_from_slice(p);
        !past(self.x, self.large)
    }
}

/// Whether a component of `x` is past `large` in magnitude, or NaN (a map that overflowed).
pub(super) fn past(x: &[f64], large: f64) -> bool {
    x.iter().any(|v| v.abs() > large || v.is_nan())
}

/// A kick–drift step's tangent map: its stages replayed from the step's start for H at each
/// kick's q (the stage momenta where a later drift reads them), then each column carried
/// through all the shears at once, so that its entries stay in registers between them.
#[derive(Clone, Debug)]
struct Shears {
    splitting: Splitting,
    n: usize,
    q: Vec<f64>,
    p: Vec<f64>,
    v: Vec<f64>,
    force: Vec<f64>,
    /// H at each kick's q (n × n, symmetric, so that column r is row r), kick by kick.
    hessians: Vec<f64>,
    /// The q of the last kick's H, where the next step's first kick takes it again, while
    /// `last_kept` holds.
    last_at: Vec<f64>,
    last_kept: bool,
    /// A differenced H, and the gradients it takes.
    differenced: DMatrix<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    /// Evaluations of ∇V and of H (exact or differenced) made.
    evaluations: u64,
}

impl Shears {
    fn new(splitting: Splitting, n: usize) -> Self {
        let buffer = || vec![0.0; n];
        Shears {
            hessians: vec![0.0; splitting.kicks().len() * n * n],
            splitting,
            n,
            q: buffer(),
            p: buffer(),
            v: buffer(),
            force: buffer(),
            last_at: buffer(),
            last_kept: false,
            differenced: DMatrix::zeros(n, n),
            plus: buffer(),
            minus: buffer(),
            evaluations: 0,
        }
    }

    /// The step of size h from (q₀, p₀) to q₁ = `end` applied to the columns of `x`: each
    /// kick's H taken where that kick acts (a last kick after a drift acts at q₁, the replay's
    /// last q but for round-off, where the next step's first kick takes the same H again).
    fn apply<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        h: f64,
        start: (&[f64], &[f64]),
        end: &[f64],
        x: &mut [f64],
    ) -> Result<(), ModelError> {
        let n = self.n;
        sized!(replay(self, sys, h, start, end; n))?;
        sized!(shear(&self.splitting, h, sys.mass(), &self.hessians, &mut self.v, x; n));
        Ok(())
    }

    /// H = ∂²V/∂q² at the stage's q into kick i's place: the model's own, or central
    /// differences of ∇V ([`central_jacobian`]), symmetrized.
    fn hessian<S: MechanicalSystem + ?Sized>(&mut self, sys: &S, i: usize) -> Result<(), ModelError> {
        let n = self.n;
        let slot = &mut self.hessians[i * n * n..(i + 1) * n * n];
        self.evaluations += 1;
        if let Some(exact) = sys.hessian(&self.q, slot) {
            return exact;
        }
        let at = Evaluations {
            plus: &mut self.plus,
            minus: &mut self.minus,
        };
        central_jacobian(
            |q, out| sys.gradient(q, out),
            &mut self.q,
            unit,
            at,
            &mut self.differenced,
        )?;
        self.evaluations += 2 * n as u64 - 1;
        for i in 0..n {
            for j in 0..n {
                slot[i * n + j] = 0.5 * (self.differenced[(i, j)] + self.differenced[(j, i)]);
            }
        }
        Ok(())
    }
}

/// The stages of [`Shears::apply`] on n coordinates, a literal for small n ([`sized!`]): each
/// kick's H, the kept one at the step's start where it is the last step's last.
#[inline(always)]
fn replay<S: MechanicalSystem + ?Sized>(
    shears: &mut Shears,
    sys: &S,
    h: f64,
    (q0, p0): (&[f64], &[f64]),
    end: &[f64],
    n: usize,
) -> Result<(), ModelError> {
    let mass = sys.mass();
    shears.q[..n].copy_from_slice(&q0[..n]);
    shears.p[..n].copy_from_slice(&p0[..n]);
    let kept = shears.last_kept && shears.last_at[..n] == q0[..n];
    // Forgotten until this step's last H is whole, so that a failed evaluation is not kept.
    shears.last_kept = false;
    let last = shears.splitting.kicks().len() - 1;
    for i in 0..=last {
        let a = shears.splitting.kicks()[i];
        if i > 0 {
            let b = shears.splitting.drifts()[i - 1] * h;
            if i == last {
                shears.q[..n].copy_from_slice(&end[..n]);
            } else {
                mass.velocity(&shears.p, &mut shears.v);
                shears.q.iter_mut().zip(&shears.v).for_each(|(q, v)| *q += b * v);
            }
        }
        if a == 0.0 {
            continue;
        }
        if i == 0 && kept {
            shears.hessians.copy_within(last * n * n..(last + 1) * n * n, 0);
        } else {
            shears.hessian(sys, i)?;
        }
        // The stage momenta, for the drifts after this kick but the last, which ends at q₁.
        if i + 1 < last {
            shears.evaluations += 1;
            sys.gradient(&shears.q, &mut shears.force)?;
            shears
                .p
                .iter_mut()
                .zip(&shears.force)
                .for_each(|(p, f)| *p -= a * h * f);
        }
    }
    if shears.splitting.kicks()[last] != 0.0 {
        shears.last_at[..n].copy_from_slice(&end[..n]);
        shears.last_kept = true;
    }
    Ok(())
}

/// Every column (δq, δp) of `x` through the step's shears in turn, of n coordinates (a literal
/// for small n, [`sized!`], so that the column's loops unroll): a drift δq += bhM⁻¹δp, a kick
/// δp −= ahH δq with kick i's H. Column by column, so that no shear's loads wait on the last
/// one's stores.
#[inline(always)]
fn shear(splitting: &Splitting, h: f64, mass: &Mass, hessians: &[f64], velocity: &mut [f64], x: &mut [f64], n: usize) {
    let (kicks, drifts) = (splitting.kicks(), splitting.drifts());
    let velocity = &mut velocity[..n];
    for column in x.chunks_exact_mut(2 * n) {
        let (dq, dp) = column.split_at_mut(n);
        for (i, &a) in kicks.iter().enumerate() {
            if i > 0 {
                let b = drifts[i - 1] * h;
                mass.velocity(dp, velocity);
                dq.iter_mut().zip(&*velocity).for_each(|(d, v)| *d += b * v);
            }
            if a == 0.0 {
                continue;
            }
            let a = a * h;
            let hessian = &hessians[i * n * n..(i + 1) * n * n];
            for (d, row) in dp.iter_mut().zip(hessian.chunks_exact(n)) {
                *d -= a * row.iter().zip(dq.iter()).map(|(h, x)| h * x).sum::<f64>();
            }
        }
    }
}

/// An implicit step's map as its tangent map linearizes it: the solution x of its equations
/// that the step left, and at any (x, q₀, p₀) the equations F and the end (q₁, p₁)
/// ([`Del::step_map`], [`super::Rattle::step_map`]).
pub(super) trait StepMap {
    fn solution(&self) -> &[f64];

    /// The size of the unknowns at the step h below which their differences are not taken:
    /// where a change of about that size moves the step's end by a change of order 1 (h, times
    /// the velocities, for increments; 2/h² for multipliers, which move q₁ by (h²/2)M⁻¹Gᵀλ).
    fn unknowns_scale(&self, h: f64) -> f64;

    fn step_map(
        &mut self,
        model: &dyn Dynamics,
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError>;
}

impl StepMap for Rattle {
    fn solution(&self) -> &[f64] {
        self.multipliers()
    }

    fn unknowns_scale(&self, h: f64) -> f64 {
        2.0 / (h * h)
    }

    fn step_map(
        &mut self,
        model: &dyn Dynamics,
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        let sys = model
            .as_mechanical()
            .expect("RATTLE's model is separable, checked by Tangent::new");
        let constraints = model
            .holonomic()
            .expect("RATTLE's model is constrained, checked by Tangent::new");
        Rattle::step_map(self, (sys, constraints), start, x, out)
    }
}

impl<Sc: StepEquations> StepMap for Del<Sc> {
    fn solution(&self) -> &[f64] {
        Del::solution(self)
    }

    fn unknowns_scale(&self, h: f64) -> f64 {
        h
    }

    fn step_map(
        &mut self,
        model: &dyn Dynamics,
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        Del::step_map(self, model.as_lagrangian(), start, x, out)
    }
}

/// The tangent map of an implicit step, with its buffers (sized at the first step: u unknowns,
/// n coordinates): z = (x, q₀, p₀), the Jacobian of (F, q₁, p₁) in z, F_x's factors,
/// Y = F_x⁻¹F_z₀ and DΨ_h itself.
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
    /// Evaluations of the step's map (F and the end together).
    evaluations: u64,
}

impl Implicit {
    fn size(&mut self, u: usize, n: usize) {
        if self.z.len() == u + 2 * n && self.map.nrows() == 2 * n {
            return;
        }
        let w = u + 2 * n;
        *self = Implicit {
            z: vec![0.0; w],
            plus: vec![0.0; w],
            minus: vec![0.0; w],
            jacobian: DMatrix::zeros(w, w),
            lu: DMatrix::zeros(u, u),
            pivots: vec![0; u],
            y: DMatrix::zeros(u, 2 * n),
            map: DMatrix::zeros(2 * n, 2 * n),
            column: vec![0.0; 2 * n],
            evaluations: self.evaluations,
        };
    }

    /// DΨ_h of the step from `start` whose solution `step` holds: with E = (q₁, p₁) and the
    /// unknowns' δx = −F_x⁻¹F_z₀δz₀, DΨ_h = E_z₀ − E_x F_x⁻¹F_z₀.
    fn linearize(
        &mut self,
        step: &mut dyn StepMap,
        model: &dyn Dynamics,
        start: StepStart<'_>,
    ) -> Result<(), ModelError> {
        let n = start.q.len();
        let u = step.solution().len();
        self.size(u, n);
        self.z[..u].copy_from_slice(step.solution());
        self.z[u..u + n].copy_from_slice(start.q);
        self.z[u + n..].copy_from_slice(start.p);
        let (t, h) = (start.t, start.h);
        // The unknowns' steps are relative to their scale at least, so that the difference's
        // error stays at ε^⅔ of the end it moves (a rule's 1/h in q̇ = δq/h, RATTLE's h² in q₁).
        let floor = step.unknowns_scale(h);
        let size = move |j: usize, x: f64| if j < u { x.abs().max(floor) } else { unit(j, x) };
        let evaluations = &mut self.evaluations;
        let map = |z: &[f64], out: &mut [f64]| {
            *evaluations += 1;
            let (x, state) = z.split_at(u);
            let (q, p) = state.split_at(n);
            step.step_map(model, StepStart { t, h, q, p }, x, out)
        };
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
        for c in 0..2 * n {
            for i in 0..2 * n {
                let through: f64 = (0..u).map(|j| self.jacobian[(u + i, j)] * self.y[(j, c)]).sum();
                self.map[(i, c)] = self.jacobian[(u + i, u + c)] - through;
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
