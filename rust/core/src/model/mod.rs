//! Models: what is integrated.
//!
//! - [`Lagrangian`]: a Lagrangian system L(q, q̇, t) on ℝⁿ, the most general model;
//! - [`MechanicalSystem`]: the separable case L = ½q̇ᵀMq̇ − V(q) with constant mass, and its
//!   energy [`hamiltonian`] H = ½pᵀM⁻¹p + V(q);
//! - [`Mass`]: the constant mass matrix M (scalar, diagonal or full symmetric positive definite);
//! - [`NaturalSystem`]: L = ½q̇ᵀM(q)q̇ − V(q) with configuration-dependent mass, a
//!   [`Lagrangian`] through [`Natural`];
//! - [`HolonomicConstraints`]: g(q) = 0 with its Jacobian, [`Distances`] for rigid links, and
//!   [`Constrained`], a mechanical system on them;
//! - [`VelocityConstraints`]: nonholonomic constraints A(q)q̇ = 0, and [`Nonholonomic`], a
//!   Lagrangian system on them; [`curvature`], Frobenius' test of whether they integrate;
//! - [`Mixed`]: a Lagrangian system on holonomic and velocity constraints together;
//!   [`ConstraintSet`], a model's constraints of either kind as one record;
//! - [`NBody`]: point masses under Newtonian gravity, the model of the N-body scenes and of
//!   the Wisdom–Holman methods;
//! - [`Rest`]: a model held at rest at q, its multipliers, tangent space and fastest frequency;
//! - [`Routhian`]: Routh reduction, R = L − μ·ċ on the non-cyclic coordinates;
//! - [`Scale`]: the size a conserved quantity's error is judged against;
//! - [`Generator`]: infinitesimal symmetries ξ(q) and their Noether momenta J = p·ξ(q);
//! - [`compiled`]: models whose functions are instruction tapes derived symbolically.
//!
//! Derivatives a model does not supply come from [`crate::solve::difference`].

pub mod compiled;
mod constraint_set;
mod constraints;
mod energy;
mod frobenius;
mod lagrangian;
mod mass;
mod mechanical;
mod mixed;
mod natural;
mod nbody;
mod nonholonomic;
mod reactions;
mod rest;
mod routh;
mod scale;
mod symmetry;

pub use constraint_set::ConstraintSet;
pub use constraints::{
    check_dense, differenced_jacobian, inverse_mass, project, Action, Anchor, Constrained, Distances,
    HolonomicConstraints, Link, PhaseState, Residuals,
};
pub use energy::{hamiltonian, EnergyTerms};
pub use frobenius::curvature;
pub use lagrangian::{delayed_block, delayed_slots, differenced_dl_dt, inverse_legendre, Hessians, Lagrangian};
pub use mass::Mass;
pub use mechanical::MechanicalSystem;
pub use mixed::Mixed;
pub use natural::{differenced_kinetic_gradient, kinetic_gradient_from_mass_derivative, Natural, NaturalSystem};
pub use nbody::{NBody, PairKernel};
pub use nonholonomic::{differenced_derivative, Nonholonomic, VelocityConstraints};
pub use reactions::{Reaction, Reactions, Rows};
pub use rest::{reaction_force, Fastest, ForceAtRest, Rest};
pub use routh::Routhian;
pub use scale::Scale;
pub use symmetry::{momentum_along, Generator};
