//! # varmech
//!
//! Variational integrators for long conservative simulations of mechanical systems.
//!
//! The crate is layered, one folder a layer:
//! - [`solve`]: numerical solvers shared by every layer (in-place LU, central differences,
//!   Newton's method);
//! - [`model`]: Lagrangian systems L(q, q̇, t), mechanical systems L = ½q̇ᵀMq̇ − V(q), symmetries;
//! - [`discrete`]: discrete Lagrangians L_d(q₀, q₁, h) and their discrete Legendre transforms;
//! - [`integrators`]: one-step methods in position–momentum form and the fixed-step driver;
//! - [`diagnostics`]: energy, Noether momenta, conservation verdicts, symplecticity defect;
//! - [`scenes`]: native test problems with their published reference solutions.
//!
//! Nothing here links Python: the binding crate `rust/python` adapts Python closures to
//! [`model::MechanicalSystem`].

pub mod diagnostics;
pub mod discrete;
pub mod error;
pub mod integrators;
pub mod model;
pub mod scenes;
pub mod solve;

pub use error::{Error, ModelError};
