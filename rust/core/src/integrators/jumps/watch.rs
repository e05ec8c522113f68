//! What a run or a stepper watches besides its states: events, contacts and a schedule of
//! impulses and samples, begun once on a stepper's state and checked after every step.

use std::borrow::BorrowMut;
use std::ops::Deref;

use super::{Resolver, Schedule};
use crate::integrators::events::Search;
use crate::integrators::{Contacts, Detector, Dynamics, Poll, Stepper, StepperState, Trajectory};
use crate::Error;

/// What a run watches besides its states: events ([`Detector`]), contacts ([`Contacts`]) and
/// a [`Schedule`] of impulses and samples, any of them or none. They are checked after every
/// step (contacts alone inside the method's own loop up to the next scheduled time, events with
/// the steps taken one at a time); a step that crosses a contact or holds an impulse is redone
/// in pieces at each jump, and the events are evaluated and located on the pieces.
#[derive(Default)]
pub struct Watch<'w, 'e, 'c> {
    /// The events, located by partial steps of the method ([`crate::integrators::integrate_watching`]).
    pub events: Option<&'w mut Detector<'e>>,
    /// The unilateral contacts φ(q) ≥ 0, whose impacts the run resolves.
    pub contacts: Option<&'w Contacts<'c>>,
    /// The impulses the run applies and the samples it takes (then saving those alone).
    pub schedule: Option<&'w Schedule<'c>>,
}

impl<'w, 'e> Watch<'w, 'e, '_> {
    /// The `events` alone.
    pub fn events(events: &'w mut Detector<'e>) -> Self {
        Watch {
            events: Some(events),
            ..Watch::default()
        }
    }

    /// Whether what it watches can put energy in or take it out: contacts with friction or
    /// e < 1 (each law's loss, the closures', the projections onto closed contacts), or
    /// impulses. A run then counts that energy in its work W (`Stepper::work`), which it and
    /// the report balance E − E₀ against, as a forced model's; elastic contacts alone put in
    /// none (their laws' loss is 0).
    pub fn exchanges(&self) -> bool {
        let contacts = self
            .contacts
            .is_some_and(|c| c.contacts().iter().any(|c| c.friction.is_some() || c.restitution < 1.0));
        contacts || self.schedule.is_some_and(|s| !s.impulses().is_empty())
    }
}

/// A [`Watch`] begun on a stepper's state: the events' search and the contacts' resolver, with
/// their scratch steppers and buffers, made once. [`Watcher::advance`] takes a stepper's steps
/// as a run does ([`crate::integrators::integrate_watching`]: one loop for both), so that a
/// stepper stepped through a watcher is bit for bit the run. Outside a run it serves the
/// binding's `Stepper` with contacts and events.
pub struct Watcher<'w, 'e, 'c, M> {
    search: Option<Search<'w, 'e, M>>,
    resolver: Option<Resolver<'w, 'c, M>>,
}

impl<'w, 'e, 'c, M> Watcher<'w, 'e, 'c, M>
where
    M: Deref<Target: Dynamics> + Copy,
{
    /// The watcher of `watch` for `stepper` on `model` from its state: the events started
    /// there, the contacts checked against the model and its method and the state (named
    /// `argument`, `q0` or `checkpoint`, if outside a contact). A stepper watching what can
    /// put energy in or take it out ([`Watch::exchanges`]) counts that energy from then on
    /// (`Stepper::work`).
    pub fn begin<St: BorrowMut<StepperState>>(
        model: M,
        stepper: &mut Stepper<M, St>,
        watch: Watch<'w, 'e, 'c>,
        argument: &'static str,
    ) -> Result<Self, Error> {
        Self::make(model, stepper, watch, Some(argument))
    }

    /// As [`Watcher::begin`], for a stepper whose state a watcher of the same `watch` has
    /// checked (begun there) or reached (stepped there): the contacts are not checked again.
    /// A state that an impact located on a surface's far side leaves a round-off past it
    /// (φ ≈ −1e-17) is then taken, as within one run, for one leaving the surface, so that a
    /// stepper advanced through a watcher resumed for each call is bit for bit one run (the
    /// binding's `Stepper`).
    pub fn resume<St: BorrowMut<StepperState>>(
        model: M,
        stepper: &mut Stepper<M, St>,
        watch: Watch<'w, 'e, 'c>,
    ) -> Result<Self, Error> {
        Self::make(model, stepper, watch, None)
    }

    /// The watcher, its contacts checked at the state named `argument` if given.
    fn make<St: BorrowMut<StepperState>>(
        model: M,
        stepper: &mut Stepper<M, St>,
        watch: Watch<'w, 'e, 'c>,
        argument: Option<&'static str>,
    ) -> Result<Self, Error> {
        if watch.exchanges() {
            stepper.count_contact_work();
        }
        let search = watch.events.map(|events| events.begin(model, &*stepper)).transpose()?;
        let resolver = (watch.contacts.is_some() || watch.schedule.is_some())
            .then(|| {
                if let (Some(argument), Some(contacts)) = (argument, watch.contacts) {
                    contacts.check(&*model, stepper.method(), (stepper.t(), stepper.q()), argument)?;
                }
                Resolver::begin(model, stepper, (watch.contacts, watch.schedule))
            })
            .transpose()?;
        Ok(Watcher { search, resolver })
    }

    /// A new run's start at the stepper's t0: the samples there, then the impulses there
    /// applied, their states just before and after saved to `record` (see [`Watcher::advance`]).
    /// A resumed run skips this: its times at the start are the first run's.
    pub fn start<St: BorrowMut<StepperState>>(
        &mut self,
        stepper: &mut Stepper<M, St>,
        record: &mut Trajectory,
    ) -> Result<(), Error> {
        match self.resolver.as_mut() {
            Some(resolver) => resolver.start(stepper, self.search.as_mut(), record),
            None => Ok(()),
        }
    }

    /// Whether the run saves the samples' states, and those alone.
    pub fn sampling(&self) -> bool {
        self.resolver.as_ref().is_some_and(|r| r.sampling())
    }

    /// How many samples the run's schedule holds (0 without).
    pub fn samples(&self) -> usize {
        self.resolver.as_ref().map_or(0, |r| r.samples())
    }

    /// The watcher of nothing: the steps many at a time, as a plain run takes them.
    pub(in crate::integrators) fn idle() -> Self {
        Watcher {
            search: None,
            resolver: None,
        }
    }

    /// Advances `stepper` by up to `n` steps, pushing the located events to `record.events`,
    /// the impacts to `record.impacts` and the states just before and after each impact and
    /// impulse to its saved states (or, with samples, the samples' states alone). Returns the event whose terminal count was reached (the stepper stopping at
    /// the end of that step); None after the n steps. On failure the stepper is at the last good
    /// step ([`Error::Contact`]: the start of the step of the impact).
    pub fn advance<St: BorrowMut<StepperState>, P: Poll>(
        &mut self,
        stepper: &mut Stepper<M, St>,
        n: usize,
        record: &mut Trajectory,
        poll: &mut P,
    ) -> Result<Option<usize>, Error> {
        match (self.search.as_mut(), self.resolver.as_mut()) {
            (None, None) => stepper
                .advance(n, crate::integrators::Counting(|steps| poll.poll(steps)))
                .map(|()| None),
            (Some(search), None) => search.advance(stepper, n, &mut record.events, poll),
            (search, Some(resolver)) => resolver.advance(stepper, n, search, record, poll),
        }
    }

    /// Whether it reflects impacts by Newton's law ([`super::Law::Reflect`]), which moves the
    /// modified energy of a method that is not symmetric.
    pub fn reflects(&self) -> bool {
        self.resolver.as_ref().is_some_and(|r| r.reflects())
    }

    /// Force evaluations of the partial steps (located events and impacts).
    pub fn force_evaluations(&self) -> u64 {
        self.search.as_ref().map_or(0, |s| s.force_evaluations())
            + self.resolver.as_ref().map_or(0, |r| r.force_evaluations())
    }
}
