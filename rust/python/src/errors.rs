//! Core errors as Python exceptions, with the partial trajectory attached.

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use varmech::integrators::Failure;
use varmech::Error;

use crate::convert::trajectory_tuple;

pyo3::create_exception!(_core, VarmechError, PyRuntimeError, "Base class of varmech's errors.");
pyo3::create_exception!(
    _core,
    ConvergenceError,
    VarmechError,
    "Newton's method did not solve a step's implicit equations (a smaller step usually helps)."
);
pyo3::create_exception!(
    _core,
    SpuriousBranchError,
    ConvergenceError,
    "A step's implicit equations were solved beyond a fold of the DEL map, on a branch that need not \
     continue the trajectory (take a smaller step)."
);
pyo3::create_exception!(
    _core,
    DivergenceError,
    VarmechError,
    "The solution blew up: a non-finite state, or an energy error beyond max_energy_error."
);

/// The Python exception for a core error: ValueError naming the argument, DivergenceError,
/// or the model's own exception (a closure's, or KeyboardInterrupt) unchanged.
pub fn to_pyerr(py: Python<'_>, error: Error) -> PyErr {
    match error {
        Error::InvalidArgument { argument, reason } => PyValueError::new_err(format!("{argument}: {reason}")),
        Error::Divergence { step, time, ref reason } => {
            let err = DivergenceError::new_err(format!("diverged at step {step} (t = {time}): {reason}"));
            let value = err.value(py);
            // Attributes of our own exception class: setting them cannot fail.
            let _ = value.setattr("step", step).and(value.setattr("time", time));
            err
        }
        Error::Convergence {
            step,
            time,
            residual,
            iterations,
            reason,
        } => {
            let err = ConvergenceError::new_err(format!(
                "{reason} at step {step} (t = {time}): residual {residual:.3e} after {iterations} iterations; a smaller step usually helps"
            ));
            let value = err.value(py);
            let _ = value
                .setattr("step", step)
                .and(value.setattr("time", time))
                .and(value.setattr("residual", residual))
                .and(value.setattr("iterations", iterations));
            err
        }
        Error::SpuriousBranch { step, time, reason } => {
            let err = SpuriousBranchError::new_err(format!(
                "spurious branch at step {step} (t = {time}): {reason}; take a smaller step"
            ));
            let value = err.value(py);
            let _ = value.setattr("step", step).and(value.setattr("time", time));
            err
        }
        Error::Model { step, time, source } | Error::Interrupted { step, time, source } => {
            match source.downcast::<PyErr>() {
                Ok(original) => {
                    let err = *original;
                    // Exceptions without a __dict__ keep their type and simply lack the attributes.
                    let value = err.value(py);
                    let _ = value.setattr("step", step).and(value.setattr("time", time));
                    err
                }
                Err(other) => VarmechError::new_err(format!("model failed at step {step} (t = {time}): {other}")),
            }
        }
    }
}

/// The Python exception for a failed run, carrying `_varmech_partial`, the raw partial
/// trajectory that the Python layer turns into `err.partial`.
pub fn failure_to_pyerr(py: Python<'_>, failure: Failure) -> PyErr {
    let Failure { error, partial } = failure;
    let invalid = matches!(error, Error::InvalidArgument { .. });
    let err = to_pyerr(py, error);
    if !invalid {
        if let Ok(partial) = trajectory_tuple(py, partial) {
            let _ = err.value(py).setattr("_varmech_partial", partial);
        }
    }
    err
}
