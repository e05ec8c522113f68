//! Compiled models: a model's functions (L and its derivatives, or V, ∇V and M; the
//! constraints and their Jacobian) as instruction tapes derived symbolically, evaluated in the
//! core with no call out per evaluation.
//!
//! - [`Tape`]: straight-line SSA code over the input slots [q, q̇, t] and the parameters;
//! - `Code` (feature `jit`, on by default): a tape compiled to machine code by Cranelift, bit for
//!   bit the interpreter's results;
//! - [`Function`]: one model function, a tape run by its code or by the interpreter;
//! - [`CompiledLagrangian`]: a general L(q, q̇, t) with exact derivatives and Hessians;
//! - [`CompiledSeparable`]: L = ½q̇ᵀMq̇ − V(q) with constant M, for every method;
//! - [`CompiledConstraints`]: g(q) = 0 with its exact Jacobian;
//! - [`CompiledVelocityConstraints`]: A(q)q̇ = 0 with its exact derivatives ∂A/∂q.

/// `with_parameters` of a compiled model whose parameter vector `params` is all that its
/// parameters change: the same functions with another vector (of the same length, finite).
macro_rules! with_parameters {
    ($model:ident) => {
        impl $model {
            /// The same functions with another parameter vector (of the same length, finite).
            pub fn with_parameters(&self, params: &[f64]) -> Result<Self, Error> {
                check_parameters(params, self.params.len())?;
                Ok($model {
                    params: params.to_vec(),
                    ..self.clone()
                })
            }
        }
    };
}

mod constraints;
mod function;
#[cfg(feature = "jit")]
mod jit;
mod lagrangian;
mod separable;
mod tape;
mod velocity_constraints;

pub use constraints::CompiledConstraints;
pub use function::Function;
#[cfg(feature = "jit")]
pub use jit::Code;
pub use lagrangian::CompiledLagrangian;
pub use separable::CompiledSeparable;
pub use tape::{sign, Binary, Op, Tape, Unary};
pub use velocity_constraints::CompiledVelocityConstraints;

use crate::model::{Constrained, Mixed, Nonholonomic};
use crate::Error;

/// A compiled model of each kind the integrators know (see
/// [`crate::integrators::ModelKind`]).
#[derive(Clone, Debug)]
pub enum CompiledModel {
    Separable(CompiledSeparable),
    Lagrangian(CompiledLagrangian),
    ConstrainedSeparable(Constrained<CompiledSeparable, CompiledConstraints>),
    ConstrainedLagrangian(Constrained<CompiledLagrangian, CompiledConstraints>),
    NonholonomicSeparable(Nonholonomic<CompiledSeparable, CompiledVelocityConstraints>),
    NonholonomicLagrangian(Nonholonomic<CompiledLagrangian, CompiledVelocityConstraints>),
    MixedSeparable(Mixed<CompiledSeparable, CompiledConstraints, CompiledVelocityConstraints>),
    MixedLagrangian(Mixed<CompiledLagrangian, CompiledConstraints, CompiledVelocityConstraints>),
}

impl CompiledModel {
    /// The same model with another parameter vector (of the same length, finite); the tapes
    /// and their code are shared.
    pub fn with_parameters(&self, params: &[f64]) -> Result<Self, Error> {
        let constrained = |c: &CompiledConstraints| c.with_parameters(params);
        Ok(match self {
            CompiledModel::Separable(s) => CompiledModel::Separable(s.with_parameters(params)?),
            CompiledModel::Lagrangian(l) => CompiledModel::Lagrangian(l.with_parameters(params)?),
            CompiledModel::ConstrainedSeparable(c) => CompiledModel::ConstrainedSeparable(Constrained {
                system: c.system.with_parameters(params)?,
                constraints: constrained(&c.constraints)?,
            }),
            CompiledModel::ConstrainedLagrangian(c) => CompiledModel::ConstrainedLagrangian(Constrained {
                system: c.system.with_parameters(params)?,
                constraints: constrained(&c.constraints)?,
            }),
            CompiledModel::NonholonomicSeparable(c) => CompiledModel::NonholonomicSeparable(Nonholonomic {
                system: c.system.with_parameters(params)?,
                constraints: c.constraints.with_parameters(params)?,
            }),
            CompiledModel::NonholonomicLagrangian(c) => CompiledModel::NonholonomicLagrangian(Nonholonomic {
                system: c.system.with_parameters(params)?,
                constraints: c.constraints.with_parameters(params)?,
            }),
            CompiledModel::MixedSeparable(c) => CompiledModel::MixedSeparable(Mixed {
                system: c.system.with_parameters(params)?,
                holonomic: constrained(&c.holonomic)?,
                velocity: c.velocity.with_parameters(params)?,
            }),
            CompiledModel::MixedLagrangian(c) => CompiledModel::MixedLagrangian(Mixed {
                system: c.system.with_parameters(params)?,
                holonomic: constrained(&c.holonomic)?,
                velocity: c.velocity.with_parameters(params)?,
            }),
        })
    }

    /// The parameter vector.
    pub fn parameters(&self) -> &[f64] {
        match self {
            CompiledModel::Separable(s) => s.parameters(),
            CompiledModel::Lagrangian(l) => l.parameters(),
            CompiledModel::ConstrainedSeparable(c) => c.system.parameters(),
            CompiledModel::ConstrainedLagrangian(c) => c.system.parameters(),
            CompiledModel::NonholonomicSeparable(c) => c.system.parameters(),
            CompiledModel::NonholonomicLagrangian(c) => c.system.parameters(),
            CompiledModel::MixedSeparable(c) => c.system.parameters(),
            CompiledModel::MixedLagrangian(c) => c.system.parameters(),
        }
    }
}
