//! `varmech._core`: the thin pyo3 binding of the varmech core.
//!
//! Its remit is conversion, adapters and errors only — no physics, no policy: arguments and
//! results are converted between numpy and the core ([`convert`], [`trajectory`],
//! [`generator`]); Python closures are adapted to the core's model traits ([`closure`]), native
//! scenes wrapped ([`native`], [`scenes`]), symbolic models' tapes decoded ([`compiled`]), function pointers called
//! ([`pointers`]), ensembles of native and compiled models run in parallel ([`ensemble`]), and every model resolved to the core by the one
//! dispatch [`bind::bind_model`]; core errors become Python exceptions with the core's messages
//! ([`errors`]). Policy, such as which method fits which kind of model, is the core's
//! ([`bind::kind_of`] only shows it). The Python API in `python/varmech` is built on these functions;
//! `_core.pyi` documents them.

mod bind;
mod closure;
mod compiled;
mod constraints;
mod contacts;
mod convert;
mod diagnostics;
mod ensemble;
mod errors;
mod events;
mod generator;
mod impulsive;
mod modes;
mod native;
mod pointers;
mod routh;
mod run;
mod runspec;
mod scenes;
mod schedule;
mod stepper;
mod trajectory;

use pyo3::prelude::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add_class::<generator::Generator>()?;
    bind::register(m)?;
    closure::register(m)?;
    compiled::register(m)?;
    pointers::register(m)?;
    scenes::register(m)?;
    routh::register(m)?;
    run::register(m)?;
    runspec::register(m)?;
    contacts::register(m)?;
    ensemble::register(m)?;
    m.add_class::<stepper::Stepper>()?;
    diagnostics::register(m)?;
    constraints::register(m)?;
    impulsive::register(m)?;
    modes::register(m)?;
    Ok(())
}
