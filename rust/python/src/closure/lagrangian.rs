//! A general Lagrangian L(q, q̇, t), with an optional non-conservative force, from Python
//! closures.

use std::cell::RefCell;

use numpy::PyArray1;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use varmech::model::{differenced_dl_dt, Hessians, Lagrangian};
use varmech::solve::difference::central_gradient;
use varmech::ModelError;

use super::readers::{call_array, call_scalar, call_vector, check_closures, type_name};
use crate::errors::boxed;
use crate::generator::{self, Generator as Spec};

/// A general Lagrangian L(q, q̇, t) given by Python closures: `lagrangian(q, v, t) -> float`
/// and, optionally, `dl_dq(q, v, t)` and `dl_dv(q, v, t)` (arrays (n,)); missing derivatives
/// come from central differences of L. An optional `force(q, v, t)` (array (n,)) is a
/// non-conservative generalized force; an optional `dl_dt(q, v, t) -> float`, ∂L/∂t of an L that
/// depends on t (else a central difference of L in t).
#[pyclass(frozen, module = "varmech._core")]
pub struct ClosureLagrangian {
    dim: usize,
    lagrangian: Py<PyAny>,
    dl_dq: Option<Py<PyAny>>,
    dl_dv: Option<Py<PyAny>>,
    hessians: Option<Py<PyAny>>,
    force: Option<Py<PyAny>>,
    dl_dt: Option<Py<PyAny>>,
    time_dependent: bool,
}

#[pymethods]
impl ClosureLagrangian {
    #[new]
    /// `symmetries` are only checked here (the core's Lagrangian trait declares none); the
    /// Python model keeps them for the conservation report.
    #[pyo3(signature = (dim, lagrangian, dl_dq, dl_dv, hessians, force, time_dependent, symmetries, dl_dt=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        dim: usize,
        lagrangian: Bound<'_, PyAny>,
        dl_dq: Option<Bound<'_, PyAny>>,
        dl_dv: Option<Bound<'_, PyAny>>,
        hessians: Option<Bound<'_, PyAny>>,
        force: Option<Bound<'_, PyAny>>,
        time_dependent: bool,
        symmetries: Vec<Spec>,
        dl_dt: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        generator::generators(symmetries, dim)?;
        check_closures(
            dim,
            [
                ("lagrangian", Some(&lagrangian)),
                ("dl_dq", dl_dq.as_ref()),
                ("dl_dv", dl_dv.as_ref()),
                ("hessians", hessians.as_ref()),
                ("force", force.as_ref()),
                ("dl_dt", dl_dt.as_ref()),
            ],
        )?;
        Ok(ClosureLagrangian {
            dim,
            lagrangian: lagrangian.unbind(),
            dl_dq: dl_dq.map(Bound::unbind),
            dl_dv: dl_dv.map(Bound::unbind),
            hessians: hessians.map(Bound::unbind),
            force: force.map(Bound::unbind),
            dl_dt: dl_dt.map(Bound::unbind),
            time_dependent,
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.dim
    }

    fn __repr__(&self) -> String {
        format!("ClosureLagrangian(dim={})", self.dim)
    }
}

/// A [`ClosureLagrangian`] bound to the GIL: it implements the core's [`Lagrangian`] trait.
pub struct ClosureLagrangianSystem<'a, 'py> {
    py: Python<'py>,
    model: &'a ClosureLagrangian,
    lagrangian: Bound<'py, PyAny>,
    dl_dq: Option<Bound<'py, PyAny>>,
    dl_dv: Option<Bound<'py, PyAny>>,
    hessians: Option<Bound<'py, PyAny>>,
    force: Option<Bound<'py, PyAny>>,
    dl_dt: Option<Bound<'py, PyAny>>,
    work: RefCell<Vec<f64>>,
}

impl<'a, 'py> ClosureLagrangianSystem<'a, 'py> {
    pub fn new(py: Python<'py>, model: &'a ClosureLagrangian) -> Self {
        ClosureLagrangianSystem {
            py,
            model,
            lagrangian: model.lagrangian.bind(py).clone(),
            dl_dq: model.dl_dq.as_ref().map(|f| f.bind(py).clone()),
            dl_dv: model.dl_dv.as_ref().map(|f| f.bind(py).clone()),
            hessians: model.hessians.as_ref().map(|f| f.bind(py).clone()),
            force: model.force.as_ref().map(|f| f.bind(py).clone()),
            dl_dt: model.dl_dt.as_ref().map(|f| f.bind(py).clone()),
            work: RefCell::new(vec![0.0; model.dim]),
        }
    }

    fn args(&self, q: &[f64], v: &[f64], t: f64) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, f64) {
        (PyArray1::from_slice(self.py, q), PyArray1::from_slice(self.py, v), t)
    }
}

impl Lagrangian for ClosureLagrangianSystem<'_, '_> {
    fn dim(&self) -> usize {
        self.model.dim
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        call_scalar(self.lagrangian.call1(self.args(q, v, t)), "lagrangian(q, v, t)")
    }

    fn dl_dq(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        match &self.dl_dq {
            Some(f) => call_vector(f.call1(self.args(q, v, t)), "dl_dq(q, v, t)", out),
            None => central_gradient(|x| self.lagrangian(x, v, t), q, &mut self.work.borrow_mut(), out),
        }
    }

    fn dl_dv(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        match &self.dl_dv {
            Some(f) => call_vector(f.call1(self.args(q, v, t)), "dl_dv(q, v, t)", out),
            None => central_gradient(|x| self.lagrangian(q, x, t), v, &mut self.work.borrow_mut(), out),
        }
    }

    /// `hessians(q, v, t)` returns (∂²L/∂q², ∂²L/∂q∂q̇, ∂²L/∂q̇²), each (n, n) in C order.
    fn hessians(&self, q: &[f64], v: &[f64], t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        let Some(f) = &self.hessians else {
            return Ok(false);
        };
        let n = self.model.dim;
        let result = f.call1(self.args(q, v, t)).map_err(boxed)?;
        let parts: [Bound<'_, PyAny>; 3] = result.extract().map_err(|_| {
            boxed(PyTypeError::new_err(format!(
                "hessians(q, v, t) must return three arrays (L_qq, L_qv, L_vv), got {}",
                type_name(&result)
            )))
        })?;
        for (part, (name, m)) in
            parts
                .into_iter()
                .zip([("L_qq", &mut out.qq), ("L_qv", &mut out.qv), ("L_vv", &mut out.vv)])
        {
            call_array(
                Ok(part),
                &format!("hessians(q, v, t)'s {name}"),
                &[n, n],
                m.as_mut_slice(),
            )?;
            // Read in C order into column-major storage.
            m.transpose_mut();
        }
        Ok(true)
    }

    fn is_time_dependent(&self) -> bool {
        self.model.time_dependent
    }

    fn dl_dt(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        match &self.dl_dt {
            Some(f) => call_scalar(f.call1(self.args(q, v, t)), "dl_dt(q, v, t)"),
            None => differenced_dl_dt(self, q, v, t),
        }
    }

    fn is_forced(&self) -> bool {
        self.force.is_some()
    }

    fn force(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        match &self.force {
            Some(f) => call_vector(f.call1(self.args(q, v, t)), "force(q, v, t)", out),
            None => {
                out.fill(0.0);
                Ok(())
            }
        }
    }
}
