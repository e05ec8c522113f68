use crate::Error;
use serde::{Deserialize, Serialize};

/// The fixed-step methods of varmech.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Method {
    /// Explicit Euler (baseline; not symplectic).
    ExplicitEuler,
    /// Symplectic Euler, the variational integrator of L_d = h·L(q₀, (q₁−q₀)/h).
    SymplecticEuler,
    /// Störmer–Verlet, the variational integrator of the trapezoidal L_d.
    Verlet,
    /// Yoshida's triple jump (Yoshida 1990), order 4.
    Yoshida4,
    /// Suzuki's 5-stage composition (Suzuki 1990), order 4.
    Suzuki4,
    /// McLachlan's 5-stage composition (McLachlan 1995), order 4.
    McLachlan4,
    /// Yoshida's 7-stage composition (Yoshida 1990, solution A), order 6.
    Yoshida6,
    /// Kahan & Li's 9-stage composition (Kahan & Li 1997), order 6.
    KahanLi6,
    /// Suzuki & Umeno's 15-stage composition (Suzuki & Umeno 1993), order 8.
    SuzukiUmeno8,
    /// Kahan & Li's 17-stage composition (Kahan & Li 1997), order 8.
    KahanLi8,
    /// McLachlan's 9-stage composition SS9 (McLachlan 1995), order 6.
    McLachlan6,
    /// McLachlan's 17-stage composition SS17 (McLachlan 1995), order 8: Blanes & Casas's
    /// (2016, p. 91) order-8 composition, the one of REBOUND's leapfrog with order = 8.
    McLachlan8,
    /// McLachlan's SS17 composed of Störmer–Verlet in position form (drift–kick–drift), as
    /// REBOUND's leapfrog with order = 8 applies it: an ABA splitting, 17 force evaluations.
    McLachlan8Dkd,
    /// Blanes & Moan's SRKN₆ᵇ (2002), order 4: a BAB splitting with 6 force evaluations.
    BlanesMoan4,
    /// Blanes & Moan's SRKN₁₁ᵇ (2002), order 6: a BAB splitting with 11 force evaluations.
    BlanesMoan6,
    /// ABA(8,6,4) of Blanes, Casas, Farrés, Laskar, Makazaga & Murua (2013), 7 force
    /// evaluations: error O(εh⁸ + ε²h⁶ + ε³h⁴) on H = A + εB, order 4 in general.
    Aba864,
    /// ABA(10,6,4) of the same paper, 8 force evaluations: error O(εh¹⁰ + ε²h⁶ + ε³h⁴).
    Aba1064,
    /// The classical Runge–Kutta method (baseline; not symplectic).
    Rk4,
    /// The variational integrator of the midpoint discrete Lagrangian (implicit; any L).
    Midpoint,
    /// The variational integrator of the trapezoidal discrete Lagrangian (implicit; any L;
    /// Störmer–Verlet for separable systems).
    Trapezoid,
    /// The Galerkin variational integrator of degree 2 with 2-point Gauss quadrature (order 4).
    Galerkin4,
    /// The Galerkin variational integrator of degree 3 with 3-point Gauss quadrature (order 6).
    Galerkin6,
    /// RATTLE for holonomic constraints (Andersen 1983), multipliers by Newton's method.
    Rattle,
    /// RATTLE composed by Yoshida's triple jump, order 4.
    Rattle4,
    /// SHAKE (Ryckaert, Ciccotti & Berendsen 1977): positions on the constraints, one
    /// constraint at a time to the Newton tolerance; momenta off the hidden constraint.
    Shake,
    /// The discrete Lagrange–d'Alembert integrator of the midpoint L_d with the discrete
    /// constraint at the step's start, A(q₀)(q₁ − q₀) = 0 (Cortés & Martínez 2001): not
    /// reversible, order 1. The contrast McLachlan & Perlmutter (2006) draw with the reversible
    /// step (`midpoint`); not a default.
    CortesMartinez,
    /// The reversible discrete Lagrange–d'Alembert step (`midpoint`) composed by Yoshida's
    /// triple jump, order 4, every stage on the velocity constraints.
    Dla4,
    /// The Wisdom–Holman method (Wisdom & Holman 1991) in Jacobi coordinates, as WHFast (Rein &
    /// Tamayo 2015): Kepler drifts and interaction kicks, order 2 with error O(εh²).
    WisdomHolman,
    /// The Wisdom–Holman method with Wisdom, Holman & Touma's (1996) symplectic corrector of
    /// order 11 (WHFast's `corrector=11`): error O(εh¹² + ε²h²).
    WisdomHolmanCorrected,
    /// The Wisdom–Holman method with the corrector of order 11 and the lazy implementer's
    /// modified-kick kernel of Wisdom, Holman & Touma (1996) (Rein, Tamayo & Brown 2019's
    /// WHCKL): error O(εh¹² + ε²h⁴), at two force evaluations a step.
    WisdomHolmanLazyKernel,
}

/// What `varmech.methods()` lists about a method.
#[derive(Clone, Debug, PartialEq)]
pub struct MethodInfo {
    pub method: Method,
    pub name: &'static str,
    pub order: u32,
    /// Stages: force evaluations of a kick–drift splitting (first same as last reused), the
    /// Verlet steps of a composition; 1 for the others.
    pub stages: usize,
    /// Force evaluations ∇V per step, first-same-as-last evaluations reused (0 for the
    /// implicit methods, whose cost depends on the Newton iterations).
    pub force_evaluations: usize,
    /// Whether each step solves implicit equations (by Newton's method); implicit methods
    /// integrate general Lagrangians, explicit ones only separable mechanical systems (read
    /// from the table of [`ModelKind`](super::ModelKind)).
    pub implicit: bool,
    /// Whether the method integrates separable systems on holonomic constraints (and only
    /// those; read from the table of [`ModelKind`](super::ModelKind)).
    pub constrained: bool,
    /// Whether the method integrates velocity constraints A(q)q̇ = 0 and only those (read from
    /// the table of [`ModelKind`](super::ModelKind); `midpoint`, which integrates them too, is not among these).
    pub nonholonomic: bool,
    /// Whether the method integrates the gravitational N-body problem only (the Wisdom–Holman
    /// methods; read from the table of [`ModelKind`](super::ModelKind)).
    pub nbody: bool,
    pub symplectic: bool,
    pub symmetric: bool,
    /// Linear stability limit: the method is stable on q̈ = −ω²q iff hω < `h_omega_max`
    /// (0 for explicit Euler, which is never stable; infinite for the midpoint rule; NaN for the
    /// Wisdom–Holman methods, which do not integrate the oscillator).
    pub h_omega_max: f64,
    pub reference: &'static str,
    /// What its step offers beyond the kinds of model it integrates ([`Method::features`]).
    pub features: &'static [Feature],
}

/// What a method's step offers beyond the kinds of model it integrates ([`ModelKind`](super::ModelKind)): which
/// method has which is [`Method::features`] alone, and every check that refuses a method for
/// a feature reads it there.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Feature {
    /// E_d = −∂L_d/∂τ of its step ([`super::DiscreteEnergy`]), which the variational collision
    /// law keeps across an impact.
    DiscreteEnergy,
    /// The linearization DΨ_h of its step in (q, p) ([`super::Tangent`]): Lyapunov spectra.
    TangentMap,
    /// A step with contacts held closed, RATTLE composed as the method is (jumps/hold.rs):
    /// bodies at rest on a contact, and friction.
    HeldStep,
    /// Delayed forces: one force node a step, which the run's history keeps (del/history.rs).
    DelayedForces,
}

impl Feature {
    /// Its name in the Python API (`MethodInfo.features`).
    pub fn name(self) -> &'static str {
        match self {
            Feature::DiscreteEnergy => "discrete_energy",
            Feature::TangentMap => "tangent_map",
            Feature::HeldStep => "held_step",
            Feature::DelayedForces => "delayed_forces",
        }
    }
}

/// Names as a message offers them: "a", "a or b", "a, b or c".
pub(crate) fn one_of(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => (*one).to_string(),
        [rest @ .., last] => format!("{} or {last}", rest.join(", ")),
    }
}

impl Method {
    /// Every method, from the simplest.
    pub const ALL: [Method; 22] = [
        Method::ExplicitEuler,
        Method::SymplecticEuler,
        Method::Verlet,
        Method::Yoshida4,
        Method::Suzuki4,
        Method::McLachlan4,
        Method::Yoshida6,
        Method::KahanLi6,
        Method::SuzukiUmeno8,
        Method::KahanLi8,
        Method::McLachlan6,
        Method::McLachlan8,
        Method::McLachlan8Dkd,
        Method::BlanesMoan4,
        Method::BlanesMoan6,
        Method::Aba864,
        Method::Aba1064,
        Method::Rk4,
        Method::Midpoint,
        Method::Trapezoid,
        Method::Galerkin4,
        Method::Galerkin6,
    ];

    /// The methods for holonomic constraints.
    pub const CONSTRAINED: [Method; 3] = [Method::Rattle, Method::Rattle4, Method::Shake];

    /// The methods for velocity constraints alone (the reversible discrete Lagrange–d'Alembert
    /// step itself is `midpoint`).
    pub const NONHOLONOMIC: [Method; 2] = [Method::CortesMartinez, Method::Dla4];

    /// The methods for the gravitational N-body problem alone.
    pub const WISDOM_HOLMAN: [Method; 3] = [
        Method::WisdomHolman,
        Method::WisdomHolmanCorrected,
        Method::WisdomHolmanLazyKernel,
    ];

    /// Every method: the unconstrained ones, then the constrained, the nonholonomic and the
    /// N-body ones.
    pub fn every() -> impl Iterator<Item = Method> {
        Method::ALL
            .into_iter()
            .chain(Method::CONSTRAINED)
            .chain(Method::NONHOLONOMIC)
            .chain(Method::WISDOM_HOLMAN)
    }

    /// The names of the methods that `pick` picks, in [`Method::every`]'s order.
    pub fn names(pick: impl Fn(Method) -> bool) -> Vec<&'static str> {
        Method::every().filter(|&m| pick(m)).map(|m| m.info().name).collect()
    }

    /// The one table of method × feature: what this method's step offers (a line a family,
    /// every method named, so that a new one must take its line).
    pub fn features(self) -> &'static [Feature] {
        use Feature::*;
        use Method::*;
        match self {
            Verlet | Yoshida4 | Suzuki4 | McLachlan4 | Yoshida6 | KahanLi6 | SuzukiUmeno8 | KahanLi8 | McLachlan6
            | McLachlan8 => &[DiscreteEnergy, TangentMap, HeldStep],
            SymplecticEuler | McLachlan8Dkd | BlanesMoan4 | BlanesMoan6 | Aba864 | Aba1064 => {
                &[DiscreteEnergy, TangentMap]
            }
            Midpoint | Trapezoid => &[DiscreteEnergy, TangentMap, DelayedForces],
            Galerkin4 | Galerkin6 => &[DiscreteEnergy, TangentMap],
            Rattle => &[TangentMap],
            ExplicitEuler
            | Rk4
            | Rattle4
            | Shake
            | CortesMartinez
            | Dla4
            | WisdomHolman
            | WisdomHolmanCorrected
            | WisdomHolmanLazyKernel => &[],
        }
    }

    /// Whether this method's step offers `feature` ([`Method::features`]).
    pub fn supports(self, feature: Feature) -> bool {
        self.features().contains(&feature)
    }

    /// The method's own facts, as its literature gives them: name, order, whether symplectic
    /// and symmetric, stability limit and reference ([`Method::info`] adds what the table of
    /// kinds says it integrates, and its stages).
    pub(super) fn facts(self) -> (&'static str, u32, bool, bool, f64, &'static str) {
        match self {
            Method::ExplicitEuler => ("explicit_euler", 1, false, false, 0.0, "baseline"),
            Method::SymplecticEuler => ("symplectic_euler", 1, true, false, 2.0, "HLW I.1; L_d = h L(q0, v)"),
            Method::Verlet => ("verlet", 2, true, true, 2.0, "HLW I.3; trapezoidal L_d"),
            Method::Yoshida4 => ("yoshida4", 4, true, true, 1.5734, "Yoshida, Phys. Lett. A 150 (1990)"),
            Method::Suzuki4 => ("suzuki4", 4, true, true, 2.721, "Suzuki, Phys. Lett. A 146 (1990)"),
            Method::McLachlan4 => (
                "mclachlan4",
                4,
                true,
                true,
                3.0182,
                "McLachlan, SIAM J. Sci. Comput. 16 (1995)",
            ),
            Method::Yoshida6 => ("yoshida6", 6, true, true, 2.2691, "Yoshida, Phys. Lett. A 150 (1990)"),
            Method::KahanLi6 => ("kahan_li6", 6, true, true, 2.5326, "Kahan & Li, Math. Comp. 66 (1997)"),
            Method::SuzukiUmeno8 => ("suzuki_umeno8", 8, true, true, 3.3932, "Suzuki & Umeno (1993)"),
            Method::KahanLi8 => ("kahan_li8", 8, true, true, 3.0964, "Kahan & Li, Math. Comp. 66 (1997)"),
            Method::McLachlan6 => (
                "mclachlan6",
                6,
                true,
                true,
                2.7031,
                "McLachlan, SIAM J. Sci. Comput. 16 (1995), SS9",
            ),
            Method::McLachlan8 => (
                "mclachlan8",
                8,
                true,
                true,
                3.0871,
                "McLachlan, SIAM J. Sci. Comput. 16 (1995), SS17; Blanes & Casas (2016), p. 91",
            ),
            Method::McLachlan8Dkd => (
                "mclachlan8_dkd",
                8,
                true,
                true,
                3.0871,
                "McLachlan (1995), SS17 of position Verlet; Blanes & Casas (2016), p. 91; REBOUND leapfrog order=8",
            ),
            Method::BlanesMoan4 => (
                "blanes_moan4",
                4,
                true,
                true,
                3.1635,
                "Blanes & Moan, J. Comput. Appl. Math. 142 (2002), SRKN6b",
            ),
            Method::BlanesMoan6 => (
                "blanes_moan6",
                6,
                true,
                true,
                3.1414,
                "Blanes & Moan, J. Comput. Appl. Math. 142 (2002), SRKN11b",
            ),
            Method::Aba864 => (
                "aba864",
                4,
                true,
                true,
                3.1422,
                "Blanes, Casas, Farres, Laskar, Makazaga & Murua, Appl. Numer. Math. 68 (2013), ABA(8,6,4)",
            ),
            Method::Aba1064 => (
                "aba1064",
                4,
                true,
                true,
                3.1461,
                "Blanes, Casas, Farres, Laskar, Makazaga & Murua, Appl. Numer. Math. 68 (2013), ABA(10,6,4)",
            ),
            Method::Rk4 => ("rk4", 4, false, false, 2.0 * std::f64::consts::SQRT_2, "baseline"),
            Method::Midpoint => (
                "midpoint",
                2,
                true,
                true,
                f64::INFINITY,
                "Marsden & West (2001); midpoint L_d",
            ),
            Method::Trapezoid => (
                "trapezoid",
                2,
                true,
                true,
                2.0,
                "Marsden & West (2001); trapezoidal L_d",
            ),
            Method::Galerkin4 => (
                "galerkin4",
                4,
                true,
                true,
                f64::INFINITY,
                "Marsden & West (2001), §2.6; Gauss quadrature",
            ),
            Method::Galerkin6 => (
                "galerkin6",
                6,
                true,
                true,
                f64::INFINITY,
                "Marsden & West (2001), §2.6; Gauss quadrature",
            ),
            Method::Rattle => ("rattle", 2, true, true, 2.0, "Andersen (1983); HLW VII.1.4"),
            Method::Rattle4 => ("rattle4", 4, true, true, 1.5734, "RATTLE, Yoshida's triple jump"),
            Method::Shake => ("shake", 2, false, true, 2.0, "Ryckaert, Ciccotti & Berendsen (1977)"),
            // Not symplectic: nonholonomic flows have no symplectic form to keep.
            Method::CortesMartinez => (
                "cortes_martinez",
                1,
                false,
                false,
                f64::INFINITY,
                "Cortés & Martínez, Nonlinearity 14 (2001); McLachlan & Perlmutter, J. Nonlinear Sci. 16 (2006)",
            ),
            Method::Dla4 => (
                "dla4",
                4,
                false,
                true,
                // The midpoint rule rotates the oscillator's phase at any hω; so do its compositions.
                f64::INFINITY,
                "McLachlan & Perlmutter (2006), midpoint DLA; Yoshida's triple jump",
            ),
            Method::WisdomHolman => (
                "wh",
                2,
                true,
                true,
                f64::NAN,
                "Wisdom & Holman, AJ 102 (1991); Rein & Tamayo, MNRAS 452 (2015)",
            ),
            Method::WisdomHolmanCorrected => (
                "whc",
                2,
                true,
                true,
                f64::NAN,
                "Wisdom, Holman & Touma, Fields Inst. Commun. 10 (1996); Rein & Tamayo, MNRAS 452 (2015)",
            ),
            Method::WisdomHolmanLazyKernel => (
                "whckl",
                4,
                true,
                true,
                f64::NAN,
                "Wisdom, Holman & Touma (1996), §10; Rein, Tamayo & Brown, MNRAS 489 (2019)",
            ),
        }
    }

    /// The method called `name` (as listed by [`Method::info`]).
    pub fn from_name(name: &str) -> Result<Method, Error> {
        Method::every().find(|m| m.info().name == name).ok_or_else(|| {
            Error::invalid(
                "method",
                format!(
                    "unknown method {name:?}; choose one of {}",
                    Method::names(|_| true).join(", ")
                ),
            )
        })
    }
}
