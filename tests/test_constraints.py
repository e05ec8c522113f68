"""Holonomic constraints from Python: RATTLE on the native constrained scenes, consistent
initial data, residuals in the trajectory and the conservation report."""

import math

import numpy as np
import pytest

import varmech
from varmech import scenes


def test_rattle_is_the_default_and_holds_both_constraint_levels():
    scene = scenes.cartesian_pendulum()
    assert scene.model.constraints == 1 and not scene.model.separable
    traj = varmech.integrate(scene, dt=scene.dt, steps=20_000, save_every=10)
    assert traj.method == "rattle"
    g, v = traj.constraint_residuals()
    assert np.max(g) <= 1e-14 and np.max(v) <= 1e-14
    report = varmech.check_conservation(traj)
    assert report.constraint_residuals == (np.max(g), np.max(v))
    assert report.verdict == "bounded" and report.energy.max_error * abs(math.cos(2.0)) < 0.0062
    assert "max |G M⁻¹ p|" in str(report)


def test_the_spherical_pendulum_in_cartesian_coordinates_keeps_l_z_and_reaches_the_reference():
    scene = scenes.cartesian_spherical_pendulum()
    traj = varmech.integrate(scene, dt=0.0025, t_end=scene.t_end, save_every=100, method="rattle4")
    report = varmech.check_conservation(traj)
    assert report.momenta[0].name == "L_z" and report.momenta[0].max_rel_error < 1e-12
    assert np.max(np.abs(traj.q[-1] - scene.reference.q)) < 1e-6


def test_inconsistent_initial_data_is_refused_and_project_repairs_it():
    scene = scenes.cartesian_pendulum()
    with pytest.raises(ValueError, match="^q0: is off the constraints"):
        varmech.integrate(scene.model, [1.0, 0.1], [0.0, 0.0], dt=0.1, steps=10)
    with pytest.raises(ValueError, match="^p0: is off the hidden constraint"):
        varmech.integrate(scene.model, scene.q0, [0.3, 0.2], dt=0.1, steps=10)
    with pytest.raises(ValueError, match="^method: verlet would ignore the constraints"):
        varmech.integrate(scene, dt=0.1, steps=10, method="verlet")
    q, p = varmech.project(scene.model, [1.0, 0.1], v0=[0.3, 0.2])
    g, v = varmech.integrate(scene.model, q, p, dt=0.1, steps=10).constraint_residuals()
    assert g[0] <= 1e-15 and v[0] <= 1e-15
    with pytest.raises(ValueError, match="^q0: the constraints are not independent here"):  # at the anchor, G = 0
        varmech.project(scene.model, [0.0, 0.0])
    with pytest.raises(ValueError, match="^model: has no holonomic constraints"):
        varmech.project(scenes.pendulum().model, [1.0])


def test_loose_shake_drifts_where_rattle_does_not():
    scene = scenes.cartesian_pendulum()
    drift = {}
    for method, tol in (("rattle", 1e-14), ("shake", 1e-4)):
        traj = varmech.integrate(scene, dt=0.1, steps=100_000, save_every=10, method=method, newton_tolerance=tol)
        drift[method] = abs(varmech.check_conservation(traj).energy.drift_rate)
    assert drift["shake"] > 100 * drift["rattle"]


def test_constrained_methods_are_listed_and_refused_elsewhere():
    constrained = {m.name for m in varmech.methods() if m.constrained}
    assert constrained == {"rattle", "rattle4", "shake"}
    with pytest.raises(ValueError, match="^method: rattle integrates systems with holonomic constraints"):
        varmech.integrate(scenes.pendulum(), dt=0.1, steps=10, method="rattle")
