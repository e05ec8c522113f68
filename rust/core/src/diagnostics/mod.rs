//! What a run should conserve, and how well it did.
//!
//! - [`energies`]: H(q, p) = ½pᵀM⁻¹p + V(q) along a run of a mechanical system, and
//!   [`energy_terms`]: E = p·q̇ − L with its kinetic and potential terms along any run;
//! - [`Statistics`]: the error of a conserved quantity against its scale, its band and drift
//!   rate, and a [`Verdict`] ("conserved to round-off", "bounded", "too short to judge",
//!   "secular drift", "too coarse", "failed"); [`energy_statistics`] builds them for the energy or a forced run's balance;
//! - [`symplecticity_defect`]: ‖ΨᵀJΨ − J‖ of a one-step map;
//! - [`lyapunov`]: Lyapunov exponents from the step's own tangent map;
//! - [`equilibrium`], [`linearize`] and [`modes`]: small oscillations about an equilibrium, on
//!   holonomic constraints too, and
//!   [`stable_step`] and [`accurate_step`]: the step a method takes on them.

mod conservation;
mod energy;
mod lyapunov;
mod modes;
mod symplecticity;

pub use conservation::{Series, Statistics, Verdict};
pub use energy::{energies, energy_statistics, energy_terms};
pub use lyapunov::{lyapunov, LyapunovOptions, Stretching};
pub use modes::{
    accurate_step, equilibrium, linearize, modes, phase_error, stable_step, Equilibrium, Linearization, Model, Modes,
    Shapes,
};
pub use symplecticity::symplecticity_defect;
