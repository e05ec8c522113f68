"""Pickling: scenes, models and trajectories round-trip, and what comes back integrates to the
same bits; closures pickle by reference (a lambda raises pickle's own error naming it); a
process pool maps integrate over scenes."""

import concurrent.futures
import dataclasses
import functools
import multiprocessing
import pickle
import warnings

import numpy as np
import pytest

import varmech
from varmech import scenes

STEPS = 40


def _same(a, b):
    """Bit for bit (so that -0.0 ≠ 0.0), None only with None."""
    if a is None or b is None:
        return a is None and b is None
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def _assert_same_trajectory(a, b):
    """Equal arrays (bit for bit) and metadata; the models are compared by what they integrate."""
    assert type(a.model) is type(b.model) and a.model.name == b.model.name
    for f in dataclasses.fields(varmech.Trajectory):
        if f.name in ("model", "_v"):
            continue
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            assert _same(x, y), f.name
        else:
            assert x == y, f.name


def _round_trip(obj):
    return pickle.loads(pickle.dumps(obj))


def _run(model, q0, p0, dt):
    return varmech.integrate(model, q0, p0, dt=dt, steps=STEPS)


def _check_model(model, q0, p0, dt):
    """The unpickled model integrates to the original's bits, and the original's trajectory
    survives pickling (arrays, metadata, and a model that integrates to the same bits)."""
    traj = _run(model, q0, p0, dt)
    copy = _round_trip(model)
    assert type(copy) is type(model) and copy is not model
    _assert_same_trajectory(_run(copy, q0, p0, dt), traj)
    traj_copy = _round_trip(traj)
    _assert_same_trajectory(traj_copy, traj)
    _assert_same_trajectory(_run(traj_copy.model, q0, p0, dt), traj)


@pytest.mark.parametrize("name", list(scenes.CATALOGUE))
def test_every_native_scene_pickles_and_integrates_to_the_same_bits(name):
    scene = scenes.get(name)
    copy = _round_trip(scene)
    for f in dataclasses.fields(scenes.Scene):
        if f.name not in ("model", "q0", "p0", "reference"):
            assert getattr(copy, f.name) == getattr(scene, f.name), f.name
    assert _same(copy.q0, scene.q0) and _same(copy.p0, scene.p0)
    assert (copy.reference is None) == (scene.reference is None)
    if scene.reference is not None:
        assert copy.reference.t == scene.reference.t and copy.reference.source == scene.reference.source
        assert _same(copy.reference.q, scene.reference.q)
    assert copy.model.parameters == scene.parameters
    _assert_same_trajectory(
        varmech.integrate(copy, dt=scene.dt, steps=STEPS), varmech.integrate(scene, dt=scene.dt, steps=STEPS)
    )
    _check_model(scene.model, scene.q0, scene.p0, scene.dt)


@pytest.mark.parametrize("scene", [scenes.kepler(e=0.3), scenes.planar_chain(links=3)], ids=["kepler", "planar_chain"])
def test_a_native_scene_pickles_with_its_parameters(scene):
    default = scenes.get(scene.name)
    copy = _round_trip(scene.model)
    assert copy.parameters == scene.parameters != default.parameters
    assert copy.dim == scene.model.dim
    _check_model(scene.model, scene.q0, scene.p0, scene.dt)


def test_a_trajectory_pickled_under_its_old_module_loads():
    """Trajectory moved from varmech.integrate to varmech.trajectory; a pickle made before names
    the old module, which still holds it, and loads to the same trajectory."""
    scene = scenes.pendulum()
    traj = _run(scene.model, scene.q0, scene.p0, scene.dt)
    assert type(traj).__module__ == "varmech.trajectory"
    new = pickle.dumps(traj, protocol=0)  # protocol 0 names a class as text: "c<module>\n<name>\n"
    old = new.replace(b"cvarmech.trajectory\nTrajectory\n", b"cvarmech.integrate\nTrajectory\n")
    assert old.count(b"cvarmech.integrate\nTrajectory\n") == 1
    copy = pickle.loads(old)
    assert type(copy) is varmech.Trajectory
    _assert_same_trajectory(copy, traj)


def test_a_native_nbody_model_pickles_by_its_masses():
    rng = np.random.default_rng(3)
    scene = scenes.nbody([1.0, 1e-3, 2e-3], rng.normal(size=(3, 3)), rng.normal(size=(3, 3)) * 0.1, G=0.5)
    assert _round_trip(scene.model)._core.gravity == (0.5, [1.0, 1e-3, 2e-3])
    _check_model(scene.model, scene.q0, scene.p0, 1e-3)


def test_a_compiled_model_and_its_scene_pickle():
    pytest.importorskip("sympy")
    scene = scenes.get("elastic_pendulum")
    model = scene.model.with_parameters(**{next(iter(scene.model.parameters)): 1.25})
    assert _round_trip(model).parameters == model.parameters
    _check_model(model, scene.q0, scene.p0, scene.dt)
    copy = _round_trip(scene)
    _assert_same_trajectory(
        varmech.integrate(copy, dt=scene.dt, steps=STEPS), varmech.integrate(scene, dt=scene.dt, steps=STEPS)
    )


# Module-level functions: pickle stores them by reference.
def pendulum_potential(q):
    return -np.cos(q[0])


def pendulum_gradient(q):
    return np.array([np.sin(q[0])])


def oscillator_lagrangian(q, v, t):
    return 0.5 * v[0] ** 2 - 0.5 * q[0] ** 2


def oscillator_dl_dq(q, v, t):
    return -q


def oscillator_dl_dv(q, v, t):
    return v.copy()


def test_closure_models_with_module_level_functions_pickle():
    mechanical = varmech.MechanicalSystem(1, pendulum_potential, pendulum_gradient, mass=2.0, name="pendulum")
    _check_model(mechanical, [0.3], [0.1], 0.05)
    # rayleigh adds a force varmech builds itself: the model pickles as its arguments, not that.
    damped = varmech.Lagrangian(1, oscillator_lagrangian, dl_dq=oscillator_dl_dq, dl_dv=oscillator_dl_dv, rayleigh=0.1)
    copy = _round_trip(damped)
    assert copy.forced and copy.lagrangian is oscillator_lagrangian
    _check_model(damped, [1.0], [0.0], 0.05)


def test_a_closure_model_rebuilt_from_a_pickle_warns_no_more():
    with pytest.warns(varmech.DerivativeWarning, match="central differences"):
        model = varmech.MechanicalSystem(1, pendulum_potential)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _check_model(model, [0.3], [0.1], 0.05)


# A lambda at module level (pickle looks its name up in the module and fails) and one inside a
# function (a local object).
MODULE_LAMBDAS = [lambda q: -np.cos(q[0])]


def _local_lambda():
    return lambda q: -np.cos(q[0])


@pytest.mark.parametrize(
    "potential, error",
    [(MODULE_LAMBDAS[0], pickle.PicklingError), (_local_lambda(), AttributeError)],
    ids=["module-lambda", "local-lambda"],
)
def test_a_lambda_closure_raises_picklings_own_error_naming_it(potential, error):
    model = varmech.MechanicalSystem(1, potential, pendulum_gradient)
    with pytest.raises(error, match="<lambda>"):
        pickle.dumps(model)


def test_a_local_function_raises_picklings_own_error_naming_it():
    def local_friction(q, v, t):
        return -0.1 * v

    model = varmech.Lagrangian(
        1, oscillator_lagrangian, dl_dq=oscillator_dl_dq, dl_dv=oscillator_dl_dv, force=local_friction
    )
    with pytest.raises(AttributeError, match="local_friction"):
        pickle.dumps(model)


def test_a_routh_reduced_model_and_its_reconstruction_pickle():
    scene = scenes.kepler_polar()
    reduced = varmech.routh(scene)
    x0, px0 = reduced.reduce(scene.q0, scene.p0)
    _check_model(reduced, x0, px0, 0.01)
    copy = _round_trip(reduced)
    assert copy.cyclic == reduced.cyclic and _same(copy.momenta, reduced.momenta)
    # Pickled together, a trajectory keeps its model: the copy reconstructs the full motion.
    traj = varmech.integrate(reduced, x0, px0, dt=0.01, steps=STEPS, method="midpoint")
    model_copy, traj_copy = _round_trip((reduced, traj))
    assert traj_copy.model is model_copy
    _assert_same_trajectory(model_copy.reconstruct(traj_copy), reduced.reconstruct(traj))


@pytest.mark.parametrize(("scene", "method"), [(scenes.kepler(), "verlet"), (scenes.double_pendulum(), "midpoint")])
def test_a_pickled_stepper_goes_on_bit_for_bit(scene, method):
    # Its checkpoint carries the compensated-summation carries and the Newton predictor.
    stepper = varmech.Stepper(scene, dt=0.01, method=method)
    stepper.advance(100)
    copy = _round_trip(stepper)
    stepper.advance(50)
    copy.advance(50)
    assert _same(copy.q, stepper.q) and _same(copy.p, stepper.p)
    assert (copy.steps, copy.newton_iterations, copy.force_evaluations) == (
        stepper.steps,
        stepper.newton_iterations,
        stepper.force_evaluations,
    )


def test_models_that_record_no_recipe_refuse_pickling_with_a_type_error():
    bare = varmech.NativeSystem(varmech._core.scene("pendulum").model)
    with pytest.raises(TypeError, match="NativeSystem 'pendulum' built without its parameters"):
        pickle.dumps(bare)

    class Bare(varmech.Model):
        name = "bare"

    with pytest.raises(TypeError, match="cannot pickle Bare 'bare'"):
        pickle.dumps(Bare())


def test_a_process_pool_integrates_scenes_as_in_process():
    chosen = [scenes.kepler(e=0.3), scenes.double_pendulum()]
    run = functools.partial(varmech.integrate, dt=0.01, steps=200)
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(max_workers=2, mp_context=context) as pool:
        pooled = list(pool.map(run, chosen))
    for scene, traj in zip(chosen, pooled):
        _assert_same_trajectory(traj, run(scene))
