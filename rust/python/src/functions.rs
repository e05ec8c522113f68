//! The functions of `varmech._core`.

use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use varmech::diagnostics::{self, EnergyStatistics, InvariantStatistics};
use varmech::integrators::{self, Method, Options};
use varmech::model::MechanicalSystem;
use varmech::scenes::{self, Problem, Scene};
use varmech::{Error, ModelError};

use crate::convert::{self, rows, slice, trajectory_tuple};
use crate::errors::{failure_to_pyerr, to_pyerr};
use crate::model::{ClosureModel, ClosureSystem, NativeModel};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(integrate, m)?)?;
    m.add_function(wrap_pyfunction!(energy, m)?)?;
    m.add_function(wrap_pyfunction!(apply_mass, m)?)?;
    m.add_function(wrap_pyfunction!(momentum, m)?)?;
    m.add_function(wrap_pyfunction!(energy_statistics, m)?)?;
    m.add_function(wrap_pyfunction!(invariant_statistics, m)?)?;
    m.add_function(wrap_pyfunction!(symplecticity_defect, m)?)?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(scene, m)?)?;
    m.add_function(wrap_pyfunction!(nbody, m)?)?;
    Ok(())
}

fn boxed(e: PyErr) -> ModelError {
    Box::new(e)
}

fn model_type_error(model: &Bound<'_, PyAny>) -> PyErr {
    let ty = model.get_type().name().map(|n| n.to_string()).unwrap_or_default();
    PyTypeError::new_err(format!(
        "model: expected a varmech model (a scene's or varmech.MechanicalSystem), got {ty}"
    ))
}

/// Runs `body` with the model as a core system: a native scene with the GIL released, a
/// closure model with it held.
macro_rules! with_system {
    ($py:ident, $model:expr, |$sys:ident| $body:expr) => {{
        if let Ok(native) = $model.cast::<NativeModel>() {
            let $sys = &native.get().scene;
            $py.detach(|| $body)
        } else if let Ok(closure) = $model.cast::<ClosureModel>() {
            let $sys = &ClosureSystem::new($py, closure.get());
            $body
        } else {
            return Err(model_type_error($model));
        }
    }};
}

/// Integrates; returns (t, q, p, steps, force_evaluations, newton_iterations) or raises with
/// `_varmech_partial`.
#[pyfunction]
#[pyo3(signature = (model, q0, p0, *, dt, steps, method, save_every=1, compensated=true, max_energy_error=None, t0=0.0))]
#[allow(clippy::too_many_arguments)]
fn integrate<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q0: PyReadonlyArray1<'py, f64>,
    p0: PyReadonlyArray1<'py, f64>,
    dt: f64,
    steps: usize,
    method: &str,
    save_every: usize,
    compensated: bool,
    max_energy_error: Option<f64>,
    t0: f64,
) -> PyResult<Bound<'py, PyTuple>> {
    let method = Method::from_name(method).map_err(|e| to_pyerr(py, e))?;
    let options = Options {
        dt,
        steps,
        save_every,
        compensated,
        max_energy_error,
        t0,
    };
    let (q0, p0) = (slice("q0", &q0)?.to_vec(), slice("p0", &p0)?.to_vec());
    let result = if let Ok(native) = model.cast::<NativeModel>() {
        let scene: &Scene = &native.get().scene;
        // No Python runs here; the poll takes the GIL only to look for Ctrl-C.
        py.detach(|| {
            integrators::integrate(scene, method, &q0, &p0, &options, || {
                Python::attach(|py| py.check_signals()).map_err(boxed)
            })
        })
    } else if let Ok(closure) = model.cast::<ClosureModel>() {
        let sys = ClosureSystem::new(py, closure.get());
        integrators::integrate(&sys, method, &q0, &p0, &options, || py.check_signals().map_err(boxed))
    } else {
        return Err(model_type_error(model));
    };
    match result {
        Ok(traj) => trajectory_tuple(py, traj),
        Err(failure) => Err(failure_to_pyerr(py, *failure)),
    }
}

/// H(q, p) = ½pᵀM⁻¹p + V(q) for each row of (q, p).
#[pyfunction]
fn energy<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let ((q, n), (p, _)) = (rows("q", &q)?, rows("p", &p)?);
    check_rows(model, n, q.len(), p.len())?;
    let result: Result<Vec<f64>, ModelError> = with_system!(py, model, |sys| {
        q.chunks_exact(n)
            .zip(p.chunks_exact(n))
            .map(|(q, p)| diagnostics::hamiltonian(sys, q, p))
            .collect()
    });
    match result {
        Ok(h) => Ok(PyArray1::from_vec(py, h)),
        Err(e) => Err(match e.downcast::<PyErr>() {
            Ok(err) => *err,
            Err(e) => PyValueError::new_err(e.to_string()),
        }),
    }
}

/// Checks that q and p are (N, n) arrays of the model's dimension n.
fn check_rows(model: &Bound<'_, PyAny>, n: usize, q_len: usize, p_len: usize) -> PyResult<()> {
    let dim = if let Ok(native) = model.cast::<NativeModel>() {
        native.get().scene.dim()
    } else if let Ok(closure) = model.cast::<ClosureModel>() {
        closure.get().dim()
    } else {
        return Err(model_type_error(model));
    };
    if n != dim || q_len != p_len {
        return Err(PyValueError::new_err(format!("q, p: must both have shape (N, {dim})")));
    }
    Ok(())
}

/// q̇ = M⁻¹p for each row of `x` (`inverse`), or p = Mq̇.
#[pyfunction]
fn apply_mass<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    x: PyReadonlyArray2<'py, f64>,
    inverse: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (x, n) = rows("x", &x)?;
    check_rows(model, n, x.len(), x.len())?;
    let y: Vec<f64> = with_system!(py, model, |sys| {
        let mut y = vec![0.0; x.len()];
        for (x, y) in x.chunks_exact(n).zip(y.chunks_exact_mut(n)) {
            if inverse {
                sys.mass().velocity(x, y)
            } else {
                sys.mass().momentum(x, y)
            }
        }
        y
    });
    convert::matrix(py, y, n)
}

/// J = p·ξ(q) of a generator spec for each row of (q, p).
#[pyfunction]
fn momentum<'py>(
    py: Python<'py>,
    generator: (String, usize, usize),
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let g = convert::generator(generator)?;
    let ((q, n), (p, _)) = (rows("q", &q)?, rows("p", &p)?);
    g.check(n).map_err(|e| to_pyerr(py, e))?;
    let j = q
        .chunks_exact(n.max(1))
        .zip(p.chunks_exact(n.max(1)))
        .map(|(q, p)| g.momentum(q, p))
        .collect();
    Ok(PyArray1::from_vec(py, j))
}

/// The energy statistics of a series, as a dict.
#[pyfunction]
fn energy_statistics<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    h: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let (t, h) = (slice("t", &t)?, slice("energy", &h)?);
    if t.len() != h.len() || t.is_empty() {
        return Err(PyValueError::new_err("energy: needs one value per time, at least one"));
    }
    let s = EnergyStatistics::new(t, h);
    let d = PyDict::new(py);
    d.set_item("initial", s.initial)?;
    d.set_item("max_error", s.max_error)?;
    d.set_item("band", s.band)?;
    d.set_item("max_error_first_tenth", s.max_error_first_tenth)?;
    d.set_item("max_error_last_tenth", s.max_error_last_tenth)?;
    d.set_item("drift_rate", s.drift_rate)?;
    d.set_item("drift_rate_stderr", s.drift_rate_stderr)?;
    d.set_item("verdict", s.verdict.to_string())?;
    d.set_item("noise_floor", EnergyStatistics::NOISE_FLOOR)?;
    Ok(d)
}

/// (initial, max_abs_error, max_rel_error) of a conserved quantity's series.
#[pyfunction]
fn invariant_statistics(values: PyReadonlyArray1<'_, f64>) -> PyResult<(f64, f64, f64)> {
    let s = InvariantStatistics::new(slice("values", &values)?);
    Ok((s.initial, s.max_abs_error, s.max_rel_error))
}

/// ‖ΨᵀJΨ − J‖_F of one step.
#[pyfunction]
fn symplecticity_defect<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    method: &str,
    q: PyReadonlyArray1<'py, f64>,
    p: PyReadonlyArray1<'py, f64>,
    dt: f64,
) -> PyResult<f64> {
    let method = Method::from_name(method).map_err(|e| to_pyerr(py, e))?;
    let (q, p) = (slice("q", &q)?, slice("p", &p)?);
    let result = with_system!(py, model, |sys| diagnostics::symplecticity_defect(
        sys, method, q, p, dt
    ));
    result.map_err(|e| to_pyerr(py, e))
}

/// Every method's facts, as dicts.
#[pyfunction]
fn methods(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    Method::ALL
        .iter()
        .map(|m| {
            let i = m.info();
            let d = PyDict::new(py);
            d.set_item("name", i.name)?;
            d.set_item("order", i.order)?;
            d.set_item("stages", i.stages)?;
            d.set_item("force_evaluations", i.force_evaluations)?;
            d.set_item("implicit", i.implicit)?;
            d.set_item("symplectic", i.symplectic)?;
            d.set_item("symmetric", i.symmetric)?;
            d.set_item("h_omega_max", i.h_omega_max)?;
            d.set_item("reference", i.reference)?;
            Ok(d)
        })
        .collect()
}

type SceneTuple<'py> = (
    NativeModel,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    f64,
    Option<Bound<'py, PyTuple>>,
);

fn scene_tuple<'py, S>(
    py: Python<'py>,
    p: Problem<S>,
    wrap: fn(S) -> Scene,
    name: &'static str,
) -> PyResult<SceneTuple<'py>> {
    let reference = match p.reference {
        Some((r, source)) => {
            Some((r.t, PyArray1::from_vec(py, r.q), PyArray1::from_vec(py, r.p), source).into_pyobject(py)?)
        }
        None => None,
    };
    Ok((
        NativeModel::new(wrap(p.system), name),
        PyArray1::from_vec(py, p.initial.q),
        PyArray1::from_vec(py, p.initial.p),
        p.t_end,
        reference,
    ))
}

/// A native scene by name: (model, q0, p0, t_end, reference (t, q, p, source) or None).
#[pyfunction]
#[pyo3(signature = (name, *, e=0.6, omega=1.0))]
fn scene<'py>(py: Python<'py>, name: &str, e: f64, omega: f64) -> PyResult<SceneTuple<'py>> {
    let invalid = |err: Error| to_pyerr(py, err);
    match name {
        "harmonic_oscillator" => scene_tuple(
            py,
            scenes::HarmonicOscillator::problem(omega).map_err(invalid)?,
            Scene::HarmonicOscillator,
            "harmonic_oscillator",
        ),
        "pendulum" => scene_tuple(py, scenes::Pendulum::problem(), Scene::Pendulum, "pendulum"),
        "kepler" => scene_tuple(
            py,
            scenes::Kepler::problem(e).map_err(invalid)?,
            Scene::Kepler,
            "kepler",
        ),
        "henon_heiles" => scene_tuple(py, scenes::HenonHeiles::problem(), Scene::HenonHeiles, "henon_heiles"),
        "fermi_pasta_ulam" => scene_tuple(
            py,
            scenes::FermiPastaUlam::problem(),
            Scene::FermiPastaUlam,
            "fermi_pasta_ulam",
        ),
        "outer_solar_system" => scene_tuple(
            py,
            scenes::NBody::outer_solar_system(),
            Scene::NBody,
            "outer_solar_system",
        ),
        _ => Err(PyValueError::new_err(format!("name: unknown scene {name:?}"))),
    }
}

/// A native gravitational N-body model in 3 dimensions.
#[pyfunction]
#[pyo3(name = "nbody")]
fn nbody(py: Python<'_>, g: f64, masses: Vec<f64>) -> PyResult<NativeModel> {
    let system = scenes::NBody::new(g, masses).map_err(|e| to_pyerr(py, e))?;
    Ok(NativeModel::new(Scene::NBody(system), "nbody"))
}
