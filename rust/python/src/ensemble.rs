//! Ensembles of native and compiled models: the core's parallel loop
//! ([`integrators::integrate_ensemble`]) with the GIL released. Closure models hold the GIL,
//! so the Python layer runs them member by member through `integrate`.

use numpy::PyReadonlyArray2;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use varmech::integrators::{self, Dynamics, MemberEvents, MemberWatch, Members, Parallel};

use crate::bind::check_signals;
use crate::compiled::CompiledModel;
use crate::convert::rows;
use crate::errors::{model_error, to_pyerr};
use crate::events::Events;
use crate::native::NativeModel;
use crate::run::reporting;
use crate::runspec::RunSpec;
use crate::trajectory::TrajectoryRecord;

/// A model the core evaluates without the GIL.
enum Released<'a> {
    Native(&'a NativeModel),
    Compiled(&'a CompiledModel),
}

/// The members' models: one shared by all, or one each.
struct Models<'a>(Vec<Released<'a>>);

impl Members for Models<'_> {
    fn models(&self) -> Option<usize> {
        (self.0.len() != 1).then_some(self.0.len())
    }

    fn with_model<R>(&self, member: usize, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        match self.0[if self.0.len() == 1 { 0 } else { member }] {
            Released::Native(m) => m.with_integrable(body),
            Released::Compiled(m) => m.with_integrable(body),
        }
    }
}

fn released<'a>(i: usize, model: &'a Bound<'_, PyAny>) -> PyResult<Released<'a>> {
    if let Ok(native) = model.cast::<NativeModel>() {
        return Ok(Released::Native(native.get()));
    }
    if let Ok(compiled) = model.cast::<CompiledModel>() {
        return Ok(Released::Compiled(compiled.get()));
    }
    let ty = model.get_type().name().map(|n| n.to_string()).unwrap_or_default();
    Err(PyTypeError::new_err(format!(
        "models[{i}]: the parallel ensemble runs native and compiled models, got {ty}"
    )))
}

/// One member's result: its record (the partial one of a failure) and its exception, if any.
type MemberResult = (TrajectoryRecord, Option<Py<PyAny>>);

/// Integrates the members (rows of `q0` and `p0`, (members, n)) with `models` (one shared, or
/// one a member) on at most `workers` threads in tasks of `chunk_size` members, the GIL
/// released, each watching `events` (spec tuples of built-in events, see [`Events::new`]) and
/// resolving the impacts on `contacts` (native surfaces, see [`crate::contacts::ContactSpecs::new`]), applying
/// `impulses` (their components as numbers, see [`crate::schedule::ScheduleSpecs::new`]) and taking the samples
/// `t_eval`;
/// `progress(steps)` gets the steps of all members so far. Returns each member's
/// record and exception (None when it completed), and the exception (KeyboardInterrupt) that
/// stopped the ensemble, if one did: the members then stopped where they were.
#[pyfunction]
#[pyo3(signature = (models, q0, p0, spec, *, workers=None, chunk_size=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn ensemble<'py>(
    py: Python<'py>,
    models: Vec<Bound<'py, PyAny>>,
    q0: PyReadonlyArray2<'py, f64>,
    p0: PyReadonlyArray2<'py, f64>,
    spec: &RunSpec,
    workers: Option<usize>,
    chunk_size: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Vec<MemberResult>, Option<Py<PyAny>>)> {
    let (method, options) = spec.options()?;
    let ((q0, _), (p0, _)) = (rows("q0", &q0)?, rows("p0", &p0)?);
    let models = Models(
        models
            .iter()
            .enumerate()
            .map(|(i, m)| released(i, m))
            .collect::<PyResult<_>>()?,
    );
    if models.0.is_empty() {
        return Err(PyValueError::new_err("models: at least one model is needed"));
    }
    let n = models.with_model(0, |sys| sys.dim());
    let events = match spec.events(py)? {
        Some(tuples) => {
            let (functions, specs) = Events::new(py, tuples, n)?;
            let functions = functions.into_native(&specs)?;
            MemberEvents { functions, specs }
        }
        None => MemberEvents::default(),
    };
    let contacts = match spec.contacts(py)? {
        Some(contacts) => contacts.into_native()?,
        None => Vec::new(),
    };
    let impulses = spec.schedule(py)?.into_native()?;
    let watched = MemberWatch {
        events,
        contacts,
        impulses,
        samples: spec.t_eval().to_vec(),
    };
    let parallel = Parallel { workers, chunk_size };
    let run = py.detach(|| {
        let report = reporting(&check_signals, &progress);
        integrators::integrate_ensemble(&models, method, q0, p0, &options, parallel, &watched, report)
    });
    let run = run.map_err(|e| to_pyerr(py, e))?;
    let members = run
        .members
        .into_iter()
        .map(|outcome| match outcome {
            Ok(traj) => Ok((TrajectoryRecord::new(py, traj)?, None)),
            Err(failure) => {
                let error = to_pyerr(py, failure.error).into_value(py).into_any();
                Ok((TrajectoryRecord::new(py, failure.partial)?, Some(error)))
            }
        })
        .collect::<PyResult<_>>()?;
    let interrupted = run.interrupted.map(|e| model_error(e).into_value(py).into_any());
    Ok((members, interrupted))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(m, [ensemble]);
    Ok(())
}
