//! The core's scene catalogue, as Python reads it: [`scene`] builds a scene by name with
//! keyword parameters, [`catalogue`] lists the scenes; and [`nbody`], a custom N-body model.

use numpy::PyArray1;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use varmech::scenes::{self, Problem, Scene, SceneModel, Setup, CATALOGUE};

use crate::errors::to_pyerr;
use crate::native::NativeModel;

/// The parameters' values by name: whole-number parameters as ints.
fn parameters<'py>(py: Python<'py>, setup: &Setup) -> PyResult<Bound<'py, PyDict>> {
    let values = PyDict::new(py);
    for parameter in setup.entry().parameters {
        let value = setup.get(parameter.name).unwrap_or(parameter.default);
        if parameter.integer {
            values.set_item(parameter.name, value as u64)?;
        } else {
            values.set_item(parameter.name, value)?;
        }
    }
    Ok(values)
}

/// One scene of the catalogue: its name, its parameters with their defaults, and its
/// description with them.
#[pyclass(frozen, name = "CatalogueEntry", module = "varmech._core")]
pub struct PyCatalogueEntry(Setup);

#[pymethods]
impl PyCatalogueEntry {
    #[getter]
    fn name(&self) -> &'static str {
        self.0.entry().name
    }

    /// The defaults of the parameters, by name.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        parameters(py, &self.0)
    }

    #[getter]
    fn description(&self) -> String {
        self.0.description()
    }

    fn __repr__(&self) -> String {
        format!("CatalogueEntry({:?})", self.0.entry().name)
    }
}

/// A scene's reference solution at time `t`, exact or published, and where it comes from.
#[pyclass(frozen, get_all, module = "varmech._core")]
pub struct SceneReference {
    t: f64,
    q: Py<PyArray1<f64>>,
    p: Py<PyArray1<f64>>,
    source: &'static str,
}

/// A scene built from the catalogue: the model with its initial state (`q0`, `p0`), horizon
/// `t_end` and reference, and from the catalogue its description, step `dt`, invariants at
/// t = 0 and the values of its parameters.
#[pyclass(frozen, module = "varmech._core")]
pub struct SceneRecord {
    setup: Setup,
    #[pyo3(get)]
    model: Py<NativeModel>,
    #[pyo3(get)]
    q0: Py<PyArray1<f64>>,
    #[pyo3(get)]
    p0: Py<PyArray1<f64>>,
    #[pyo3(get)]
    t_end: f64,
    #[pyo3(get)]
    reference: Option<Py<SceneReference>>,
}

impl SceneRecord {
    fn new(py: Python<'_>, setup: Setup, problem: Problem<SceneModel>) -> PyResult<Self> {
        let reference = match problem.reference {
            Some((state, source)) => Some(Py::new(
                py,
                SceneReference {
                    t: state.t,
                    q: PyArray1::from_vec(py, state.q).unbind(),
                    p: PyArray1::from_vec(py, state.p).unbind(),
                    source,
                },
            )?),
            None => None,
        };
        Ok(SceneRecord {
            model: Py::new(py, NativeModel::new(problem.system, setup.entry().name))?,
            q0: PyArray1::from_vec(py, problem.initial.q).unbind(),
            p0: PyArray1::from_vec(py, problem.initial.p).unbind(),
            t_end: problem.t_end,
            reference,
            setup,
        })
    }
}

#[pymethods]
impl SceneRecord {
    #[getter]
    fn name(&self) -> &'static str {
        self.setup.entry().name
    }

    #[getter]
    fn description(&self) -> String {
        self.setup.description()
    }

    #[getter]
    fn dt(&self) -> f64 {
        self.setup.dt()
    }

    /// The conserved quantities by name, with their values at t = 0.
    #[getter]
    fn invariants<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let invariants = PyDict::new(py);
        for (name, value) in self.setup.invariants() {
            invariants.set_item(name, value)?;
        }
        Ok(invariants)
    }

    /// The values of the parameters the scene was built with, by name.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        parameters(py, &self.setup)
    }

    fn __repr__(&self) -> String {
        format!("SceneRecord({:?})", self.setup.entry().name)
    }
}

/// The catalogue scene `name` with its parameters set by keyword (the others at their
/// defaults); ValueError for an unknown scene or parameter, or a value out of range.
#[pyfunction]
#[pyo3(signature = (name, **parameters))]
fn scene(py: Python<'_>, name: &str, parameters: Option<&Bound<'_, PyDict>>) -> PyResult<SceneRecord> {
    let mut setup = scenes::lookup(name).map_err(|e| to_pyerr(py, e))?.setup();
    for (key, value) in parameters.into_iter().flat_map(|d| d.iter()) {
        let key: String = key.extract()?;
        let value: f64 = value
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("{key}: must be a number")))?;
        setup.set(&key, value).map_err(|e| to_pyerr(py, e))?;
    }
    let problem = setup.build().map_err(|e| to_pyerr(py, e))?;
    SceneRecord::new(py, setup, problem)
}

/// Every scene of the catalogue, in the order of the tour, with its defaults.
#[pyfunction]
fn catalogue() -> Vec<PyCatalogueEntry> {
    CATALOGUE.iter().map(|entry| PyCatalogueEntry(entry.setup())).collect()
}

/// A native gravitational N-body model in 3 dimensions (not a catalogue scene: its masses are
/// the caller's).
#[pyfunction]
fn nbody(py: Python<'_>, g: f64, masses: Vec<f64>) -> PyResult<NativeModel> {
    let system = scenes::NBody::new(g, masses).map_err(|e| to_pyerr(py, e))?;
    Ok(NativeModel::new(SceneModel::Mechanical(Scene::NBody(system)), "nbody"))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<NativeModel>()?;
    m.add_class::<PyCatalogueEntry>()?;
    m.add_class::<SceneRecord>()?;
    m.add_class::<SceneReference>()?;
    add_functions!(m, [scene, catalogue, nbody]);
    Ok(())
}
