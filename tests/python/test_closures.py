"""A closure model of each native scene reproduces the native trajectory."""

import numpy as np
import pytest

import varmech
from varmech import examples, scenes

# Impact scenes run through their contacts; their twins, with the contacts from closures, are
# checked in test_impact_scenes.py.
SEPARABLE = [n for n in scenes.CATALOGUE if scenes.get(n).model.separable and not scenes.get(n).contacts]
# Constrained scenes have no closure twins: constraints are not yet taken from closures. The
# nonholonomic scenes' twins (midpoint only) are checked bit for bit in test_nonholonomic_scenes.py.
GENERAL = [
    n
    for n in scenes.CATALOGUE
    if not scenes.get(n).model.separable and not scenes.get(n).model.constraints and not scenes.get(n).model.velocity_constraints
]


@pytest.mark.parametrize(
    "name, method",
    [(n, m) for n in SEPARABLE for m in ["verlet", "kahan_li8", "rk4", "symplectic_euler", "midpoint"]]
    + [(n, m) for n in GENERAL for m in ["midpoint", "trapezoid"]],
)
def test_closure_reproduces_native(name, method):
    scene = scenes.get(name)
    closure = examples.closure_of(scene)
    steps = 500
    native = varmech.integrate(scene, dt=scene.dt, steps=steps, method=method)
    python = varmech.integrate(closure, scene.q0, scene.p0, dt=scene.dt, steps=steps, method=method)
    # Explicit methods agree to round-off; implicit ones to their Newton tolerance, through
    # which round-off differences between Rust and NumPy arithmetic pass. Their Newton
    # iterations stop at round-off, so those differences can add or save an iteration in a
    # few steps.
    if native.newton_iterations:
        assert abs(python.nfev - native.nfev) <= 0.01 * native.nfev
        tol = 1e-10
    else:
        assert python.nfev == native.nfev
        tol = 1e-12
    for a, b in [(native.q, python.q), (native.p, python.p)]:
        scale = np.max(np.abs(a))
        assert np.max(np.abs(a - b)) <= tol * scale
    np.testing.assert_allclose(python.energy(), native.energy(), rtol=tol, atol=tol * abs(native.energy()[0]))


def test_closure_symmetries_are_checked_like_native_ones():
    scene = scenes.outer_solar_system()
    closure = examples.closure_of(scene)
    traj = varmech.integrate(closure, scene.q0, scene.p0, dt=200.0, steps=500, method="kahan_li8")
    report = varmech.check_conservation(traj)
    assert [m.name for m in report.momenta] == ["P_x", "P_y", "P_z", "L_x", "L_y", "L_z"]
    assert all(m.max_rel_error <= 1e-13 for m in report.momenta), report


def test_missing_gradient_warns_and_uses_central_differences():
    with pytest.warns(varmech.DerivativeWarning, match="central differences"):
        fd = varmech.MechanicalSystem(2, examples.henon_heiles().potential)
    exact = examples.henon_heiles()
    scene = scenes.henon_heiles()
    a = varmech.integrate(fd, scene.q0, scene.p0, dt=0.1, steps=200)
    b = varmech.integrate(exact, scene.q0, scene.p0, dt=0.1, steps=200)
    assert a.nfev == b.nfev
    assert np.max(np.abs(a.q - b.q)) < 1e-8


def test_full_and_diagonal_mass_matrices():
    # Two uncoupled oscillators with masses 2 and 3, as diag and as a full matrix rotated into
    # other coordinates: the energy is the same function of the state either way.
    k = np.array([1.0, 4.0])
    diag = varmech.MechanicalSystem(2, lambda q: 0.5 * q @ (k * q), lambda q: k * q, mass=[2.0, 3.0])
    c, s = np.cos(0.3), np.sin(0.3)
    r = np.array([[c, -s], [s, c]])
    m_full = r @ np.diag([2.0, 3.0]) @ r.T
    k_full = r @ np.diag(k) @ r.T
    full = varmech.MechanicalSystem(2, lambda q: 0.5 * q @ k_full @ q, lambda q: k_full @ q, mass=m_full)
    q0, v0 = np.array([1.0, 0.5]), np.array([0.0, 0.2])
    a = varmech.integrate(diag, q0, v0=v0, dt=0.01, steps=1000, method="kahan_li6")
    b = varmech.integrate(full, r @ q0, v0=r @ v0, dt=0.01, steps=1000, method="kahan_li6")
    np.testing.assert_allclose(b.q, a.q @ r.T, atol=1e-12)
    np.testing.assert_allclose(b.v, a.v @ r.T, atol=1e-12)
    np.testing.assert_allclose(a.p, a.v * [2.0, 3.0], rtol=1e-14)


@pytest.mark.parametrize("method", ["midpoint", "trapezoid"])
def test_implicit_methods_on_closures_match_native(method):
    scene = scenes.kepler()
    native = varmech.integrate(scene, dt=scene.dt, steps=500, method=method)
    python = varmech.integrate(examples.kepler(), scene.q0, scene.p0, dt=scene.dt, steps=500, method=method)
    assert native.newton_iterations > 0 and python.newton_iterations == native.newton_iterations
    per_step = native.newton_iterations_per_step
    assert per_step.shape == (500,) and 1 <= per_step.min() and per_step.max() <= 6
    np.testing.assert_allclose(python.q, native.q, atol=1e-12)
    # Trapezoid is Störmer–Verlet for a separable system, solved implicitly.
    if method == "trapezoid":
        verlet = varmech.integrate(scene, dt=scene.dt, steps=500, method="verlet")
        np.testing.assert_allclose(native.q, verlet.q, atol=1e-11)
