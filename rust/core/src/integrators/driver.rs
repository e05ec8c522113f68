use std::time::{Duration, Instant};

use super::{compensated, Integrator, Method, NewtonOptions, StepError};
use crate::diagnostics::hamiltonian;
use crate::error::check_vector;
use crate::model::{self, Constrained, HolonomicConstraints, Lagrangian, MechanicalSystem, PhaseState};
use crate::{Error, ModelError};

/// What the driver integrates: separable mechanical systems take every method; a general
/// Lagrangian, wrapped in [`General`], takes the implicit (variational) methods.
pub trait Integrable {
    /// Number of coordinates n.
    fn dim(&self) -> usize;

    /// Whether `method` applies to this system.
    fn check_method(&self, method: Method) -> Result<(), Error>;

    /// Whether (q₀, p₀) is admissible initial data: for constrained systems |g(q₀)|∞ and
    /// |G(q₀)q̇₀|∞ within 1e-10 (relative to the state's size), since the methods hold the
    /// constraints where they start and starting off them is a user error. `q0` and `p0` are
    /// finite and of the right length here.
    fn check_initial(&self, q0: &[f64], p0: &[f64]) -> Result<(), Error> {
        let Some(residuals) = self.constraint_residuals(q0, p0) else {
            return Ok(());
        };
        let (position, velocity) =
            residuals.map_err(|e| Error::invalid("q0", format!("the constraints failed to evaluate: {e}")))?;
        let scale = q0.iter().chain(p0).fold(1.0_f64, |m, x| m.max(x.abs()));
        if position > 1e-10 * scale {
            return Err(Error::invalid(
                "q0",
                format!("is off the constraints: |g(q0)| = {position:.3e}; project the initial state first"),
            ));
        }
        if velocity > 1e-10 * scale {
            return Err(Error::invalid(
                "p0",
                format!("is off the hidden constraint: |G(q0)M⁻¹p0| = {velocity:.3e}; project the initial state first"),
            ));
        }
        Ok(())
    }

    /// One step's increments, from (q, p) at time t.
    #[allow(clippy::too_many_arguments)]
    fn increment(
        &self,
        integrator: &mut Integrator,
        t: f64,
        q: &[f64],
        p: &[f64],
        h: f64,
        dq: &mut [f64],
        dp: &mut [f64],
    ) -> Result<(), StepError>;

    /// The conserved energy at (q, p), where the driver can evaluate it.
    fn energy(&self, q: &[f64], p: &[f64]) -> Option<Result<f64, ModelError>>;

    /// The system as a Lagrangian, for the diagnostics (energy function, Legendre transforms).
    fn as_lagrangian(&self) -> &dyn Lagrangian;

    /// (|g(q)|∞, |G(q)M⁻¹p|∞) for a constrained system; None for the others.
    fn constraint_residuals(&self, _q: &[f64], _p: &[f64]) -> Option<Result<(f64, f64), ModelError>> {
        None
    }

    /// The nearest consistent state for a constrained system; None for the others.
    fn project(&self, _q: &[f64], _p: &[f64]) -> Option<Result<PhaseState, Error>> {
        None
    }
}

impl<S: MechanicalSystem> Integrable for S {
    fn dim(&self) -> usize {
        MechanicalSystem::dim(self)
    }

    fn check_method(&self, method: Method) -> Result<(), Error> {
        unconstrained(method)
    }

    fn increment(
        &self,
        integrator: &mut Integrator,
        t: f64,
        q: &[f64],
        p: &[f64],
        h: f64,
        dq: &mut [f64],
        dp: &mut [f64],
    ) -> Result<(), StepError> {
        integrator.increment(self, t, q, p, h, dq, dp)
    }

    fn energy(&self, q: &[f64], p: &[f64]) -> Option<Result<f64, ModelError>> {
        Some(hamiltonian(self, q, p))
    }

    fn as_lagrangian(&self) -> &dyn Lagrangian {
        self
    }
}

/// A general Lagrangian L(q, q̇, t), for the implicit variational methods.
pub struct General<'a, L: ?Sized>(pub &'a L);

impl<L: Lagrangian> Integrable for General<'_, L> {
    fn dim(&self) -> usize {
        self.0.dim()
    }

    fn check_method(&self, method: Method) -> Result<(), Error> {
        unconstrained(method)?;
        if method.info().implicit {
            Ok(())
        } else {
            let reason = format!(
                "{} needs a separable mechanical system; use midpoint or trapezoid",
                method.info().name
            );
            Err(Error::invalid("method", reason))
        }
    }

    fn increment(
        &self,
        integrator: &mut Integrator,
        t: f64,
        q: &[f64],
        p: &[f64],
        h: f64,
        dq: &mut [f64],
        dp: &mut [f64],
    ) -> Result<(), StepError> {
        integrator.increment_lagrangian(self.0, t, q, p, h, dq, dp)
    }

    /// E = p·q̇ − L, unless L depends on t or forces act (then it is not conserved).
    fn energy(&self, q: &[f64], p: &[f64]) -> Option<Result<f64, ModelError>> {
        (!self.0.is_time_dependent() && !self.0.is_forced()).then(|| self.0.energy(q, p, 0.0))
    }

    fn as_lagrangian(&self) -> &dyn Lagrangian {
        self.0
    }
}

/// A constrained method is refused for a system without constraints.
fn unconstrained(method: Method) -> Result<(), Error> {
    if method.info().constrained {
        let reason = format!("{} integrates systems with holonomic constraints", method.info().name);
        return Err(Error::invalid("method", reason));
    }
    Ok(())
}

/// A separable mechanical system on holonomic constraints, for RATTLE and SHAKE.
impl<S: MechanicalSystem, C: HolonomicConstraints> Integrable for Constrained<S, C> {
    fn dim(&self) -> usize {
        MechanicalSystem::dim(&self.system)
    }

    fn check_method(&self, method: Method) -> Result<(), Error> {
        if method.info().constrained {
            return Ok(());
        }
        let reason = format!(
            "{} would ignore the constraints; use rattle, rattle4 or shake",
            method.info().name
        );
        Err(Error::invalid("method", reason))
    }

    fn increment(
        &self,
        integrator: &mut Integrator,
        _t: f64,
        q: &[f64],
        p: &[f64],
        h: f64,
        dq: &mut [f64],
        dp: &mut [f64],
    ) -> Result<(), StepError> {
        integrator.increment_constrained(&self.system, &self.constraints, q, p, h, dq, dp)
    }

    fn energy(&self, q: &[f64], p: &[f64]) -> Option<Result<f64, ModelError>> {
        Some(hamiltonian(&self.system, q, p))
    }

    fn as_lagrangian(&self) -> &dyn Lagrangian {
        &self.system
    }

    fn constraint_residuals(&self, q: &[f64], p: &[f64]) -> Option<Result<(f64, f64), ModelError>> {
        Some(self.residuals(q, p))
    }

    fn project(&self, q: &[f64], p: &[f64]) -> Option<Result<PhaseState, Error>> {
        Some(Constrained::project(self, q, p))
    }
}

/// A general Lagrangian on holonomic constraints, for the implicit variational methods with
/// multipliers (the constrained DEL equations; see [`super::Del`]).
impl<L: Lagrangian, C: HolonomicConstraints> Integrable for Constrained<General<'_, L>, C> {
    fn dim(&self) -> usize {
        self.system.0.dim()
    }

    /// The two-point rules only: Galerkin with multipliers at the step's ends alone falls to
    /// order 2 (measured), since its interior points leave the constraints; full order needs
    /// them constrained too (Jay's SPARK methods).
    fn check_method(&self, method: Method) -> Result<(), Error> {
        if matches!(method, Method::Trapezoid | Method::Midpoint) {
            return Ok(());
        }
        let reason = format!(
            "{} does not integrate a general Lagrangian on constraints; use trapezoid (RATTLE's \
             discrete Lagrangian) or midpoint",
            method.info().name
        );
        Err(Error::invalid("method", reason))
    }

    fn increment(
        &self,
        integrator: &mut Integrator,
        t: f64,
        q: &[f64],
        p: &[f64],
        h: f64,
        dq: &mut [f64],
        dp: &mut [f64],
    ) -> Result<(), StepError> {
        integrator.increment_constrained_lagrangian(self.system.0, &self.constraints, t, q, p, h, dq, dp)
    }

    fn energy(&self, q: &[f64], p: &[f64]) -> Option<Result<f64, ModelError>> {
        self.system.energy(q, p)
    }

    fn as_lagrangian(&self) -> &dyn Lagrangian {
        self.system.0
    }

    fn constraint_residuals(&self, q: &[f64], p: &[f64]) -> Option<Result<(f64, f64), ModelError>> {
        Some(self.residuals_general(q, p))
    }

    fn project(&self, q: &[f64], p: &[f64]) -> Option<Result<PhaseState, Error>> {
        Some(self.project_general(q, p))
    }
}

impl<L: Lagrangian, C: HolonomicConstraints> Constrained<General<'_, L>, C> {
    /// q̇(q, p), the inverse Legendre transform.
    fn velocity(&self) -> impl Fn(&[f64], &[f64], &mut [f64]) -> Result<(), ModelError> + '_ {
        |q, p, v| self.system.0.velocity(q, p, 0.0, v)
    }

    /// (|g(q)|∞, |G(q)q̇(q, p)|∞).
    pub fn residuals_general(&self, q: &[f64], p: &[f64]) -> Result<(f64, f64), ModelError> {
        model::residuals(&self.constraints, &self.velocity(), q, p)
    }

    /// The nearest consistent state, with M(q)⁻¹x = q̇(q, x) − q̇(q, 0) (exact for L quadratic
    /// in q̇, whose inverse Legendre transform is affine in p).
    pub fn project_general(&self, q0: &[f64], p0: &[f64]) -> Result<PhaseState, Error> {
        let velocity = self.velocity();
        let minv = |q: &[f64], x: &[f64], out: &mut [f64]| {
            let mut rest = vec![0.0; x.len()];
            velocity(q, &vec![0.0; x.len()], &mut rest)?;
            velocity(q, x, out)?;
            out.iter_mut().zip(&rest).for_each(|(o, r)| *o -= r);
            Ok(())
        };
        model::project(&self.constraints, &minv, &velocity, q0, p0)
    }
}

/// Options of a fixed-step run.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// The step h > 0.
    pub dt: f64,
    /// Number of steps.
    pub steps: usize,
    /// Keep every k-th state (the initial and the final state are always kept).
    pub save_every: usize,
    /// Add the increments with compensated summation (on by default, as in Hairer's GNI codes).
    pub compensated: bool,
    /// Stop with [`Error::Divergence`] when the relative energy error |H − H₀|/|H₀| at a saved
    /// state exceeds this (the absolute error when H₀ = 0). `None`: only non-finite states stop
    /// the run. Checking costs one potential evaluation per saved state.
    pub max_energy_error: Option<f64>,
    /// The initial time.
    pub t0: f64,
    /// Tolerance and iteration cap of the implicit methods' Newton iteration.
    pub newton: NewtonOptions,
}

impl Options {
    /// `steps` steps of size `dt`, every state kept, compensated summation on.
    pub fn new(dt: f64, steps: usize) -> Self {
        Options {
            dt,
            steps,
            save_every: 1,
            compensated: true,
            max_energy_error: None,
            t0: 0.0,
            newton: NewtonOptions::default(),
        }
    }

    fn check(&self) -> Result<(), Error> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::invalid(
                "dt",
                format!("must be finite and positive, got {}", self.dt),
            ));
        }
        if self.save_every == 0 {
            return Err(Error::invalid("save_every", "must be at least 1"));
        }
        if !self.t0.is_finite() {
            return Err(Error::invalid("t0", "must be finite"));
        }
        let NewtonOptions {
            tolerance,
            max_iterations,
        } = self.newton;
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(Error::invalid(
                "newton_tolerance",
                format!("must be finite and positive, got {tolerance}"),
            ));
        }
        if max_iterations == 0 {
            return Err(Error::invalid("newton_max_iterations", "must be at least 1"));
        }
        match self.max_energy_error {
            Some(x) if x.is_nan() || x <= 0.0 => {
                Err(Error::invalid("max_energy_error", format!("must be positive, got {x}")))
            }
            _ => Ok(()),
        }
    }
}

/// The saved states of a run: row k is (`t[k]`, `q[k]`, `p[k]`); q and p are stored row-major.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    pub dim: usize,
    pub t: Vec<f64>,
    pub q: Vec<f64>,
    pub p: Vec<f64>,
    /// Steps completed.
    pub steps: usize,
    /// Force evaluations made (see [`Integrator::force_evaluations`]).
    pub force_evaluations: u64,
    /// Newton iterations made (implicit methods).
    pub newton_iterations: u64,
    /// Newton iterations made up to each saved state (cumulative; all zero for explicit
    /// methods): their differences give the iterations per step between saves.
    pub newton: Vec<u64>,
    /// Work done by non-conservative forces up to each saved state (forced systems): the
    /// energy balance E(t) − E(0) − W(t) is the discrete Lagrange–d'Alembert check.
    pub work: Vec<f64>,
}

impl Trajectory {
    /// Number of saved states.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// q at saved state k.
    pub fn q_at(&self, k: usize) -> &[f64] {
        &self.q[k * self.dim..(k + 1) * self.dim]
    }

    /// p at saved state k.
    pub fn p_at(&self, k: usize) -> &[f64] {
        &self.p[k * self.dim..(k + 1) * self.dim]
    }

    fn push(&mut self, t: f64, q: &[f64], p: &[f64], integrator: &Integrator) {
        self.t.push(t);
        self.newton.push(integrator.newton_iterations());
        self.work.push(integrator.work());
        self.q.extend_from_slice(q);
        self.p.extend_from_slice(p);
    }
}

/// A run that stopped early: why, and every state saved up to the last good step.
#[derive(Debug)]
pub struct Failure {
    pub error: Error,
    pub partial: Trajectory,
}

/// Polls for interrupts at a stride that adapts to keep polls about 10–40 ms apart, so that a
/// step of 50 ns and a step of 50 ms are both interruptible promptly and cheaply.
struct InterruptPoll {
    stride: usize,
    countdown: usize,
    last: Instant,
}

impl InterruptPoll {
    const FAST: Duration = Duration::from_millis(10);
    const SLOW: Duration = Duration::from_millis(40);

    fn new() -> Self {
        InterruptPoll {
            stride: 1,
            countdown: 1,
            last: Instant::now(),
        }
    }

    /// Whether to poll before this step.
    #[inline]
    fn due(&mut self) -> bool {
        self.countdown -= 1;
        if self.countdown > 0 {
            return false;
        }
        let now = Instant::now();
        let elapsed = now - self.last;
        if elapsed < Self::FAST {
            self.stride = (self.stride * 2).min(1 << 24);
        } else if elapsed > Self::SLOW {
            self.stride = (self.stride / 2).max(1);
        }
        self.last = now;
        self.countdown = self.stride;
        true
    }
}

/// Integrates `sys` from (q0, p0) with `method` for `options.steps` steps of `options.dt`.
///
/// `poll` is called every 10–40 ms of run time; an error from it stops the run with
/// [`Error::Interrupted`] (the binding checks for Ctrl-C there). The step loop allocates
/// nothing beyond the saved states, whose storage is reserved up front.
///
/// On failure the returned [`Failure`] holds every state saved so far and the last good state.
pub fn integrate<S, P>(
    sys: &S,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    options: &Options,
    mut poll: P,
) -> Result<Trajectory, Box<Failure>>
where
    S: Integrable + ?Sized,
    P: FnMut() -> Result<(), ModelError>,
{
    let n = sys.dim();
    let mut traj = Trajectory {
        dim: n,
        ..Default::default()
    };
    let fail = |error, partial| Box::new(Failure { error, partial });
    let energy_check = match options.max_energy_error {
        Some(_) if sys.energy(q0, p0).is_none() => Err(Error::invalid(
            "max_energy_error",
            "needs a conserved energy, and a time-dependent or forced Lagrangian has none",
        )),
        _ => Ok(()),
    };
    if let Err(e) = check_vector("q0", q0, n)
        .and(check_vector("p0", p0, n))
        .and(options.check())
        .and(sys.check_method(method))
        .and(energy_check)
        .and_then(|_| sys.check_initial(q0, p0))
    {
        return Err(fail(e, traj));
    }
    let Options {
        dt,
        steps,
        save_every,
        compensated,
        max_energy_error,
        t0,
        newton,
    } = *options;
    let saved = (steps / save_every).saturating_add(2);
    let reserved = saved.checked_mul(n).is_some_and(|len| {
        traj.t.try_reserve_exact(saved).is_ok()
            && traj.newton.try_reserve_exact(saved).is_ok()
            && traj.work.try_reserve_exact(saved).is_ok()
            && traj.q.try_reserve_exact(len).is_ok()
            && traj.p.try_reserve_exact(len).is_ok()
    });
    if !reserved {
        let gib = saved as f64 * (2 * n + 3) as f64 * 8.0 / (1u64 << 30) as f64;
        let reason =
            format!("keeping {saved} states needs {gib:.3e} GiB, more than can be allocated; raise save_every");
        return Err(fail(Error::invalid("save_every", reason), traj));
    }

    let (mut q, mut p) = (q0.to_vec(), p0.to_vec());
    let (mut dq, mut dp) = (vec![0.0; n], vec![0.0; n]);
    let (mut eq, mut ep) = (vec![0.0; n], vec![0.0; n]);
    // The next state is written beside the current one and swapped in once it is known to be
    // finite, so that a failing step leaves the last good state intact.
    let (mut q_next, mut p_next) = (vec![0.0; n], vec![0.0; n]);
    let (mut eq_next, mut ep_next) = (vec![0.0; n], vec![0.0; n]);
    let mut integrator = Integrator::with_newton(method, n, newton);
    let mut interrupt = InterruptPoll::new();
    traj.push(t0, &q, &p, &integrator);
    let h0 = match max_energy_error.and_then(|_| sys.energy(&q, &p)) {
        None => None,
        Some(energy) => match energy {
            Ok(h) => Some(h),
            Err(source) => {
                return Err(fail(
                    Error::Model {
                        step: 0,
                        time: t0,
                        source,
                    },
                    traj,
                ))
            }
        },
    };

    for step in 1..=steps {
        let time = t0 + (step - 1) as f64 * dt;
        // Stops with the last good state (step − 1) kept, and the work counted.
        let stop = |error: Error, mut traj: Trajectory, q: &[f64], p: &[f64], integrator: &Integrator| {
            if traj.t.last() != Some(&time) {
                traj.push(time, q, p, integrator);
            }
            traj.steps = step - 1;
            traj.force_evaluations = integrator.force_evaluations();
            traj.newton_iterations = integrator.newton_iterations();
            fail(error, traj)
        };
        if interrupt.due() {
            if let Err(source) = poll() {
                return Err(stop(
                    Error::Interrupted { step, time, source },
                    traj,
                    &q,
                    &p,
                    &integrator,
                ));
            }
        }
        if let Err(e) = sys.increment(&mut integrator, time, &q, &p, dt, &mut dq, &mut dp) {
            return Err(stop(e.at(step, time), traj, &q, &p, &integrator));
        }
        let finite = if compensated {
            compensated::add(&q, &eq, &dq, &mut q_next, &mut eq_next)
                & compensated::add(&p, &ep, &dp, &mut p_next, &mut ep_next)
        } else {
            compensated::add_plain(&q, &dq, &mut q_next) & compensated::add_plain(&p, &dp, &mut p_next)
        };
        if !finite {
            let reason =
                "the state became non-finite (the method is unstable at this step size, or the model is singular here)"
                    .to_string();
            return Err(stop(
                Error::Divergence { step, time, reason },
                traj,
                &q,
                &p,
                &integrator,
            ));
        }
        std::mem::swap(&mut q, &mut q_next);
        std::mem::swap(&mut p, &mut p_next);
        if compensated {
            std::mem::swap(&mut eq, &mut eq_next);
            std::mem::swap(&mut ep, &mut ep_next);
        }
        if step % save_every == 0 || step == steps {
            let t = t0 + step as f64 * dt;
            traj.push(t, &q, &p, &integrator);
            if let (Some(tol), Some(h0)) = (max_energy_error, h0) {
                // The state of this step is kept: it is finite, only its energy is off.
                let error = match sys.energy(&q, &p).expect("checked before the first step") {
                    Ok(h) => {
                        let err = (h - h0).abs() / if h0 != 0.0 { h0.abs() } else { 1.0 };
                        (err.is_nan() || err > tol).then(|| {
                            let reason = format!("energy error {err:.3e} exceeds max_energy_error = {tol:.3e}");
                            Error::Divergence { step, time: t, reason }
                        })
                    }
                    Err(source) => Some(Error::Model { step, time: t, source }),
                };
                if let Some(error) = error {
                    traj.steps = step;
                    traj.force_evaluations = integrator.force_evaluations();
                    traj.newton_iterations = integrator.newton_iterations();
                    return Err(fail(error, traj));
                }
            }
        }
    }
    traj.steps = steps;
    traj.force_evaluations = integrator.force_evaluations();
    traj.newton_iterations = integrator.newton_iterations();
    Ok(traj)
}
