//! The core's integration tests, one module a subject, built as one test binary (one link
//! instead of one a file). `allocation.rs` is a binary of its own: it installs a counting
//! global allocator.

mod common;

mod bits;
mod catalogue;
mod charged_particle;
mod checkpoint;
mod compiled;
mod constraints;
mod convergence;
mod crafted_checkpoints;
mod damped_driven_pendulum;
mod discrete_energy;
mod ensemble;
mod events;
mod failures;
mod forcing;
mod general_lagrangian;
mod heavy_top;
mod hessians;
mod holds;
mod impacts;
mod impulses;
#[cfg(feature = "jit")]
mod jit;
mod kepler;
mod kepler_polar;
mod lyapunov;
mod mixed_constraints;
mod modes;
mod nbody_kernel;
mod nonholonomic;
mod nonholonomic_scenes;
mod nonholonomic_variants;
mod properties;
mod reactions;
mod routh;
mod solar_system;
mod splitting;
mod spurious_branch;
mod stability;
mod stepper;
mod time_dependent;
mod variational;
mod wisdom_holman;
