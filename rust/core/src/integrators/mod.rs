//! One-step methods in position–momentum form, and the fixed-step driver.
//!
//! Every method advances (qₙ, pₙ) by increments (δq, δp) computed from the step's start, so that
//! the driver can add them with compensated summation ([`compensated`]).
//!
//! - [`Method`]: the catalogue, with order, cost and linear stability limit of each method;
//! - [`KickDrift`]: Störmer–Verlet, symplectic Euler and the symmetric compositions of Verlet;
//! - [`ExplicitRk`]: explicit Euler and classical RK4, the non-structure-preserving baselines;
//! - [`integrate`]: the step loop with saving, divergence detection and interrupt polling.

pub mod compensated;
mod composition;
mod driver;
mod explicit_rk;
mod kick_drift;
mod method;

pub use composition::Composition;
pub use driver::{integrate, Failure, Options, Trajectory};
pub use explicit_rk::ExplicitRk;
pub use kick_drift::KickDrift;
pub use method::{Method, MethodInfo};

use crate::model::MechanicalSystem;
use crate::ModelError;

/// A one-step method Ψ_h: (qₙ, pₙ) ↦ (qₙ + δq, pₙ + δp) with its work buffers.
#[derive(Clone, Debug)]
pub struct Integrator {
    method: Method,
    scheme: Scheme,
}

#[derive(Clone, Debug)]
enum Scheme {
    KickDrift(KickDrift),
    ExplicitRk(ExplicitRk),
}

impl Integrator {
    /// An integrator of `method` for n coordinates; buffers are allocated here, not per step.
    pub fn new(method: Method, n: usize) -> Self {
        let scheme = match method {
            Method::ExplicitEuler => Scheme::ExplicitRk(ExplicitRk::euler(n)),
            Method::Rk4 => Scheme::ExplicitRk(ExplicitRk::rk4(n)),
            Method::SymplecticEuler => Scheme::KickDrift(KickDrift::symplectic_euler(n)),
            _ => Scheme::KickDrift(KickDrift::composition(
                &Composition::of(method).expect("every other method is a composition of Verlet"),
                n,
            )),
        };
        Integrator { method, scheme }
    }

    /// The method this integrator applies.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Forgets the force cached from the last step (first same as last): call it whenever
    /// the next step does not start where the last one ended.
    pub fn reset(&mut self) {
        if let Scheme::KickDrift(s) = &mut self.scheme {
            s.reset();
        }
    }

    /// Force evaluations ∇V made so far.
    pub fn force_evaluations(&self) -> u64 {
        match &self.scheme {
            Scheme::KickDrift(s) => s.force_evaluations(),
            Scheme::ExplicitRk(s) => s.force_evaluations(),
        }
    }

    /// Writes the increments of one step of size h from (q, p) into (dq, dp).
    pub fn increment<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        q: &[f64],
        p: &[f64],
        h: f64,
        dq: &mut [f64],
        dp: &mut [f64],
    ) -> Result<(), ModelError> {
        match &mut self.scheme {
            Scheme::KickDrift(s) => s.increment(sys, q, p, h, dq, dp),
            Scheme::ExplicitRk(s) => s.increment(sys, q, p, h, dq, dp),
        }
    }

    /// One plain step (q, p) ← Ψ_h(q, p), without compensated summation.
    pub fn step<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        q: &mut [f64],
        p: &mut [f64],
        h: f64,
    ) -> Result<(), ModelError> {
        let mut dq = vec![0.0; q.len()];
        let mut dp = vec![0.0; p.len()];
        self.increment(sys, q, p, h, &mut dq, &mut dp)?;
        q.iter_mut().zip(&dq).for_each(|(x, d)| *x += d);
        p.iter_mut().zip(&dp).for_each(|(x, d)| *x += d);
        Ok(())
    }
}
