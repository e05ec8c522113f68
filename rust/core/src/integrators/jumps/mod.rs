//! Jumps of the state inside a step: impacts on unilateral contacts φ(q) ≥ 0 and impulses at
//! given times, resolved by the one step loop that runs, resumes, events, steppers and
//! ensembles share (the resolve law a replaceable function, as in REBOUND; the reset in the
//! solver loop, as in diffsol).
//!
//! - [`Surface`]: φ(q) and ∇φ(q), native ([`NativeSurface`]) or the binding's closures;
//! - [`Contact`]: a surface with its restitution e ∈ [0, 1], its [`Law`] and its name;
//!   [`Contacts`]: the set a run watches, checked once;
//! - `resolve.rs`: a step that crosses a surface, redone in pieces at each contact;
//!   `reflect.rs` and `variational.rs`: the laws that give the jump's multiplier λ;
//! - `hold.rs`: a contact held closed (a body resting, sliding or rolling on it), by RATTLE on
//!   the closed surfaces, until its multiplier crosses 0; `friction.rs`: Coulomb friction on
//!   it ([`Friction`]), sliding or sticking;
//! - [`Impacts`]: what a run reports of them ([`super::Trajectory::impacts`]), with the
//!   contacts' closures and releases ([`Switches`]);
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
mod surfaces;
mod unsolved;
mod variational;
mod watch;

pub use friction::{Friction, Slip, SlipRows};
pub use resolve::Gaps;
pub(in crate::integrators) use resolve::Resolver;
pub use schedule::{Blow, Generalized, Impulse, PointFunction, Schedule, Struck};
pub use surfaces::NativeSurface;
pub(crate) use surfaces::{check_ellipsoid, ellipsoid, wall};
pub use watch::{Watch, Watcher};

use super::{Dynamics, Method};
use crate::{Error, ModelError};

/// Impacts resolved in one step at most: more is an accumulation (a body coming to rest, Zeno),
/// which ends the run with [`Error::Contact`].
pub const MAX_IMPACTS: usize = 64;

/// A unilateral constraint's function φ(q) ≥ 0 (positive on the allowed side) and its gradient.
///
/// The binding implements it with Python callables, whose exceptions come back as the
/// [`ModelError`] unchanged.
pub trait Surface {
    /// φ(q).
    fn phi(&self, q: &[f64]) -> Result<f64, ModelError>;

    /// Writes ∇φ(q) into `out` (n entries).
    fn gradient(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError>;

    /// Why the surface cannot act on n coordinates, if it cannot (a native surface's
    /// coordinates out of range). By default it can.
    fn misfit(&self, _n: usize) -> Option<String> {
        None
    }

    /// The surface as a native one, which a run evaluates after every step without dispatch
    /// ([`Gaps`]); None (the default) for the others.
    fn native(&self) -> Option<&NativeSurface> {
        None
    }
}

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
    /// The law's name, as the Python API spells it.
    pub fn name(self) -> &'static str {
        match self {
            Law::Reflect => "reflect",
            Law::Variational => "variational",
        }
    }
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
/// its own [`Contacts`] of them ([`super::integrate_ensemble_watching`]).
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
            if c.law == Law::Variational {
                if let Some(reason) = resolve::variational_misfit(model, method) {
                    return Err(c.refused(i, format!("the variational collision integrator {reason}")));
                }
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

/// The impacts of a run, in order of time, row by row: impact k on contact `contact[k]` during
/// step `step[k]` (counted from 1) at time `t[k]`, at the contact configuration q̃ = `q_at(k)`
/// with the momenta `p_before_at(k)` just before and `p_after_at(k)` just after the jump.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Impacts {
    pub dim: usize,
    pub contact: Vec<usize>,
    pub step: Vec<usize>,
    pub t: Vec<f64>,
    pub q: Vec<f64>,
    pub p_before: Vec<f64>,
    pub p_after: Vec<f64>,
    /// Impacts under the variational law that found no discrete-energy root near the reflection
    /// (grazing, |∇φ·q̇| of order h) and took Newton's law instead.
    pub grazing: usize,
    /// The contacts' closures and releases.
    pub switches: Switches,
}

/// A change of a contact's state: closed, released, stuck (its friction holding its slip at 0:
/// a body resting or rolling) or slipped (sliding from then on).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Switch {
    Closed,
    Released,
    Stuck,
    Slipped,
}

/// The closures, releases and friction switches of a run's contacts, in order of time:
/// contact `contact[k]` switched (`kind[k]`) during step `step[k]`, at time `t[k]` and the
/// state (`q_at(k)`, `p_at(k)`).
///
/// A contact closes at the impact that ends its bounces, when the rest of their Zeno series
/// (flights 2v⁺/|a|, 2ev⁺/|a|, … under the normal acceleration a) sums to less than a step:
/// t is then the series' limit t∞ = t_impact + 2v⁺/(|a|(1 − e)) and the state the impact's
/// (the motion is held from the impact on). An arrival without normal velocity closes it at
/// once. It is released at lift-off, where its multiplier λ crosses 0. With friction, a
/// sliding contact sticks where its slip comes to rest with the force it needs within μ_s N,
/// and a stuck one slips where that force reaches μ_s N.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Switches {
    pub contact: Vec<usize>,
    pub step: Vec<usize>,
    pub t: Vec<f64>,
    pub kind: Vec<Switch>,
    pub q: Vec<f64>,
    pub p: Vec<f64>,
}

impl Switches {
    /// Adds a switch.
    pub(in crate::integrators) fn push(
        &mut self,
        contact: usize,
        step: usize,
        t: f64,
        kind: Switch,
        (q, p): (&[f64], &[f64]),
    ) {
        self.contact.push(contact);
        self.step.push(step);
        self.t.push(t);
        self.kind.push(kind);
        self.q.extend_from_slice(q);
        self.p.extend_from_slice(p);
    }

    fn append(&mut self, other: &mut Switches) {
        self.contact.append(&mut other.contact);
        self.step.append(&mut other.step);
        self.t.append(&mut other.t);
        self.kind.append(&mut other.kind);
        self.q.append(&mut other.q);
        self.p.append(&mut other.p);
    }

    fn clear(&mut self) {
        self.contact.clear();
        self.step.clear();
        self.t.clear();
        self.kind.clear();
        self.q.clear();
        self.p.clear();
    }

    /// The number of switches.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there were none.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}

impl Impacts {
    /// No impacts of n coordinates, with room for `rows` of them.
    pub(in crate::integrators) fn with_capacity(n: usize, rows: usize) -> Self {
        Impacts {
            dim: n,
            contact: Vec::with_capacity(rows),
            step: Vec::with_capacity(rows),
            t: Vec::with_capacity(rows),
            q: Vec::with_capacity(rows * n),
            p_before: Vec::with_capacity(rows * n),
            p_after: Vec::with_capacity(rows * n),
            grazing: 0,
            switches: Switches::default(),
        }
    }

    /// Adds an impact.
    pub(in crate::integrators) fn push(
        &mut self,
        contact: usize,
        step: usize,
        t: f64,
        q: &[f64],
        p_before: &[f64],
        p_after: &[f64],
    ) {
        self.contact.push(contact);
        self.step.push(step);
        self.t.push(t);
        self.q.extend_from_slice(q);
        self.p_before.extend_from_slice(p_before);
        self.p_after.extend_from_slice(p_after);
    }

    /// Moves `other`'s impacts to the end of these, leaving it empty (its storage kept).
    pub fn append(&mut self, other: &mut Impacts) {
        self.contact.append(&mut other.contact);
        self.step.append(&mut other.step);
        self.t.append(&mut other.t);
        self.q.append(&mut other.q);
        self.p_before.append(&mut other.p_before);
        self.p_after.append(&mut other.p_after);
        self.grazing += std::mem::take(&mut other.grazing);
        self.switches.append(&mut other.switches);
    }

    /// Forgets every impact, keeping the storage.
    pub(in crate::integrators) fn clear(&mut self) {
        self.contact.clear();
        self.step.clear();
        self.t.clear();
        self.q.clear();
        self.p_before.clear();
        self.p_after.clear();
        self.grazing = 0;
        self.switches.clear();
    }

    /// The number of impacts.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there were none.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// q̃ of impact k.
    pub fn q_at(&self, k: usize) -> &[f64] {
        &self.q[k * self.dim..(k + 1) * self.dim]
    }

    /// The momenta just before impact k.
    pub fn p_before_at(&self, k: usize) -> &[f64] {
        &self.p_before[k * self.dim..(k + 1) * self.dim]
    }

    /// The momenta just after impact k.
    pub fn p_after_at(&self, k: usize) -> &[f64] {
        &self.p_after[k * self.dim..(k + 1) * self.dim]
    }
}
