//! `varmech._core`: the thin pyo3 binding of the varmech core.
//!
//! Argument conversion ([`convert`]), the adapter that lets Python closures implement the core's
//! model trait ([`model`]), and the mapping of core errors to Python exceptions ([`errors`]).
//! The Python API in `python/varmech` is built on these functions; `_core.pyi` documents them.

mod convert;
mod errors;
mod functions;
mod model;

use pyo3::prelude::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("VarmechError", py.get_type::<errors::VarmechError>())?;
    m.add("DivergenceError", py.get_type::<errors::DivergenceError>())?;
    m.add("ConvergenceError", py.get_type::<errors::ConvergenceError>())?;
    m.add("SpuriousBranchError", py.get_type::<errors::SpuriousBranchError>())?;
    m.add_class::<model::NativeModel>()?;
    m.add_class::<model::ClosureModel>()?;
    m.add_class::<model::ClosureLagrangian>()?;
    m.add_class::<model::ClosureNatural>()?;
    m.add_class::<model::ClosureConstrained>()?;
    m.add_class::<model::RouthModel>()?;
    functions::register(m)?;
    Ok(())
}
