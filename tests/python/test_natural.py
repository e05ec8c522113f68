"""Mechanical systems with configuration-dependent mass, L = ½q̇ᵀM(q)q̇ − V(q), from closures."""

import math

import numpy as np
import pytest

import varmech
from varmech import scenes

M1, M2, L1, L2, G = 1.0, 2.0, 2.0, 3.0, 9.80665


def mass(q):
    c = M2 * L1 * L2 * math.cos(q[0] - q[1])
    return np.array([[(M1 + M2) * L1 * L1, c], [c, M2 * L2 * L2]])


def mass_derivative(q):
    s = M2 * L1 * L2 * math.sin(q[0] - q[1])
    return np.array([[[0.0, -s], [-s, 0.0]], [[0.0, s], [s, 0.0]]])


def potential(q):
    return -(M1 + M2) * G * L1 * math.cos(q[0]) - M2 * G * L2 * math.cos(q[1])


def gradient(q):
    return np.array([(M1 + M2) * G * L1 * math.sin(q[0]), M2 * G * L2 * math.sin(q[1])])


def double_pendulum(**kwargs):
    return varmech.MechanicalSystem(2, potential, gradient, mass=mass, name="double pendulum (M(q))", **kwargs)


@pytest.mark.parametrize("method", ["midpoint", "galerkin4"])
def test_mass_closure_matches_the_native_double_pendulum(method):
    scene = scenes.double_pendulum()
    model = double_pendulum(mass_derivative=mass_derivative)
    assert not model.separable
    native = varmech.integrate(scene, dt=0.01, steps=300, method=method)
    closure = varmech.integrate(model, scene.q0, scene.p0, dt=0.01, steps=300, method=method)
    assert np.max(np.abs(closure.q - native.q)) < 1e-10
    assert np.max(np.abs(closure.p - native.p)) < 1e-10
    # The exact inverse Legendre transform: the energies agree to round-off.
    assert np.max(np.abs(closure.energy() - native.energy())) < 1e-10


def test_mass_derivative_by_differences_warns_and_agrees():
    scene = scenes.double_pendulum()
    with pytest.warns(varmech.DerivativeWarning, match="no mass_derivative given"):
        model = double_pendulum()
    native = varmech.integrate(scene, dt=0.01, steps=200, method="midpoint")
    closure = varmech.integrate(model, scene.q0, scene.p0, dt=0.01, steps=200, method="midpoint")
    assert np.max(np.abs(closure.q - native.q)) < 1e-7


def test_cyclic_coordinate_of_a_natural_system_keeps_its_momentum(spherical_natural):
    # The spherical pendulum, M(θ) = diag(1, sin²θ), V = −cos θ: p_φ is conserved to round-off.
    model = spherical_natural(symmetries=[varmech.Cyclic(1)])
    scene = scenes.spherical_pendulum()
    traj = varmech.integrate(model, scene.q0, scene.p0, dt=0.01, t_end=50.0, method="midpoint")
    report = varmech.check_conservation(traj)
    assert report.momenta[0].max_rel_error < 1e-12
    assert abs(traj.q[-1, 0] - scene.reference.q[0]) < 1e-2


def test_bad_mass_closures_are_named():
    q0, p0 = [0.1, 0.2], [0.0, 0.0]
    wrong_shape = varmech.MechanicalSystem(2, potential, gradient, mass=lambda q: np.eye(3), mass_derivative=mass_derivative)
    with pytest.raises(ValueError, match=r"mass\(q\) returned an array of shape \[3, 3\], expected \[2, 2\]"):
        varmech.integrate(wrong_shape, q0, p0, dt=0.1, steps=2, method="midpoint")
    asymmetric = varmech.MechanicalSystem(
        2, potential, gradient, mass=lambda q: np.array([[1.0, 0.5], [0.0, 1.0]]), mass_derivative=mass_derivative
    )
    with pytest.raises(ValueError, match="not symmetric"):
        varmech.integrate(asymmetric, q0, p0, dt=0.1, steps=2, method="midpoint")
    indefinite = varmech.MechanicalSystem(2, potential, gradient, mass=lambda q: -np.eye(2), mass_derivative=mass_derivative)
    with pytest.raises(varmech.VarmechError, match="not symmetric positive definite"):
        varmech.integrate(indefinite, q0, p0, dt=0.1, steps=2, method="midpoint")
    with pytest.raises(TypeError, match=r"mass\(q\) must return an array"):
        varmech.integrate(
            varmech.MechanicalSystem(2, potential, gradient, mass=lambda q: "heavy", mass_derivative=mass_derivative),
            q0, p0, dt=0.1, steps=2, method="midpoint",
        )
    with pytest.raises(ValueError, match="mass_derivative: only with a mass closure"):
        varmech.MechanicalSystem(2, potential, gradient, mass=1.0, mass_derivative=mass_derivative)
    with pytest.raises(ValueError, match="method"):
        varmech.integrate(double_pendulum(mass_derivative=mass_derivative), q0, p0, dt=0.1, steps=2, method="verlet")


def test_lists_are_accepted_as_mass_matrices():
    model = varmech.MechanicalSystem(
        1, lambda q: 0.5 * q[0] ** 2, lambda q: [q[0]], mass=lambda q: [[2]], mass_derivative=lambda q: [[[0]]]
    )
    traj = varmech.integrate(model, [1.0], [0.0], dt=0.01, steps=10, method="midpoint")
    assert traj.v[0, 0] == 0.0 and abs(traj.p[1, 0] - 2 * traj.v[1, 0]) < 1e-15
