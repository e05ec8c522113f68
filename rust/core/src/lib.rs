//! # varmech
//!
//! Variational integrators for long conservative simulations of mechanical systems: discrete
//! Lagrangians and their discrete Euler–Lagrange (DEL) equations, RATTLE and SHAKE on holonomic
//! constraints, symplectic compositions, Routh reduction, and the diagnostics that show what a
//! run conserved. This crate is the numerical core; it links no Python.
//!
//! The crate is layered, one folder a layer, each using only the layers before it:
//! - [`model`]: Lagrangian systems L(q, q̇, t), mechanical systems L = ½q̇ᵀMq̇ − V(q) and their
//!   energy, holonomic constraints, Routhians, symmetries;
//! - [`discrete`]: discrete Lagrangians L_d(q₀, q₁, h) and their discrete Legendre transforms;
//! - [`integrators`]: one-step methods in position–momentum form, which method fits which
//!   kind of model ([`integrators::ModelKind`]), the [`integrators::Stepper`] and the
//!   fixed-step run;
//! - [`diagnostics`]: energy series, Noether momenta, conservation verdicts, symplecticity
//!   defect.
//!
//! Beside them, [`solve`] holds the numerics every layer shares, each solver once (Newton's
//! method, central differences, the in-place LU and Cholesky, fixed-point iteration, the secant
//! and bracketing root finders, the interrupt check), [`memory`] the guard on allocations that
//! users' arguments size, and [`scenes`], which use the model layer only, hold the native test problems with
//! their published reference solutions and the catalogue that lists them by name.
//!
//! The binding crate `rust/python` adapts Python closures to [`model::MechanicalSystem`] and
//! [`model::Lagrangian`].

pub mod diagnostics;
pub mod discrete;
pub mod error;
pub mod integrators;
pub mod memory;
pub mod model;
pub mod scenes;
pub mod solve;

pub use error::{Error, ModelError, StepError};
