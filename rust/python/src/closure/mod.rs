//! Models given by Python closures, each pyclass beside its adapter: the adapter binds the
//! closures to the GIL and implements the core's model trait by calling them.

pub mod constraints;
pub mod lagrangian;
pub mod mechanical;
pub mod natural;
pub mod nonholonomic;
pub mod readers;

pub use constraints::ClosureConstrained;
pub use lagrangian::{ClosureLagrangian, ClosureLagrangianSystem};
pub use mechanical::{ClosureModel, ClosureSystem};
pub use natural::{ClosureNatural, ClosureNaturalSystem};
pub use nonholonomic::ClosureNonholonomic;

use pyo3::prelude::*;

/// The closure models' classes, for the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ClosureModel>()?;
    m.add_class::<ClosureLagrangian>()?;
    m.add_class::<ClosureNatural>()?;
    m.add_class::<ClosureConstrained>()?;
    m.add_class::<ClosureNonholonomic>()?;
    Ok(())
}
