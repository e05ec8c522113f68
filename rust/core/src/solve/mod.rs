//! Numerical solvers shared by every layer, each allocation-free in its loop:
//!
//! - `lu`: LU factorisation with partial pivoting, in place;
//! - [`difference`]: gradients and Jacobians by central differences, and the noise floor of
//!   equations built from them;
//! - `newton`: Newton's method, simplified (a kept Jacobian) or full, with [`NewtonOptions`];
//! - [`interrupt`]: when to poll for Ctrl-C, and the check the iterative solves poll.

pub mod difference;
pub mod interrupt;
pub(crate) mod lu;
pub(crate) mod newton;

pub use newton::NewtonOptions;
