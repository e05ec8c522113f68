//! The detector: the sign-change test after each step, and each crossing located by the
//! method's own partial step.

use std::borrow::{Borrow, BorrowMut};
use std::ops::Deref;

use super::{EventFunctions, EventSpec, Occurrence};
use crate::integrators::{Counting, Dynamics, Poll, Stepper, StepperState};
use crate::solve::bracket::illinois;
use crate::{Error, ModelError};

/// Event functions with their [`EventSpec`]s, for a run ([`crate::integrators::integrate_watching`]).
///
/// After every step (tₙ, qₙ, pₙ) → (tₙ₊₁, qₙ₊₁, pₙ₊₁) the run evaluates every gᵢ; a crossing
/// of event i is gᵢ(zₙ) ≠ 0 and gᵢ(zₙ₊₁) of the other sign or 0, in the spec's direction. It is
/// located on the method's own map: τ* ∈ (0, h] with gᵢ(Φ_τ*(zₙ)) = 0 to round-off, Φ_τ one
/// step of size τ of the run's method from zₙ (the Illinois method on the bracket [0, h];
/// [`illinois`]). The located state is then a state of the integrator, with the method's error
/// (of order p in h, whatever τ); its time tₙ + τ* is off the exact crossing time by O(hᵖ).
/// Two crossings of one gᵢ within a step cancel and are not seen (as in `solve_ivp`).
pub struct Detector<'f> {
    functions: Box<dyn EventFunctions + 'f>,
    specs: Vec<EventSpec>,
}

impl<'f> Detector<'f> {
    /// The detector of `functions` with one spec each. Refuses (naming `events`) a count that
    /// differs from the functions' and a direction other than −1, 0, +1.
    pub fn new(functions: Box<dyn EventFunctions + 'f>, specs: Vec<EventSpec>) -> Result<Self, Error> {
        if functions.len() != specs.len() {
            let reason = format!("{} functions, {} specs", functions.len(), specs.len());
            return Err(Error::invalid("events", reason));
        }
        if let Some(spec) = specs.iter().find(|s| !(-1..=1).contains(&s.direction)) {
            let reason = format!("{}: direction must be -1, 0 or +1, got {}", spec.name, spec.direction);
            return Err(Error::invalid("events", reason));
        }
        Ok(Detector { functions, specs })
    }

    /// The specs, in the order of the functions.
    pub fn specs(&self) -> &[EventSpec] {
        &self.specs
    }

    /// A run's search from the state of `stepper` (where the run starts or resumes), on
    /// `model`: the functions started and evaluated there, the scratch stepper of the partial
    /// steps made (a copy of the stepper: its method, summation and Newton options), and the
    /// buffers of the state before a step, once per run.
    pub(in crate::integrators) fn begin<'d, M, St>(
        &'d mut self,
        model: M,
        stepper: &Stepper<M, St>,
    ) -> Result<Search<'d, 'f, M>, Error>
    where
        M: Deref<Target: Dynamics>,
        St: Borrow<StepperState>,
    {
        let (t, q, p) = (stepper.t(), stepper.q(), stepper.p());
        let m = self.specs.len();
        let model_error = |source| Error::Model {
            step: 0,
            time: t,
            source,
        };
        let mut g = vec![0.0; m];
        self.functions
            .start(model.as_dynamics(), t, q, p)
            .map_err(model_error)?;
        self.functions
            .evaluate(model.as_dynamics(), t, q, p, &mut g)
            .map_err(model_error)?;
        check_finite(&self.specs, &g, 0, t)?;
        let scratch = Stepper::resume(model, StepperState::clone(stepper))?;
        Ok(Search {
            detector: self,
            counted: scratch.force_evaluations(),
            scratch,
            t: 0.0,
            q: q.to_vec(),
            p: p.to_vec(),
            q_at: q.to_vec(),
            p_at: p.to_vec(),
            g,
            g_next: vec![0.0; m],
            g_trial: vec![0.0; m],
            counts: vec![0; m],
        })
    }
}

/// The partial steps of a piece that the run's method alone does not take: a held contact's
/// (RATTLE on the closed contacts, [`crate::integrators::jumps`]). A crossing on such a piece
/// is located on them, so that the located state keeps the contact.
pub(in crate::integrators) trait PieceSteps {
    /// The state τ into the piece, from its start (the search's kept start).
    fn state_at(&mut self, step: usize, tau: f64) -> Result<(&[f64], &[f64]), Error>;
}

/// A run's detector: the scratch [`Stepper`] of the partial steps, on the run's model, and the
/// state (tₙ, qₙ, pₙ) and values gᵢ(zₙ) before the step, kept in buffers made once.
pub(in crate::integrators) struct Search<'d, 'f, M> {
    detector: &'d mut Detector<'f>,
    scratch: Stepper<M>,
    /// The scratch's force evaluations when it was made (the run's so far).
    counted: u64,
    t: f64,
    q: Vec<f64>,
    p: Vec<f64>,
    /// The state of the last partial step.
    q_at: Vec<f64>,
    p_at: Vec<f64>,
    g: Vec<f64>,
    g_next: Vec<f64>,
    g_trial: Vec<f64>,
    counts: Vec<usize>,
}

impl<M: Deref<Target: Dynamics>> Search<'_, '_, M> {
    /// Advances `stepper` by up to `n` steps, one at a time, pushing every located crossing to
    /// `occurrences` (in order of time within a step). Returns the event whose terminal count
    /// was reached, the run stopping at the end of that step; None after the n steps.
    pub(in crate::integrators) fn advance<St: BorrowMut<StepperState>, P: Poll>(
        &mut self,
        stepper: &mut Stepper<M, St>,
        n: usize,
        occurrences: &mut Vec<Occurrence>,
        poll: &mut P,
    ) -> Result<Option<usize>, Error> {
        for _ in 0..n {
            self.start_step(stepper);
            stepper.advance(1, Counting(|steps| poll.poll(steps)))?;
            let first = occurrences.len();
            let (step, t, h) = (stepper.steps(), stepper.t(), stepper.dt());
            self.piece(step, (t, stepper.q(), stepper.p()), h, occurrences)?;
            if let Some(stop) = self.count(occurrences, first) {
                return Ok(Some(stop));
            }
        }
        Ok(None)
    }

    /// Keeps the stepper's state (tₙ, qₙ, pₙ), the start of its next step; gᵢ(zₙ) are those
    /// of the last step's end.
    pub(in crate::integrators) fn start_step<St: Borrow<StepperState>>(&mut self, stepper: &Stepper<M, St>) {
        self.t = stepper.t();
        self.q.copy_from_slice(stepper.q());
        self.p.copy_from_slice(stepper.p());
    }

    /// The piece of step `step` of size τ from the kept start to `end` = (t, q, p): the
    /// functions evaluated at its end, and each crossing located on it, pushed to `occurrences`.
    /// The end's values are then the next piece's start's. A step without impacts is one piece.
    pub(in crate::integrators) fn piece(
        &mut self,
        step: usize,
        end: (f64, &[f64], &[f64]),
        tau: f64,
        occurrences: &mut Vec<Occurrence>,
    ) -> Result<(), Error> {
        self.piece_on(step, end, tau, occurrences, None)
    }

    /// [`Search::piece`], its crossings located on `steps` where given (a held piece's).
    pub(in crate::integrators) fn piece_on(
        &mut self,
        step: usize,
        (t, q, p): (f64, &[f64], &[f64]),
        tau: f64,
        occurrences: &mut Vec<Occurrence>,
        mut steps: Option<&mut dyn PieceSteps>,
    ) -> Result<(), Error> {
        let model = self.scratch.model().as_dynamics();
        let functions = &mut self.detector.functions;
        if let Err(source) = functions.evaluate(model, t, q, p, &mut self.g_next) {
            return Err(Error::Model {
                step,
                time: self.t,
                source,
            });
        }
        check_finite(&self.detector.specs, &self.g_next, step, t)?;
        for i in 0..self.g.len() {
            if crosses(self.detector.specs[i].direction, self.g[i], self.g_next[i]) {
                let occurrence = self.locate(i, step, tau, &mut steps)?;
                occurrences.push(occurrence);
            }
        }
        std::mem::swap(&mut self.g, &mut self.g_next);
        Ok(())
    }

    /// A new piece from (t, q, p), the state just after a jump: the functions evaluated there.
    pub(in crate::integrators) fn restart_piece(
        &mut self,
        step: usize,
        (t, q, p): (f64, &[f64], &[f64]),
    ) -> Result<(), Error> {
        self.t = t;
        self.q.copy_from_slice(q);
        self.p.copy_from_slice(p);
        let model = self.scratch.model().as_dynamics();
        let evaluated = self.detector.functions.evaluate(model, t, q, p, &mut self.g);
        evaluated.map_err(|source| Error::model(step, t, source))?;
        check_finite(&self.detector.specs, &self.g, step, t)
    }

    /// Sorts the step's occurrences (from `first` on) by time and counts them: the event whose
    /// terminal count they reach first, if any.
    pub(in crate::integrators) fn count(&mut self, occurrences: &mut [Occurrence], first: usize) -> Option<usize> {
        occurrences[first..].sort_unstable_by(|a, b| a.t.total_cmp(&b.t));
        let mut stop = None;
        for occurrence in &occurrences[first..] {
            let i = occurrence.event;
            self.counts[i] += 1;
            if self.counts[i] == self.detector.specs[i].terminal && stop.is_none() {
                stop = Some(i);
            }
        }
        stop
    }

    /// The crossing of event i in step `step` of size h: τ* with f(τ*) = 0, f(τ) = ±gᵢ(Φ_τ(zₙ))
    /// signed so that f(0) < 0 ≤ f(h), and the partial step's state there.
    fn locate(
        &mut self,
        i: usize,
        step: usize,
        h: f64,
        steps: &mut Option<&mut dyn PieceSteps>,
    ) -> Result<Occurrence, Error> {
        let sign = -self.g[i].signum();
        let (start, end) = ((0.0, sign * self.g[i]), (h, sign * self.g_next[i]));
        let (tau, _) = illinois(
            |tau| Ok(sign * self.partial_step(i, step, tau, steps)?),
            start,
            end,
            0.0,
        )?;
        self.partial_step(i, step, tau, steps)?;
        Ok(Occurrence {
            event: i,
            step,
            t: self.t + tau,
            q: self.q_at.clone(),
            p: self.p_at.clone(),
            q_start: self.q.clone(),
            p_start: self.p.clone(),
        })
    }

    /// gᵢ(Φ_τ(zₙ)), Φ_τ(zₙ) kept in `q_at`, `p_at`: `steps`' state τ into the piece, or the
    /// scratch stepper reset to zₙ and one step of size τ (an error names the run's `step`).
    fn partial_step(
        &mut self,
        i: usize,
        step: usize,
        tau: f64,
        steps: &mut Option<&mut dyn PieceSteps>,
    ) -> Result<f64, Error> {
        let (q, p) = match steps {
            Some(steps) => steps.state_at(step, tau)?,
            None => {
                self.scratch.reset(self.t, &self.q, &self.p)?;
                self.scratch.set_dt(tau)?;
                self.scratch.step()?;
                (self.scratch.q(), self.scratch.p())
            }
        };
        self.q_at.copy_from_slice(q);
        self.p_at.copy_from_slice(p);
        let (t, model) = (self.t + tau, self.scratch.model().as_dynamics());
        let evaluated = self
            .detector
            .functions
            .evaluate(model, t, &self.q_at, &self.p_at, &mut self.g_trial);
        evaluated.map_err(|source: ModelError| Error::Model {
            step,
            time: self.t,
            source,
        })?;
        Ok(self.g_trial[i])
    }

    /// Force evaluations of the partial steps.
    pub(in crate::integrators) fn force_evaluations(&self) -> u64 {
        self.scratch.force_evaluations() - self.counted
    }
}

/// Whether g went from `before` ≠ 0 to the other sign or 0, in `direction` (+1 up, −1 down, 0
/// either).
fn crosses(direction: i8, before: f64, after: f64) -> bool {
    let up = before < 0.0 && after >= 0.0;
    let down = before > 0.0 && after <= 0.0;
    match direction {
        1 => up,
        -1 => down,
        _ => up || down,
    }
}

/// A non-finite gᵢ is an error naming the event, at the state where it was evaluated.
fn check_finite(specs: &[EventSpec], g: &[f64], step: usize, time: f64) -> Result<(), Error> {
    match g.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => {
            let (name, value) = (&specs[i].name, g[i]);
            let source = format!("event {name} returned a non-finite value g = {value} at t = {time}").into();
            Err(Error::model(step, time, source))
        }
    }
}
