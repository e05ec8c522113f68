//! Compiled models: a model's functions (L and its derivatives, or V, ∇V and M; the
//! constraints and their Jacobian) as instruction tapes derived symbolically, evaluated in the
//! core with no call out per evaluation.
//!
//! - [`Tape`]: straight-line SSA code over the inputs (q, q̇, t) and the parameters;
//! - `Code` (feature `jit`, on by default): a tape compiled to machine code by Cranelift, bit for
//!   bit the interpreter's results;

#[cfg(feature = "jit")]
mod jit;
mod tape;

#[cfg(feature = "jit")]
pub use jit::Code;
pub use tape::{sign, Binary, Op, Tape, Unary};
