//! One model, one method and the state, advanced step by step.

use std::ops::Deref;

use super::interrupt::InterruptPoll;
use super::{compensated, Dynamics, Increment, Integrator, Method, Options, StepStart};
use crate::error::check_vector;
use crate::{Error, ModelError};

/// A model `M` (a reference `&S` to borrow it, a `Box<S>` to own it) with a method's
/// [`Integrator`] and the state (tₙ, qₙ, pₙ) after n steps of size h from (t₀, q₀, p₀):
/// tₙ = t₀ + n·h, (qₙ₊₁, pₙ₊₁) = (qₙ + δq, pₙ + δp), the increments added with compensated
/// summation (Kahan; the lost low-order bits carried in (e_q, e_p)) unless switched off.
///
/// A step allocates nothing, and a step that fails leaves the last good state in place.
#[derive(Debug)]
pub struct Stepper<M> {
    model: M,
    integrator: Integrator,
    t0: f64,
    h: f64,
    steps: usize,
    compensated: bool,
    q: Vec<f64>,
    p: Vec<f64>,
    eq: Vec<f64>,
    ep: Vec<f64>,
    dq: Vec<f64>,
    dp: Vec<f64>,
    // The next state is written beside the current one and swapped in once it is known to be
    // finite, so that a failing step leaves the last good state intact.
    q_next: Vec<f64>,
    p_next: Vec<f64>,
    eq_next: Vec<f64>,
    ep_next: Vec<f64>,
    interrupt: InterruptPoll,
}

impl<M> Stepper<M>
where
    M: Deref<Target: Dynamics>,
{
    /// A stepper of `method` on `model` from (q0, p0) at `options.t0`, with the step
    /// `options.dt`, `options.compensated` summation and `options.newton` for the implicit
    /// methods.
    ///
    /// Refuses, in this order: q0 or p0 of the wrong length or not finite, malformed options, a
    /// method that does not integrate the model's kind ([`Method::check`]), an energy check
    /// (`options.max_energy_error`) on a model without a conserved energy, and initial data off
    /// the constraints ([`Dynamics::check_initial`]).
    pub fn new(model: M, method: Method, q0: &[f64], p0: &[f64], options: &Options) -> Result<Self, Error> {
        let n = model.dim();
        check_vector("q0", q0, n)?;
        check_vector("p0", p0, n)?;
        options.check()?;
        method.check(model.kind())?;
        if options.max_energy_error.is_some() && model.energy(q0, p0).is_none() {
            return Err(Error::invalid(
                "max_energy_error",
                "needs a conserved energy, and a time-dependent or forced Lagrangian has none",
            ));
        }
        model.check_initial(q0, p0)?;
        let zeros = || vec![0.0; n];
        Ok(Stepper {
            integrator: Integrator::with_newton(method, n, options.newton),
            model,
            t0: options.t0,
            h: options.dt,
            steps: 0,
            compensated: options.compensated,
            q: q0.to_vec(),
            p: p0.to_vec(),
            eq: zeros(),
            ep: zeros(),
            dq: zeros(),
            dp: zeros(),
            q_next: zeros(),
            p_next: zeros(),
            eq_next: zeros(),
            ep_next: zeros(),
            interrupt: InterruptPoll::new(),
        })
    }

    /// Advances one step. On failure the state stays at the last good step, and the error
    /// names the step (counted from 1) and the time it started at.
    pub fn step(&mut self) -> Result<(), Error> {
        let step = self.steps + 1;
        let time = self.t();
        let start = StepStart {
            t: time,
            h: self.h,
            q: &self.q,
            p: &self.p,
        };
        let mut increment = Increment {
            dq: &mut self.dq,
            dp: &mut self.dp,
        };
        let model: &M::Target = &self.model;
        if let Err(e) = model.increment(&mut self.integrator, &start, &mut increment) {
            return Err(e.at(step, time));
        }
        let finite = if self.compensated {
            compensated::add(&self.q, &self.eq, &self.dq, &mut self.q_next, &mut self.eq_next)
                & compensated::add(&self.p, &self.ep, &self.dp, &mut self.p_next, &mut self.ep_next)
        } else {
            compensated::add_plain(&self.q, &self.dq, &mut self.q_next)
                & compensated::add_plain(&self.p, &self.dp, &mut self.p_next)
        };
        if !finite {
            let reason =
                "the state became non-finite (the method is unstable at this step size, or the model is singular here)"
                    .to_string();
            return Err(Error::Divergence { step, time, reason });
        }
        std::mem::swap(&mut self.q, &mut self.q_next);
        std::mem::swap(&mut self.p, &mut self.p_next);
        if self.compensated {
            std::mem::swap(&mut self.eq, &mut self.eq_next);
            std::mem::swap(&mut self.ep, &mut self.ep_next);
        }
        self.steps = step;
        Ok(())
    }

    /// Advances `n` steps, calling `poll` before a step every 10–40 ms of run time; an error
    /// from it stops with [`Error::Interrupted`] (the binding checks for Ctrl-C there). On
    /// failure the state stays at the last good step.
    pub fn advance<P>(&mut self, n: usize, mut poll: P) -> Result<(), Error>
    where
        P: FnMut() -> Result<(), ModelError>,
    {
        for _ in 0..n {
            if self.interrupt.due() {
                if let Err(source) = poll() {
                    return Err(Error::Interrupted {
                        step: self.steps + 1,
                        time: self.t(),
                        source,
                    });
                }
            }
            self.step()?;
        }
        Ok(())
    }

    /// The time tₙ = t₀ + n·h.
    pub fn t(&self) -> f64 {
        self.t0 + self.steps as f64 * self.h
    }

    /// The steps n completed.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// The step size h.
    pub fn dt(&self) -> f64 {
        self.h
    }

    /// The positions qₙ.
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// The momenta pₙ.
    pub fn p(&self) -> &[f64] {
        &self.p
    }

    /// The model stepped.
    pub fn model(&self) -> &M::Target {
        &self.model
    }

    /// The method applied.
    pub fn method(&self) -> Method {
        self.integrator.method()
    }

    /// Force evaluations made so far (see [`Integrator::force_evaluations`]).
    pub fn force_evaluations(&self) -> u64 {
        self.integrator.force_evaluations()
    }

    /// Newton iterations made so far (0 for the explicit methods).
    pub fn newton_iterations(&self) -> u64 {
        self.integrator.newton_iterations()
    }

    /// The work done by non-conservative forces so far (forced Lagrangians; 0 otherwise).
    pub fn work(&self) -> f64 {
        self.integrator.work()
    }
}
