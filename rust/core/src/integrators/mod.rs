//! One-step methods in position–momentum form, the stepper that applies them, and the
//! fixed-step run.
//!
//! Every method advances (qₙ, pₙ) by increments (δq, δp) computed from the step's start
//! ([`StepStart`] → [`Increment`]), so that the stepper can add them with compensated summation
//! ([`compensated`]).
//!
//! - [`Method`]: the catalogue, with order, cost and linear stability limit of each method;
//! - [`ModelKind`]: which method integrates which kind of model, and each kind's default;
//! - [`Dynamics`]: what a method integrates (a separable system, a [`General`] Lagrangian,
//!   either on holonomic constraints, or a Lagrangian with velocity constraints);
//! - [`Splitting`]: the coefficients of the kick–drift methods (symplectic Euler, Störmer–Verlet,
//!   its symmetric compositions, the Runge–Kutta–Nyström splittings);
//! - [`KickDrift`]: a [`Splitting`] applied to a separable system;
//! - [`DiscreteEnergy`]: E_d = −∂L_d/∂τ of a kick–drift method's, a two-point or Galerkin rule's step,
//!   which the variational collision integrator conserves across an impact;
//! - [`ExplicitRk`]: explicit Euler and classical RK4, the non-structure-preserving baselines;
//! - [`wisdom_holman`]: the Wisdom–Holman methods of the N-body problem, Kepler drifts and
//!   interaction kicks in Jacobi coordinates, with symplectic correctors ([`WisdomHolman`]);
//! - [`Stepper`]: one model, one method and the state, advanced step by step; its
//!   [`StepperState`] apart from the model, to resume;
//! - [`integrate`]: a run of a [`Stepper`] with saving and an energy check, into a
//!   [`Trajectory`]; [`resume`] goes on from its [`Checkpoint`], bit for bit;
//!   [`integrate_watching`] also watches [`events`], located by partial steps, and contacts;
//! - [`integrate_ensemble`]: many such runs in parallel ([`Ensemble`]), each bit for bit its
//!   single run.

use serde::{Deserialize, Serialize};
mod checkpoint;
mod clear;
mod clock;
pub mod compensated;
mod composition;
mod del;
mod discrete_energy;
mod divergence;
mod dynamics;
mod ensemble;
pub mod events;
mod explicit_rk;
mod impacts;
pub mod jumps;
mod kick_drift;
mod kind;
mod method;
mod options;
mod poll;
mod rattle;
mod run;
mod splitting;
mod step;
mod stepper;
mod surfaces;
mod tangent;
mod trajectory;
pub mod wisdom_holman;

pub use crate::discrete::{Galerkin, Quadrature};
pub use crate::error::StepError;
pub use crate::solve::NewtonOptions;
use checkpoint::derived::Reached;
pub use checkpoint::{Checkpoint, Fingerprint, FORMAT as CHECKPOINT_FORMAT};
pub use clear::{Clear, Gaps};
pub use composition::Composition;
pub use del::{Composed, Del, StepEquations, TwoPoint};
use del::{Constraints, DiscreteConstraint};
pub use discrete_energy::DiscreteEnergy;
pub use divergence::{beyond_limit, BeyondLimit};
pub use dynamics::{Dynamics, General};
pub use ensemble::{
    integrate_ensemble, Ensemble, MemberEvents, MemberWatch, Members, Outcome, Parallel, Shared, Stopped,
};
pub use events::{Detector, EventFunctions, EventSpec, NativeEvent, Occurrence};
pub use explicit_rk::ExplicitRk;
pub use impacts::{Impacts, Switch, Switches};
pub use jumps::{
    impulsive, Blow, Contact, Contacts, Friction, Generalized, Impulse, Law, NativeContact, PointFunction, Schedule,
    Slip, SlipRows, Struck, Watch, Watcher, MAX_IMPACTS,
};
pub use kick_drift::KickDrift;
pub use kind::ModelKind;
use method::one_of;
pub use method::{Feature, Method, MethodInfo};
pub use options::Options;
pub use poll::{Counting, Poll};
pub use rattle::Rattle;
pub use run::{integrate, integrate_watching, resume, resume_watching};
pub use splitting::{Leading, Splitting};
pub use step::{Increment, StepStart};
use stepper::Phase;
pub use stepper::{Carry, Stepper, StepperState};
pub use surfaces::{NativeSurface, Surface};
pub use tangent::Tangent;
pub use trajectory::{Failure, Trajectory};
pub use wisdom_holman::{Kernel, WisdomHolman};

use crate::discrete::{Midpoint, Trapezoidal};
use crate::model::{HolonomicConstraints, Lagrangian, MechanicalSystem, VelocityConstraints};

/// A one-step method Ψ_h: (qₙ, pₙ) ↦ (qₙ + δq, pₙ + δp) with its work buffers.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Integrator {
    method: Method,
    scheme: Scheme,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
enum Scheme {
    KickDrift(KickDrift),
    ExplicitRk(ExplicitRk),
    Midpoint(Del<TwoPoint<Midpoint>>),
    Trapezoid(Del<TwoPoint<Trapezoidal>>),
    Galerkin(Del<Galerkin>),
    ComposedMidpoint(Composed<TwoPoint<Midpoint>>),
    Rattle(Rattle),
    WisdomHolman(WisdomHolman),
}

/// Refuses a method that does not integrate the model's kind ([`Method::check`]) and, for a
/// model with delayed forces, a method without [`Feature::DelayedForces`] (the two-point rules,
/// whose one force node a step the history keeps) or a delay the history cannot read at the
/// step h ([`del::check_delays`]): for a new stepper, a resumed state and a checkpoint alike.
pub(in crate::integrators) fn check_method<S: Dynamics + ?Sized>(
    model: &S,
    method: Method,
    h: f64,
) -> Result<(), crate::Error> {
    method.check(model.kind())?;
    let delays = model.as_lagrangian().delays();
    if delays.is_empty() {
        return Ok(());
    }
    if !method.supports(Feature::DelayedForces) {
        let reason = format!(
            "{} does not take delayed forces; use {}, whose one force node a step the run's history keeps",
            method.info().name,
            one_of(&Method::names(|m| m.supports(Feature::DelayedForces)))
        );
        return Err(crate::Error::invalid("method", reason));
    }
    del::check_delays(model.as_lagrangian(), h)
}

impl Integrator {
    /// An integrator of `method` for n coordinates; buffers are allocated here, not per step.
    pub fn new(method: Method, n: usize) -> Self {
        Self::with_newton(method, n, NewtonOptions::default())
    }

    /// As [`Integrator::new`], with the options of the implicit methods' Newton iteration.
    pub fn with_newton(method: Method, n: usize, newton: NewtonOptions) -> Self {
        let scheme = match method {
            // Cortés–Martínez's step differs only in its discrete constraint (see increment_nonholonomic).
            Method::Midpoint | Method::CortesMartinez => {
                Scheme::Midpoint(Del::new(TwoPoint::new(Midpoint, n), n, newton))
            }
            Method::Dla4 => Scheme::ComposedMidpoint(Composed::new(
                TwoPoint::new(Midpoint, n),
                Composition::of(Method::Yoshida4)
                    .expect("a composition")
                    .gamma()
                    .to_vec(),
                n,
                newton,
            )),
            Method::Trapezoid => Scheme::Trapezoid(Del::new(TwoPoint::new(Trapezoidal, n), n, newton)),
            Method::Galerkin4 => Scheme::Galerkin(Del::new(Galerkin::new(2, n), n, newton)),
            Method::Galerkin6 => Scheme::Galerkin(Del::new(Galerkin::new(3, n), n, newton)),
            // Sized for no constraints; the first constrained step sizes the buffers.
            Method::Rattle => Scheme::Rattle(Rattle::new(false, vec![1.0], newton, n, 0)),
            Method::Shake => Scheme::Rattle(Rattle::new(true, vec![1.0], newton, n, 0)),
            Method::Rattle4 => Scheme::Rattle(Rattle::new(
                false,
                Composition::of(Method::Yoshida4)
                    .expect("a composition")
                    .gamma()
                    .to_vec(),
                newton,
                n,
                0,
            )),
            Method::WisdomHolman => {
                Scheme::WisdomHolman(WisdomHolman::new(Kernel::Standard, 0, n).expect("no corrector"))
            }
            Method::WisdomHolmanCorrected => {
                Scheme::WisdomHolman(WisdomHolman::new(Kernel::Standard, 11, n).expect("WHFast's corrector 11"))
            }
            Method::WisdomHolmanLazyKernel => {
                Scheme::WisdomHolman(WisdomHolman::new(Kernel::LazyModifiedKick, 11, n).expect("corrector 11"))
            }
            Method::ExplicitEuler => Scheme::ExplicitRk(ExplicitRk::euler(n)),
            Method::Rk4 => Scheme::ExplicitRk(ExplicitRk::rk4(n)),
            _ => Scheme::KickDrift(KickDrift::new(
                &Splitting::of(method).expect("every other method is a kick–drift splitting"),
                n,
            )),
        };
        Integrator { method, scheme }
    }

    /// The method this integrator applies.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Forgets the force cached from the last step (first same as last) and the implicit
    /// methods' predictor: call it whenever the next step does not start where the last one
    /// ended.
    pub fn reset(&mut self) {
        match &mut self.scheme {
            Scheme::KickDrift(s) => s.reset(),
            Scheme::Midpoint(s) => s.reset(),
            Scheme::Trapezoid(s) => s.reset(),
            Scheme::Galerkin(s) => s.reset(),
            Scheme::ComposedMidpoint(s) => s.reset(),
            Scheme::Rattle(s) => s.reset(),
            Scheme::WisdomHolman(s) => s.reset(),
            Scheme::ExplicitRk(_) => {}
        }
    }

    /// Sizes the buffers as the first step on a model of n coordinates with m constraints
    /// (`holonomic` of them holonomic) does: a template of a running state's shape.
    pub(super) fn prepare(&mut self, n: usize, m: usize, holonomic: usize) {
        match &mut self.scheme {
            Scheme::Midpoint(s) => s.size_for(n, m, holonomic),
            Scheme::Trapezoid(s) => s.size_for(n, m, holonomic),
            Scheme::Galerkin(s) => s.size_for(n, m, holonomic),
            Scheme::ComposedMidpoint(s) => s.size_for(n, m, holonomic),
            Scheme::Rattle(s) => s.size_for(m),
            Scheme::WisdomHolman(s) => s.prepare(n),
            Scheme::KickDrift(_) | Scheme::ExplicitRk(_) => {}
        }
    }

    /// Keeps the history of the delayed forces of `sys` at the step h: the two-point rules
    /// alone take them ([`check_method`] refuses the other methods).
    pub(super) fn keep_history(&mut self, n: usize, sys: &dyn Lagrangian, h: f64) {
        match &mut self.scheme {
            Scheme::Midpoint(s) => s.keep_history(n, sys, h),
            Scheme::Trapezoid(s) => s.keep_history(n, sys, h),
            _ => {}
        }
    }

    /// Why a decoded integrator's derived values are not those its method computes on `model`
    /// at the state `at` (its caches; see `checkpoint/derived.rs`), if they are not.
    pub(in crate::integrators) fn derived_misfit(&self, model: &dyn Dynamics, at: &Reached<'_>) -> Option<String> {
        match &self.scheme {
            Scheme::KickDrift(s) => s.misfit(model.as_mechanical()?, at),
            Scheme::Rattle(s) => s.misfit(model.as_mechanical()?, model.holonomic()?, at),
            Scheme::Midpoint(s) => s.misfit(model, at),
            Scheme::Trapezoid(s) => s.misfit(model, at),
            Scheme::Galerkin(s) => s.misfit(model, at),
            Scheme::WisdomHolman(s) => s.misfit(model.as_mechanical()?.as_nbody()?, at),
            // A composed stage's cache is not used (its next start is elsewhere), and explicit
            // Runge–Kutta keeps none.
            Scheme::ComposedMidpoint(_) | Scheme::ExplicitRk(_) => None,
        }
    }

    /// The options of the implicit methods' Newton iteration; None for the explicit methods.
    pub fn newton_options(&self) -> Option<NewtonOptions> {
        self.newton_solve().map(|(options, _)| options)
    }

    /// The options and the iterations so far of the methods that solve their step by Newton's
    /// method; None for the others.
    fn newton_solve(&self) -> Option<(NewtonOptions, u64)> {
        match &self.scheme {
            Scheme::Midpoint(s) => Some((s.options(), s.iterations())),
            Scheme::Trapezoid(s) => Some((s.options(), s.iterations())),
            Scheme::Galerkin(s) => Some((s.options(), s.iterations())),
            Scheme::ComposedMidpoint(s) => Some((s.options(), s.iterations())),
            Scheme::Rattle(s) => Some((s.options(), s.iterations())),
            _ => None,
        }
    }

    /// The method's own variables, for a method that keeps them from step to step and shows
    /// them as (q, p) only when synchronised (the Wisdom–Holman methods; see
    /// [`Stepper::advance`]); None for the methods that step (q, p) itself.
    pub(super) fn own_variables(&mut self) -> Option<&mut WisdomHolman> {
        match &mut self.scheme {
            Scheme::WisdomHolman(s) => Some(s),
            _ => None,
        }
    }

    /// The step map of an implicit method's last unconstrained step, for its tangent map; None
    /// for the methods that solve no DEL equations.
    pub(in crate::integrators) fn step_map(&mut self) -> Option<&mut dyn tangent::StepMap> {
        match &mut self.scheme {
            Scheme::Midpoint(s) => Some(s),
            Scheme::Trapezoid(s) => Some(s),
            Scheme::Galerkin(s) => Some(s),
            Scheme::Rattle(s) => Some(s),
            _ => None,
        }
    }

    /// The discrete energy of a Galerkin method's last step, from `start`; None for the other
    /// methods.
    pub(super) fn galerkin_energy(
        &mut self,
        sys: &dyn Lagrangian,
        start: StepStart<'_>,
    ) -> Option<Result<f64, crate::ModelError>> {
        match &mut self.scheme {
            Scheme::Galerkin(s) => Some(s.energy(sys, start)),
            _ => None,
        }
    }

    /// Evaluations made so far: of ∇V for the explicit methods, of D₁L_d or D₂L_d (each one
    /// evaluation of ∂L/∂q and ∂L/∂q̇) for the implicit ones.
    pub fn force_evaluations(&self) -> u64 {
        match &self.scheme {
            Scheme::KickDrift(s) => s.force_evaluations(),
            Scheme::ExplicitRk(s) => s.force_evaluations(),
            Scheme::Midpoint(s) => s.evaluations(),
            Scheme::Trapezoid(s) => s.evaluations(),
            Scheme::Galerkin(s) => s.evaluations(),
            Scheme::ComposedMidpoint(s) => s.evaluations(),
            Scheme::Rattle(s) => s.evaluations(),
            Scheme::WisdomHolman(s) => s.force_evaluations(),
        }
    }

    /// The energy put in so far by non-conservative forces and by L's dependence on t,
    /// −Σ∂L_d/∂t (implicit methods; 0 otherwise).
    pub fn work(&self) -> f64 {
        match &self.scheme {
            Scheme::Midpoint(s) => s.work(),
            Scheme::Trapezoid(s) => s.work(),
            Scheme::Galerkin(s) => s.work(),
            Scheme::ComposedMidpoint(s) => s.work(),
            _ => 0.0,
        }
    }

    /// Newton iterations made so far; None for the methods that solve no equations.
    pub fn newton(&self) -> Option<u64> {
        self.newton_solve().map(|(_, iterations)| iterations)
    }

    /// Newton iterations made so far (0 for the explicit methods).
    pub fn newton_iterations(&self) -> u64 {
        self.newton().unwrap_or(0)
    }

    /// The kick–drift scheme, for the stepper's fixed-size loop.
    pub(super) fn kick_drift(&mut self) -> Option<&mut KickDrift> {
        match &mut self.scheme {
            Scheme::KickDrift(s) => Some(s),
            _ => None,
        }
    }

    /// The next `steps` steps of a general Lagrangian `sys` of N coordinates in the fixed-size
    /// loop of the two-point DEL methods ([`Del::run`]); None where it does not apply (another
    /// method, constraints, forces, or the run's first step, which the general step makes),
    /// stopping after a step whose end is not `clear` (true then, [`Phase::run`]).
    fn run_two_point<S: Lagrangian + ?Sized, const N: usize, C: Clear + ?Sized>(
        &mut self,
        sys: &S,
        phase: Phase<'_>,
        steps: usize,
        clear: &mut C,
    ) -> Option<Result<bool, crate::Error>> {
        match &mut self.scheme {
            Scheme::Midpoint(s) if s.runs_fixed(sys) => Some(s.run::<S, N, C>(sys, phase, steps, clear)),
            Scheme::Trapezoid(s) if s.runs_fixed(sys) => Some(s.run::<S, N, C>(sys, phase, steps, clear)),
            _ => None,
        }
    }

    /// Writes the increments of one step of size h from (q, p) at time t into (δq, δp).
    #[inline(always)]
    pub fn increment<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError> {
        match &mut self.scheme {
            Scheme::KickDrift(s) => Ok(s.increment(sys, start, increment)?),
            Scheme::ExplicitRk(s) => Ok(s.increment(sys, start, increment)?),
            Scheme::Rattle(_) => Err(self.method.refusal(ModelKind::Separable).into()),
            Scheme::WisdomHolman(s) => match sys.as_nbody() {
                Some(model) => s.increment(model, start, increment),
                None => Err(self.method.refusal(ModelKind::Separable).into()),
            },
            _ => self.increment_lagrangian(sys, start, increment),
        }
    }

    /// As [`Integrator::increment`] for a general Lagrangian, which only the implicit
    /// (variational) methods integrate; another method is an error here (runs refuse it before
    /// the first step).
    pub fn increment_lagrangian<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError> {
        match &mut self.scheme {
            Scheme::Midpoint(s) => s.increment(sys, Constraints::None, *start, increment.reborrow()),
            Scheme::Trapezoid(s) => s.increment(sys, Constraints::None, *start, increment.reborrow()),
            Scheme::Galerkin(s) => s.increment(sys, Constraints::None, *start, increment.reborrow()),
            _ => Err(self.method.refusal(ModelKind::Lagrangian).into()),
        }
    }

    /// As [`Integrator::increment_lagrangian`] on holonomic constraints: the constrained DEL
    /// equations of the implicit methods (see [`Del`]).
    pub fn increment_constrained_lagrangian<S, C>(
        &mut self,
        sys: &S,
        constraints: &C,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError>
    where
        S: Lagrangian + ?Sized,
        C: HolonomicConstraints,
    {
        let c = Constraints::Holonomic(constraints);
        match &mut self.scheme {
            Scheme::Midpoint(s) => s.increment(sys, c, *start, increment.reborrow()),
            Scheme::Trapezoid(s) => s.increment(sys, c, *start, increment.reborrow()),
            _ => Err(self.method.refusal(ModelKind::ConstrainedLagrangian).into()),
        }
    }

    /// As [`Integrator::increment_lagrangian`] with velocity constraints: the discrete
    /// Lagrange–d'Alembert equations of the midpoint rule (see [`Del`]), with the discrete
    /// constraint at the midpoint (reversible; `midpoint`, and composed, `dla4`) or at the
    /// step's start (`cortes_martinez`).
    pub fn increment_nonholonomic<S, C>(
        &mut self,
        sys: &S,
        constraints: &C,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError>
    where
        S: Lagrangian + ?Sized,
        C: VelocityConstraints,
    {
        let c = Constraints::Velocity(constraints, self.discrete_constraint());
        match &mut self.scheme {
            Scheme::Midpoint(s) => s.increment(sys, c, *start, increment.reborrow()),
            Scheme::ComposedMidpoint(s) => s.increment(sys, c, *start, increment.reborrow()),
            _ => Err(self.method.refusal(ModelKind::Nonholonomic).into()),
        }
    }

    /// As [`Integrator::increment_nonholonomic`] with holonomic constraints g(q) = 0 beside the
    /// velocity constraints: the discrete Lagrange–d'Alembert equations with g(q₁) = 0 among
    /// the discrete constraints and the momenta put on both hidden constraints (see [`Del`]).
    pub fn increment_mixed<S, H, C>(
        &mut self,
        sys: &S,
        (holonomic, velocity): (&H, &C),
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError>
    where
        S: Lagrangian + ?Sized,
        H: HolonomicConstraints,
        C: VelocityConstraints,
    {
        let c = Constraints::Mixed(holonomic, velocity, self.discrete_constraint());
        match &mut self.scheme {
            Scheme::Midpoint(s) => s.increment(sys, c, *start, increment.reborrow()),
            Scheme::ComposedMidpoint(s) => s.increment(sys, c, *start, increment.reborrow()),
            _ => Err(self.method.refusal(ModelKind::Nonholonomic).into()),
        }
    }

    /// Where the method takes the velocity constraints' discrete constraint: at the step's
    /// start for `cortes_martinez`, at its midpoint (reversible) otherwise.
    fn discrete_constraint(&self) -> DiscreteConstraint {
        match self.method {
            Method::CortesMartinez => DiscreteConstraint::Start,
            _ => DiscreteConstraint::Midpoint,
        }
    }

    /// As [`Integrator::increment`] for a separable system on holonomic constraints, which only
    /// the constrained methods integrate (runs refuse the others before the first step).
    pub fn increment_constrained<S, C>(
        &mut self,
        sys: &S,
        constraints: &C,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError>
    where
        S: MechanicalSystem + ?Sized,
        C: HolonomicConstraints + ?Sized,
    {
        match &mut self.scheme {
            Scheme::Rattle(s) => {
                s.size_for(constraints.count());
                s.increment(sys, constraints, *start, increment.reborrow())
            }
            _ => Err(self.method.refusal(ModelKind::ConstrainedSeparable).into()),
        }
    }
}
