//! A stepper of a Python model: the core's [`StepperState`] kept between calls and resumed on
//! the model, through the one dispatch [`bind_model`], for each call; with contacts, impulses or
//! events, each call's steps go through a [`Watcher`] resumed on that state.

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use varmech::integrators::{
    self, Checkpoint, Contacts, Detector, Dynamics, EventSpec, Impacts, Occurrence, Schedule, StepperState, Tangent,
    Trajectory, Watch, Watcher,
};
use varmech::Error;

use crate::bind::{bind_model, Poll};
use crate::contacts::ContactSpecs;
use crate::convert::slice;
use crate::errors::to_pyerr;
use crate::events::{EventTuple, Events};
use crate::run::detector_parts;
use crate::runspec::RunSpec;
use crate::schedule::ScheduleSpecs;
use crate::trajectory::{event_arrays, impact_arrays, switch_arrays, EventArrays, ImpactArrays, SwitchArrays};

/// One model, one method and the state, advanced step by step
/// ([`varmech::integrators::Stepper`]): native models with the GIL released, Ctrl-C honoured
/// by `advance`, and a failed step leaves the last good state. With `contacts` and `impulses`,
/// the steps go through their impacts and blows as a run's do ([`Watcher`]), bit for bit; with
/// `events`, their crossings are located as a run's are, a terminal one stopping the call.
///
/// A call holds the stepper mutably (pyo3's borrow flag, not a lock): another call while one
/// runs (a thread while the GIL is released, a closure model re-entering) raises RuntimeError
/// rather than wait on a lock that the running call's Ctrl-C poll, which takes the GIL, could
/// deadlock against.
#[pyclass(module = "varmech._core")]
pub struct Stepper {
    model: Py<PyAny>,
    state: StepperState,
    /// The contacts whose impacts the steps resolve, if any.
    contacts: Option<ContactSpecs>,
    /// The impulses the steps apply (those after the state's time).
    impulses: ScheduleSpecs,
    /// The impacts gone through since the start or the last reset.
    impacts: Impacts,
    /// Force evaluations of the impacts' and the events' partial steps.
    partial_evaluations: u64,
    /// The event functions the steps watch, with their specs (terminal counts carried from call
    /// to call, as a run gone on from counts them).
    events: Option<(Events, Vec<EventSpec>)>,
    /// The events' crossings since the start or the last reset.
    occurrences: Vec<Occurrence>,
    /// The event whose terminal count stopped the last call, if one did.
    terminated_by: Option<usize>,
}

type Core<'s, 'a> = integrators::Stepper<&'s dyn Dynamics, &'a mut StepperState>;

impl Stepper {
    /// The stepper of `state` on `model`, watching the spec's contacts (checked at the state,
    /// named `argument` if outside one) and events (started at the state) and applying its impulses:
    /// those at the state's time too where `fresh` (a new stepper; a checkpoint's were its
    /// run's).
    fn watching<'py>(
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
        state: StepperState,
        spec: &RunSpec,
        (argument, fresh): (&'static str, bool),
    ) -> PyResult<Self> {
        let (contacts, impulses) = (spec.contacts(py)?, spec.schedule(py)?);
        let events = detector_parts(py, model, spec.events(py)?)?;
        let n = state.q().len();
        let mut stepper = Stepper {
            model: model.clone().unbind(),
            state,
            contacts,
            impulses,
            impacts: Impacts::default(),
            partial_evaluations: 0,
            events,
            occurrences: Vec::new(),
            terminated_by: None,
        };
        stepper.impacts.dim = n;
        stepper.check(py, argument, fresh)?;
        Ok(stepper)
    }

    /// Whether the steps are the method's alone, with no contacts, impulses or events to watch.
    fn unwatched(&self) -> bool {
        self.contacts.is_none() && self.impulses.is_empty() && self.events.is_none()
    }

    /// Whether the contacts and impulses fit the model and method and the state lies in φ ≥ 0
    /// (named `argument` if not), the events started at the state; where `fresh`, the impulses
    /// at the state's time applied.
    fn check(&mut self, py: Python<'_>, argument: &'static str, fresh: bool) -> PyResult<()> {
        if self.unwatched() {
            return Ok(());
        }
        let (specs, impulses, state) = (&self.contacts, &self.impulses, &mut self.state);
        let events = &mut self.events;
        bind_model(py, self.model.bind(py), |sys, _| {
            let mut stepper = integrators::Stepper::resume(sys, state)?;
            let watched = Watched::new(specs, impulses)?;
            let mut detector = lend(events)?;
            let mut watcher = Watcher::begin(sys, &mut stepper, watched.watch(detector.as_mut()), argument)?;
            if fresh {
                watcher.start(&mut stepper, &mut Trajectory::default())?;
            }
            Ok(())
        })?
        .map_err(|e| to_pyerr(py, e))
    }

    /// Runs `body` on the state resumed on the model; the state stays put whatever happens.
    fn with<R, F>(&mut self, py: Python<'_>, body: F) -> PyResult<R>
    where
        R: Send,
        F: for<'s, 'a> FnOnce(&mut Core<'s, 'a>, Poll<'s>) -> Result<R, Error> + Send,
    {
        let Stepper { model, state, .. } = self;
        bind_model(py, model.bind(py), |sys, poll| {
            body(&mut integrators::Stepper::resume(sys, state)?, poll)
        })?
        .map_err(|e| to_pyerr(py, e))
    }

    /// Advances `n` steps (one by [`integrators::Stepper::step`] where `single`), through the
    /// contacts' impacts if any: a [`Watcher`] resumed on the state, its impacts kept.
    fn go(&mut self, py: Python<'_>, n: usize, single: bool) -> PyResult<()> {
        self.state.check_horizon(n).map_err(|e| to_pyerr(py, e))?;
        if self.unwatched() {
            return self.with(py, |stepper, poll| {
                if single {
                    stepper.step()
                } else {
                    stepper.advance(n, poll)
                }
            });
        }
        let (specs, impulses) = (&self.contacts, &self.impulses);
        let (impacts, evaluations) = (&mut self.impacts, &mut self.partial_evaluations);
        let (events, occurrences, terminated_by) = (&mut self.events, &mut self.occurrences, &mut self.terminated_by);
        let state = &mut self.state;
        *terminated_by = None;
        bind_model(py, self.model.bind(py), |sys, mut poll| {
            let mut stepper = integrators::Stepper::resume(sys, state)?;
            let watched = Watched::new(specs, impulses)?;
            let mut detector = lend(events)?;
            let mut watcher = Watcher::resume(sys, &mut stepper, watched.watch(detector.as_mut()))?;
            let mut record = Trajectory::default();
            let advanced = watcher.advance(&mut stepper, n, &mut record, &mut poll);
            // The impacts and crossings of the steps completed, a failed step's excepted.
            impacts.append(&mut record.impacts);
            *evaluations += watcher.force_evaluations();
            drop(watcher);
            drop(detector);
            if let Some((_, specs)) = events {
                EventSpec::carry(specs, &record.events);
            }
            occurrences.append(&mut record.events);
            *terminated_by = advanced?;
            Ok(())
        })?
        .map_err(|e| to_pyerr(py, e))
    }
}

/// A call's [`Detector`] of the stepper's event functions, lent to it with a copy of their specs.
fn lend(events: &mut Option<(Events, Vec<EventSpec>)>) -> Result<Option<Detector<'_>>, varmech::Error> {
    events
        .as_mut()
        .map(|(functions, specs)| Detector::new(Box::new(functions), specs.clone()))
        .transpose()
}

/// The core's contacts and schedule of a stepper's specs, made for a call.
struct Watched<'a> {
    contacts: Option<Contacts<'a>>,
    schedule: Option<Schedule<'a>>,
}

impl<'a> Watched<'a> {
    fn new(contacts: &'a Option<ContactSpecs>, impulses: &'a ScheduleSpecs) -> Result<Self, Error> {
        Ok(Watched {
            contacts: contacts.as_ref().map(ContactSpecs::contacts).transpose()?,
            schedule: (!impulses.is_empty()).then(|| impulses.schedule()).transpose()?,
        })
    }

    /// The watch of these, with the call's `events`.
    fn watch<'w, 'e>(&'w self, events: Option<&'w mut Detector<'e>>) -> Watch<'w, 'e, 'a> {
        Watch {
            events,
            contacts: self.contacts.as_ref(),
            schedule: self.schedule.as_ref(),
        }
    }
}

#[pymethods]
impl Stepper {
    #[new]
    fn new<'py>(
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
        q0: PyReadonlyArray1<'py, f64>,
        p0: PyReadonlyArray1<'py, f64>,
        spec: &RunSpec,
    ) -> PyResult<Self> {
        let (method, options) = spec.options()?;
        let (q0, p0) = (slice("q0", &q0)?, slice("p0", &p0)?);
        let state = bind_model(py, model, |sys, _| {
            integrators::Stepper::new(sys, method, q0, p0, &options).map(integrators::Stepper::into_state)
        })?
        .map_err(|e| to_pyerr(py, e))?;
        Stepper::watching(py, model, state, spec, ("q0", true))
    }

    /// The stepper's whole state as bytes, with its model's fingerprint (see [`Checkpoint`]).
    fn checkpoint<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self.with(py, |stepper, _| Ok(Checkpoint::of(stepper.model(), stepper).to_bytes()))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// The stepper of `model` at the state of `checkpoint` (from `checkpoint()`, or a run's),
    /// checked against the model (and the spec's method and `dt` where given), watching what
    /// `spec` says.
    #[staticmethod]
    fn from_checkpoint<'py>(
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
        checkpoint: &[u8],
        spec: &RunSpec,
    ) -> PyResult<Self> {
        let checkpoint = spec.checkpoint(py, checkpoint)?;
        let state = bind_model(py, model, |sys, _| {
            let state = checkpoint.into_state(sys)?;
            integrators::Stepper::resume(sys, state).map(integrators::Stepper::into_state)
        })?
        .map_err(|e| to_pyerr(py, e))?;
        Stepper::watching(py, model, state, spec, ("checkpoint", false))
    }

    /// Advances one step.
    fn step(&mut self, py: Python<'_>) -> PyResult<()> {
        self.go(py, 1, true)
    }

    /// Advances `n` steps, checking for Ctrl-C on the way.
    fn advance(&mut self, py: Python<'_>, n: usize) -> PyResult<()> {
        self.go(py, n, false)
    }

    /// Advances `n` steps as `advance` does, carrying the tangent vectors `x` (k columns (δq, δp)
    /// of 2n entries one after the other) by the steps' tangent map, and returns them carried.
    /// A stepper that watches contacts, impulses or events is refused: their jumps have no
    /// tangent map here.
    fn advance_tangent<'py>(
        &mut self,
        py: Python<'py>,
        n: usize,
        x: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        if !self.unwatched() {
            return Err(PyValueError::new_err(
                "tangent: a stepper with contacts, impulses or events has jumps, which have no tangent map here; \
                 carry tangent vectors on a stepper of the model alone",
            ));
        }
        let mut x = slice("tangent", &x)?.to_vec();
        let vectors = &mut x;
        self.with(py, |stepper, poll| {
            let mut tangent = Tangent::new(stepper.method(), stepper.model())?;
            stepper.advance_with_tangent(n, &mut tangent, vectors, poll)
        })?;
        Ok(PyArray1::from_vec(py, x))
    }

    /// Starts afresh from (q0, p0) at t0, with the step count at 0, no impacts and no event
    /// crossings, the impulses at t0 applied and the `events` (the constructor's again) started
    /// as a new stepper's; a state outside a contact is refused (naming `q0`), the stepper
    /// unchanged.
    #[pyo3(signature = (q0, p0, t0, *, events=None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        q0: PyReadonlyArray1<'py, f64>,
        p0: PyReadonlyArray1<'py, f64>,
        t0: f64,
        events: Option<Vec<EventTuple<'py>>>,
    ) -> PyResult<()> {
        let (q0, p0) = (slice("q0", &q0)?, slice("p0", &p0)?);
        let fresh = detector_parts(py, self.model.bind(py), events)?;
        let (state, events) = (self.state.clone(), std::mem::replace(&mut self.events, fresh));
        self.with(py, |stepper, _| stepper.reset(t0, q0, p0))?;
        if let Err(e) = self.check(py, "q0", true) {
            (self.state, self.events) = (state, events);
            return Err(e);
        }
        self.impacts = Impacts {
            dim: self.impacts.dim,
            ..Impacts::default()
        };
        (self.occurrences, self.terminated_by) = (Vec::new(), None);
        Ok(())
    }

    /// The events' crossings since the start or the last reset, as a run's record holds them.
    #[getter]
    fn events(&self, py: Python<'_>) -> PyResult<EventArrays> {
        event_arrays(py, &self.occurrences, self.impacts.dim)
    }

    /// The index of the event whose terminal count stopped the last call, if one did.
    #[getter]
    fn terminated_by(&self) -> Option<usize> {
        self.terminated_by
    }

    #[getter]
    fn t(&self) -> f64 {
        self.state.t()
    }

    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.state.q())
    }

    #[getter]
    fn p<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.state.p())
    }

    #[getter]
    fn steps(&self) -> usize {
        self.state.steps()
    }

    #[getter]
    fn dt(&self) -> f64 {
        self.state.dt()
    }

    #[setter]
    fn set_dt(&mut self, py: Python<'_>, dt: f64) -> PyResult<()> {
        self.with(py, |stepper, _| stepper.set_dt(dt))
    }

    #[getter]
    fn method(&self) -> &'static str {
        self.state.method().info().name
    }

    #[getter]
    fn force_evaluations(&self) -> u64 {
        self.state.force_evaluations() + self.partial_evaluations
    }

    /// The impacts gone through since the start or the last reset, as a run's record has them:
    /// the contact's index (k,), t (k,), q, p before and p after (k, n).
    #[getter]
    fn impacts(&self, py: Python<'_>) -> PyResult<ImpactArrays> {
        impact_arrays(py, self.impacts.clone(), self.impacts.dim)
    }

    /// The contacts' switches since the start or the last reset, as a run's record has them:
    /// the contact's index (k,), t (k,), the kind (k,), q and p (k, n).
    #[getter]
    fn switches(&self, py: Python<'_>) -> PyResult<SwitchArrays> {
        switch_arrays(py, self.impacts.switches.clone(), self.impacts.dim)
    }

    /// Impacts under the variational law that took Newton's law (grazing), as a run's.
    #[getter]
    fn grazing(&self) -> usize {
        self.impacts.grazing
    }

    #[getter]
    fn newton_iterations(&self) -> u64 {
        self.state.newton_iterations()
    }

    #[getter]
    fn work(&self) -> f64 {
        self.state.work()
    }
}
