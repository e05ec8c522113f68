//! Models whose functions are native function pointers (numba `cfunc`, ctypes, cffi,
//! `scipy.LowLevelCallable`), called from the core with no Python in the loop and the GIL
//! released.
//!
//! Every function has the one C signature
//! `int32_t f(const double *q, const double *v, double t, int64_t n, double *out)`: it reads q
//! and q̇ (n numbers each), writes its outputs to `out` and returns 0, or another status, which
//! stops the run with an error naming the function and the status. Functions of q alone get
//! q̇ = 0 and t = 0. `varmech.pointers` checks the signature of each pointer before it gets here.

use std::cell::RefCell;
use std::fmt;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::integrators::{Dynamics, General};
use varmech::model::{Generator, Hessians, Lagrangian, Mass, MechanicalSystem};
use varmech::solve::difference::central_gradient;
use varmech::ModelError;

use crate::closure::readers::check_closures;
use crate::convert;
use crate::generator::{self, Generator as Spec};

/// The C signature of every pointer.
type Native = unsafe extern "C" fn(q: *const f64, v: *const f64, t: f64, n: i64, out: *mut f64) -> i32;

/// A pointer as Python hands it over: its address and the object that owns its code.
type Handed<'py> = (usize, Bound<'py, PyAny>);

/// A nonzero status returned by a pointer function.
#[derive(Debug)]
pub struct Status {
    function: &'static str,
    status: i32,
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the function pointer {} returned status {}",
            self.function, self.status
        )
    }
}

impl std::error::Error for Status {}

/// One model function: the pointer, its name for errors, the number of coordinates n and of
/// outputs it writes, and the Python object that owns its code.
struct Entry {
    name: &'static str,
    function: Native,
    dim: usize,
    outputs: usize,
    _owner: Py<PyAny>,
}

impl Entry {
    fn new(name: &'static str, (address, owner): Handed<'_>, dim: usize, outputs: usize) -> PyResult<Self> {
        if address == 0 {
            return Err(PyValueError::new_err(format!("{name}: a null function pointer")));
        }
        let code = std::ptr::with_exposed_provenance::<()>(address);
        // SAFETY: `varmech.pointers.address` checked that `owner` is a function of the signature
        // `Native` (from its ctypes prototype, numba signature or C signature string) and gave
        // its address; `_owner` keeps it, and so its code, alive as long as this entry. What the
        // function does inside is the user's contract: read n numbers at q and v, write
        // `outputs` numbers at out.
        let function = unsafe { std::mem::transmute::<*const (), Native>(code) };
        Ok(Entry {
            name,
            function,
            dim,
            outputs,
            _owner: owner.unbind(),
        })
    }

    /// Calls the function at (q, q̇, t) into `out`.
    fn call(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        if q.len() != self.dim || v.len() != self.dim || out.len() != self.outputs {
            return Err(format!(
                "{}: called with {} coordinates, {} velocities and {} outputs, expected {}, {} and {}",
                self.name,
                q.len(),
                v.len(),
                out.len(),
                self.dim,
                self.dim,
                self.outputs
            )
            .into());
        }
        // SAFETY: the signature is `Native` (see `Entry::new`), and the slices hold the n, n
        // and `outputs` numbers it reads and writes, checked just above.
        let status = unsafe { (self.function)(q.as_ptr(), v.as_ptr(), t, self.dim as i64, out.as_mut_ptr()) };
        match status {
            0 => Ok(()),
            status => Err(Box::new(Status {
                function: self.name,
                status,
            })),
        }
    }

    /// The function's one output at (q, q̇, t).
    fn scalar(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        let mut out = [0.0];
        self.call(q, v, t, &mut out)?;
        Ok(out[0])
    }
}

/// A separable mechanical system L = ½q̇ᵀMq̇ − V(q) with constant M whose potential V(q) and
/// gradient ∇V(q) are function pointers.
#[pyclass(frozen, module = "varmech._core")]
pub struct PointerSystem {
    dim: usize,
    mass: Mass,
    potential: Entry,
    gradient: Entry,
    symmetries: Vec<Generator>,
    /// The q̇ = 0 the functions of q alone are given.
    zeros: Vec<f64>,
}

#[pymethods]
impl PointerSystem {
    #[new]
    #[pyo3(signature = (dim, potential, gradient, mass, symmetries))]
    fn new(
        dim: usize,
        potential: Handed<'_>,
        gradient: Handed<'_>,
        mass: &Bound<'_, PyAny>,
        symmetries: Vec<Spec>,
    ) -> PyResult<Self> {
        check_closures(dim, [])?;
        Ok(PointerSystem {
            dim,
            mass: convert::mass(mass, dim)?,
            potential: Entry::new("potential", potential, dim, 1)?,
            gradient: Entry::new("gradient", gradient, dim, dim)?,
            symmetries: generator::generators(symmetries, dim)?,
            zeros: vec![0.0; dim],
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.dim
    }

    fn __repr__(&self) -> String {
        format!("PointerSystem(dim={})", self.dim)
    }
}

impl MechanicalSystem for PointerSystem {
    fn dim(&self) -> usize {
        self.dim
    }

    fn mass(&self) -> &Mass {
        &self.mass
    }

    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        self.potential.scalar(q, &self.zeros, 0.0)
    }

    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        self.gradient.call(q, &self.zeros, 0.0, grad)
    }

    fn symmetries(&self) -> Vec<Generator> {
        self.symmetries.clone()
    }
}

/// A general Lagrangian L(q, q̇, t) whose functions are pointers: L (one output) and,
/// optionally, ∂L/∂q and ∂L/∂q̇ (n each; central differences of L without them), the Hessians
/// ∂²L/∂q², ∂²L/∂q∂q̇ and ∂²L/∂q̇² (3n², each row-major; differenced Newton Jacobians without
/// them) and a generalized force (n).
#[pyclass(frozen, module = "varmech._core")]
pub struct PointerLagrangian {
    dim: usize,
    lagrangian: Entry,
    dl_dq: Option<Entry>,
    dl_dv: Option<Entry>,
    hessians: Option<Entry>,
    force: Option<Entry>,
    time_dependent: bool,
}

#[pymethods]
impl PointerLagrangian {
    #[new]
    /// `symmetries` are only checked here (the core's Lagrangian trait declares none); the
    /// Python model keeps them for the conservation report.
    #[pyo3(signature = (dim, lagrangian, dl_dq, dl_dv, hessians, force, time_dependent, symmetries))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        dim: usize,
        lagrangian: Handed<'_>,
        dl_dq: Option<Handed<'_>>,
        dl_dv: Option<Handed<'_>>,
        hessians: Option<Handed<'_>>,
        force: Option<Handed<'_>>,
        time_dependent: bool,
        symmetries: Vec<Spec>,
    ) -> PyResult<Self> {
        check_closures(dim, [])?;
        generator::generators(symmetries, dim)?;
        let entry = |name, f: Option<Handed<'_>>, outputs| f.map(|f| Entry::new(name, f, dim, outputs)).transpose();
        Ok(PointerLagrangian {
            dim,
            lagrangian: Entry::new("lagrangian", lagrangian, dim, 1)?,
            dl_dq: entry("dl_dq", dl_dq, dim)?,
            dl_dv: entry("dl_dv", dl_dv, dim)?,
            hessians: entry("hessians", hessians, 3 * dim * dim)?,
            force: entry("force", force, dim)?,
            time_dependent,
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.dim
    }

    fn __repr__(&self) -> String {
        format!("PointerLagrangian(dim={})", self.dim)
    }
}

impl PointerLagrangian {
    /// Runs `body` with the model as the core's [`Dynamics`].
    pub fn with_integrable<R>(&self, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        let n = self.dim;
        body(&General(&PointerLagrangianSystem {
            model: self,
            work: RefCell::new(vec![0.0; n]),
            hessians: RefCell::new(vec![0.0; if self.hessians.is_some() { 3 * n * n } else { 0 }]),
        }))
    }
}

/// A [`PointerLagrangian`] with the scratch space of one run: it implements the core's
/// [`Lagrangian`] trait.
struct PointerLagrangianSystem<'a> {
    model: &'a PointerLagrangian,
    /// The differences' scratch vector.
    work: RefCell<Vec<f64>>,
    /// The three Hessians as the pointer writes them, row-major.
    hessians: RefCell<Vec<f64>>,
}

impl Lagrangian for PointerLagrangianSystem<'_> {
    fn dim(&self) -> usize {
        self.model.dim
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        self.model.lagrangian.scalar(q, v, t)
    }

    fn dl_dq(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        match &self.model.dl_dq {
            Some(f) => f.call(q, v, t, out),
            None => central_gradient(|x| self.lagrangian(x, v, t), q, &mut self.work.borrow_mut(), out),
        }
    }

    fn dl_dv(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        match &self.model.dl_dv {
            Some(f) => f.call(q, v, t, out),
            None => central_gradient(|x| self.lagrangian(q, x, t), v, &mut self.work.borrow_mut(), out),
        }
    }

    fn hessians(&self, q: &[f64], v: &[f64], t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        let Some(f) = &self.model.hessians else {
            return Ok(false);
        };
        let buffer = &mut *self.hessians.borrow_mut();
        f.call(q, v, t, buffer)?;
        out.set_rows(buffer);
        Ok(true)
    }

    fn is_time_dependent(&self) -> bool {
        self.model.time_dependent
    }

    fn is_forced(&self) -> bool {
        self.model.force.is_some()
    }

    fn force(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        match &self.model.force {
            Some(f) => f.call(q, v, t, out),
            None => {
                out.fill(0.0);
                Ok(())
            }
        }
    }
}

/// The pointer models' classes, for the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PointerSystem>()?;
    m.add_class::<PointerLagrangian>()?;
    Ok(())
}
