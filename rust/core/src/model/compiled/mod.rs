//! Compiled models: a model's functions (L and its derivatives, or V, ∇V and M; the
//! constraints and their Jacobian) as instruction tapes derived symbolically, evaluated in the
//! core with no call out per evaluation.
//!
//! - [`Tape`]: straight-line SSA code over the inputs (q, q̇, t) and the parameters;

mod tape;

pub use tape::{sign, Binary, Op, Tape, Unary};
