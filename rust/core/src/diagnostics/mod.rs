//! What a run should conserve, and how well it did.
//!
//! - [`energies`]: H(q, p) = ½pᵀM⁻¹p + V(q) along a run of a mechanical system;
//! - [`EnergyStatistics`]: band, drift rate with its uncertainty, and the verdict
//!   ("bounded" or "secular drift") of an energy-error series;
//! - [`InvariantStatistics`]: the error of a Noether momentum J = p·ξ(q) along a run;
//! - [`symplecticity_defect`]: ‖ΨᵀJΨ − J‖ of a one-step map.

mod conservation;
mod energy;
mod symplecticity;

pub use conservation::{EnergyStatistics, InvariantStatistics, Verdict};
pub use energy::energies;
pub use symplecticity::symplecticity_defect;
