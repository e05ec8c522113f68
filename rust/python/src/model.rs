//! Models seen from Python: native scenes, and Python closures adapted to the core's model
//! traits ([`MechanicalSystem`] and [`Lagrangian`]).

use std::cell::RefCell;

use nalgebra::DMatrix;
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use varmech::model::{
    differenced_jacobian, differenced_kinetic_gradient, Constrained, Distances, Generator, Hessians,
    HolonomicConstraints, Lagrangian, Mass, MechanicalSystem, NaturalSystem, Routhian,
};
use varmech::scenes::{LagrangianScene, LinkedMasses, RigidBody, Scene};
use varmech::solve::difference::central_gradient;
use varmech::ModelError;

use crate::convert;

/// A native scene: a separable mechanical system, a general Lagrangian, or a mechanical
/// system on holonomic constraints.
pub enum Native {
    Mechanical(Scene),
    General(LagrangianScene),
    Constrained(LinkedMasses),
    /// A general Lagrangian on constraints (the rigid body in quaternions).
    ConstrainedGeneral(Constrained<RigidBody, Distances>),
}

/// A native scene: every evaluation runs in Rust, with the GIL released.
#[pyclass(frozen, module = "varmech._core")]
pub struct NativeModel {
    pub native: Native,
    name: &'static str,
}

impl NativeModel {
    pub fn new(native: Native, name: &'static str) -> Self {
        NativeModel { native, name }
    }

    pub fn dim(&self) -> usize {
        match &self.native {
            Native::Mechanical(s) => MechanicalSystem::dim(s),
            Native::General(s) => Lagrangian::dim(s),
            Native::Constrained(s) => MechanicalSystem::dim(&s.system),
            Native::ConstrainedGeneral(s) => Lagrangian::dim(&s.system),
        }
    }
}

#[pymethods]
impl NativeModel {
    #[getter(dim)]
    fn py_dim(&self) -> usize {
        self.dim()
    }

    #[getter]
    fn name(&self) -> &'static str {
        self.name
    }

    /// Whether the model is a separable mechanical system (every method applies to it).
    #[getter]
    fn separable(&self) -> bool {
        matches!(self.native, Native::Mechanical(_))
    }

    #[getter]
    fn time_dependent(&self) -> bool {
        matches!(&self.native, Native::General(s) if s.is_time_dependent())
    }

    #[getter]
    fn forced(&self) -> bool {
        matches!(&self.native, Native::General(s) if s.is_forced())
    }

    /// (G, masses) of an N-body scene, None for the others.
    #[getter]
    fn gravity(&self) -> Option<(f64, Vec<f64>)> {
        match &self.native {
            Native::Mechanical(Scene::NBody(s)) => Some((s.gravitational_constant(), s.masses().to_vec())),
            _ => None,
        }
    }

    /// The declared symmetries, as (kind, axis or index, spatial_dim, name).
    #[getter]
    fn symmetries(&self) -> Vec<(&'static str, usize, usize, String)> {
        match &self.native {
            Native::Mechanical(s) => s.symmetries().into_iter().map(convert::generator_spec).collect(),
            Native::General(s) => s.symmetries().into_iter().map(convert::generator_spec).collect(),
            Native::Constrained(s) => s.system.symmetries().into_iter().map(convert::generator_spec).collect(),
            Native::ConstrainedGeneral(_) => Vec::new(),
        }
    }

    /// The method `integrate` uses when none is given, for constrained models.
    #[getter]
    fn default_method(&self) -> Option<&'static str> {
        match &self.native {
            Native::Constrained(_) => Some("rattle"),
            Native::ConstrainedGeneral(_) => Some("trapezoid"),
            _ => None,
        }
    }

    /// Number of holonomic constraints (0 for unconstrained models).
    #[getter]
    fn constraints(&self) -> usize {
        match &self.native {
            Native::Constrained(s) => s.constraints.count(),
            Native::ConstrainedGeneral(s) => s.constraints.count(),
            _ => 0,
        }
    }

    fn __repr__(&self) -> String {
        format!("NativeModel({:?}, dim={})", self.name, self.dim())
    }
}

/// A mechanical system L = ½q̇ᵀMq̇ − V(q) given by Python closures `potential(q) -> float` and,
/// optionally, `gradient(q) -> array (n,)`; without a gradient, central differences of the
/// potential are used (2n potential calls per gradient).
#[pyclass(frozen, module = "varmech._core")]
pub struct ClosureModel {
    dim: usize,
    mass: Mass,
    potential: Py<PyAny>,
    gradient: Option<Py<PyAny>>,
    symmetries: Vec<Generator>,
}

#[pymethods]
impl ClosureModel {
    #[new]
    #[pyo3(signature = (dim, potential, gradient, mass, symmetries))]
    fn new(
        dim: usize,
        potential: Bound<'_, PyAny>,
        gradient: Option<Bound<'_, PyAny>>,
        mass: &Bound<'_, PyAny>,
        symmetries: Vec<(String, usize, usize)>,
    ) -> PyResult<Self> {
        check_closures(dim, [("potential", Some(&potential)), ("gradient", gradient.as_ref())])?;
        let mass = convert::mass(mass)?;
        if let Some(n) = mass.dim().filter(|n| *n != dim) {
            return Err(PyValueError::new_err(format!(
                "mass: has dimension {n}, the model has dim = {dim}"
            )));
        }
        let symmetries = convert::generators(symmetries, dim)?;
        Ok(ClosureModel {
            dim,
            mass,
            potential: potential.unbind(),
            gradient: gradient.map(Bound::unbind),
            symmetries,
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.dim
    }

    #[getter]
    fn has_gradient(&self) -> bool {
        self.gradient.is_some()
    }

    #[getter]
    fn separable(&self) -> bool {
        true
    }

    #[getter]
    fn time_dependent(&self) -> bool {
        false
    }

    #[getter]
    fn forced(&self) -> bool {
        false
    }

    fn __repr__(&self) -> String {
        format!("ClosureModel(dim={})", self.dim)
    }
}

/// A closure model (a [`ClosureModel`], or a [`ClosureNatural`] with configuration-dependent
/// mass) on holonomic constraints given by Python closures `constraints(q) -> array (m,)` and,
/// optionally, `jacobian(q) -> array (m, n)`; without a Jacobian, central differences of g are
/// used (2n calls of g per Jacobian).
#[pyclass(frozen, module = "varmech._core")]
pub struct ClosureConstrained {
    system: ConstrainedSystem,
    count: usize,
    constraints: Py<PyAny>,
    jacobian: Option<Py<PyAny>>,
}

#[pymethods]
impl ClosureConstrained {
    #[new]
    #[pyo3(signature = (system, count, constraints, jacobian))]
    fn new(
        system: Bound<'_, PyAny>,
        count: usize,
        constraints: Bound<'_, PyAny>,
        jacobian: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let system = if let Ok(s) = system.cast::<ClosureModel>() {
            ConstrainedSystem::Separable(s.clone().unbind())
        } else if let Ok(s) = system.cast::<ClosureNatural>() {
            ConstrainedSystem::Natural(s.clone().unbind())
        } else {
            return Err(PyTypeError::new_err(
                "system: expected a ClosureModel or a ClosureNatural",
            ));
        };
        let dim = system.dim();
        check_closures(
            dim,
            [
                ("constraints", Some(&constraints)),
                ("constraint_jacobian", jacobian.as_ref()),
            ],
        )?;
        if count == 0 || count >= dim {
            return Err(PyValueError::new_err(format!(
                "constraint_count: must be between 1 and dim − 1 = {}, got {count}",
                dim - 1
            )));
        }
        Ok(ClosureConstrained {
            system,
            count,
            constraints: constraints.unbind(),
            jacobian: jacobian.map(Bound::unbind),
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.system.dim()
    }

    #[getter]
    fn constraints(&self) -> usize {
        self.count
    }

    /// RATTLE for a separable system, the trapezoidal rule's constrained DEL equations (RATTLE's
    /// discrete Lagrangian) for one with configuration-dependent mass.
    #[getter]
    fn default_method(&self) -> &'static str {
        match self.system {
            ConstrainedSystem::Separable(_) => "rattle",
            ConstrainedSystem::Natural(_) => "trapezoid",
        }
    }

    #[getter]
    fn separable(&self) -> bool {
        false
    }

    #[getter]
    fn time_dependent(&self) -> bool {
        false
    }

    #[getter]
    fn forced(&self) -> bool {
        false
    }

    fn __repr__(&self) -> String {
        format!("ClosureConstrained(dim={}, constraints={})", self.dim(), self.count)
    }
}

impl ClosureConstrained {
    pub fn system(&self) -> &ConstrainedSystem {
        &self.system
    }
}

/// The unconstrained model under a [`ClosureConstrained`]: RATTLE integrates a separable one,
/// the constrained DEL equations a natural one.
pub enum ConstrainedSystem {
    Separable(Py<ClosureModel>),
    Natural(Py<ClosureNatural>),
}

impl ConstrainedSystem {
    fn dim(&self) -> usize {
        match self {
            ConstrainedSystem::Separable(s) => s.get().dim,
            ConstrainedSystem::Natural(s) => s.get().dim,
        }
    }
}

/// A natural mechanical system L = ½q̇ᵀM(q)q̇ − V(q) given by Python closures `mass(q) -> array
/// (n, n)`, `potential(q) -> float` and, optionally, `gradient(q) -> array (n,)` and
/// `mass_derivative(q) -> array (n, n, n)` (∂M/∂qᵢ at index i); missing derivatives come from
/// central differences.
#[pyclass(frozen, module = "varmech._core")]
pub struct ClosureNatural {
    dim: usize,
    mass: Py<PyAny>,
    potential: Py<PyAny>,
    gradient: Option<Py<PyAny>>,
    mass_derivative: Option<Py<PyAny>>,
}

#[pymethods]
impl ClosureNatural {
    #[new]
    /// `symmetries` are only checked here, as for [`ClosureLagrangian`].
    #[pyo3(signature = (dim, mass, potential, gradient, mass_derivative, symmetries))]
    fn new(
        dim: usize,
        mass: Bound<'_, PyAny>,
        potential: Bound<'_, PyAny>,
        gradient: Option<Bound<'_, PyAny>>,
        mass_derivative: Option<Bound<'_, PyAny>>,
        symmetries: Vec<(String, usize, usize)>,
    ) -> PyResult<Self> {
        convert::generators(symmetries, dim)?;
        check_closures(
            dim,
            [
                ("mass", Some(&mass)),
                ("potential", Some(&potential)),
                ("gradient", gradient.as_ref()),
                ("mass_derivative", mass_derivative.as_ref()),
            ],
        )?;
        Ok(ClosureNatural {
            dim,
            mass: mass.unbind(),
            potential: potential.unbind(),
            gradient: gradient.map(Bound::unbind),
            mass_derivative: mass_derivative.map(Bound::unbind),
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.dim
    }

    #[getter]
    fn separable(&self) -> bool {
        false
    }

    #[getter]
    fn time_dependent(&self) -> bool {
        false
    }

    #[getter]
    fn forced(&self) -> bool {
        false
    }

    fn __repr__(&self) -> String {
        format!("ClosureNatural(dim={})", self.dim)
    }
}

/// A general Lagrangian L(q, q̇, t) given by Python closures: `lagrangian(q, v, t) -> float`
/// and, optionally, `dl_dq(q, v, t)` and `dl_dv(q, v, t)` (arrays (n,)); missing derivatives
/// come from central differences of L. An optional `force(q, v, t)` (array (n,)) is a
/// non-conservative generalized force.
#[pyclass(frozen, module = "varmech._core")]
pub struct ClosureLagrangian {
    dim: usize,
    lagrangian: Py<PyAny>,
    dl_dq: Option<Py<PyAny>>,
    dl_dv: Option<Py<PyAny>>,
    hessians: Option<Py<PyAny>>,
    force: Option<Py<PyAny>>,
    time_dependent: bool,
}

#[pymethods]
impl ClosureLagrangian {
    #[new]
    /// `symmetries` are only checked here (the core's Lagrangian trait declares none); the
    /// Python model keeps them for the conservation report.
    #[pyo3(signature = (dim, lagrangian, dl_dq, dl_dv, hessians, force, time_dependent, symmetries))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        dim: usize,
        lagrangian: Bound<'_, PyAny>,
        dl_dq: Option<Bound<'_, PyAny>>,
        dl_dv: Option<Bound<'_, PyAny>>,
        hessians: Option<Bound<'_, PyAny>>,
        force: Option<Bound<'_, PyAny>>,
        time_dependent: bool,
        symmetries: Vec<(String, usize, usize)>,
    ) -> PyResult<Self> {
        convert::generators(symmetries, dim)?;
        check_closures(
            dim,
            [
                ("lagrangian", Some(&lagrangian)),
                ("dl_dq", dl_dq.as_ref()),
                ("dl_dv", dl_dv.as_ref()),
                ("hessians", hessians.as_ref()),
                ("force", force.as_ref()),
            ],
        )?;
        Ok(ClosureLagrangian {
            dim,
            lagrangian: lagrangian.unbind(),
            dl_dq: dl_dq.map(Bound::unbind),
            dl_dv: dl_dv.map(Bound::unbind),
            hessians: hessians.map(Bound::unbind),
            force: force.map(Bound::unbind),
            time_dependent,
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.dim
    }

    #[getter]
    fn separable(&self) -> bool {
        false
    }

    #[getter]
    fn time_dependent(&self) -> bool {
        self.time_dependent
    }

    #[getter]
    fn forced(&self) -> bool {
        self.force.is_some()
    }

    fn __repr__(&self) -> String {
        format!("ClosureLagrangian(dim={})", self.dim)
    }
}

/// A Routh-reduced model: the Routhian R = L − μ·ċ of a full model (native or closures) on
/// its non-cyclic coordinates, built by `_core.routh` (which checks it).
#[pyclass(frozen, module = "varmech._core")]
pub struct RouthModel {
    pub full: Py<PyAny>,
    pub cyclic: Vec<usize>,
    pub momenta: Vec<f64>,
    pub reference: Vec<f64>,
    pub dim: usize,
    pub time_dependent: bool,
}

impl RouthModel {
    /// The Routhian of the full model's Lagrangian `full`.
    pub fn routhian<'a>(&self, full: &'a dyn Lagrangian) -> Routhian<'a, dyn Lagrangian + 'a> {
        Routhian::new(full, &self.cyclic, &self.momenta, &self.reference)
            .expect("the arguments were checked when the model was built")
    }
}

#[pymethods]
impl RouthModel {
    #[getter]
    pub fn dim(&self) -> usize {
        self.dim
    }

    #[getter]
    fn separable(&self) -> bool {
        false
    }

    #[getter]
    fn time_dependent(&self) -> bool {
        self.time_dependent
    }

    #[getter]
    fn forced(&self) -> bool {
        false
    }

    /// The model whose cyclic coordinates are ignored.
    #[getter]
    fn full(&self, py: Python<'_>) -> Py<PyAny> {
        self.full.clone_ref(py)
    }

    #[getter]
    fn cyclic(&self) -> Vec<usize> {
        self.cyclic.clone()
    }

    #[getter]
    fn momenta(&self) -> Vec<f64> {
        self.momenta.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "RouthModel(cyclic={:?}, momenta={:?}, dim={})",
            self.cyclic, self.momenta, self.dim
        )
    }
}

/// A positive dimension and callable closures (the optional ones may be None).
fn check_closures<const N: usize>(dim: usize, closures: [(&str, Option<&Bound<'_, PyAny>>); N]) -> PyResult<()> {
    if dim == 0 {
        return Err(PyValueError::new_err("dim: must be at least 1"));
    }
    for (name, f) in closures {
        if f.is_some_and(|f| !f.is_callable()) {
            return Err(PyTypeError::new_err(format!("{name}: must be callable")));
        }
    }
    Ok(())
}

fn boxed(e: PyErr) -> ModelError {
    Box::new(e)
}

/// The name of a Python object's type, for messages.
fn type_name(x: &Bound<'_, PyAny>) -> String {
    x.get_type().name().map(|n| n.to_string()).unwrap_or_default()
}

/// Reads a closure's result, a float; a wrong type is a TypeError naming the closure as `call`.
fn call_scalar(result: PyResult<Bound<'_, PyAny>>, call: &str) -> Result<f64, ModelError> {
    let result = result.map_err(boxed)?;
    result.extract::<f64>().map_err(|_| {
        boxed(PyTypeError::new_err(format!(
            "{call} must return a float, got {}",
            type_name(&result)
        )))
    })
}

/// Reads a closure's result, an array (n,) of floats, into `out`: a float64 numpy array is
/// read in place, any other sequence of numbers is converted. A wrong length is a ValueError
/// and a wrong type a TypeError, both naming the closure as `call`.
fn call_vector(result: PyResult<Bound<'_, PyAny>>, call: &str, out: &mut [f64]) -> Result<(), ModelError> {
    let result = result.map_err(boxed)?;
    let n = out.len();
    let wrong_length = |len: usize| {
        boxed(PyValueError::new_err(format!(
            "{call} returned {len} values, expected {n} (one per coordinate)"
        )))
    };
    if let Ok(arr) = result.cast::<PyArray1<f64>>() {
        let ro = arr.readonly();
        let view = ro.as_array();
        if view.len() != n {
            return Err(wrong_length(view.len()));
        }
        out.iter_mut().zip(view.iter()).for_each(|(o, v)| *o = *v);
        return Ok(());
    }
    let values: Vec<f64> = result.extract().map_err(|_| {
        let shape = result
            .getattr("shape")
            .map(|s| format!(" of shape {s}"))
            .unwrap_or_default();
        boxed(PyTypeError::new_err(format!(
            "{call} must return a 1-d array of {n} floats, got {}{shape}",
            type_name(&result)
        )))
    })?;
    if values.len() != n {
        return Err(wrong_length(values.len()));
    }
    out.copy_from_slice(&values);
    Ok(())
}

/// Reads a closure's result, a float array of `shape`, into `out` in C order: a float64 numpy
/// array is read in place, anything else goes through `numpy.asarray`. A wrong shape is a
/// ValueError and a wrong type a TypeError, both naming the closure as `call`.
fn call_array(
    result: PyResult<Bound<'_, PyAny>>,
    call: &str,
    shape: &[usize],
    out: &mut [f64],
) -> Result<(), ModelError> {
    let result = result.map_err(boxed)?;
    let wrong_type = || {
        boxed(PyTypeError::new_err(format!(
            "{call} must return an array of shape {shape:?} of floats, got {}",
            type_name(&result)
        )))
    };
    let array = match result.cast::<PyArrayDyn<f64>>() {
        Ok(a) => a.clone(),
        Err(_) => {
            let numpy = result.py().import("numpy").map_err(boxed)?;
            let converted = numpy
                .call_method1("asarray", (&result, "float64"))
                .map_err(|_| wrong_type())?;
            converted.cast_into::<PyArrayDyn<f64>>().map_err(|_| wrong_type())?
        }
    };
    let readonly = array.readonly();
    let view = readonly.as_array();
    if view.shape() != shape {
        return Err(boxed(PyValueError::new_err(format!(
            "{call} returned an array of shape {:?}, expected {shape:?}",
            view.shape()
        ))));
    }
    out.iter_mut().zip(view.iter()).for_each(|(o, v)| *o = *v);
    Ok(())
}

/// A [`ClosureModel`] bound to the GIL for the duration of a call: it implements the core's
/// model trait by calling the closures.
pub struct ClosureSystem<'a, 'py> {
    py: Python<'py>,
    model: &'a ClosureModel,
    potential: Bound<'py, PyAny>,
    gradient: Option<Bound<'py, PyAny>>,
    work: RefCell<Vec<f64>>,
}

impl<'a, 'py> ClosureSystem<'a, 'py> {
    pub fn new(py: Python<'py>, model: &'a ClosureModel) -> Self {
        ClosureSystem {
            py,
            model,
            potential: model.potential.bind(py).clone(),
            gradient: model.gradient.as_ref().map(|g| g.bind(py).clone()),
            work: RefCell::new(vec![0.0; model.dim]),
        }
    }
}

impl MechanicalSystem for ClosureSystem<'_, '_> {
    fn dim(&self) -> usize {
        self.model.dim
    }

    fn mass(&self) -> &Mass {
        &self.model.mass
    }

    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        call_scalar(
            self.potential.call1((PyArray1::from_slice(self.py, q),)),
            "potential(q)",
        )
    }

    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        match &self.gradient {
            Some(f) => call_vector(f.call1((PyArray1::from_slice(self.py, q),)), "gradient(q)", grad),
            None => central_gradient(|x| self.potential(x), q, &mut self.work.borrow_mut(), grad),
        }
    }

    fn symmetries(&self) -> Vec<Generator> {
        self.model.symmetries.clone()
    }
}

/// The constraints of a [`ClosureConstrained`] bound to the GIL: they implement the core's
/// [`HolonomicConstraints`] trait.
pub struct ClosureConstraints<'py> {
    py: Python<'py>,
    count: usize,
    constraints: Bound<'py, PyAny>,
    jacobian: Option<Bound<'py, PyAny>>,
    rows: RefCell<Vec<f64>>,
}

impl<'py> ClosureConstraints<'py> {
    pub fn new(py: Python<'py>, model: &ClosureConstrained) -> Self {
        ClosureConstraints {
            py,
            count: model.count,
            constraints: model.constraints.bind(py).clone(),
            jacobian: model.jacobian.as_ref().map(|f| f.bind(py).clone()),
            rows: RefCell::new(vec![0.0; model.count * model.dim()]),
        }
    }
}

impl HolonomicConstraints for ClosureConstraints<'_> {
    fn count(&self) -> usize {
        self.count
    }

    fn residual(&self, q: &[f64], g: &mut [f64]) -> Result<(), ModelError> {
        call_vector(
            self.constraints.call1((PyArray1::from_slice(self.py, q),)),
            "constraints(q)",
            g,
        )
    }

    /// `jacobian(q)`, an array (m, n) in C order, or the trait's differences of g.
    fn jacobian(&self, q: &[f64], jac: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let Some(f) = &self.jacobian else {
            return differenced_jacobian(self, q, jac);
        };
        let (m, n) = jac.shape();
        let rows = &mut *self.rows.borrow_mut();
        call_array(
            f.call1((PyArray1::from_slice(self.py, q),)),
            "constraint_jacobian(q)",
            &[m, n],
            rows,
        )?;
        for (i, row) in rows.chunks_exact(n).enumerate() {
            jac.row_mut(i).iter_mut().zip(row).for_each(|(j, r)| *j = *r);
        }
        Ok(())
    }
}

/// A [`ClosureNatural`] bound to the GIL: it implements the core's [`NaturalSystem`] trait
/// (a [`Lagrangian`] through `varmech::model::Natural`).
pub struct ClosureNaturalSystem<'a, 'py> {
    py: Python<'py>,
    model: &'a ClosureNatural,
    mass: Bound<'py, PyAny>,
    potential: Bound<'py, PyAny>,
    gradient: Option<Bound<'py, PyAny>>,
    mass_derivative: Option<Bound<'py, PyAny>>,
    /// ∂M/∂qᵢ for i = 0..n, C order.
    derivative: RefCell<Vec<f64>>,
    work: RefCell<Vec<f64>>,
}

impl<'a, 'py> ClosureNaturalSystem<'a, 'py> {
    pub fn new(py: Python<'py>, model: &'a ClosureNatural) -> Self {
        let n = model.dim;
        ClosureNaturalSystem {
            py,
            model,
            mass: model.mass.bind(py).clone(),
            potential: model.potential.bind(py).clone(),
            gradient: model.gradient.as_ref().map(|f| f.bind(py).clone()),
            mass_derivative: model.mass_derivative.as_ref().map(|f| f.bind(py).clone()),
            derivative: RefCell::new(vec![0.0; n * n * n]),
            work: RefCell::new(vec![0.0; n]),
        }
    }
}

impl NaturalSystem for ClosureNaturalSystem<'_, '_> {
    fn dim(&self) -> usize {
        self.model.dim
    }

    /// M(q), which must be symmetric (to 1e-12 relative): Cholesky reads one triangle only.
    fn mass_matrix(&self, q: &[f64], m: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let n = self.model.dim;
        let call = self.mass.call1((PyArray1::from_slice(self.py, q),));
        call_array(call, "mass(q)", &[n, n], m.as_mut_slice())?;
        let scale = m.amax();
        if (0..n).any(|i| (0..i).any(|j| (m[(i, j)] - m[(j, i)]).abs() > 1e-12 * scale)) {
            return Err(boxed(PyValueError::new_err(format!(
                "mass(q) returned a matrix that is not symmetric at q = {q:?}"
            ))));
        }
        Ok(())
    }

    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        call_scalar(
            self.potential.call1((PyArray1::from_slice(self.py, q),)),
            "potential(q)",
        )
    }

    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        match &self.gradient {
            Some(f) => call_vector(f.call1((PyArray1::from_slice(self.py, q),)), "gradient(q)", grad),
            None => central_gradient(|x| self.potential(x), q, &mut self.work.borrow_mut(), grad),
        }
    }

    /// (∂T/∂q)ᵢ = ½q̇ᵀ(∂M/∂qᵢ)q̇ from `mass_derivative`, or the trait's differences of M.
    fn kinetic_gradient(&self, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        let Some(f) = &self.mass_derivative else {
            return differenced_kinetic_gradient(self, q, v, out);
        };
        let n = self.model.dim;
        let derivative = &mut *self.derivative.borrow_mut();
        call_array(
            f.call1((PyArray1::from_slice(self.py, q),)),
            "mass_derivative(q)",
            &[n, n, n],
            derivative,
        )?;
        for (o, d) in out.iter_mut().zip(derivative.chunks_exact(n * n)) {
            *o = 0.5
                * (0..n)
                    .map(|j| v[j] * (0..n).map(|k| d[j * n + k] * v[k]).sum::<f64>())
                    .sum::<f64>();
        }
        Ok(())
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
