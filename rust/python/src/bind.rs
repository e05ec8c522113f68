//! The one dispatch from a Python model object to the core: [`bind_model`] resolves it to an
//! [`Integrable`] and runs a body with it; and [`kind_of`], the one place for the policy that
//! depends on the kind of model.

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use varmech::integrators::{General, Integrable};
use varmech::model::Natural;
use varmech::ModelError;

use crate::closure::constraints::ConstrainedSystem;
use crate::closure::{
    ClosureConstrained, ClosureLagrangian, ClosureLagrangianSystem, ClosureModel, ClosureNatural, ClosureNaturalSystem,
    ClosureSystem,
};
use crate::errors::boxed;
use crate::native::{Native, NativeModel};
use crate::routh::RouthModel;

/// The Ctrl-C check the driver polls: a Python error (KeyboardInterrupt) stops the run.
pub type Poll<'a> = &'a dyn Fn() -> Result<(), ModelError>;

/// Runs `body` with the model as the core's [`Integrable`] and the Ctrl-C check: native models
/// with the GIL released (the poll takes it back briefly), closure models with it held. A
/// Routh-reduced model is the Routhian of its full model, built in place.
pub fn bind_model<R, F>(py: Python<'_>, model: &Bound<'_, PyAny>, body: F) -> PyResult<R>
where
    R: Send,
    F: for<'s> FnOnce(&'s dyn Integrable, Poll<'s>) -> R + Send,
{
    match model.cast::<RouthModel>() {
        Ok(reduced) => {
            let reduced = reduced.get();
            bind_full(py, reduced.full.bind(py), |full, poll| {
                body(&General(&reduced.routhian(full.as_lagrangian())), poll)
            })
        }
        Err(_) => bind_full(py, model, body),
    }
}

/// [`bind_model`] for the models that are not reduced.
pub fn bind_full<R, F>(py: Python<'_>, model: &Bound<'_, PyAny>, body: F) -> PyResult<R>
where
    R: Send,
    F: for<'s> FnOnce(&'s dyn Integrable, Poll<'s>) -> R + Send,
{
    if let Ok(native) = model.cast::<NativeModel>() {
        let native = native.get();
        let poll = || Python::attach(|py| py.check_signals()).map_err(boxed);
        return Ok(py.detach(|| native.with_integrable(|sys| body(sys, &poll))));
    }
    let poll = || py.check_signals().map_err(boxed);
    if let Ok(closure) = model.cast::<ClosureModel>() {
        Ok(body(&ClosureSystem::new(py, closure.get()), &poll))
    } else if let Ok(closure) = model.cast::<ClosureConstrained>() {
        Ok(closure.get().with_integrable(py, |sys| body(sys, &poll)))
    } else if let Ok(closure) = model.cast::<ClosureNatural>() {
        let natural = Natural::new(ClosureNaturalSystem::new(py, closure.get()));
        Ok(body(&General(&natural), &poll))
    } else if let Ok(closure) = model.cast::<ClosureLagrangian>() {
        Ok(body(&General(&ClosureLagrangianSystem::new(py, closure.get())), &poll))
    } else {
        let ty = model.get_type().name().map(|n| n.to_string()).unwrap_or_default();
        Err(PyTypeError::new_err(format!(
            "model: expected a varmech model (a scene's, MechanicalSystem or Lagrangian), got {ty}"
        )))
    }
}

/// The model's number of coordinates n.
pub fn dim_of(py: Python<'_>, model: &Bound<'_, PyAny>) -> PyResult<usize> {
    bind_model(py, model, |sys, _| sys.dim())
}

/// The kinds of model, which decide which methods apply and which one integrates by default.
#[pyclass(frozen, eq, eq_int, skip_from_py_object, module = "varmech._core")]
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// L = ½q̇ᵀMq̇ − V(q) with constant M: every unconstrained method applies.
    Separable,
    /// A general Lagrangian (or a natural system, or a Routhian): the variational methods.
    General,
    /// A separable system on holonomic constraints: RATTLE and SHAKE.
    Constrained,
    /// A general Lagrangian on holonomic constraints: the constrained DEL equations.
    ConstrainedGeneral,
}

#[pymethods]
impl ModelKind {
    /// Whether explicit methods apply (L = ½q̇ᵀMq̇ − V(q) with constant M, unconstrained).
    #[getter]
    fn separable(&self) -> bool {
        *self == ModelKind::Separable
    }

    /// The method `integrate` uses when none is given: Störmer–Verlet for separable systems, the
    /// midpoint rule for general Lagrangians, RATTLE on constraints, and the trapezoidal rule's
    /// constrained DEL equations (RATTLE's discrete Lagrangian) for general ones on constraints.
    #[getter]
    fn default_method(&self) -> &'static str {
        match self {
            ModelKind::Separable => "verlet",
            ModelKind::General => "midpoint",
            ModelKind::Constrained => "rattle",
            ModelKind::ConstrainedGeneral => "trapezoid",
        }
    }
}

/// The kind of a model.
#[pyfunction]
pub fn kind_of(model: &Bound<'_, PyAny>) -> PyResult<ModelKind> {
    if let Ok(native) = model.cast::<NativeModel>() {
        return Ok(match native.get().native {
            Native::Mechanical(_) => ModelKind::Separable,
            Native::General(_) => ModelKind::General,
            Native::Constrained(_) => ModelKind::Constrained,
            Native::ConstrainedGeneral(_) => ModelKind::ConstrainedGeneral,
        });
    }
    if model.cast::<ClosureModel>().is_ok() {
        return Ok(ModelKind::Separable);
    }
    if let Ok(closure) = model.cast::<ClosureConstrained>() {
        return Ok(match closure.get().system() {
            ConstrainedSystem::Separable(_) => ModelKind::Constrained,
            ConstrainedSystem::Natural(_) => ModelKind::ConstrainedGeneral,
        });
    }
    // The others are general Lagrangians; the dispatch refuses what is no model.
    bind_model(model.py(), model, |_, _| ModelKind::General)
}

/// Whether L depends on t explicitly (then its energy function is not conserved).
#[pyfunction]
fn is_time_dependent(py: Python<'_>, model: &Bound<'_, PyAny>) -> PyResult<bool> {
    bind_model(py, model, |sys, _| sys.as_lagrangian().is_time_dependent())
}

/// Whether non-conservative forces act (then the energy changes by their work).
#[pyfunction]
fn is_forced(py: Python<'_>, model: &Bound<'_, PyAny>) -> PyResult<bool> {
    bind_model(py, model, |sys, _| sys.as_lagrangian().is_forced())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ModelKind>()?;
    m.add_function(wrap_pyfunction!(kind_of, m)?)?;
    m.add_function(wrap_pyfunction!(is_time_dependent, m)?)?;
    m.add_function(wrap_pyfunction!(is_forced, m)?)?;
    Ok(())
}
