//! Models seen from Python: native scenes, and Python closures adapted to the core's
//! [`MechanicalSystem`] trait.

use std::cell::RefCell;

use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use varmech::model::{finite_difference, Generator, Mass, MechanicalSystem};
use varmech::scenes::Scene;
use varmech::ModelError;

use crate::convert;

/// A native scene: every evaluation runs in Rust, with the GIL released.
#[pyclass(frozen, module = "varmech._core")]
pub struct NativeModel {
    pub scene: Scene,
    name: &'static str,
}

impl NativeModel {
    pub fn new(scene: Scene, name: &'static str) -> Self {
        NativeModel { scene, name }
    }
}

#[pymethods]
impl NativeModel {
    #[getter]
    fn dim(&self) -> usize {
        self.scene.dim()
    }

    #[getter]
    fn name(&self) -> &'static str {
        self.name
    }

    /// (G, masses) of an N-body scene, None for the others.
    #[getter]
    fn gravity(&self) -> Option<(f64, Vec<f64>)> {
        match &self.scene {
            Scene::NBody(s) => Some((s.gravitational_constant(), s.masses().to_vec())),
            _ => None,
        }
    }

    /// The declared symmetries, as (kind, axis or index, spatial_dim, name).
    #[getter]
    fn symmetries(&self) -> Vec<(&'static str, usize, usize, String)> {
        self.scene
            .symmetries()
            .into_iter()
            .map(convert::generator_spec)
            .collect()
    }

    fn __repr__(&self) -> String {
        format!("NativeModel({:?}, dim={})", self.name, self.scene.dim())
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
        if dim == 0 {
            return Err(PyValueError::new_err("dim: must be at least 1"));
        }
        for (name, f) in [("potential", Some(&potential)), ("gradient", gradient.as_ref())] {
            if let Some(f) = f {
                if !f.is_callable() {
                    return Err(PyTypeError::new_err(format!("{name}: must be callable")));
                }
            }
        }
        let mass = convert::mass(mass)?;
        if let Some(n) = mass.dim().filter(|n| *n != dim) {
            return Err(PyValueError::new_err(format!(
                "mass: has dimension {n}, the model has dim = {dim}"
            )));
        }
        let symmetries = symmetries
            .into_iter()
            .map(convert::generator)
            .collect::<PyResult<Vec<_>>>()?;
        for g in &symmetries {
            g.check(dim).map_err(|e| PyValueError::new_err(e.to_string()))?;
        }
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

    fn __repr__(&self) -> String {
        format!("ClosureModel(dim={})", self.dim)
    }
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

fn boxed(e: PyErr) -> ModelError {
    Box::new(e)
}

impl MechanicalSystem for ClosureSystem<'_, '_> {
    fn dim(&self) -> usize {
        self.model.dim
    }

    fn mass(&self) -> &Mass {
        &self.model.mass
    }

    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        let out = self
            .potential
            .call1((PyArray1::from_slice(self.py, q),))
            .map_err(boxed)?;
        out.extract::<f64>().map_err(|_| {
            let ty = out.get_type().name().map(|n| n.to_string()).unwrap_or_default();
            boxed(PyTypeError::new_err(format!(
                "potential(q) must return a float, got {ty}"
            )))
        })
    }

    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        let Some(gradient) = &self.gradient else {
            let mut work = self.work.borrow_mut();
            return finite_difference::central_gradient(|x| self.potential(x), q, &mut work, grad);
        };
        let out = gradient.call1((PyArray1::from_slice(self.py, q),)).map_err(boxed)?;
        let n = grad.len();
        let wrong_length = |len: usize| {
            boxed(PyValueError::new_err(format!(
                "gradient(q) returned {len} values, expected {n} (one per coordinate)"
            )))
        };
        // The fast path: a float64 numpy array, read in place.
        if let Ok(arr) = out.cast::<PyArray1<f64>>() {
            let ro = arr.readonly();
            let view = ro.as_array();
            if view.len() != n {
                return Err(wrong_length(view.len()));
            }
            grad.iter_mut().zip(view.iter()).for_each(|(g, v)| *g = *v);
            return Ok(());
        }
        let values: Vec<f64> = out.extract().map_err(|_| {
            let ty = out.get_type().name().map(|n| n.to_string()).unwrap_or_default();
            let shape = out
                .getattr("shape")
                .map(|s| format!(" of shape {s}"))
                .unwrap_or_default();
            boxed(PyTypeError::new_err(format!(
                "gradient(q) must return a 1-d array of {n} floats, got {ty}{shape}"
            )))
        })?;
        if values.len() != n {
            return Err(wrong_length(values.len()));
        }
        grad.copy_from_slice(&values);
        Ok(())
    }

    fn symmetries(&self) -> Vec<Generator> {
        self.model.symmetries.clone()
    }
}
