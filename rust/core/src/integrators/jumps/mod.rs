//! Jumps of the state inside a step: impacts on unilateral contacts φ(q) ≥ 0 and impulses at
//! given times, resolved by the one step loop that runs, resumes, events, steppers and
//! ensembles share (the resolve law a replaceable function, as in REBOUND; the reset in the
//! solver loop, as in diffsol).
//!
//! - [`Contact`]: a surface ([`super::Surface`]: φ(q) and ∇φ(q), native or the binding's closures) with its restitution e ∈ [0, 1], its [`Law`] and its name;
//!   [`Contacts`]: the set a run watches, checked once;
//! - `resolve.rs`: a step that crosses a surface, redone in pieces at each contact;
//!   `reflect.rs` and `variational.rs`: the laws that give the jump's multiplier λ;
//! - `hold.rs`: a contact held closed (a body resting, sliding or rolling on it), by RATTLE on
//!   the closed surfaces, until its multiplier crosses 0; `friction.rs`: Coulomb friction on
//!   it ([`Friction`]), sliding or sticking;
//! - [`super::Impacts`]: what a run reports of them ([`super::Trajectory::impacts`]), with the
//!   contacts' closures and releases ([`super::Switches`]);
//! - [`Schedule`]: impulses ([`Impulse`], a [`Blow`] at a time) and samples (`t_eval`) at given
//!   times, each splitting the step that holds it (`schedule.rs`);
//! - [`Watch`]: the events, contacts and schedule a run or a stepper watches, and [`Watcher`],
//!   the one loop of steps that checks them, begun on a stepper's state;
//! - `impulsive.rs`: Lagrange's impulsive equations at one state, outside a run: a blow's
//!   response ([`impulsive::respond`]) and constraints that engage suddenly
//!   ([`impulsive::engage`]).

mod friction;
mod hold;
pub mod impulsive;
mod reflect;
mod resolve;
mod schedule;
mod unsolved;
mod variational;
mod watch;

pub use friction::{Friction, Slip, SlipRows};
pub(in crate::integrators) use resolve::Resolver;
pub use schedule::{Blow, Generalized, Impulse, PointFunction, Schedule, Struck};
pub use watch::{Watch, Watcher};

use super::{Dynamics, Method, NativeSurface, Surface};
use crate::{Error, ModelError};
use reflect::Reflection;

/// Impacts resolved in one step at most: more is an accumulation (a body coming to rest, Zeno),
/// which ends the run with [`Error::Contact`].
pub const MAX_IMPACTS: usize = 64;

/// How an impact's multiplier λ in p⁺ = p⁻ + λ∇φ(q̃) is found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Law {
    /// The exact reflection in the metric of the kinetic energy, λ = −(1 + e)(∇φ·q̇)/(∇φᵀM⁻¹∇φ)
    /// (`reflect.rs`): any method; H kept at the impact, symplectic across it to the method's
    /// order.
    #[default]
    Reflect,
    /// The variational collision integrator of Fetecau, Marsden, Ortiz & West (2003)
    /// (`variational.rs`): λ keeps the discrete energy E_d of the piece after the jump equal to
    /// that of the piece before, so the step across the impact is symplectic. Kick–drift methods
    /// and the two-point rules, on conservative, autonomous, unconstrained models; for e < 1,
    /// Newton's law (the reflection).
    Variational,
}

impl Law {
    /// Every law, in the order the binding lists them.
    pub const ALL: [Law; 2] = [Law::Variational, Law::Reflect];

    /// The law's name, as the Python API spells it.
    pub fn name(self) -> &'static str {
        match self {
            Law::Reflect => "reflect",
            Law::Variational => "variational",
        }
    }

    /// The law of that name, if any.
    pub fn named(name: &str) -> Option<Law> {
        Law::ALL.into_iter().find(|law| law.name() == name)
    }

    /// Why the law does not fit `method` on `model`, if it does not.
    fn misfit(self, model: &dyn Dynamics, method: Method) -> Option<String> {
        match self {
            Law::Reflect => None,
            Law::Variational => variational::misfit(model, method),
        }
    }

    /// Whether the law asks for the discrete energy of the pieces about an impact
    /// ([`Impact::discrete_energy`]), which the resolver then makes.
    fn needs_discrete_energy(self) -> bool {
        self == Law::Variational
    }

    /// The jump at `impact`.
    fn jump(self, impact: &mut dyn Impact) -> Result<Jump, Error> {
        match self {
            Law::Reflect => Ok(reflect::newton(impact)),
            Law::Variational => variational::jump(impact),
        }
    }
}

/// An impact as a law sees it ([`Law::jump`]): Newton's law there, and the pieces of the step
/// about it for a law that needs their discrete energy.
trait Impact {
    /// The reflection of p⁻ with the contact's restitution e (Newton's law), and e.
    fn newton(&self) -> (Reflection, f64);

    /// Whether a law must take Newton's here: a contact held beside it (the jump's λ is not the
    /// surface's alone), or no step left after it.
    fn newton_only(&self) -> bool;

    /// E_d of the piece before the impact, and the energy's scale; None where the method has no
    /// discrete energy.
    fn discrete_energy(&mut self) -> Result<Option<(f64, f64)>, Error>;

    /// E_d of the piece after the impact, p⁺ = p⁻ + λ∇φ.
    fn discrete_energy_after(&mut self, lambda: f64) -> Result<f64, Error>;
}

/// A law's jump p⁺ = p⁻ + λ∇φ: its λ, the energy it takes (its own loss, which the energy
/// account counts), the restitution it took (which decides whether the contact closes: the
/// rebounds of Newton's law with it die out within the step), and whether it fell back on
/// Newton's law at a grazing impact.
struct Jump {
    lambda: f64,
    loss: f64,
    restitution: f64,
    grazing: bool,
}

/// A unilateral constraint φ(q) ≥ 0 with its coefficient of restitution e ∈ [0, 1] (1:
/// elastic), its impact law, its friction while held, if any, and its name (in errors, and as
/// the Python API names it).
pub struct Contact<'s> {
    pub surface: Box<dyn Surface + 's>,
    pub restitution: f64,
    pub law: Law,
    pub friction: Option<Friction>,
    pub name: String,
}

impl Contact<'_> {
    /// The refusal of this contact, the `i`-th, naming `contacts` and it.
    fn refused(&self, i: usize, reason: String) -> Error {
        Error::invalid("contacts", format!("{:?} (contacts[{i}]): {reason}", self.name))
    }
}

impl std::fmt::Debug for Contact<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Contact")
            .field("name", &self.name)
            .field("restitution", &self.restitution)
            .field("law", &self.law)
            .field("friction", &self.friction)
            .finish_non_exhaustive()
    }
}

/// A contact on a native surface, owned and `Send + Sync`: every member of an ensemble makes
/// its own [`Contacts`] of them ([`super::integrate_ensemble`]).
#[derive(Clone, Debug, PartialEq)]
pub struct NativeContact {
    pub surface: NativeSurface,
    pub restitution: f64,
    pub law: Law,
    pub friction: Option<Friction>,
    pub name: String,
}

impl NativeContact {
    /// The contact, its surface a copy of this one's.
    pub fn contact(&self) -> Contact<'static> {
        Contact {
            surface: Box::new(self.surface.clone()),
            restitution: self.restitution,
            law: self.law,
            friction: self.friction.clone(),
            name: self.name.clone(),
        }
    }
}

/// The contacts a run watches, in order (an impact names its contact by its index here).
#[derive(Debug, Default)]
pub struct Contacts<'s> {
    contacts: Vec<Contact<'s>>,
}

impl<'s> Contacts<'s> {
    /// The set of `contacts`. Refuses (naming `contacts` and the contact) a restitution outside
    /// [0, 1] and friction coefficients that are not a law's (μ_s ≥ μ_k ≥ 0, finite).
    pub fn new(contacts: Vec<Contact<'s>>) -> Result<Self, Error> {
        for (i, c) in contacts.iter().enumerate() {
            if !(0.0..=1.0).contains(&c.restitution) {
                return Err(c.refused(i, format!("restitution must lie in [0, 1], got {}", c.restitution)));
            }
            if let Some(reason) = c.friction.as_ref().and_then(Friction::invalid) {
                return Err(c.refused(i, reason));
            }
        }
        Ok(Contacts { contacts })
    }

    /// The set of native contacts (an ensemble member's), checked as [`Contacts::new`] does.
    pub fn native(contacts: &[NativeContact]) -> Result<Contacts<'static>, Error> {
        Contacts::new(contacts.iter().map(NativeContact::contact).collect())
    }

    /// The number of contacts.
    pub fn len(&self) -> usize {
        self.contacts.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.contacts.is_empty()
    }

    /// The contacts, in order.
    pub fn contacts(&self) -> &[Contact<'s>] {
        &self.contacts
    }

    /// Whether every surface and slip acts on n coordinates (a native surface's coordinates in
    /// range, slip rows of n columns).
    pub fn fit(&self, n: usize) -> Result<(), Error> {
        for (i, c) in self.contacts.iter().enumerate() {
            let friction = c.friction.as_ref().and_then(|f| f.misfit(n));
            if let Some(reason) = c.surface.misfit(n).or(friction) {
                return Err(c.refused(i, reason));
            }
        }
        Ok(())
    }

    /// Whether a run of `method` on `model` from q (named `argument`: `q0`, or the checkpoint
    /// resumed) at time t can watch these contacts: each surface fits the model's coordinates, the
    /// variational law fits the method and the model, and q lies in φ ≥ 0 for every contact (on
    /// the surface to round-off, [`on_surface`]).
    pub(in crate::integrators) fn check<S: Dynamics + ?Sized>(
        &self,
        model: &S,
        method: Method,
        (t, q): (f64, &[f64]),
        argument: &'static str,
    ) -> Result<(), Error> {
        self.fit(model.dim())?;
        for (i, c) in self.contacts.iter().enumerate() {
            if let Some(reason) = c.law.misfit(model.as_dynamics(), method) {
                return Err(c.refused(i, reason));
            }
            let model_error = |source| Error::Model {
                step: 0,
                time: t,
                source,
            };
            let value = c.surface.phi(q).map_err(model_error)?;
            if value.is_nan() || (value < 0.0 && value < -on_surface(c, q).map_err(model_error)?) {
                let reason = format!("outside the contact {:?}: φ = {value} < 0", c.name);
                return Err(Error::invalid(argument, reason));
            }
        }
        Ok(())
    }
}

/// How far from contact c's surface a state q on it lies at most, by round-off:
/// 10³ε Σᵢ|∂φ/∂qᵢ| max(1, |qᵢ|), each coordinate's rounding through the surface's own
/// gradient (a coordinate the surface does not depend on, however large, adds none). A held
/// state's φ, solved to a few ε of q, lies well within; a run may start there (a point put on
/// a curved surface in floating point).
fn on_surface(c: &Contact<'_>, q: &[f64]) -> Result<f64, ModelError> {
    let mut gradient = vec![0.0; q.len()];
    c.surface.gradient(q, &mut gradient)?;
    Ok(round_off(&gradient, q))
}

/// 10³ε Σᵢ|∂φ/∂qᵢ| max(1, |qᵢ|), ∇φ at q given ([`on_surface`]).
pub(super) fn round_off(gradient: &[f64], q: &[f64]) -> f64 {
    1e3 * f64::EPSILON
        * gradient
            .iter()
            .zip(q)
            .map(|(g, x)| (g * x.abs().max(1.0)).abs())
            .sum::<f64>()
}
