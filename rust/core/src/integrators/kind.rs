//! Which method integrates which kind of model: the one table that decides it, words the
//! refusal and names each kind's default method.

use super::{one_of, Method, MethodInfo, Splitting};
use crate::Error;

/// The kinds of model the methods tell apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ModelKind {
    /// A separable mechanical system L = ½q̇ᵀMq̇ − V(q) with constant M: every unconstrained
    /// method applies (the implicit ones through its Lagrangian).
    Separable,
    /// A general Lagrangian L(q, q̇, t), natural systems L = ½q̇ᵀM(q)q̇ − V(q) included: the
    /// implicit (variational) methods only.
    Lagrangian,
    /// A separable mechanical system on holonomic constraints g(q) = 0: RATTLE and SHAKE.
    ConstrainedSeparable,
    /// A general Lagrangian on holonomic constraints: the constrained DEL equations of the
    /// two-point rules.
    ConstrainedLagrangian,
    /// A Lagrangian (separable, natural or general) with velocity constraints A(q)q̇ = 0, alone
    /// or beside holonomic ones g(q) = 0 ([`crate::model::Mixed`]): the discrete
    /// Lagrange–d'Alembert integrators on the midpoint rule (see [`super::Del`]), the
    /// reversible one, its order-4 composition, and Cortés–Martínez's non-reversible one, each
    /// with g(q₁) = 0 among its discrete constraints when there are holonomic ones.
    Nonholonomic,
    /// The gravitational N-body problem ([`crate::model::NBody`]), a separable system with a
    /// dominant central body: every method of a separable system and the Wisdom–Holman methods.
    Gravitational,
}

impl ModelKind {
    /// Whether `method` integrates a model of this kind.
    pub fn admits(self, method: Method) -> bool {
        use Method::*;
        match self {
            ModelKind::Separable => {
                !ModelKind::ConstrainedSeparable.admits(method)
                    && !Method::WISDOM_HOLMAN.contains(&method)
                    && !Method::NONHOLONOMIC.contains(&method)
            }
            ModelKind::Gravitational => ModelKind::Separable.admits(method) || Method::WISDOM_HOLMAN.contains(&method),
            ModelKind::Lagrangian => matches!(method, Midpoint | Trapezoid | Galerkin4 | Galerkin6),
            ModelKind::ConstrainedSeparable => Method::CONSTRAINED.contains(&method),
            // Galerkin with multipliers at the step's ends alone falls to order 2 (measured),
            // since its interior points leave the constraints; full order needs them
            // constrained too (Jay's SPARK methods).
            ModelKind::ConstrainedLagrangian => matches!(method, Midpoint | Trapezoid),
            // Its reversibility needs the constraint at the midpoint, where the midpoint rule
            // evaluates L; the trapezoidal rule's ends would take another discrete constraint.
            // Cortés–Martínez's constraint at the start is the non-reversible contrast.
            ModelKind::Nonholonomic => matches!(method, Midpoint | Dla4 | CortesMartinez),
        }
    }

    /// The method a run uses when none is given: Störmer–Verlet for a separable system, the
    /// midpoint rule for a general Lagrangian, RATTLE on constraints, and the trapezoidal rule
    /// (RATTLE's discrete Lagrangian) for a general Lagrangian on constraints; the discrete
    /// Lagrange–d'Alembert integrator (midpoint) on velocity constraints.
    pub fn default_method(self) -> Method {
        match self {
            ModelKind::Separable | ModelKind::Gravitational => Method::Verlet,
            ModelKind::Lagrangian | ModelKind::Nonholonomic => Method::Midpoint,
            ModelKind::ConstrainedSeparable => Method::Rattle,
            ModelKind::ConstrainedLagrangian => Method::Trapezoid,
        }
    }

    /// The method a measurement uses when it wants accuracy more than speed (locating Poincaré
    /// crossings, say): order 6, by Kahan–Li's 9-stage composition or the Galerkin integrator of
    /// degree 3; RATTLE's order-4 composition on constraints; and the trapezoidal rule, the
    /// best order there is, for a general Lagrangian on constraints; Yoshida's triple jump of
    /// the reversible discrete Lagrange–d'Alembert step (order 4) on velocity constraints.
    pub fn accurate_method(self) -> Method {
        match self {
            ModelKind::Separable | ModelKind::Gravitational => Method::KahanLi6,
            ModelKind::Lagrangian => Method::Galerkin6,
            ModelKind::Nonholonomic => Method::Dla4,
            ModelKind::ConstrainedSeparable => Method::Rattle4,
            ModelKind::ConstrainedLagrangian => Method::Trapezoid,
        }
    }

    /// The kind's name in the Python API.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Separable => "separable",
            ModelKind::Lagrangian => "lagrangian",
            ModelKind::ConstrainedSeparable => "constrained separable",
            ModelKind::ConstrainedLagrangian => "constrained lagrangian",
            ModelKind::Gravitational => "gravitational",
            ModelKind::Nonholonomic => "nonholonomic",
        }
    }

    /// Whether the model is a separable mechanical system L = ½q̇ᵀMq̇ − V(q) with constant M, so
    /// that every unconstrained method applies.
    pub fn is_separable(self) -> bool {
        matches!(self, ModelKind::Separable | ModelKind::Gravitational)
    }
}

impl Method {
    /// The method's facts (`Method::facts`), with what the table above says it integrates
    /// and its stages.
    pub fn info(self) -> MethodInfo {
        let (name, order, symplectic, symmetric, h_omega_max, reference) = self.facts();
        let implicit = ModelKind::Lagrangian.admits(self) || ModelKind::Nonholonomic.admits(self);
        let constrained = ModelKind::ConstrainedSeparable.admits(self);
        let nonholonomic = !ModelKind::Lagrangian.admits(self) && ModelKind::Nonholonomic.admits(self);
        let nbody = !ModelKind::Separable.admits(self) && ModelKind::Gravitational.admits(self);
        let stages = match self {
            Method::Rattle4 | Method::Dla4 => 3,
            _ => Splitting::of(self).map_or(1, |s| s.stages()),
        };
        let force_evaluations = match self {
            Method::Rk4 => 4,
            Method::WisdomHolmanLazyKernel => 2,
            _ if implicit => 0,
            _ => stages,
        };
        MethodInfo {
            method: self,
            name,
            order,
            stages,
            force_evaluations,
            implicit,
            constrained,
            nonholonomic,
            nbody,
            symplectic,
            symmetric,
            h_omega_max,
            reference,
            features: self.features(),
        }
    }

    /// Whether this method integrates a model of `kind`, with the reason and the methods that
    /// would if it does not.
    pub fn check(self, kind: ModelKind) -> Result<(), Error> {
        if kind.admits(self) {
            Ok(())
        } else {
            Err(self.refusal(kind))
        }
    }

    /// Why this method does not integrate a model of `kind` (whether or not it does).
    pub(super) fn refusal(self, kind: ModelKind) -> Error {
        let name = self.info().name;
        let admitted = |kind: ModelKind| one_of(&Method::names(|m| kind.admits(m)));
        let reason = match kind {
            _ if Method::WISDOM_HOLMAN.contains(&self) => format!(
                "{name} integrates the gravitational N-body problem alone (Jacobi coordinates about a central \
                 body); this is a {} model",
                kind.name()
            ),
            _ if Method::NONHOLONOMIC.contains(&self) => format!(
                "{name} integrates velocity constraints A(q)q̇ = 0 alone; this is a {} model",
                kind.name()
            ),
            ModelKind::Separable | ModelKind::Lagrangian | ModelKind::Gravitational
                if ModelKind::ConstrainedSeparable.admits(self) =>
            {
                format!("{name} integrates systems with holonomic constraints")
            }
            ModelKind::Separable | ModelKind::Lagrangian | ModelKind::Gravitational => format!(
                "{name} needs a separable mechanical system; use {}",
                admitted(ModelKind::Lagrangian)
            ),
            ModelKind::ConstrainedSeparable => format!(
                "{name} would ignore the constraints; use {}",
                admitted(ModelKind::ConstrainedSeparable)
            ),
            ModelKind::ConstrainedLagrangian => format!(
                "{name} does not integrate a general Lagrangian on constraints; use trapezoid (RATTLE's \
                 discrete Lagrangian) or midpoint"
            ),
            ModelKind::Nonholonomic => format!(
                "{name} does not integrate velocity constraints; use midpoint (the reversible discrete \
                 Lagrange–d'Alembert integrator), dla4 (its order-4 composition) or cortes_martinez"
            ),
        };
        Error::invalid("method", reason)
    }
}
