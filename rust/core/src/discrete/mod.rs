//! Discrete Lagrangians L_d(q₀, q₁, h) ≈ ∫₀ʰ L(q, q̇) dt and their discrete Legendre transforms
//!
//! p₀ = −D₁L_d(q₀, q₁),   p₁ = D₂L_d(q₀, q₁)      (Marsden & West, Acta Numerica 2001).
//!
//! A one-step method (q₀, p₀) ↦ (q₁, p₁) defined by these two equations is symplectic, and it
//! conserves p·ξ(q) whenever L_d is invariant under the symmetry ξ. The explicit methods of
//! [`crate::integrators`] are the solutions of these equations for separable systems:
//! Störmer–Verlet for [`Trapezoidal`], symplectic Euler for [`Rectangle`].

mod rectangle;
mod trapezoidal;

pub use rectangle::Rectangle;
pub use trapezoidal::Trapezoidal;

use crate::model::MechanicalSystem;
use crate::ModelError;

/// A discrete Lagrangian for mechanical systems, with its exact slot derivatives.
pub trait DiscreteLagrangian {
    /// L_d(q₀, q₁, h).
    fn value<S: MechanicalSystem + ?Sized>(&self, sys: &S, q0: &[f64], q1: &[f64], h: f64) -> Result<f64, ModelError>;

    /// The discrete Legendre transform F⁻L_d: p₀ = −D₁L_d(q₀, q₁, h).
    fn momentum_minus<S: MechanicalSystem + ?Sized>(
        &self,
        sys: &S,
        q0: &[f64],
        q1: &[f64],
        h: f64,
    ) -> Result<Vec<f64>, ModelError>;

    /// The discrete Legendre transform F⁺L_d: p₁ = D₂L_d(q₀, q₁, h).
    fn momentum_plus<S: MechanicalSystem + ?Sized>(
        &self,
        sys: &S,
        q0: &[f64],
        q1: &[f64],
        h: f64,
    ) -> Result<Vec<f64>, ModelError>;
}

/// The momentum of the discrete velocity, M(q₁ − q₀)/h, shared by the rules here.
fn velocity_momentum<S: MechanicalSystem + ?Sized>(sys: &S, q0: &[f64], q1: &[f64], h: f64) -> (Vec<f64>, Vec<f64>) {
    let v: Vec<f64> = q0.iter().zip(q1).map(|(a, b)| (b - a) / h).collect();
    let mut p = vec![0.0; v.len()];
    sys.mass().momentum(&v, &mut p);
    (v, p)
}

/// p ← p + c·∇V(q).
fn add_gradient<S: MechanicalSystem + ?Sized>(sys: &S, c: f64, q: &[f64], p: &mut [f64]) -> Result<(), ModelError> {
    let mut g = vec![0.0; q.len()];
    sys.gradient(q, &mut g)?;
    p.iter_mut().zip(&g).for_each(|(pi, gi)| *pi += c * gi);
    Ok(())
}
