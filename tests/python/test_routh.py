"""Routh reduction from Python: varmech.routh, the reduced model, and reconstruction."""

import math

import numpy as np
import pytest

import varmech
from conftest import Boom, raising_when
from varmech import examples, scenes


def test_native_and_closure_models_reduce_to_the_same_motion(spherical_natural):
    scene = scenes.spherical_pendulum()
    mu = scene.p0[1]
    runs = []
    for model in [scene.model, examples.spherical_pendulum(), spherical_natural(name="spherical pendulum (M(q))")]:
        reduced = varmech.routh(model, [1], [mu])
        assert reduced.dim == 1 and reduced.shape == (0,) and reduced.cyclic == (1,)
        x0, px0 = reduced.reduce(scene.q0, scene.p0)
        traj = varmech.integrate(reduced, x0, px0, dt=0.01, steps=1000, method="midpoint")
        runs.append(reduced.reconstruct(traj, c0=scene.q0[[1]]))
    for other in runs[1:]:
        np.testing.assert_allclose(other.q, runs[0].q, rtol=0, atol=1e-10)
        np.testing.assert_allclose(other.p, runs[0].p, rtol=0, atol=1e-10)


def test_reconstruction_reproduces_the_unreduced_midpoint_run_and_keeps_mu_exactly():
    scene = scenes.spherical_pendulum()
    full = varmech.integrate(scene, dt=0.01, steps=2000, method="midpoint")
    reduced = varmech.routh(scene, [1])
    traj = varmech.integrate(reduced, *reduced.reduce(scene.q0, scene.p0), dt=0.01, steps=2000)
    assert traj.method == "midpoint"
    rebuilt = reduced.reconstruct(traj, c0=[0.0])
    assert rebuilt.model is scene.model
    np.testing.assert_allclose(rebuilt.q, full.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(rebuilt.p, full.p, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(rebuilt.p[:, 1], scene.p0[1])
    # R's energy is L's, and it stays in a band of the midpoint rule's O(h²).
    np.testing.assert_allclose(traj.energy(), rebuilt.energy(), rtol=0, atol=1e-14)
    report = varmech.check_conservation(traj)
    assert report.energy.verdict == "bounded", report


def test_the_conical_pendulum_is_a_critical_point_of_the_amended_potential():
    theta = 0.8
    phidot = math.sqrt(1.0 / math.cos(theta))
    mu = math.sin(theta) ** 2 * phidot
    reduced = varmech.routh(examples.spherical_pendulum(), [1], [mu])
    e = 1e-5
    slope = (reduced.amended_potential([theta + e]) - reduced.amended_potential([theta - e])) / (2 * e)
    assert abs(slope) < 1e-9
    np.testing.assert_allclose(reduced.amended_potential([theta]), mu**2 / (2 * math.sin(theta) ** 2) - math.cos(theta), rtol=1e-14)
    np.testing.assert_allclose(reduced.cyclic_velocity([theta], [0.0]), [phidot], rtol=1e-14)
    traj = varmech.integrate(reduced, [theta], [0.0], dt=0.1, steps=500, method="galerkin4")
    assert np.max(np.abs(traj.q[:, 0] - theta)) < 1e-13
    rebuilt = reduced.reconstruct(traj)
    np.testing.assert_allclose(rebuilt.q[:, 1], phidot * traj.t, rtol=1e-13, atol=1e-13)


def test_kepler_in_polar_coordinates_reduced_to_the_radius_reconstructs_at_order_four(kepler_polar):
    # R = ½ṙ² − ℓ²/(2r²) + 1/r; after one period (2π) the orbit is back at r = 1 − e, θ = 2π.
    e = 0.6
    ell = math.sqrt(1 - e * e)
    reduced = varmech.routh(kepler_polar, [1], [ell])
    errors = []
    for steps in [200, 400, 800]:
        traj = varmech.integrate(reduced, [1 - e], [0.0], dt=2 * math.pi / steps, steps=steps, method="galerkin4")
        rebuilt = reduced.reconstruct(traj)
        errors.append(math.hypot(rebuilt.q[-1, 0] - (1 - e), rebuilt.q[-1, 1] - 2 * math.pi))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 4) < 0.3), (errors, orders)


def test_a_time_dependent_lagrangian_reduces_and_reconstructs():
    # L = ½(ẋ² + ċ²) − ½(1 + 0.1 sin t)x²: c is cyclic, ċ = μ, so c(t) = c₀ + μt exactly.
    model = varmech.Lagrangian(
        2,
        lambda q, v, t: 0.5 * (v @ v) - 0.5 * (1 + 0.1 * math.sin(t)) * q[0] ** 2,
        dl_dq=lambda q, v, t: np.array([-(1 + 0.1 * math.sin(t)) * q[0], 0.0]),
        dl_dv=lambda q, v, t: v.copy(),
        time_dependent=True,
    )
    reduced = varmech.routh(model, [1], [0.7])
    assert reduced.time_dependent
    for method in ["midpoint", "trapezoid", "galerkin6"]:
        traj = varmech.integrate(reduced, [1.0], [0.0], dt=0.05, steps=200, method=method)
        rebuilt = reduced.reconstruct(traj, c0=[2.0])
        np.testing.assert_allclose(rebuilt.q[:, 1], 2.0 + 0.7 * traj.t, rtol=0, atol=1e-12)


def test_an_exception_in_a_closure_propagates_through_the_reduced_model():
    dl_dq = raising_when(
        lambda q, v, t: t > 0.5,
        lambda q, v, t: np.array([math.sin(q[0]) * math.cos(q[0]) * v[1] ** 2 - math.sin(q[0]), 0.0]),
        "from dl_dq",
    )
    model = varmech.Lagrangian(
        2,
        lambda q, v, t: 0.5 * (v[0] ** 2 + math.sin(q[0]) ** 2 * v[1] ** 2) + math.cos(q[0]),
        dl_dq=dl_dq,
        dl_dv=lambda q, v, t: np.array([v[0], math.sin(q[0]) ** 2 * v[1]]),
    )
    reduced = varmech.routh(model, [1], [0.5])
    with pytest.raises(Boom, match="from dl_dq") as info:
        varmech.integrate(reduced, [1.0], [0.0], dt=0.1, steps=100)
    assert info.value.partial.t[-1] <= 0.5 + 1e-12


def test_a_scenes_cyclic_coordinates_are_found_when_not_given():
    assert varmech.routh(scenes.heavy_top()).cyclic == (1, 2)
    assert varmech.routh(scenes.kepler_polar()).cyclic == (1,)
    with pytest.raises(ValueError, match="^cyclic:.*no cyclic coordinate"):
        varmech.routh(scenes.double_pendulum())
    with pytest.raises(ValueError, match="^cyclic:"):
        varmech.routh(examples.spherical_pendulum())


def test_bad_arguments_are_named():
    scene = scenes.spherical_pendulum()
    with pytest.raises(ValueError, match="^cyclic:"):
        varmech.routh(scene, [2])
    with pytest.raises(ValueError, match="^cyclic:"):
        varmech.routh(scene.model, [0, 1], [0.1, 0.2])
    with pytest.raises(ValueError, match="^cyclic:"):
        varmech.routh(scene.model, [1, 1], [0.1, 0.2])
    with pytest.raises(ValueError, match="^momenta:"):
        varmech.routh(scene.model, [1], [0.1, 0.2])
    with pytest.raises(ValueError, match="^momenta:"):
        varmech.routh(scene.model, [1], [math.nan])
    with pytest.raises(ValueError, match="^momenta:"):
        varmech.routh(scene.model, [1])
    with pytest.raises(ValueError, match="^model:.*forces"):
        damped = varmech.Lagrangian(
            2, lambda q, v, t: 0.5 * (v @ v), dl_dq=lambda q, v, t: np.zeros(2), dl_dv=lambda q, v, t: v.copy(),
            force=lambda q, v, t: -0.1 * v,
        )
        varmech.routh(damped, [1], [0.0])
    with pytest.raises(ValueError, match="^model:.*constraints"):
        varmech.routh(scenes.cartesian_spherical_pendulum(), [0], [0.0])
    reduced = varmech.routh(scene, [1])
    with pytest.raises(ValueError, match="^model:.*reduced already"):
        varmech.routh(reduced, [0], [0.0])
    with pytest.raises(ValueError, match="^p:"):
        reduced.reduce(scene.q0, scene.p0 + 1.0)
    with pytest.raises(ValueError, match="^method:"):
        varmech.integrate(reduced, [1.0], [0.0], dt=0.1, steps=3, method="verlet")
    other = varmech.integrate(scene, dt=0.1, steps=3)
    with pytest.raises(ValueError, match="^traj:"):
        reduced.reconstruct(other)
