"""Holonomic constraints from Python: RATTLE on the native constrained scenes, consistent
initial data, residuals in the trajectory and the conservation report."""


import numpy as np
import pytest

import varmech
from varmech import examples, scenes


def test_rattle_is_the_default_and_holds_both_constraint_levels():
    scene = scenes.cartesian_pendulum()
    assert scene.model.constraints == 1 and not scene.model.separable
    traj = varmech.integrate(scene, dt=scene.dt, steps=20_000, save_every=10)
    assert traj.method == "rattle"
    g, v = traj.constraint_residuals()
    assert np.max(g) <= 1e-14 and np.max(v) <= 1e-14
    report = varmech.check_conservation(traj)
    assert report.constraint_residuals == (np.max(g), np.max(v))
    assert report.verdict == "bounded" and report.energy.max_abs_error < 0.0062
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


def test_constraint_closures_reproduce_the_native_scene():
    scene = scenes.cartesian_pendulum()
    for method in ("rattle", "rattle4", "shake"):
        native = varmech.integrate(scene, dt=0.1, steps=500, method=method)
        closure = varmech.integrate(examples.closure_of(scene), scene.q0, scene.p0, dt=0.1, steps=500, method=method)
        # Newton stops once |g| is at round-off, which NumPy and Rust reach on slightly different steps.
        assert closure.nfev == native.nfev and abs(closure.newton_iterations - native.newton_iterations) <= 0.01 * native.newton_iterations
        assert np.max(np.abs(closure.q - native.q)) < 1e-12 and np.max(np.abs(closure.p - native.p)) < 1e-12
    twin = examples.cartesian_pendulum()
    with pytest.warns(varmech.DerivativeWarning, match="no constraint_jacobian"):
        differenced = varmech.MechanicalSystem(
            2, twin.potential, twin.gradient, constraints=twin.constraints_function, constraint_count=1
        )
    traj = varmech.integrate(differenced, scene.q0, scene.p0, dt=0.1, steps=500)
    g, v = traj.constraint_residuals()
    assert np.max(g) < 1e-14 and np.max(v) < 1e-9
    q, p = varmech.project(twin, [1.0, 0.1], v0=[0.3, 0.2])
    assert abs(0.5 * (q @ q - 1.0)) < 1e-15 and abs(q @ p) < 1e-15


def test_bad_constraint_closures_are_named():
    twin = examples.cartesian_pendulum()
    scene = scenes.cartesian_pendulum()
    with pytest.raises(ValueError, match="constraint_count: must be between 1 and dim − 1"):
        varmech.MechanicalSystem(
            2, twin.potential, twin.gradient, constraints=twin.constraints_function,
            constraint_jacobian=twin.constraint_jacobian, constraint_count=2,
        )
    with pytest.raises(ValueError, match="^constraints: give constraints"):
        varmech.MechanicalSystem(2, twin.potential, twin.gradient, constraints=twin.constraints_function)
    wrong = varmech.MechanicalSystem(
        2, twin.potential, twin.gradient, constraints=lambda q: np.zeros(2), constraint_jacobian=twin.constraint_jacobian,
        constraint_count=1,
    )
    with pytest.raises(ValueError, match=r"constraints\(q\) returned 2 values, expected 1"):
        varmech.integrate(wrong, scene.q0, scene.p0, dt=0.1, steps=3)


def test_the_rigid_body_in_quaternions_and_its_closure_twin_with_configuration_dependent_mass():
    scene = scenes.rigid_body()
    assert scene.model.constraints == 1
    native = varmech.integrate(scene, dt=0.01, steps=2000, save_every=10)
    assert native.method == "trapezoid"
    g, v = native.constraint_residuals()
    assert np.max(g) <= 1e-14 and np.max(v) <= 1e-14
    report = varmech.check_conservation(native)
    assert report.verdict == "bounded" and report.energy.max_abs_error / abs(report.energy.initial) < 1e-3
    closure = varmech.integrate(examples.closure_of(scene), scene.q0, scene.p0, dt=0.01, steps=300, save_every=10)
    assert closure.method == "trapezoid"
    k = len(closure)
    assert np.max(np.abs(closure.q - native.q[:k])) < 1e-10 and np.max(np.abs(closure.p - native.p[:k])) < 1e-10
    assert varmech.check_derivatives(examples.rigid_body(), scene.q0).ok
    with pytest.raises(ValueError, match="^method: rattle does not integrate a general Lagrangian on constraints"):
        varmech.integrate(scene, dt=0.01, steps=10, method="rattle")
    # Projection with M(q): q back on |q| = 1, p on the hidden constraint q·q̇ = 0.
    q, p = varmech.project(scene.model, 1.01 * scene.q0, scene.p0 + 0.1)
    g, v = varmech.integrate(scene.model, q, p, dt=0.01, steps=2).constraint_residuals()
    assert g[0] <= 1e-15 and v[0] <= 1e-15


@pytest.mark.parametrize("name, method", [("cartesian_pendulum", "rattle"), ("cartesian_pendulum", "shake"), ("rigid_body", "trapezoid")])
def test_a_constraint_solve_that_fails_raises_convergence_error_with_the_partial_trajectory(name, method):
    scene = scenes.get(name)
    with pytest.raises(varmech.ConvergenceError) as info:
        varmech.integrate(scene, dt=scene.dt, steps=100, method=method, newton_max_iterations=1, newton_tolerance=1e-16)
    err = info.value
    assert err.step == 1 and err.time == 0.0 and len(err.partial) == 1
