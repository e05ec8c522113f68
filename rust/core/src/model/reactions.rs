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

use nalgebra::{DMatrix, DVector};

use super::{HolonomicConstraints, Lagrangian, VelocityConstraints};
use crate::ModelError;

/// The forces of constraint at one state.
#[derive(Clone, Debug, PartialEq)]
pub struct Reaction {
    /// λ, one per constraint row (holonomic rows first).
    pub multipliers: Vec<f64>,
    /// The generalized force Cᵀλ.
    pub force: Vec<f64>,
    /// Its power Cᵀλ·q̇ = λ·(Cq̇): 0 for scleronomic constraints on a consistent state, −λ·b for
    /// affine ones.
    pub power: f64,
    /// Σᵢ|(Cᵀλ)ᵢ q̇ᵢ|, the size the power is judged against.
    pub power_size: f64,
}

/// The rows C(q) (m × n) and the affine term b(q) (m) of a model's constraints.
pub type Rows<'a> = &'a dyn Fn(&[f64], &mut DMatrix<f64>, &mut [f64]) -> Result<(), ModelError>;

/// The [`Reaction`] of the constraints `rows` on `system` at (q, p, t). M⁻¹x is q̇(q, x) − q̇(q,
/// 0), exact for every L quadratic in q̇; the derivative along the motion is a fourth-order
/// central difference (relative error about 1e-12 with exact C and b). Allocates: a diagnostic.
pub fn reaction(
    system: &dyn Lagrangian,
    rows: Rows<'_>,
    m: usize,
    q: &[f64],
    p: &[f64],
    t: f64,
) -> Result<Reaction, ModelError> {
    let n = q.len();
    let mut v = vec![0.0; n];
    system.velocity(q, p, t, &mut v)?;
    let mut pdot = vec![0.0; n];
    system.dl_dq(q, &v, t, &mut pdot)?;
    if system.is_forced() {
        let mut f = vec![0.0; n];
        system.force(q, &v, t, &mut f)?;
        pdot.iter_mut().zip(&f).for_each(|(a, b)| *a += b);
    }
    let (mut c, mut b) = (DMatrix::zeros(m, n), vec![0.0; m]);
    let (mut qs, mut ps, mut vs) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    // C(q)q̇ + b at s along the unconstrained motion (q + s q̇, p + s ṗ, t + s).
    let mut hidden = |s: f64, out: &mut DVector<f64>| -> Result<(), ModelError> {
        for i in 0..n {
            qs[i] = q[i] + s * v[i];
            ps[i] = p[i] + s * pdot[i];
        }
        system.velocity(&qs, &ps, t + s, &mut vs)?;
        rows(&qs, &mut c, &mut b)?;
        *out = &c * DVector::from_column_slice(&vs) + DVector::from_column_slice(&b);
        Ok(())
    };
    // The step moves q and p by 1e-3 of their size: truncation (ε⁴) and rounding (ε_mach/ε)
    // errors both near 1e-13.
    let amax = |x: &[f64]| x.iter().fold(0.0_f64, |a, y| a.max(y.abs()));
    let time = |x: &[f64], dx: &[f64]| amax(x).max(1.0) / amax(dx);
    let eps = 1e-3 * time(q, &v).min(time(p, &pdot)).min(1.0);
    let mut at = [
        DVector::zeros(m),
        DVector::zeros(m),
        DVector::zeros(m),
        DVector::zeros(m),
    ];
    for (x, s) in at.iter_mut().zip([eps, -eps, 2.0 * eps, -2.0 * eps]) {
        hidden(s, x)?;
    }
    let rate = (8.0 * (&at[0] - &at[1]) - (&at[2] - &at[3])) / (12.0 * eps);
    let (mut c, mut b) = (DMatrix::zeros(m, n), vec![0.0; m]);
    rows(q, &mut c, &mut b)?;
    // C M⁻¹ Cᵀ, column by column: M⁻¹x = q̇(q, x) − q̇(q, 0).
    let mut v0 = vec![0.0; n];
    system.velocity(q, &vec![0.0; n], t, &mut v0)?;
    let mut gram = DMatrix::zeros(m, m);
    let mut w = vec![0.0; n];
    for k in 0..m {
        let row: Vec<f64> = c.row(k).iter().copied().collect();
        system.velocity(q, &row, t, &mut w)?;
        w.iter_mut().zip(&v0).for_each(|(a, b)| *a -= b);
        gram.set_column(k, &(&c * DVector::from_column_slice(&w)));
    }
    let lambda = gram
        .lu()
        .solve(&(-rate))
        .ok_or("C M⁻¹ Cᵀ is singular: the constraints are not independent here")?;
    let force = c.transpose() * &lambda;
    let power = force.iter().zip(&v).map(|(f, v)| f * v).sum();
    let power_size = force.iter().zip(&v).map(|(f, v)| (f * v).abs()).sum();
    Ok(Reaction {
        multipliers: lambda.as_slice().to_vec(),
        force: force.as_slice().to_vec(),
        power,
        power_size,
    })
}

/// The rows of holonomic constraints: G(q), b = 0.
pub fn holonomic_rows<C: HolonomicConstraints + ?Sized>(
    constraints: &C,
) -> impl Fn(&[f64], &mut DMatrix<f64>, &mut [f64]) -> Result<(), ModelError> + '_ {
    |q, c, b| {
        b.fill(0.0);
        constraints.jacobian(q, c)
    }
}

/// The rows of velocity constraints: A(q) and b(q).
pub fn velocity_rows<C: VelocityConstraints + ?Sized>(
    constraints: &C,
) -> impl Fn(&[f64], &mut DMatrix<f64>, &mut [f64]) -> Result<(), ModelError> + '_ {
    |q, c, b| {
        constraints.matrix(q, c)?;
        constraints.offset(q, b)
    }
}

/// The rows of holonomic and velocity constraints together: [G(q); A(q)] and [0; b(q)].
pub fn mixed_rows<'a, H: HolonomicConstraints + ?Sized, C: VelocityConstraints + ?Sized>(
    holonomic: &'a H,
    velocity: &'a C,
) -> impl Fn(&[f64], &mut DMatrix<f64>, &mut [f64]) -> Result<(), ModelError> + 'a {
    |q, c, b| {
        let (k, m) = (holonomic.count(), velocity.count());
        let (mut g, mut a) = (DMatrix::zeros(k, q.len()), DMatrix::zeros(m, q.len()));
        holonomic.jacobian(q, &mut g)?;
        velocity.matrix(q, &mut a)?;
        c.rows_mut(0, k).copy_from(&g);
        c.rows_mut(k, m).copy_from(&a);
        b[..k].fill(0.0);
        velocity.offset(q, &mut b[k..])
    }
}
