//! What a method integrates: the dynamics of a model, seen through one step's increments.

use nalgebra::DMatrix;

use super::{Carry, Increment, Integrator, ModelKind, StepError, StepStart, StepperState};
use crate::model::{
    self, Constrained, ConstraintSet, EnergyTerms, HolonomicConstraints, Lagrangian, MechanicalSystem, Mixed,
    Nonholonomic, PhaseState, VelocityConstraints,
};
use crate::{Error, ModelError};

/// The dynamics a method integrates: separable mechanical systems take every unconstrained
/// method; a general Lagrangian, wrapped in [`General`], takes the implicit (variational)
/// methods; either on holonomic constraints ([`Constrained`]) takes the constrained ones. Which
/// method fits is decided by [`ModelKind`] alone.
pub trait Dynamics {
    /// Number of coordinates n.
    fn dim(&self) -> usize {
        self.as_lagrangian().dim()
    }

    /// The kind of model, which decides the methods that apply ([`crate::integrators::Method::check`]).
    fn kind(&self) -> ModelKind;

    /// Whether (q₀, p₀) is admissible initial data: the constraints' position and velocity
    /// residuals ([`Dynamics::constraint_residuals`]) within 1e-10 (relative to the state's
    /// size), since the methods hold the constraints where they start and starting off them is
    /// a user error. `q0` and `p0` are finite and of the right length here. A holonomic set that
    /// fails to evaluate is refused naming `q0`; a set with velocity rows fails with the model's
    /// own error at step 0 (the stepper sets its time).
    fn check_initial(&self, q0: &[f64], p0: &[f64]) -> Result<(), Error> {
        let Some(residuals) = self.constraint_residuals(q0, p0) else {
            return Ok(());
        };
        let set = self.constraints();
        let residuals = match set.velocity {
            None => residuals.map_err(|e| Error::invalid("q0", format!("the constraints failed to evaluate: {e}")))?,
            Some(_) => residuals.map_err(at_start)?,
        };
        let (position, velocity) = match (set.holonomic, set.velocity) {
            (_, None) => (("constraints", "|g(q0)|"), ("hidden constraint", "|G(q0)M⁻¹p0|")),
            (None, Some(_)) => (("constraints", "|g(q0)|"), ("velocity constraints", "|A(q0)q̇0|")),
            (Some(_), Some(_)) => (
                ("holonomic constraints", "|g(q0)|"),
                ("constraints' velocities", "|G(q0)q̇0, A(q0)q̇0 + b|"),
            ),
        };
        on_constraints(&residuals, q0, p0, position, velocity)
    }

    /// The model's constraints, holonomic and velocity, as one record; by default none. The
    /// counts, the rows of their forces and whether energy is conserved follow from it.
    fn constraints(&self) -> ConstraintSet<'_> {
        ConstraintSet::default()
    }

    /// The number of constraints m and how many of them are holonomic, which size a
    /// constrained method's buffers.
    fn constraint_counts(&self) -> (usize, usize) {
        self.constraints().counts()
    }

    /// One step's increments (δq, δp) from `start`.
    fn increment(
        &self,
        integrator: &mut Integrator,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError>;

    /// Advances `state` by `steps` steps of its method on this model, carrying `carry`
    /// ([`Carry`]: nothing, the contacts' gaps, tangent vectors), stopping at the first failure
    /// with the last good state kept, or after the first step that `carry` stops at (true
    /// then). The stepper calls it for the steps between two interrupt polls, so that a model
    /// may run them in a loop of its own, specialised to its type and size; by default, one
    /// step after the other.
    fn advance(&self, state: &mut StepperState, steps: usize, carry: Carry<'_, '_, '_>) -> Result<bool, Error> {
        state.steps_carrying(self, steps, carry)
    }

    /// The energy function and its terms at (q, p, t) (E = p·q̇ − L; H for a separable
    /// system), where no constraint does work: None where affine velocity constraints' forces
    /// do (linear constraints' and fixed holonomic ones' do none). A forced run, or one of an L
    /// that depends on t, balances it against the energy put in (`super::Stepper::work`).
    fn energy(&self, q: &[f64], p: &[f64], t: f64) -> Option<Result<EnergyTerms, ModelError>> {
        (!self.constraints().is_affine()).then(|| self.as_lagrangian().energy_terms(q, p, t))
    }

    /// The system as a Lagrangian, for the diagnostics (energy function, Legendre transforms).
    fn as_lagrangian(&self) -> &dyn Lagrangian;

    /// The system as a trait object, for what a generic run hands on (event functions).
    fn as_dynamics(&self) -> &dyn Dynamics;

    /// The system as a separable one, H = ½pᵀM⁻¹p + V(q), for the tangent maps of the kick–drift
    /// methods and of RATTLE ([`super::Tangent`]): a separable model's, or the unconstrained
    /// system of one on holonomic constraints; None for the others.
    fn as_mechanical(&self) -> Option<&dyn MechanicalSystem> {
        None
    }

    /// The residuals of [`Dynamics::constraints`] at (q, p), with their sizes
    /// ([`ConstraintSet::residuals`], q̇ by the inverse Legendre transform); None without
    /// constraints.
    fn constraint_residuals(&self, q: &[f64], p: &[f64]) -> Option<Result<model::Residuals, ModelError>> {
        let set = self.constraints();
        let velocity = |q: &[f64], p: &[f64], v: &mut [f64]| self.as_lagrangian().velocity(q, p, 0.0, v);
        (!set.is_empty()).then(|| set.residuals(&velocity, q, p))
    }

    /// The nearest consistent state ([`ConstraintSet::project`], M⁻¹ from the inverse Legendre
    /// transform); None without constraints.
    fn project(&self, q: &[f64], p: &[f64]) -> Option<Result<PhaseState, Error>> {
        let set = self.constraints();
        let velocity = |q: &[f64], p: &[f64], v: &mut [f64]| self.as_lagrangian().velocity(q, p, 0.0, v);
        let minv = model::inverse_mass(&velocity);
        (!set.is_empty()).then(|| set.project(&minv, &velocity, q, p))
    }

    /// The velocity constraints A(q)q̇ + b(q) = 0 of a nonholonomic system; None for the others.
    fn velocity_constraints(&self) -> Option<&dyn VelocityConstraints> {
        self.constraints().velocity
    }

    /// The holonomic constraints g(q) = 0 of a constrained system; None for the others.
    fn holonomic(&self) -> Option<&dyn HolonomicConstraints> {
        self.constraints().holonomic
    }

    /// The forces of constraint at (q, p, t) into `out` ([`model::Reaction::solve`], made for
    /// this model's n and m, on the rows of [`Dynamics::constraints`]); None without constraints.
    fn reaction(&self, out: &mut model::Reaction, q: &[f64], p: &[f64], t: f64) -> Option<Result<(), ModelError>> {
        let constraints = self.constraints();
        let rows = |q: &[f64], c: &mut DMatrix<f64>, b: &mut [f64]| constraints.rows(q, c, b);
        (!constraints.is_empty()).then(|| out.solve(self.as_lagrangian(), &rows, (q, p, t)))
    }

    /// The [`Self::reaction`]s at the states (`t[k]`, q row k, p row k); None without
    /// constraints.
    fn reactions(&self, t: &[f64], q: &[f64], p: &[f64]) -> Option<Result<model::Reactions, ModelError>> {
        let n = self.dim();
        let mut one = model::Reaction::new(n, self.constraint_counts().0);
        let mut all = model::Reactions::default();
        for (k, t) in t.iter().enumerate() {
            if let Err(e) = self.reaction(&mut one, &q[k * n..(k + 1) * n], &p[k * n..(k + 1) * n], *t)? {
                return Some(Err(e));
            }
            all.push(&one);
        }
        Some(Ok(all))
    }
}

impl<S: MechanicalSystem> Dynamics for S {
    fn kind(&self) -> ModelKind {
        if MechanicalSystem::as_nbody(self).is_some() {
            ModelKind::Gravitational
        } else {
            ModelKind::Separable
        }
    }

    // Inlined, like Integrator::increment, so that a separable step is one loop body: the
    // calls cost a Verlet step of Kepler about 18 instructions of its 110 (callgrind).
    #[inline(always)]
    fn increment(
        &self,
        integrator: &mut Integrator,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError> {
        integrator.increment(self, start, increment)
    }

    fn advance(&self, state: &mut StepperState, steps: usize, carry: Carry<'_, '_, '_>) -> Result<bool, Error> {
        state.advance_separable(self, steps, carry)
    }

    fn as_lagrangian(&self) -> &dyn Lagrangian {
        self
    }

    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }

    fn as_mechanical(&self) -> Option<&dyn MechanicalSystem> {
        Some(self)
    }
}

/// A general Lagrangian L(q, q̇, t), for the implicit variational methods.
pub struct General<'a, L: ?Sized>(pub &'a L);

impl<L: Lagrangian> Dynamics for General<'_, L> {
    fn kind(&self) -> ModelKind {
        ModelKind::Lagrangian
    }

    fn increment(
        &self,
        integrator: &mut Integrator,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError> {
        integrator.increment_lagrangian(self.0, start, increment)
    }

    fn advance(&self, state: &mut StepperState, steps: usize, carry: Carry<'_, '_, '_>) -> Result<bool, Error> {
        state.advance_lagrangian(self.0, steps, carry)
    }

    fn as_lagrangian(&self) -> &dyn Lagrangian {
        self.0
    }

    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }
}

/// A separable mechanical system on holonomic constraints, for RATTLE and SHAKE.
impl<S: MechanicalSystem, C: HolonomicConstraints> Dynamics for Constrained<S, C> {
    fn kind(&self) -> ModelKind {
        ModelKind::ConstrainedSeparable
    }

    fn constraints(&self) -> ConstraintSet<'_> {
        ConstraintSet {
            holonomic: Some(&self.constraints),
            velocity: None,
        }
    }

    fn increment(
        &self,
        integrator: &mut Integrator,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError> {
        integrator.increment_constrained(&self.system, &self.constraints, start, increment)
    }

    fn as_lagrangian(&self) -> &dyn Lagrangian {
        &self.system
    }

    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }

    fn as_mechanical(&self) -> Option<&dyn MechanicalSystem> {
        Some(&self.system)
    }
}

/// A general Lagrangian on holonomic constraints, for the implicit variational methods with
/// multipliers (the constrained DEL equations; see [`super::Del`]).
impl<L: Lagrangian, C: HolonomicConstraints> Dynamics for Constrained<General<'_, L>, C> {
    fn kind(&self) -> ModelKind {
        ModelKind::ConstrainedLagrangian
    }

    fn constraints(&self) -> ConstraintSet<'_> {
        ConstraintSet {
            holonomic: Some(&self.constraints),
            velocity: None,
        }
    }

    fn increment(
        &self,
        integrator: &mut Integrator,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError> {
        integrator.increment_constrained_lagrangian(self.system.0, &self.constraints, start, increment)
    }

    fn as_lagrangian(&self) -> &dyn Lagrangian {
        self.system.0
    }

    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }
}

/// A Lagrangian with velocity constraints A(q)q̇ = 0, for the discrete Lagrange–d'Alembert
/// integrator (see [`super::Del`]).
impl<L: Lagrangian, C: VelocityConstraints> Dynamics for Nonholonomic<L, C> {
    fn kind(&self) -> ModelKind {
        ModelKind::Nonholonomic
    }

    fn constraints(&self) -> ConstraintSet<'_> {
        ConstraintSet {
            holonomic: None,
            velocity: Some(&self.constraints),
        }
    }

    fn increment(
        &self,
        integrator: &mut Integrator,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError> {
        integrator.increment_nonholonomic(&self.system, &self.constraints, start, increment)
    }

    fn as_lagrangian(&self) -> &dyn Lagrangian {
        &self.system
    }

    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }
}

/// A Lagrangian on holonomic and velocity constraints together, for the discrete
/// Lagrange–d'Alembert integrator with g(q₁) = 0 among its discrete constraints (see
/// [`super::Del`]); its kind is the nonholonomic one, whose methods all take both.
impl<L: Lagrangian, H: HolonomicConstraints, C: VelocityConstraints> Dynamics for Mixed<L, H, C> {
    fn kind(&self) -> ModelKind {
        ModelKind::Nonholonomic
    }

    fn constraints(&self) -> ConstraintSet<'_> {
        Mixed::constraints(self)
    }

    fn increment(
        &self,
        integrator: &mut Integrator,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), StepError> {
        integrator.increment_mixed(&self.system, (&self.holonomic, &self.velocity), start, increment)
    }

    fn as_lagrangian(&self) -> &dyn Lagrangian {
        &self.system
    }

    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }
}

/// A model's error evaluating the initial data: its own, at step 0 (the stepper sets its time).
fn at_start(source: ModelError) -> Error {
    Error::Model {
        step: 0,
        time: 0.0,
        source,
    }
}

/// Refuses initial data off the constraints: the position residual (else `q0`) and the velocity
/// residual (else `p0`) within 1e-10 of the state's size, NaN being off. `position` and
/// `velocity` are (what the residual measures, its formula), for the messages.
fn on_constraints(
    residuals: &model::Residuals,
    q0: &[f64],
    p0: &[f64],
    position: (&str, &str),
    velocity: (&str, &str),
) -> Result<(), Error> {
    let scale = q0.iter().chain(p0).fold(1.0_f64, |m, x| m.max(x.abs()));
    for (argument, residual, (what, formula)) in [
        ("q0", residuals.position, position),
        ("p0", residuals.velocity, velocity),
    ] {
        if residual.is_nan() || residual > 1e-10 * scale {
            return Err(Error::invalid(
                argument,
                format!("is off the {what}: {formula} = {residual:.3e}; project the initial state first"),
            ));
        }
    }
    Ok(())
}
