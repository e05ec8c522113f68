"""Routh reduction: cyclic coordinates are found from ∂L/∂q."""

import math

import numpy as np
import pytest

import varmech
from varmech import examples, scenes


def test_cyclic_coordinates_are_found_where_dl_dq_vanishes(kepler_polar):
    assert varmech.cyclic_coordinates(scenes.spherical_pendulum().model, [1.0, 0.0], spread=0.5) == [1]
    assert varmech.cyclic_coordinates(examples.spherical_pendulum(), [1.0, 0.0], spread=0.5) == [1]
    assert varmech.cyclic_coordinates(kepler_polar, [2.0, 0.0]) == [1]
    # In Cartesian coordinates Kepler's symmetry is a rotation, and no coordinate is cyclic.
    assert varmech.cyclic_coordinates(scenes.kepler().model, [1.0, 1.0], spread=0.5) == []
    assert varmech.cyclic_coordinates(scenes.double_pendulum().model, [0.3, -0.4]) == []
    # A free particle: every coordinate is cyclic.
    free = varmech.MechanicalSystem(3, lambda q: 0.0, lambda q: np.zeros(3))
    assert varmech.cyclic_coordinates(free, np.zeros(3)) == [0, 1, 2]


def test_a_dependence_through_time_or_a_differenced_derivative_is_judged_right(kepler_polar):
    # L = ½|q̇|² − t·q₀: q₀ is not cyclic, though ∂L/∂q₀ vanishes at t = 0.
    driven = varmech.Lagrangian(
        2, lambda q, v, t: 0.5 * v @ v - t * q[0], dl_dq=lambda q, v, t: np.array([-t, 0.0]),
        dl_dv=lambda q, v, t: v, time_dependent=True,
    )
    assert varmech.cyclic_coordinates(driven, [0.0, 0.0]) == [1]
    with pytest.warns(UserWarning):
        differenced = varmech.Lagrangian(2, kepler_polar.lagrangian)
    assert varmech.cyclic_coordinates(differenced, [2.0, 0.0]) == [1]


def test_bad_arguments_are_named():
    model = scenes.spherical_pendulum().model
    with pytest.raises(ValueError, match="^q:"):
        varmech.cyclic_coordinates(model, [1.0])
    with pytest.raises(ValueError, match="^spread:"):
        varmech.cyclic_coordinates(model, [1.0, 0.0], spread=0.0)
    with pytest.raises(ValueError, match="^samples:"):
        varmech.cyclic_coordinates(model, [1.0, 0.0], samples=0)


def test_native_heavy_top_and_kepler_polar_have_cyclic_angles_and_integrate_with_midpoint():
    top, polar = scenes.heavy_top(), scenes.kepler_polar()
    assert varmech.cyclic_coordinates(top.model, top.q0) == [1, 2]
    assert varmech.cyclic_coordinates(polar.model, [1.0, 0.0], spread=0.5) == [1]
    assert [top.name, polar.name] == ["heavy_top", "kepler_polar"] and not top.model.separable
    for scene, momenta in [(top, ["p_phi", "p_psi"]), (polar, ["p_theta"])]:
        traj = varmech.integrate(scene, dt=scene.dt, steps=1000, method="midpoint")
        assert traj.status == 0 and np.all(np.isfinite(traj.q))
        assert traj.energy()[0] == pytest.approx(scene.invariants["E"], rel=1e-15)
        report = varmech.check_conservation(traj)
        assert report.verdict == "bounded"
        # The declared symmetries are the cyclic angles: their momenta are kept to round-off.
        assert [m.initial for m in report.momenta] == pytest.approx([scene.invariants[k] for k in momenta], rel=1e-15)
        assert all(m.max_rel_error < 1e-13 for m in report.momenta), report
    assert polar.reference is not None and polar.reference.q[1] == pytest.approx(400 * math.pi, rel=1e-15)
    assert top.reference is None
