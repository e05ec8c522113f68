//! Lagrange's impulsive equations at one state (Byerly 1916, ch. III, Arts. 26–31): a blow
//! changes the momenta by its components of impulse and the positions not at all; constraints
//! A(q)q̇ = 0 that engage suddenly act by the impulse Aᵀλ that puts q̇⁺ on them. A run's
//! impulses ([`super::Schedule`]) apply the same jump inside its step loop.

use nalgebra::{DMatrix, DVector};

use super::Blow;
use crate::model::Lagrangian;
use crate::ModelError;

/// The state just after a blow.
#[derive(Clone, Debug, PartialEq)]
pub struct Response {
    /// p⁺ = p⁻ + P(q).
    pub p: Vec<f64>,
    /// q̇(q, p⁺) and q̇(q, p⁻).
    pub v: Vec<f64>,
    pub v_before: Vec<f64>,
    /// T⁺ − T⁻.
    pub kinetic_change: f64,
}

/// The state just after constraints engage.
#[derive(Clone, Debug, PartialEq)]
pub struct Engagement {
    /// p⁺ = p⁻ + Aᵀλ and q̇⁺ = q̇(q, p⁺), with A q̇⁺ = 0.
    pub p: Vec<f64>,
    pub v: Vec<f64>,
    /// λ = −(A M⁻¹ Aᵀ)⁻¹ A q̇⁻.
    pub multipliers: Vec<f64>,
    /// T⁻ − T⁺.
    pub energy_lost: f64,
    /// Carnot's ½Δq̇ᵀMΔq̇, which `energy_lost` equals for a perfectly inelastic engagement.
    pub carnot: f64,
}

/// M(q)⁻¹, the metric of the inverse Legendre transform q̇ = M⁻¹(p − a(q)): its columns are
/// q̇(q, eᵢ) − q̇(q, 0), exact for a Lagrangian quadratic in q̇.
pub fn inverse_mass(model: &dyn Lagrangian, q: &[f64], t: f64) -> Result<DMatrix<f64>, ModelError> {
    let n = q.len();
    let (mut zero, mut column, mut unit) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    model.velocity(q, &unit, t, &mut zero)?;
    let mut minv = DMatrix::zeros(n, n);
    for i in 0..n {
        unit[i] = 1.0;
        model.velocity(q, &unit, t, &mut column)?;
        unit[i] = 0.0;
        for (k, (c, z)) in column.iter().zip(&zero).enumerate() {
            minv[(k, i)] = c - z;
        }
    }
    Ok(minv)
}

/// The state just after `blow` strikes at (q, p⁻) at time t: p⁺ = p⁻ + P(q), q̇⁺ = q̇(q, p⁺),
/// and the change of kinetic energy (Byerly, Arts. 26–28).
pub fn respond(
    model: &dyn Lagrangian,
    t: f64,
    (q, p): (&[f64], &[f64]),
    blow: &dyn Blow,
) -> Result<Response, ModelError> {
    let n = q.len();
    let mut after = vec![0.0; n];
    blow.components(q, &mut after)?;
    after.iter_mut().zip(p).for_each(|(a, b)| *a += b);
    let (mut v, mut v_before) = (vec![0.0; n], vec![0.0; n]);
    model.velocity(q, &after, t, &mut v)?;
    model.velocity(q, p, t, &mut v_before)?;
    let kinetic_change = model.energy_terms(q, &after, t)?.kinetic - model.energy_terms(q, p, t)?.kinetic;
    Ok(Response {
        p: after,
        v,
        v_before,
        kinetic_change,
    })
}

/// The state just after the constraints A(q)q̇ = 0 (`a`, m × n; the Jacobian of holonomic ones)
/// engage at (q, p⁻) at time t, by Lagrange's impulsive equations Δp = Aᵀλ, A q̇⁺ = 0 (Byerly,
/// Arts. 29–31); None for dependent constraints (A M⁻¹ Aᵀ singular).
pub fn engage(
    model: &dyn Lagrangian,
    t: f64,
    (q, p): (&[f64], &[f64]),
    a: &DMatrix<f64>,
) -> Result<Option<Engagement>, ModelError> {
    let n = q.len();
    let minv = inverse_mass(model, q, t)?;
    let mut v_before = vec![0.0; n];
    model.velocity(q, p, t, &mut v_before)?;
    let gram = a * &minv * a.transpose();
    let Some(multipliers) = (gram.lu())
        .solve(&(a * DVector::from_column_slice(&v_before)))
        .filter(|x| x.iter().all(|x| x.is_finite()))
        .map(|x| -x)
    else {
        return Ok(None);
    };
    let after = DVector::from_column_slice(p) + a.transpose() * &multipliers;
    let mut v = vec![0.0; n];
    model.velocity(q, after.as_slice(), t, &mut v)?;
    let jump = DVector::from_iterator(n, v.iter().zip(&v_before).map(|(a, b)| a - b));
    let mass_jump = (minv.lu().solve(&jump))
        .ok_or_else(|| String::from("the inverse mass matrix M⁻¹ is singular here (L not regular in q̇)"))?;
    let kinetic = |p: &[f64]| model.energy_terms(q, p, t).map(|e| e.kinetic);
    Ok(Some(Engagement {
        p: after.as_slice().to_vec(),
        v,
        multipliers: multipliers.as_slice().to_vec(),
        energy_lost: kinetic(p)? - kinetic(after.as_slice())?,
        carnot: 0.5 * jump.dot(&mass_jump),
    }))
}
