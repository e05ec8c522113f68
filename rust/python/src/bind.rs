//! The one dispatch from a Python model object to the core: [`bind_model`] resolves it to an
//! [`Dynamics`] and runs a body with it; [`kind_of`] shows the core's [`ModelKind`] of a model.

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use varmech::integrators::{Dynamics, General, Method, ModelKind};
use varmech::model::Natural;
use varmech::solve::interrupt::with_interrupt_check;
use varmech::ModelError;

use crate::closure::{
    ClosureConstrained, ClosureLagrangian, ClosureLagrangianSystem, ClosureModel, ClosureNatural, ClosureNaturalSystem,
    ClosureNonholonomic, ClosureSystem,
};
use crate::compiled::CompiledModel;
use crate::convert;
use crate::errors::boxed;
use crate::native::NativeModel;
use crate::pointers::{PointerLagrangian, PointerSystem};
use crate::routh::RouthModel;

/// The Ctrl-C check the driver polls: a Python error (KeyboardInterrupt) stops the run.
pub type Poll<'a> = &'a dyn Fn() -> Result<(), ModelError>;

/// The Ctrl-C check: Python's signal handlers run, and a KeyboardInterrupt stops the run. It
/// takes the GIL where a native run released it (a no-op where it is held).
pub(crate) fn check_signals() -> Result<(), ModelError> {
    Python::attach(|py| py.check_signals()).map_err(boxed)
}

/// Runs `body` with the model as the core's [`Dynamics`] and the Ctrl-C check: native,
/// compiled and function-pointer models with the GIL released (the poll takes it back briefly), closure models with it held. A
/// Routh-reduced model is the Routhian of its full model, built in place.
pub fn bind_model<R, F>(py: Python<'_>, model: &Bound<'_, PyAny>, body: F) -> PyResult<R>
where
    R: Send,
    F: for<'s> FnOnce(&'s dyn Dynamics, Poll<'s>) -> R + Send,
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

/// [`bind_model`] for the models that are not reduced. The iterative solves inside `body`
/// check for Ctrl-C too ([`with_interrupt_check`]), so that one long Newton iteration stops.
pub fn bind_full<R, F>(py: Python<'_>, model: &Bound<'_, PyAny>, body: F) -> PyResult<R>
where
    R: Send,
    F: for<'s> FnOnce(&'s dyn Dynamics, Poll<'s>) -> R + Send,
{
    with_interrupt_check(check_signals, || dispatch(py, model, body))
}

fn dispatch<R, F>(py: Python<'_>, model: &Bound<'_, PyAny>, body: F) -> PyResult<R>
where
    R: Send,
    F: for<'s> FnOnce(&'s dyn Dynamics, Poll<'s>) -> R + Send,
{
    if let Ok(native) = model.cast::<NativeModel>() {
        let native = native.get();
        return Ok(py.detach(|| native.with_integrable(|sys| body(sys, &check_signals))));
    }
    if let Ok(compiled) = model.cast::<CompiledModel>() {
        let compiled = compiled.get();
        return Ok(py.detach(|| compiled.with_integrable(|sys| body(sys, &check_signals))));
    }
    if let Ok(pointer) = model.cast::<PointerSystem>() {
        let pointer = pointer.get();
        return Ok(py.detach(|| body(pointer, &check_signals)));
    }
    if let Ok(pointer) = model.cast::<PointerLagrangian>() {
        let pointer = pointer.get();
        return Ok(py.detach(|| pointer.with_integrable(|sys| body(sys, &check_signals))));
    }
    let poll = || py.check_signals().map_err(boxed);
    if let Ok(closure) = model.cast::<ClosureModel>() {
        Ok(body(&ClosureSystem::new(py, closure.get()), &poll))
    } else if let Ok(closure) = model.cast::<ClosureConstrained>() {
        Ok(closure.get().with_integrable(py, |sys| body(sys, &poll)))
    } else if let Ok(closure) = model.cast::<ClosureNonholonomic>() {
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

/// A model's kind, [`varmech::integrators::ModelKind`]: the core's table decides which
/// methods apply to it and which one integrates it by default.
#[pyclass(frozen, name = "ModelKind", module = "varmech._core")]
pub struct PyModelKind(ModelKind);

#[pymethods]
impl PyModelKind {
    #[getter]
    fn name(&self) -> &'static str {
        self.0.name()
    }

    /// Whether every unconstrained method applies (L = ½q̇ᵀMq̇ − V(q) with constant M).
    #[getter]
    fn separable(&self) -> bool {
        self.0.is_separable()
    }

    #[getter]
    fn default_method(&self) -> &'static str {
        self.0.default_method().info().name
    }

    #[getter]
    fn accurate_method(&self) -> &'static str {
        self.0.accurate_method().info().name
    }

    /// Whether `method` integrates a model of this kind.
    fn admits(&self, #[pyo3(from_py_with = convert::method)] method: Method) -> bool {
        self.0.admits(method)
    }

    fn __repr__(&self) -> String {
        format!("ModelKind({:?})", self.0.name())
    }
}

/// The kind of a model.
#[pyfunction]
pub fn kind_of(py: Python<'_>, model: &Bound<'_, PyAny>) -> PyResult<PyModelKind> {
    bind_model(py, model, |sys, _| PyModelKind(sys.kind()))
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

/// Whether the model's velocity constraints are affine, A(q)q̇ + b(q) = 0 with b ≠ 0 (then
/// their forces do work and the energy is not conserved).
#[pyfunction]
fn is_affine(py: Python<'_>, model: &Bound<'_, PyAny>) -> PyResult<bool> {
    bind_model(py, model, |sys, _| {
        sys.velocity_constraints().is_some_and(|c| c.is_affine())
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyModelKind>()?;
    add_functions!(m, [is_affine, kind_of, is_time_dependent, is_forced]);
    Ok(())
}
