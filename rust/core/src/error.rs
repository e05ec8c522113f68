//! Typed errors of the core, in descriptive struct variants.

use std::fmt;

/// SHAKE's failure to reach its tolerance in its sweeps: its advice is not a smaller step.
pub(crate) const SHAKE_UNCONVERGED: &str = "SHAKE did not reach its tolerance on the constraints";

/// An error raised by a model while it is evaluated (for instance a Python exception inside a
/// user closure). The core carries it unchanged so that the binding can re-raise the original.
pub type ModelError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// What stops a computation.
#[derive(Debug)]
pub enum Error {
    /// An argument is malformed: wrong shape, not finite, out of range, unknown name.
    InvalidArgument { argument: &'static str, reason: String },
    /// The numerical solution left every sensible bound: a non-finite state, or an energy error
    /// beyond the threshold the user set.
    Divergence { step: usize, time: f64, reason: String },
    /// Newton's method did not solve the implicit equations of `step` (which starts at `time`);
    /// `advice` says what would help, from the iteration's course ([`crate::solve::Diagnosis`]).
    Convergence {
        step: usize,
        time: f64,
        residual: f64,
        iterations: usize,
        reason: &'static str,
        advice: &'static str,
    },
    /// The implicit equations of `step` (which starts at `time`) were solved, but on a branch
    /// that need not continue the trajectory: the step is too large for the dynamics there.
    SpuriousBranch {
        step: usize,
        time: f64,
        reason: &'static str,
    },
    /// The model failed while it was evaluated during `step` (which starts at `time`).
    Model { step: usize, time: f64, source: ModelError },
    /// The interrupt poll (Ctrl-C) asked the run to stop before `step`.
    Interrupted { step: usize, time: f64, source: ModelError },
    /// A contact in `step` (which starts at `time`) could not be resolved: a non-finite state
    /// after a jump, a body that crosses a surface again at once after leaving it (a resting or
    /// grazing contact), more than [`crate::integrators::MAX_IMPACTS`] impacts in the step
    /// (an accumulation, as of a ball coming to rest), or a held contact's solve that failed
    /// (its reason says which, its residual and what helps). The run ends at the step's start.
    Contact { step: usize, time: f64, reason: String },
}

impl Error {
    /// Shorthand for [`Error::InvalidArgument`].
    pub fn invalid(argument: &'static str, reason: impl Into<String>) -> Self {
        Error::InvalidArgument {
            argument,
            reason: reason.into(),
        }
    }

    /// The model's error `source` during `step`: [`Error::Model`], or, where it is a solve of
    /// the model's own that failed (the inverse Legendre transform inside a step, a Routhian's
    /// cyclic velocities), that solve's typed error, with its diagnosis.
    pub fn model(step: usize, time: f64, source: ModelError) -> Error {
        match source.downcast::<StepError>() {
            Ok(nested) => nested.at(step, time),
            Err(source) => Error::Model { step, time, source },
        }
    }

    /// The same error, named by the run's `step` and its start `time`: a partial step's, which
    /// a run reports as its own step's.
    pub(crate) fn at(mut self, step: usize, time: f64) -> Error {
        match &mut self {
            Error::Divergence { step: s, time: t, .. }
            | Error::Convergence { step: s, time: t, .. }
            | Error::SpuriousBranch { step: s, time: t, .. }
            | Error::Model { step: s, time: t, .. }
            | Error::Interrupted { step: s, time: t, .. }
            | Error::Contact { step: s, time: t, .. } => (*s, *t) = (step, time),
            Error::InvalidArgument { .. } => {}
        }
        self
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidArgument { argument, reason } => write!(f, "{argument}: {reason}"),
            Error::Divergence { step, time, reason } => {
                write!(f, "integration diverged at step {step} (t = {time}): {reason}")
            }
            Error::Convergence {
                step,
                time,
                residual,
                iterations,
                reason,
                advice,
            } => {
                write!(
                    f,
                    "{reason} at step {step} (t = {time}): residual {residual:.3e} after {iterations} iterations{}",
                    joined(advice)
                )
            }
            Error::SpuriousBranch { step, time, reason } => {
                write!(
                    f,
                    "spurious branch at step {step} (t = {time}): {reason}; take a smaller step"
                )
            }
            Error::Model { step, time, source } => {
                write!(f, "model evaluation failed at step {step} (t = {time}): {source}")
            }
            Error::Interrupted { step, time, .. } => {
                write!(f, "integration interrupted at step {step} (t = {time})")
            }
            Error::Contact { step, time, reason } => {
                write!(f, "contact not resolved in step {step} (from t = {time}): {reason}")
            }
        }
    }
}

/// `advice` after a message, where there is some.
fn joined(advice: &str) -> String {
    if advice.is_empty() {
        String::new()
    } else {
        format!("; {advice}")
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Model { source, .. } | Error::Interrupted { source, .. } => Some(source.as_ref()),
            _ => None,
        }
    }
}

/// Checks that `x` has `n` entries, all finite.
pub(crate) fn check_vector(argument: &'static str, x: &[f64], n: usize) -> Result<(), Error> {
    if x.len() != n {
        return Err(Error::invalid(
            argument,
            format!("expected {n} entries, got {}", x.len()),
        ));
    }
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(argument, format!("entry {i} is not finite ({})", x[i])));
    }
    Ok(())
}

/// Why a step failed.
#[derive(Debug)]
pub enum StepError {
    /// The model failed while it was evaluated.
    Model(ModelError),
    /// Newton's method did not solve the step's implicit equations; `advice` says what would
    /// help (from [`crate::solve::Diagnosis`]).
    Convergence {
        residual: f64,
        iterations: usize,
        reason: &'static str,
        advice: &'static str,
    },
    /// The step's equations became non-finite: the solution is blowing up.
    NonFinite { reason: &'static str },
    /// Newton's method converged to a solution the step cannot vouch for.
    SpuriousBranch { reason: &'static str },
    /// The interrupt check ([`crate::solve::interrupt`]) stopped an iterative solve.
    Interrupted(ModelError),
    /// The method does not integrate this kind of model ([`crate::integrators::ModelKind`]'s refusal); runs refuse
    /// it before the first step.
    Method(Error),
}

impl StepError {
    /// The error of the run that failed at `step`, which started at `time`.
    pub fn at(self, step: usize, time: f64) -> Error {
        match self {
            StepError::Model(source) => Error::model(step, time, source),
            StepError::Convergence {
                residual,
                iterations,
                reason,
                advice,
            } => Error::Convergence {
                step,
                time,
                residual,
                iterations,
                reason,
                advice,
            },
            StepError::NonFinite { reason } => Error::Divergence {
                step,
                time,
                reason: reason.to_string(),
            },
            StepError::SpuriousBranch { reason } => Error::SpuriousBranch { step, time, reason },
            StepError::Interrupted(source) => Error::Interrupted { step, time, source },
            StepError::Method(error) => error,
        }
    }
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepError::Model(e) | StepError::Interrupted(e) => write!(f, "{e}"),
            StepError::Convergence {
                residual,
                iterations,
                reason,
                advice,
            } => write!(
                f,
                "{reason}: residual {residual:.3e} after {iterations} iterations{}",
                joined(advice)
            ),
            StepError::NonFinite { reason } | StepError::SpuriousBranch { reason } => write!(f, "{reason}"),
            StepError::Method(e) => write!(f, "{e}"),
        }
    }
}

/// A solve's failure inside a model's evaluation travels as a [`ModelError`] and is typed again
/// where the run reports it ([`Error::model`]).
impl std::error::Error for StepError {}

impl From<ModelError> for StepError {
    fn from(e: ModelError) -> Self {
        StepError::Model(e)
    }
}

impl From<Error> for StepError {
    fn from(e: Error) -> Self {
        StepError::Method(e)
    }
}
