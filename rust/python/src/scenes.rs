//! The native scenes by name.

use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use varmech::scenes::{self, LagrangianScene, Problem, Scene};

use crate::errors::to_pyerr;
use crate::native::{Native, NativeModel};

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

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<NativeModel>()?;
    m.add_function(wrap_pyfunction!(scene, m)?)?;
    m.add_function(wrap_pyfunction!(nbody, m)?)?;
    Ok(())
}
