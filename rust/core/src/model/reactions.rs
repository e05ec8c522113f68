//! The forces of constraint at a state: the multipliers λ of the constrained equations of motion
//!
//! ṗ = ∂L/∂q + f + C(q)ᵀλ,   C(q)q̇ + b(q) = 0,
//!
//! C = G and b = 0 for holonomic constraints g(q) = 0 (their hidden constraint), C = A for
//! velocity constraints A(q)q̇ + b(q) = 0, both stacked for mixed ones. Lagrange's sign: the
//! generalized force of the constraints is Cᵀλ, so a contact φ(q) ≥ 0 pushes with λ ≥ 0.
//!
//! λ is the state's own: the one that keeps the constraints' derivative at 0,
//!
//! (C M⁻¹ Cᵀ) λ = −d/dt [C(q)q̇(q, p, t) + b(q)]  along (q̇, ∂L/∂q + f, 1),
//!
//! so the multipliers of a run's saved states converge at the method's order, whatever the
//! method solves internally (RATTLE's λ and μ are each O(h) off, their node average O(h²) for
//! every composition).

use nalgebra::DMatrix;

use super::Lagrangian;
use crate::solve::lu::{lu_in_place, lu_solve};
use crate::ModelError;

/// The forces of constraint at N states, row by row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Reactions {
    /// λ (N × m), one per constraint row (holonomic rows first).
    pub multipliers: Vec<f64>,
    /// The generalized force Cᵀλ (N × n).
    pub force: Vec<f64>,
    /// Its power Cᵀλ·q̇ = λ·(Cq̇): 0 for scleronomic constraints on a consistent state, −λ·b for
    /// affine ones.
    pub power: Vec<f64>,
    /// Σᵢ|(Cᵀλ)ᵢ q̇ᵢ|, the size the power is judged against.
    pub power_size: Vec<f64>,
}

impl Reactions {
    /// Appends one state's reaction.
    pub fn push(&mut self, r: &Reaction) {
        self.multipliers.extend_from_slice(&r.multipliers);
        self.force.extend_from_slice(&r.force);
        self.power.push(r.power);
        self.power_size.push(r.power_size);
    }
}

/// The rows C(q) (m × n) and the affine term b(q) (m) of a model's constraints.
pub type Rows<'a> = &'a dyn Fn(&[f64], &mut DMatrix<f64>, &mut [f64]) -> Result<(), ModelError>;

/// The forces of constraint at one state, with the buffers that compute them (made once, so
/// that an event function of λ allocates nothing per step).
#[derive(Clone, Debug, PartialEq)]
pub struct Reaction {
    /// λ, one per constraint row (holonomic rows first).
    pub multipliers: Vec<f64>,
    /// The generalized force Cᵀλ.
    pub force: Vec<f64>,
    /// Cᵀλ·q̇, and Σᵢ|(Cᵀλ)ᵢ q̇ᵢ|, the size it is judged against.
    pub power: f64,
    pub power_size: f64,
    v: Vec<f64>,
    pdot: Vec<f64>,
    f: Vec<f64>,
    qs: Vec<f64>,
    ps: Vec<f64>,
    vs: Vec<f64>,
    zero: Vec<f64>,
    c: DMatrix<f64>,
    b: Vec<f64>,
    /// C(q)q̇ + b at the four points of the difference.
    at: [Vec<f64>; 4],
    gram: DMatrix<f64>,
    pivots: Vec<usize>,
}

impl Reaction {
    /// For n coordinates and m constraint rows.
    pub fn new(n: usize, m: usize) -> Self {
        let v = || vec![0.0; n];
        Reaction {
            multipliers: vec![0.0; m],
            force: v(),
            power: 0.0,
            power_size: 0.0,
            v: v(),
            pdot: v(),
            f: v(),
            qs: v(),
            ps: v(),
            vs: v(),
            zero: v(),
            c: DMatrix::zeros(m, n),
            b: vec![0.0; m],
            at: std::array::from_fn(|_| vec![0.0; m]),
            gram: DMatrix::zeros(m, m),
            pivots: vec![0; m],
        }
    }

    /// C(q)q̇ + b at s along the unconstrained motion (q + s q̇, p + s ṗ, t + s), into `at[k]`.
    fn hidden(
        &mut self,
        system: &dyn Lagrangian,
        rows: Rows<'_>,
        (q, p, t): (&[f64], &[f64], f64),
        s: f64,
        k: usize,
    ) -> Result<(), ModelError> {
        for i in 0..q.len() {
            self.qs[i] = q[i] + s * self.v[i];
            self.ps[i] = p[i] + s * self.pdot[i];
        }
        system.velocity(&self.qs, &self.ps, t + s, &mut self.vs)?;
        rows(&self.qs, &mut self.c, &mut self.b)?;
        for (j, x) in self.at[k].iter_mut().enumerate() {
            *x = self.b[j] + self.c.row(j).iter().zip(&self.vs).map(|(c, v)| c * v).sum::<f64>();
        }
        Ok(())
    }

    /// The reaction of the constraints `rows` on `system` at (q, p, t). M⁻¹x is q̇(q, x) −
    /// q̇(q, 0), exact for every L quadratic in q̇; the derivative along the motion is a
    /// fourth-order central difference (relative error about 1e-12 with exact C and b).
    pub fn solve(
        &mut self,
        system: &dyn Lagrangian,
        rows: Rows<'_>,
        state: (&[f64], &[f64], f64),
    ) -> Result<(), ModelError> {
        let (q, p, t) = state;
        let m = self.multipliers.len();
        system.velocity(q, p, t, &mut self.v)?;
        system.dl_dq(q, &self.v, t, &mut self.pdot)?;
        if system.is_forced() {
            system.force(q, &self.v, t, &mut self.f)?;
            self.pdot.iter_mut().zip(&self.f).for_each(|(a, b)| *a += b);
        }
        // The step moves q and p by 1e-3 of their size: truncation (ε⁴) and rounding
        // (ε_mach/ε) errors both near 1e-13.
        let amax = |x: &[f64]| x.iter().fold(0.0_f64, |a, y| a.max(y.abs()));
        let time = |x: &[f64], dx: &[f64]| amax(x).max(1.0) / amax(dx);
        let eps = 1e-3 * time(q, &self.v).min(time(p, &self.pdot)).min(1.0);
        for (k, s) in [eps, -eps, 2.0 * eps, -2.0 * eps].into_iter().enumerate() {
            self.hidden(system, rows, state, s, k)?;
        }
        let [plus, minus, plus2, minus2] = &self.at;
        for (j, lambda) in self.multipliers.iter_mut().enumerate() {
            // −d/dt (C q̇ + b), the right-hand side of (C M⁻¹ Cᵀ)λ.
            *lambda = -(8.0 * (plus[j] - minus[j]) - (plus2[j] - minus2[j])) / (12.0 * eps);
        }
        rows(q, &mut self.c, &mut self.b)?;
        // C M⁻¹ Cᵀ, column by column: M⁻¹x = q̇(q, x) − q̇(q, 0).
        system.velocity(q, &self.zero, t, &mut self.f)?;
        for k in 0..m {
            self.ps.iter_mut().zip(self.c.row(k).iter()).for_each(|(x, c)| *x = *c);
            system.velocity(q, &self.ps, t, &mut self.vs)?;
            self.vs.iter_mut().zip(&self.f).for_each(|(a, b)| *a -= b);
            for j in 0..m {
                self.gram[(j, k)] = self.c.row(j).iter().zip(&self.vs).map(|(c, v)| c * v).sum();
            }
        }
        if lu_in_place(&mut self.gram, &mut self.pivots).is_none() {
            return Err("C M⁻¹ Cᵀ is singular: the constraints are not independent here".into());
        }
        lu_solve(&self.gram, &self.pivots, &mut self.multipliers);
        for (i, f) in self.force.iter_mut().enumerate() {
            *f = (0..m).map(|k| self.c[(k, i)] * self.multipliers[k]).sum();
        }
        self.power = self.force.iter().zip(&self.v).map(|(f, v)| f * v).sum();
        self.power_size = self.force.iter().zip(&self.v).map(|(f, v)| (f * v).abs()).sum();
        Ok(())
    }
}
