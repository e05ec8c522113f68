//! The functions of `varmech._core`.

use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use varmech::diagnostics::{self, EnergyStatistics, InvariantStatistics};
use varmech::discrete::{DiscreteLagrangian, Midpoint, Trapezoidal};
use varmech::integrators::{self, Dynamics, General, Method, NewtonOptions, Options};
use varmech::model::{Constrained, Natural, Routhian};
use varmech::scenes::{self, LagrangianScene, LinkedMasses, Problem, Scene};
use varmech::ModelError;

use crate::convert::{self, rows, slice, trajectory_tuple};
use crate::errors::{failure_to_pyerr, to_pyerr};
use crate::model::{
    ClosureConstrained, ClosureConstraints, ClosureLagrangian, ClosureLagrangianSystem, ClosureModel, ClosureNatural,
    ClosureNaturalSystem, ClosureSystem, ConstrainedSystem, Native, NativeModel, RouthModel,
};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(integrate, m)?)?;
    m.add_function(wrap_pyfunction!(energy, m)?)?;
    m.add_function(wrap_pyfunction!(derivative, m)?)?;
    m.add_function(wrap_pyfunction!(momentum, m)?)?;
    m.add_function(wrap_pyfunction!(energy_statistics, m)?)?;
    m.add_function(wrap_pyfunction!(invariant_statistics, m)?)?;
    m.add_function(wrap_pyfunction!(symplecticity_defect, m)?)?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(scene, m)?)?;
    m.add_function(wrap_pyfunction!(nbody, m)?)?;
    m.add_function(wrap_pyfunction!(constraint_residuals, m)?)?;
    m.add_function(wrap_pyfunction!(project, m)?)?;
    m.add_function(wrap_pyfunction!(routh, m)?)?;
    m.add_function(wrap_pyfunction!(cyclic_increments, m)?)?;
    m.add_function(wrap_pyfunction!(amended_potential, m)?)?;
    m.add_function(wrap_pyfunction!(cyclic_velocity, m)?)?;
    Ok(())
}

fn boxed(e: PyErr) -> ModelError {
    Box::new(e)
}

fn model_type_error(model: &Bound<'_, PyAny>) -> PyErr {
    let ty = model.get_type().name().map(|n| n.to_string()).unwrap_or_default();
    PyTypeError::new_err(format!(
        "model: expected a varmech model (a scene's, MechanicalSystem or Lagrangian), got {ty}"
    ))
}

/// Runs `body` with `sys` bound to the model as an [`Dynamics`], and `poll` to the Ctrl-C
/// check: native models with the GIL released (the poll takes it back briefly), closure models
/// with it held. A Routh-reduced model is the Routhian of its full model, built in place.
macro_rules! with_system {
    ($py:ident, $model:expr, |$sys:ident, $poll:ident| $body:expr) => {{
        if let Ok(reduced) = $model.cast::<RouthModel>() {
            let reduced = reduced.get();
            with_full_system!($py, reduced.full.bind($py), |full, $poll| {
                let routhian = reduced.routhian(full.as_lagrangian());
                let $sys = &General(&routhian);
                $body
            })
        } else {
            with_full_system!($py, $model, |$sys, $poll| $body)
        }
    }};
}

/// [`with_system`] for the models that are not reduced.
macro_rules! with_full_system {
    ($py:ident, $model:expr, |$sys:ident, $poll:ident| $body:expr) => {{
        if let Ok(native) = $model.cast::<NativeModel>() {
            match &native.get().native {
                Native::Mechanical(scene) => $py.detach(|| {
                    let $sys: &Scene = scene;
                    let $poll = || Python::attach(|py| py.check_signals()).map_err(boxed);
                    $body
                }),
                Native::General(scene) => $py.detach(|| {
                    let $sys = &General::<LagrangianScene>(scene);
                    let $poll = || Python::attach(|py| py.check_signals()).map_err(boxed);
                    $body
                }),
                Native::Constrained(scene) => $py.detach(|| {
                    let $sys: &LinkedMasses = scene;
                    let $poll = || Python::attach(|py| py.check_signals()).map_err(boxed);
                    $body
                }),
                Native::ConstrainedGeneral(scene) => $py.detach(|| {
                    let $sys = &Constrained {
                        system: General(&scene.system),
                        constraints: scene.constraints.clone(),
                    };
                    let $poll = || Python::attach(|py| py.check_signals()).map_err(boxed);
                    $body
                }),
            }
        } else if let Ok(closure) = $model.cast::<ClosureModel>() {
            let $sys = &ClosureSystem::new($py, closure.get());
            let $poll = || $py.check_signals().map_err(boxed);
            $body
        } else if let Ok(closure) = $model.cast::<ClosureConstrained>() {
            let closure = closure.get();
            let $poll = || $py.check_signals().map_err(boxed);
            match closure.system() {
                ConstrainedSystem::Separable(system) => {
                    let $sys = &Constrained {
                        system: ClosureSystem::new($py, system.get()),
                        constraints: ClosureConstraints::new($py, closure),
                    };
                    $body
                }
                ConstrainedSystem::Natural(system) => {
                    let natural = Natural::new(ClosureNaturalSystem::new($py, system.get()));
                    let $sys = &Constrained {
                        system: General(&natural),
                        constraints: ClosureConstraints::new($py, closure),
                    };
                    $body
                }
            }
        } else if let Ok(closure) = $model.cast::<ClosureNatural>() {
            let natural = Natural::new(ClosureNaturalSystem::new($py, closure.get()));
            let $sys = &General(&natural);
            let $poll = || $py.check_signals().map_err(boxed);
            $body
        } else if let Ok(closure) = $model.cast::<ClosureLagrangian>() {
            let closure = ClosureLagrangianSystem::new($py, closure.get());
            let $sys = &General(&closure);
            let $poll = || $py.check_signals().map_err(boxed);
            $body
        } else {
            return Err(model_type_error($model));
        }
    }};
}

/// A model's error as the Python exception it stands for.
fn model_error(e: ModelError) -> PyErr {
    match e.downcast::<PyErr>() {
        Ok(err) => *err,
        Err(e) => PyValueError::new_err(e.to_string()),
    }
}

/// Integrates; returns (t, q, p, steps, force_evaluations, newton, work) or raises with
/// `_varmech_partial` (`newton`, `work`: cumulative Newton iterations and work of the forces at
/// each saved state).
#[pyfunction]
#[pyo3(signature = (model, q0, p0, *, dt, steps, method, save_every=1, compensated=true, max_energy_error=None, t0=0.0, newton_tolerance=1e-14, newton_max_iterations=50))]
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
    newton_tolerance: f64,
    newton_max_iterations: usize,
) -> PyResult<Bound<'py, PyTuple>> {
    let method = Method::from_name(method).map_err(|e| to_pyerr(py, e))?;
    let newton = NewtonOptions {
        tolerance: newton_tolerance,
        max_iterations: newton_max_iterations,
    };
    let options = Options {
        dt,
        steps,
        save_every,
        compensated,
        max_energy_error,
        t0,
        newton,
    };
    let (q0, p0) = (slice("q0", &q0)?.to_vec(), slice("p0", &p0)?.to_vec());
    let result = with_system!(py, model, |sys, poll| integrators::integrate(
        sys, method, &q0, &p0, &options, poll
    ));
    match result {
        Ok(traj) => trajectory_tuple(py, traj),
        Err(failure) => Err(failure_to_pyerr(py, *failure)),
    }
}

/// Times, positions and a second quantity per state, as flat rows, with the dimension n.
type States<'a> = (&'a [f64], &'a [f64], &'a [f64], usize);

/// Checks that t, q and x are N times, and (N, n) arrays for the model's n, and returns them.
fn states<'a>(
    py: Python<'_>,
    model: &Bound<'_, PyAny>,
    t: &'a PyReadonlyArray1<'_, f64>,
    q: &'a PyReadonlyArray2<'_, f64>,
    x: &'a PyReadonlyArray2<'_, f64>,
) -> PyResult<States<'a>> {
    let dim = with_system!(py, model, |sys, _poll| sys.dim());
    let (t, (q, n), (x, m)) = (slice("t", t)?, rows("q", q)?, rows("x", x)?);
    if n != dim || m != dim || q.len() != x.len() || q.len() != t.len() * dim {
        return Err(PyValueError::new_err(format!(
            "t, q: need N times and two (N, {dim}) arrays of states"
        )));
    }
    Ok((t, q, x, dim))
}

/// Two arrays, as the constraint functions return them.
type ArrayPair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

fn unconstrained() -> PyErr {
    PyValueError::new_err("model: has no holonomic constraints")
}

/// (|g(q)|∞, |G(q)M⁻¹p|∞) at each state of a constrained model.
#[pyfunction]
fn constraint_residuals<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
) -> PyResult<ArrayPair<'py>> {
    let n = with_system!(py, model, |sys, _poll| sys.dim());
    let ((q, nq), (p, np)) = (rows("q", &q)?, rows("p", &p)?);
    if nq != n || np != n || q.len() != p.len() {
        return Err(PyValueError::new_err(format!(
            "q, p: need two (N, {n}) arrays of states"
        )));
    }
    let result: Option<Result<Vec<(f64, f64)>, ModelError>> = with_system!(py, model, |sys, _poll| {
        q.chunks_exact(n)
            .zip(p.chunks_exact(n))
            .map(|(q, p)| sys.constraint_residuals(q, p))
            .collect::<Option<Result<Vec<(f64, f64)>, ModelError>>>()
    });
    let (position, velocity) = result
        .ok_or_else(unconstrained)?
        .map_err(model_error)?
        .into_iter()
        .unzip();
    Ok((PyArray1::from_vec(py, position), PyArray1::from_vec(py, velocity)))
}

/// The nearest consistent state (q on the constraints, p on the hidden constraint).
#[pyfunction]
fn project<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q0: PyReadonlyArray1<'py, f64>,
    p0: PyReadonlyArray1<'py, f64>,
) -> PyResult<ArrayPair<'py>> {
    let (q0, p0) = (slice("q0", &q0)?, slice("p0", &p0)?);
    let result = with_system!(py, model, |sys, _poll| Dynamics::project(sys, q0, p0));
    let (q, p) = result.ok_or_else(unconstrained)?.map_err(|e| to_pyerr(py, e))?;
    Ok((PyArray1::from_vec(py, q), PyArray1::from_vec(py, p)))
}

/// The energy function E = p·q̇ − L (= ½pᵀM⁻¹p + V for mechanical systems) at each state.
#[pyfunction]
fn energy<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (t, q, p, n) = states(py, model, &t, &q, &p)?;
    let result: Result<Vec<f64>, ModelError> = with_system!(py, model, |sys, _poll| {
        let l = sys.as_lagrangian();
        t.iter()
            .zip(q.chunks_exact(n).zip(p.chunks_exact(n)))
            .map(|(t, (q, p))| l.energy(q, p, *t))
            .collect()
    });
    Ok(PyArray1::from_vec(py, result.map_err(model_error)?))
}

/// A first derivative of L at each state (t, q, x): `"momentum"`, p = ∂L/∂q̇(q, x, t) from
/// velocities x (Mq̇ for mechanical systems); `"velocity"`, the inverse Legendre transform,
/// q̇ with ∂L/∂q̇ = x from momenta x (M⁻¹p); `"dl_dq"`, ∂L/∂q(q, x, t) from velocities x.
#[pyfunction]
fn derivative<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    what: &str,
    t: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    x: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    if !matches!(what, "momentum" | "velocity" | "dl_dq") {
        return Err(PyValueError::new_err(format!(
            "what: expected \"momentum\", \"velocity\" or \"dl_dq\", got {what:?}"
        )));
    }
    let (t, q, x, n) = states(py, model, &t, &q, &x)?;
    let result: Result<Vec<f64>, ModelError> = with_system!(py, model, |sys, _poll| {
        let l = sys.as_lagrangian();
        let mut y = vec![0.0; x.len()];
        let mut rows = t
            .iter()
            .zip(q.chunks_exact(n).zip(x.chunks_exact(n)))
            .zip(y.chunks_exact_mut(n));
        rows.try_for_each(|((t, (q, x)), y)| match what {
            "velocity" => l.velocity(q, x, *t, y),
            "momentum" => l.dl_dv(q, x, *t, y),
            _ => l.dl_dq(q, x, *t, y),
        })
        .map(|()| y)
    });
    convert::matrix(py, result.map_err(model_error)?, n)
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
    let result = with_system!(py, model, |sys, _poll| diagnostics::symplecticity_defect(
        sys, method, q, p, dt
    ));
    result.map_err(|e| to_pyerr(py, e))
}

/// Every method's facts, as dicts.
#[pyfunction]
fn methods(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    Method::ALL
        .iter()
        .chain(&Method::CONSTRAINED)
        .map(|m| {
            let i = m.info();
            let d = PyDict::new(py);
            d.set_item("name", i.name)?;
            d.set_item("order", i.order)?;
            d.set_item("stages", i.stages)?;
            d.set_item("force_evaluations", i.force_evaluations)?;
            d.set_item("implicit", i.implicit)?;
            d.set_item("constrained", i.constrained)?;
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
    wrap: impl FnOnce(S) -> Native,
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

/// A native scene by name: (model, q0, p0, t_end, reference (t, q, p, source) or None). The
/// keywords are the parameters of the scenes that take them: `e` (kepler, kepler_polar), `omega`
/// (harmonic_oscillator), `b` (charged_particle), `gamma`, `amplitude` and `drive`
/// (damped_driven_pendulum), `links` (planar_chain).
#[pyfunction]
#[pyo3(signature = (name, *, e=0.6, omega=1.0, b=1.0, gamma=0.5, amplitude=1.5, drive=2.0 / 3.0, links=8))]
#[allow(clippy::too_many_arguments)]
fn scene<'py>(
    py: Python<'py>,
    name: &str,
    e: f64,
    omega: f64,
    b: f64,
    gamma: f64,
    amplitude: f64,
    drive: f64,
    links: usize,
) -> PyResult<SceneTuple<'py>> {
    let mech = |s| Native::Mechanical(s);
    let err = |e| to_pyerr(py, e);
    match name {
        "harmonic_oscillator" => {
            let p = scenes::HarmonicOscillator::problem(omega).map_err(err)?;
            scene_tuple(py, p, |s| mech(Scene::HarmonicOscillator(s)), "harmonic_oscillator")
        }
        "pendulum" => scene_tuple(
            py,
            scenes::Pendulum::problem(),
            |s| mech(Scene::Pendulum(s)),
            "pendulum",
        ),
        "kepler" => scene_tuple(
            py,
            scenes::Kepler::problem(e).map_err(err)?,
            |s| mech(Scene::Kepler(s)),
            "kepler",
        ),
        "henon_heiles" => scene_tuple(
            py,
            scenes::HenonHeiles::problem(),
            |s| mech(Scene::HenonHeiles(s)),
            "henon_heiles",
        ),
        "fermi_pasta_ulam" => scene_tuple(
            py,
            scenes::FermiPastaUlam::problem(),
            |s| mech(Scene::FermiPastaUlam(s)),
            "fermi_pasta_ulam",
        ),
        "outer_solar_system" => scene_tuple(
            py,
            scenes::NBody::outer_solar_system(),
            |s| mech(Scene::NBody(s)),
            "outer_solar_system",
        ),
        "double_pendulum" => scene_tuple(
            py,
            scenes::DoublePendulum::problem(),
            |s| Native::General(LagrangianScene::DoublePendulum(s)),
            "double_pendulum",
        ),
        "spherical_pendulum" => scene_tuple(
            py,
            scenes::SphericalPendulum::problem(),
            |s| Native::General(LagrangianScene::SphericalPendulum(s)),
            "spherical_pendulum",
        ),
        "charged_particle" => scene_tuple(
            py,
            scenes::ChargedParticle::uniform_field(b).map_err(err)?,
            |s| Native::General(LagrangianScene::ChargedParticle(s)),
            "charged_particle",
        ),
        "charged_particle_nonuniform" => scene_tuple(
            py,
            scenes::ChargedParticle::nonuniform_field(),
            |s| Native::General(LagrangianScene::ChargedParticle(s)),
            "charged_particle_nonuniform",
        ),
        "damped_driven_pendulum" => scene_tuple(
            py,
            scenes::DampedDrivenPendulum::problem(gamma, amplitude, drive).map_err(err)?,
            |s| Native::General(LagrangianScene::DampedDrivenPendulum(s)),
            "damped_driven_pendulum",
        ),
        "heavy_top" => scene_tuple(
            py,
            scenes::HeavyTop::problem(),
            |s| Native::General(LagrangianScene::HeavyTop(s)),
            "heavy_top",
        ),
        "kepler_polar" => scene_tuple(
            py,
            scenes::KeplerPolar::problem(e).map_err(err)?,
            |s| Native::General(LagrangianScene::KeplerPolar(s)),
            "kepler_polar",
        ),
        "cartesian_pendulum" => scene_tuple(
            py,
            scenes::cartesian_pendulum(),
            Native::Constrained,
            "cartesian_pendulum",
        ),
        "cartesian_spherical_pendulum" => scene_tuple(
            py,
            scenes::cartesian_spherical_pendulum(),
            Native::Constrained,
            "cartesian_spherical_pendulum",
        ),
        "rigid_body" => scene_tuple(
            py,
            scenes::RigidBody::problem(),
            Native::ConstrainedGeneral,
            "rigid_body",
        ),
        "planar_chain" => scene_tuple(
            py,
            scenes::planar_chain(links).map_err(err)?,
            Native::Constrained,
            "planar_chain",
        ),
        _ => Err(PyValueError::new_err(format!("name: unknown scene {name:?}"))),
    }
}

/// A native gravitational N-body model in 3 dimensions.
#[pyfunction]
fn nbody(py: Python<'_>, g: f64, masses: Vec<f64>) -> PyResult<NativeModel> {
    let system = scenes::NBody::new(g, masses).map_err(|e| to_pyerr(py, e))?;
    Ok(NativeModel::new(Native::Mechanical(Scene::NBody(system)), "nbody"))
}

/// The model as a [`RouthModel`], or a TypeError.
fn reduced<'a>(model: &'a Bound<'_, PyAny>) -> PyResult<&'a RouthModel> {
    model
        .cast::<RouthModel>()
        .map(|m| m.get())
        .map_err(|_| PyTypeError::new_err("model: expected a Routh-reduced model (varmech.routh)"))
}

/// Runs `body` with `r` bound to the [`Routhian`] of a reduced model.
macro_rules! with_routhian {
    ($py:ident, $reduced:expr, |$r:ident| $body:expr) => {{
        let reduced: &RouthModel = $reduced;
        with_full_system!($py, reduced.full.bind($py), |full, _poll| {
            let $r = reduced.routhian(full.as_lagrangian());
            $body
        })
    }};
}

/// The Routh-reduced model of `full` that ignores the coordinates `cyclic` at momenta
/// `momenta`; `reference` holds values for those coordinates, which L does not see.
#[pyfunction]
fn routh(
    py: Python<'_>,
    full: &Bound<'_, PyAny>,
    cyclic: Vec<usize>,
    momenta: Vec<f64>,
    reference: Vec<f64>,
) -> PyResult<RouthModel> {
    if full.cast::<RouthModel>().is_ok() {
        return Err(PyValueError::new_err(
            "model: is reduced already; ignore all the cyclic coordinates of the full model at once",
        ));
    }
    let constraints = full
        .getattr("constraints")
        .and_then(|c| c.extract::<usize>())
        .unwrap_or(0);
    if constraints > 0 {
        return Err(PyValueError::new_err(
            "model: has holonomic constraints; Routh reduction needs generalized coordinates",
        ));
    }
    use varmech::model::Lagrangian;
    let result = with_full_system!(py, full, |sys, _poll| Routhian::new(
        sys.as_lagrangian(),
        &cyclic,
        &momenta,
        &reference
    )
    .map(|r| (r.dim(), r.is_time_dependent())));
    let (dim, time_dependent) = result.map_err(|e| to_pyerr(py, e))?;
    Ok(RouthModel {
        full: full.clone().unbind(),
        cyclic,
        momenta,
        reference,
        dim,
        time_dependent,
    })
}

/// The increments of the ignored coordinates between consecutive states (t, x, p) of a reduced
/// trajectory, shape (N − 1, m): by the discrete momentum equation of `rule` ("midpoint" or
/// "trapezoid"), or by Gauss quadrature along the Hermite interpolant (`rule` None).
#[pyfunction]
fn cyclic_increments<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
    rule: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let reduced = reduced(model)?;
    let (t, x, p, _) = states(py, model, &t, &x, &p)?;
    let rule = match rule {
        None => None,
        Some("midpoint") => Some(Midpoint.quadrature()),
        Some("trapezoid") => Some(Trapezoidal.quadrature()),
        Some(other) => {
            return Err(PyValueError::new_err(format!(
                "rule: expected \"midpoint\", \"trapezoid\" or None, got {other:?}"
            )))
        }
    };
    let result = with_routhian!(py, reduced, |r| r.cyclic_increments(t, x, p, rule));
    convert::matrix(py, result.map_err(model_error)?, reduced.cyclic.len())
}

/// The amended potential V_μ(x, t) = −R(x, 0, t) at each state, shape (N,).
#[pyfunction]
fn amended_potential<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let reduced = reduced(model)?;
    let (t, x, _, n) = states(py, model, &t, &x, &x)?;
    let result: Result<Vec<f64>, ModelError> = with_routhian!(py, reduced, |r| t
        .iter()
        .zip(x.chunks_exact(n))
        .map(|(t, x)| r.amended_potential(x, *t))
        .collect());
    Ok(PyArray1::from_vec(py, result.map_err(model_error)?))
}

/// The velocities ċ of the ignored coordinates at each state (t, x, ẋ), shape (N, m).
#[pyfunction]
fn cyclic_velocity<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray2<'py, f64>,
    xdot: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let reduced = reduced(model)?;
    let (t, x, xdot, n) = states(py, model, &t, &x, &xdot)?;
    let m = reduced.cyclic.len();
    let result: Result<Vec<f64>, ModelError> = with_routhian!(py, reduced, |r| {
        let mut out = vec![0.0; t.len() * m];
        t.iter()
            .zip(x.chunks_exact(n).zip(xdot.chunks_exact(n)))
            .zip(out.chunks_exact_mut(m))
            .try_for_each(|((t, (x, v)), c)| r.cyclic_velocity(x, v, *t, c))
            .map(|()| out)
    });
    convert::matrix(py, result.map_err(model_error)?, m)
}
