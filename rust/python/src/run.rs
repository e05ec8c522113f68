//! Running the integrators: `integrate`, one step's symplecticity defect, and the catalogue of
//! methods.

use numpy::PyReadonlyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::diagnostics;
use varmech::integrators::{self, Counting, Detector, EventSpec, Failure, Method, Splitting, Trajectory, Watch};
use varmech::ModelError;

use crate::bind::{bind_model, dim_of, Poll};
use crate::contacts::ContactSpecs;
use crate::convert::{self, count, slice};
use crate::errors::{boxed, failure_to_pyerr, to_pyerr};
use crate::events::{EventTuple, Events};
use crate::runspec::RunSpec;
use crate::schedule::ScheduleSpecs;
use crate::trajectory::TrajectoryRecord;

/// Integrates as `spec` says; returns the saved states as a [`TrajectoryRecord`] or raises
/// with `_varmech_partial`, the states up to the failure. The run watches the spec's events (see
/// [`Events::new`]), resolves the impacts on its contacts (see [`ContactSpecs::new`]), applies
/// its impulses (see [`ScheduleSpecs::new`]) and saves the states at its `t_eval` alone, if
/// given ([`integrators::integrate_watching`]).
#[pyfunction]
#[pyo3(signature = (model, q0, p0, spec, *, progress=None))]
fn integrate<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q0: PyReadonlyArray1<'py, f64>,
    p0: PyReadonlyArray1<'py, f64>,
    spec: &RunSpec,
    progress: Option<Py<PyAny>>,
) -> PyResult<TrajectoryRecord> {
    let (method, options) = spec.options()?;
    let (q0, p0) = (slice("q0", &q0)?, slice("p0", &p0)?);
    let events = detector_parts(py, model, spec.events(py)?)?;
    let (contacts, schedule) = (spec.contacts(py)?, spec.schedule(py)?);
    let result = bind_model(py, model, |sys, poll| {
        let report = reporting(poll, &progress);
        watching(events, contacts.as_ref(), &schedule, |watch| {
            integrators::integrate_watching(sys, method, q0, p0, &options, report, watch)
        })
    })?;
    record(py, result)
}

/// Runs `run` with the [`Watch`] of `events`, `contacts` and `schedule`, or the failure of a
/// run that never started (events, contacts or schedule malformed).
fn watching<'c>(
    events: Option<(Events, Vec<EventSpec>)>,
    contacts: Option<&'c ContactSpecs>,
    schedule: &'c ScheduleSpecs,
    run: impl FnOnce(Watch<'_, '_, 'c>) -> Result<Trajectory, Box<Failure>>,
) -> Result<Trajectory, Box<Failure>> {
    let never_started = |error| {
        let partial = Trajectory::default();
        Box::new(Failure { error, partial })
    };
    let mut detector = match events {
        None => None,
        Some((functions, specs)) => Some(Detector::new(Box::new(functions), specs).map_err(never_started)?),
    };
    let contacts = contacts
        .map(ContactSpecs::contacts)
        .transpose()
        .map_err(never_started)?;
    let schedule = (!schedule.is_empty())
        .then(|| schedule.schedule())
        .transpose()
        .map_err(never_started)?;
    run(Watch {
        events: detector.as_mut(),
        contacts: contacts.as_ref(),
        schedule: schedule.as_ref(),
    })
}

/// The event functions and specs of `events`, checked against the model.
pub(crate) fn detector_parts<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    events: Option<Vec<EventTuple<'py>>>,
) -> PyResult<Option<(Events, Vec<EventSpec>)>> {
    events
        .map(|tuples| Events::new(py, tuples, dim_of(py, model)?))
        .transpose()
}

/// Goes on from a run's checkpoint for the spec's `steps` more steps (see
/// [`integrators::resume`]), watching its events, resolving the impacts on its contacts,
/// applying its impulses and taking its samples `t_eval` after the checkpoint's time (as
/// `integrate`'s); a checkpoint of another method or `dt` than the spec's is refused
/// ([`varmech::integrators::Checkpoint::expect`]).
#[pyfunction]
#[pyo3(signature = (model, checkpoint, spec, *, progress=None))]
fn resume<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    checkpoint: &[u8],
    spec: &RunSpec,
    progress: Option<Py<PyAny>>,
) -> PyResult<TrajectoryRecord> {
    let checkpoint = spec.checkpoint(py, checkpoint)?;
    let events = detector_parts(py, model, spec.events(py)?)?;
    let (contacts, schedule) = (spec.contacts(py)?, spec.schedule(py)?);
    let (steps, save_every) = (spec.steps, spec.save_every);
    let result = bind_model(py, model, |sys, poll| {
        let report = reporting(poll, &progress);
        watching(events, contacts.as_ref(), &schedule, |watch| {
            integrators::resume_watching(sys, checkpoint, steps, save_every, report, watch)
        })
    })?;
    record(py, result)
}

/// The poll of a run: the Ctrl-C check, then `progress(steps)` if given.
pub(crate) fn reporting<'a>(
    poll: Poll<'a>,
    progress: &'a Option<Py<PyAny>>,
) -> Counting<impl FnMut(usize) -> Result<(), ModelError> + 'a> {
    Counting(move |steps: usize| {
        poll()?;
        match progress {
            Some(progress) => Python::attach(|py| progress.call1(py, (steps,)).map(drop)).map_err(boxed),
            None => Ok(()),
        }
    })
}

/// The record of a run, or its error with the partial trajectory.
fn record(py: Python<'_>, result: Result<Trajectory, Box<Failure>>) -> PyResult<TrajectoryRecord> {
    match result {
        Ok(traj) => TrajectoryRecord::new(py, traj),
        Err(failure) => Err(failure_to_pyerr(py, *failure)),
    }
}

// The counts, each named in its errors (see [`count`]).
pub(crate) fn steps_count(x: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("steps", x)
}

pub(crate) fn save_every_count(x: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("save_every", x)
}

pub(crate) fn newton_max_iterations_count(x: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("newton_max_iterations", x)
}

/// ‖ΨᵀJΨ − J‖_F of one step.
#[pyfunction]
fn symplecticity_defect<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = convert::method)] method: Method,
    q: PyReadonlyArray1<'py, f64>,
    p: PyReadonlyArray1<'py, f64>,
    dt: f64,
) -> PyResult<f64> {
    let (q, p) = (slice("q", &q)?, slice("p", &p)?);
    let defect = bind_model(py, model, |sys, _poll| {
        diagnostics::symplecticity_defect(sys, method, q, p, dt)
    })?
    .map_err(|e| to_pyerr(py, e))?;
    Ok(defect)
}

/// Facts about one fixed-step method.
///
/// ``h_omega_max`` is the linear stability limit: the method is stable on q'' = -ω²q exactly
/// when hω < h_omega_max (0 for explicit Euler, which is never stable).
/// ``force_evaluations`` counts gradient evaluations per step, first-same-as-last reused (0 for
/// the implicit methods, whose cost depends on their Newton iterations). ``implicit`` methods
/// solve each step by Newton's method; ``constrained`` ones (RATTLE, SHAKE) integrate systems
/// on holonomic constraints, and only those; ``nonholonomic`` ones (``cortes_martinez``,
/// ``dla4``) integrate velocity constraints, and only those; ``nbody`` ones (the Wisdom–Holman methods ``wh``
/// and ``whc``) integrate the gravitational N-body problem, and only that (``h_omega_max`` is
/// NaN for them). ``force_evaluations`` of the Wisdom–Holman methods counts the kicks of a step
/// between synchronisations; ``whc``'s corrector adds 20 kicks at the start and at every saved
/// state. ``splitting`` is (a₀, …, aₛ; b₁, …, bₛ), the kick and drift fractions of a kick–drift
/// method, Ψ_h = φ^V_{aₛh} ∘ φ^T_{bₛh} ∘ … ∘ φ^T_{b₁h} ∘ φ^V_{a₀h}; None for the others.
/// ``features`` names what its step offers beyond the models it integrates, from the core's one
/// table: ``discrete_energy`` (the variational collision law), ``tangent_map`` (Lyapunov
/// spectra), ``held_step`` (contacts held closed, friction), ``delayed_forces``.
#[pyclass(frozen, get_all, module = "varmech._core")]
pub struct MethodInfo {
    name: &'static str,
    order: u32,
    stages: usize,
    force_evaluations: usize,
    implicit: bool,
    constrained: bool,
    nonholonomic: bool,
    nbody: bool,
    symplectic: bool,
    symmetric: bool,
    h_omega_max: f64,
    reference: &'static str,
    splitting: Option<(Vec<f64>, Vec<f64>)>,
    features: Vec<&'static str>,
}

impl From<integrators::MethodInfo> for MethodInfo {
    fn from(i: integrators::MethodInfo) -> Self {
        MethodInfo {
            name: i.name,
            order: i.order,
            stages: i.stages,
            force_evaluations: i.force_evaluations,
            implicit: i.implicit,
            constrained: i.constrained,
            nonholonomic: i.nonholonomic,
            nbody: i.nbody,
            symplectic: i.symplectic,
            symmetric: i.symmetric,
            h_omega_max: i.h_omega_max,
            reference: i.reference,
            splitting: Splitting::of(i.method).map(|s| (s.kicks().to_vec(), s.drifts().to_vec())),
            features: i.features.iter().map(|f| f.name()).collect(),
        }
    }
}

#[pymethods]
impl MethodInfo {
    fn __repr__(&self) -> String {
        format!("MethodInfo(name={:?}, order={})", self.name, self.order)
    }
}

/// Every method's facts, the unconstrained ones first, each from the simplest, then the
/// constrained ones, the nonholonomic ones and the N-body ones.
#[pyfunction]
fn methods() -> Vec<MethodInfo> {
    Method::every().map(|m| m.info().into()).collect()
}

/// Refuses, naming `argument` (ValueError), `count` items of `size` bytes each that the memory
/// available to the process cannot hold ([`varmech::memory::check_bytes`]): for an allocation
/// that Python sizes from an argument before the core sees it (`t_eval`'s rows).
#[pyfunction]
fn check_allocation(argument: &str, count: usize, size: usize) -> PyResult<()> {
    varmech::memory::check_bytes(count, size).map_err(|reason| PyValueError::new_err(format!("{argument}: {reason}")))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<TrajectoryRecord>()?;
    m.add_class::<MethodInfo>()?;
    add_functions!(m, [check_allocation, integrate, resume, symplecticity_defect, methods]);
    Ok(())
}
