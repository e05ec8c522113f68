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
// A cdylib's Rust items are nobody's API: its docs are read with --document-private-items.
#![allow(rustdoc::private_intra_doc_links)]

/// Adds the `#[pyfunction]`s listed to the module `m` (each module's `register` lists its own).
macro_rules! add_functions {
    ($m:expr, [$($function:ident),+ $(,)?]) => {
        $($m.add_function(pyo3::wrap_pyfunction!($function, $m)?)?;)+
    };
}

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

/// A module's `register`: adds its functions and classes to `_core`.
type Register = fn(&Bound<'_, PyModule>) -> PyResult<()>;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<generator::Generator>()?;
    m.add_class::<stepper::Stepper>()?;
    let modules: [Register; 15] = [
        errors::register,
        bind::register,
        closure::register,
        compiled::register,
        pointers::register,
        scenes::register,
        routh::register,
        run::register,
        runspec::register,
        contacts::register,
        ensemble::register,
        diagnostics::register,
        constraints::register,
        impulsive::register,
        modes::register,
    ];
    modules.iter().try_for_each(|register| register(m))
}
