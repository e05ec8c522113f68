//! Core errors as Python exceptions: the message is the core's `Display`, the data its fields,
//! and a failed run carries its partial trajectory.

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use varmech::integrators::Failure;
use varmech::{Error, ModelError};

use crate::trajectory::TrajectoryRecord;

pyo3::create_exception!(varmech, VarmechError, PyRuntimeError, "Base class of varmech's errors.");
pyo3::create_exception!(
    varmech,
    ConvergenceError,
    VarmechError,
    "Newton's method did not solve a step's implicit equations; the message says what helps."
);
pyo3::create_exception!(
    varmech,
    SpuriousBranchError,
    ConvergenceError,
    "A step's implicit equations were solved beyond a fold of the DEL map, on a branch that need not \
     continue the trajectory (take a smaller step)."
);
pyo3::create_exception!(
    varmech,
    ContactError,
    VarmechError,
    "A contact could not be resolved: a resting or grazing contact, an accumulation of impacts, or a held \
     contact's solve that failed."
);
pyo3::create_exception!(
    varmech,
    DivergenceError,
    VarmechError,
    "The solution blew up: a non-finite state, or an energy error beyond max_energy_error."
);

/// The exceptions, for the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("VarmechError", py.get_type::<VarmechError>())?;
    m.add("DivergenceError", py.get_type::<DivergenceError>())?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    m.add("SpuriousBranchError", py.get_type::<SpuriousBranchError>())?;
    m.add("ContactError", py.get_type::<ContactError>())?;
    Ok(())
}

/// A Python error as the core's model error, which carries it unchanged.
pub fn boxed(e: PyErr) -> ModelError {
    Box::new(e)
}

/// A model's error as the Python exception it stands for (a closure's own, or a ValueError).
pub fn model_error(e: ModelError) -> PyErr {
    match e.downcast::<PyErr>() {
        Ok(err) => *err,
        Err(e) => PyValueError::new_err(e.to_string()),
    }
}

/// [`model_error`] at states the caller names for its user (`"q0, p0"`): the core's own error
/// starts with those names and says what checks them; a closure's exception stays unchanged.
pub fn model_error_at(e: ModelError, names: &str) -> PyErr {
    match e.downcast::<PyErr>() {
        Ok(err) => *err,
        Err(e) => PyValueError::new_err(format!(
            "{names}: {e} (at these {names}; varmech.check_derivatives compares the model's derivatives with \
             differences there)"
        )),
    }
}

/// The Python exception for a core error, with the core's message: ValueError (which names the
/// argument), DivergenceError, ConvergenceError (with `residual` and `iterations`),
/// SpuriousBranchError, ContactError, or the model's own exception (a closure's, or KeyboardInterrupt)
/// unchanged; all but the ValueError carry the `step` and `time` where they happened.
pub fn to_pyerr(py: Python<'_>, error: Error) -> PyErr {
    let (exception, step, time) = match error {
        Error::InvalidArgument { .. } => return PyValueError::new_err(error.to_string()),
        Error::Divergence { step, time, .. } => (DivergenceError::new_err(error.to_string()), step, time),
        Error::Convergence {
            step,
            time,
            residual,
            iterations,
            ..
        } => {
            let err = ConvergenceError::new_err(error.to_string());
            let value = err.value(py);
            // Attributes of our own exception class: setting them cannot fail.
            let _ = value
                .setattr("residual", residual)
                .and(value.setattr("iterations", iterations));
            (err, step, time)
        }
        Error::SpuriousBranch { step, time, .. } => (SpuriousBranchError::new_err(error.to_string()), step, time),
        Error::Contact { step, time, .. } => (ContactError::new_err(error.to_string()), step, time),
        Error::Model { step, time, source } => match Error::model(step, time, source) {
            Error::Model { source, .. } => (raised(source, |source| Error::Model { step, time, source }), step, time),
            // A solve inside the model's evaluation that failed: its own typed error.
            typed => return to_pyerr(py, typed),
        },
        Error::Interrupted { step, time, source } => (
            raised(source, |source| Error::Interrupted { step, time, source }),
            step,
            time,
        ),
    };
    // Exceptions without a __dict__ keep their type and simply lack the attributes.
    let value = exception.value(py);
    let _ = value.setattr("step", step).and(value.setattr("time", time));
    exception
}

/// The Python exception a model raised, or a VarmechError with the core's message for `error`
/// (rebuilt around `source`) when the model's error did not come from Python.
fn raised(source: ModelError, error: impl FnOnce(ModelError) -> Error) -> PyErr {
    match source.downcast::<PyErr>() {
        Ok(original) => *original,
        Err(other) => VarmechError::new_err(error(other).to_string()),
    }
}

/// The Python exception for a failed run, carrying `_varmech_partial`, the partial
/// [`TrajectoryRecord`] that the Python layer turns into `err.partial`.
pub fn failure_to_pyerr(py: Python<'_>, failure: Failure) -> PyErr {
    let Failure { error, partial } = failure;
    let invalid = matches!(error, Error::InvalidArgument { .. });
    let err = to_pyerr(py, error);
    if !invalid {
        if let Ok(partial) = TrajectoryRecord::new(py, partial).and_then(|r| Bound::new(py, r)) {
            let _ = err.value(py).setattr("_varmech_partial", partial);
        }
    }
    err
}
