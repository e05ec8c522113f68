//! What a method's own loop checks at the end of each step ([`Clear`]): nothing ([`Always`]),
//! or the gaps φ of a run's contacts ([`Gaps`]), with the test by which a step crosses one. A
//! check of the stepper's layer: the model kinds and the stepper name it, and the jumps build
//! it, so that neither names a type of the other.

use super::surfaces::{NativeSurface, Surface};
use crate::ModelError;

/// What a method's own loop checks at the end of each step: whether the step is clear, so that
/// the loop goes on ([`Gaps`]: it crosses no contact; `super::tangent::Carried`: its tangent
/// map carried the vectors, none past a bound). A trait, not a closure, so that the check is
/// inlined into the loop: as a closure it was called out of line, a third of a Verlet step.
pub trait Clear {
    /// Whether the step ending at (q, p) is clear.
    fn clear(&mut self, q: &[f64], p: &[f64]) -> bool;
}

/// Nothing watched: every step is clear.
pub(in crate::integrators) struct Always;

impl Clear for Always {
    #[inline(always)]
    fn clear(&mut self, _: &[f64], _: &[f64]) -> bool {
        true
    }
}

/// Whether a step from φ at its start to φ at its end crosses a contact.
pub(in crate::integrators) fn crosses(phi_start: &[f64], phi_end: &[f64]) -> bool {
    phi_start.iter().zip(phi_end).any(|(&start, &end)| crossing(start, end))
}

/// Whether a step from φ = `start` to φ = `end` crosses the contact (one it starts on or past,
/// it leaves: only φ < 0 past the start's counts).
#[inline(always)]
pub(in crate::integrators) fn crossing(start: f64, end: f64) -> bool {
    let leaving = start <= 0.0;
    below(end - floor(start, leaving), leaving)
}

/// φ of a contact's `surface` at q (through `native`, the surface if native, without
/// dispatch); a non-finite φ is an error naming the contact.
#[inline(always)]
pub(in crate::integrators) fn gap(
    (surface, name): (&(dyn Surface + '_), &str),
    native: Option<&NativeSurface>,
    q: &[f64],
) -> Result<f64, ModelError> {
    let phi = match native {
        Some(surface) => surface.value(q),
        None => surface.phi(q)?,
    };
    if !phi.is_finite() {
        return Err(format!("contact {name} returned a non-finite φ = {phi}").into());
    }
    Ok(phi)
}

/// φ of a run's contacts, checked at the end of each step the method's own loop takes
/// ([`crate::integrators::Dynamics::advance`] with [`crate::integrators::Carry::Gaps`]): a step is clear when it crosses no
/// contact, by the test the one-at-a-time loop judges a step by; φ at its end is then the next
/// step's start. A failing φ stops the steps as a crossing does, its error kept for the run.
///
/// While every φ at a step's start is above its surface (φ > 0, the body in flight), the step
/// crosses a contact exactly where some φ at its end is ≤ 0, whatever the values at its start:
/// then, for native surfaces, φ is tested and not kept (`above`), and the resolver evaluates it
/// again where it needs it (`stale`). So a contact never hit costs a run its φ and a comparison
/// a step, inlined, and all else is out of the loop (1.03× the run without it, verlet on the
/// ball, `benches/impacts.py`).
pub struct Gaps<'g, 's> {
    /// Each contact's surface and name.
    surfaces: &'g [(&'g (dyn Surface + 's), &'g str)],
    /// Each contact's surface, if native.
    native: &'g [Option<&'g NativeSurface>],
    /// φ at the state (the next step's start), and at a step's end: the resolver's, swapped
    /// (`swapped`) rather than copied after a clear step.
    phi: &'g mut [f64],
    phi_end: &'g mut [f64],
    pub(in crate::integrators) swapped: bool,
    /// Flight mode: every φ at the next step's start is > 0, and `phi` is not kept.
    above: bool,
    /// `phi` may not hold φ at the next step's start (flight mode was entered): the resolver
    /// evaluates it again.
    pub(in crate::integrators) stale: bool,
    pub(in crate::integrators) error: Option<ModelError>,
}

impl<'g, 's> Gaps<'g, 's> {
    /// The gaps of the contacts' `surfaces` (with their names) with φ at the state in `phi`.
    pub(in crate::integrators) fn new(
        surfaces: &'g [(&'g (dyn Surface + 's), &'g str)],
        native: &'g [Option<&'g NativeSurface>],
        phi: &'g mut [f64],
        phi_end: &'g mut [f64],
    ) -> Self {
        let above = in_flight(native, phi);
        Gaps {
            surfaces,
            native,
            phi,
            phi_end,
            swapped: false,
            above,
            stale: above,
            error: None,
        }
    }

    /// Whether every φ at q is positive and finite (`above`: the surfaces are native).
    #[inline(always)]
    fn flying(&self, q: &[f64]) -> bool {
        let mut flying = true;
        for surface in self.native.iter().flatten() {
            let phi = surface.value(q);
            // Positive and finite (NaN fails both).
            flying &= phi > 0.0 && phi <= f64::MAX;
        }
        flying
    }

    /// [`Clear::clear`] but for a flight's clear step: out of line, so that the loop of a
    /// flight stays as tight as an unwatched one.
    #[cold]
    #[inline(never)]
    fn judge(&mut self, q: &[f64]) -> bool {
        let contacts = self.surfaces.iter().zip(self.native);
        if self.above {
            // A crossing, or an error: φ at the end, for the resolver, and the step stops.
            self.above = false;
            for ((c, native), end) in contacts.zip(self.phi_end.iter_mut()) {
                match gap(*c, *native, q) {
                    Ok(phi) => *end = phi,
                    Err(error) => {
                        self.error = Some(error);
                        break;
                    }
                }
            }
            return false;
        }
        let mut crossed = false;
        for ((c, native), (start, end)) in contacts.zip(self.phi.iter().zip(self.phi_end.iter_mut())) {
            *end = match gap(*c, *native, q) {
                Ok(phi) => phi,
                Err(error) => {
                    self.error = Some(error);
                    return false;
                }
            };
            crossed |= crossing(*start, *end);
        }
        if crossed {
            return false;
        }
        std::mem::swap(&mut self.phi, &mut self.phi_end);
        self.swapped = !self.swapped;
        if in_flight(self.native, self.phi) {
            (self.above, self.stale) = (true, true);
        }
        true
    }
}

impl Clear for Gaps<'_, '_> {
    /// Whether a step ending at q crosses no contact, each φ evaluated (finite); φ at q is
    /// then the next step's start.
    #[inline(always)]
    fn clear(&mut self, q: &[f64], _: &[f64]) -> bool {
        (self.above && self.flying(q)) || self.judge(q)
    }
}

/// Whether the flight test of [`Gaps`] applies from φ at a step's start: every surface native,
/// every φ > 0.
pub(in crate::integrators) fn in_flight(native: &[Option<&NativeSurface>], phi: &[f64]) -> bool {
    native.iter().all(Option::is_some) && phi.iter().all(|&phi| phi > 0.0)
}

/// The level a piece's φ must fall below to cross again: 0, or φ at its start for a piece that
/// starts a little past the surface (a contact state located to round-off on its far side),
/// so that a piece leaving it, however short, is not taken for a crossing.
pub(in crate::integrators) fn floor(phi_start: f64, leaving: bool) -> f64 {
    if leaving {
        phi_start.min(0.0)
    } else {
        0.0
    }
}

/// Whether φ at a piece's end is past the surface: φ < 0, or φ = 0 on a piece that did not
/// start on it (a crossing ends at 0 or below, as events count it).
pub(in crate::integrators) fn below(phi: f64, leaving: bool) -> bool {
    phi < 0.0 || (phi <= 0.0 && !leaving)
}
