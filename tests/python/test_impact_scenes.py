"""The impact scenes (reference/impulses_and_rolling.md): the bouncing ball and the elliptic
billiard of the core's catalogue, with their contacts watched natively, against their twins
from closures (MechanicalSystem + Contact(phi, gradient)) to the bit, and their physics: the
ball's e² height ratio and exact apex, the billiard's focal invariant, and the hard-sphere
scattering angle off an ellipsoid obstacle."""

import math
import pickle

import numpy as np
import pytest

import varmech
from varmech import examples, scenes
from varmech._catalogue import DECLARED


def _same_runs(native, python):
    for a, b in [(native.t, python.t), (native.q, python.q), (native.p, python.p)]:
        np.testing.assert_array_equal(a, b)
    assert native.nfev == python.nfev
    for a, b in zip(native.events, python.events, strict=True):
        for x, y in [(a.t, b.t), (a.q, b.q), (a.p, b.p)]:
            np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize("law", ["variational", "reflect"])
@pytest.mark.parametrize("e", [1.0, 0.7])
def test_the_native_bouncing_ball_is_its_closure_twin_to_the_bit(e, law):
    # The native floor evaluates φ = q₀ − 0 in the core, the closure q[0]: the same numbers, so
    # the same impacts, and the same model arithmetic (V = gq, ∇V = g) in Rust and NumPy.
    scene = scenes.bouncing_ball(restitution=e)
    native_floor = varmech.Contact.wall(0, restitution=e, name="floor", law=law)
    floor = varmech.Contact(lambda q: q[0], lambda q: [1.0], restitution=e, name="floor", law=law)
    native = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end, contacts=[native_floor])
    python = varmech.integrate(examples.bouncing_ball(), scene.q0, scene.p0, dt=scene.dt, t_end=scene.t_end, contacts=[floor])
    assert len(native.events[0]) == 10
    _same_runs(native, python)


def test_the_native_elliptic_billiard_is_its_closure_twin_to_the_bit():
    # φ = 1 − (u² + v²) with u = x/A, v = y/B, and ∇φ = −2(u/A, v/B): the native ellipse's
    # arithmetic in the same order (the core sums from 0), so the runs agree to the bit.
    scene = scenes.elliptic_billiard()
    a, b = scene.parameters["A"], scene.parameters["B"]

    def phi(q):
        u, v = q[0] / a, q[1] / b
        return 1.0 - (u * u + v * v)

    def gradient(q):
        return np.array([-2.0 * (q[0] / a) / a, -2.0 * (q[1] / b) / b])

    native = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    python = varmech.integrate(
        examples.elliptic_billiard(), scene.q0, scene.p0, dt=scene.dt, t_end=scene.t_end, contacts=[varmech.Contact(phi, gradient, name="wall")]
    )
    assert len(native.events[0]) > 20
    _same_runs(native, python)


@pytest.mark.parametrize("e", [0.9, 0.5])
def test_an_inelastic_ball_scene_falls_by_e_squared_per_bounce_and_ends_at_its_exact_apex(e):
    scene = scenes.bouncing_ball(g=3.0, h0=2.0, restitution=e)
    assert scene.invariants == {} and scene.contacts[0].restitution == e
    traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    hits = traj.events[0]
    assert len(hits) == 10
    # The k-th impact at t₁(1 + 2(e + … + eᵏ⁻¹)); the apex after it at h₀e²ᵏ = (e v⁻ₖ)²/2g.
    t1 = math.sqrt(2 * 2.0 / 3.0)
    exact = t1 * (1 + 2 * np.concatenate(([0.0], np.cumsum(e ** np.arange(1, 10)))))
    np.testing.assert_allclose(hits.t, exact, rtol=1e-12)
    heights = (e * hits.p[:, 0]) ** 2 / (2 * 3.0)
    np.testing.assert_allclose(heights[1:] / heights[:-1], e**2, rtol=1e-12)
    np.testing.assert_allclose(heights, 2.0 * e ** (2 * np.arange(1, 11)), rtol=1e-12)
    # The exact reference: the apex after the tenth bounce.
    ref = scene.reference
    assert ref is not None and ref.t == scene.t_end and traj.t[-1] == pytest.approx(ref.t, rel=1e-15)
    np.testing.assert_allclose(traj.q[-1], ref.q, rtol=1e-10)
    assert abs(traj.p[-1, 0]) < 1e-12


def test_a_nearly_dead_ball_scene_follows_the_bounces_its_step_can_resolve():
    # e = 0.05: the tenth flight would last 2e⁹t₁ ≈ 1e-12 s, and a step resolving it 10¹³ steps
    # to the tenth apex; the scene follows K = 3 bounces (e³ ≥ 10⁻⁴ > e⁴) to the apex after the
    # third, h₀e⁶, in some 10⁵ steps, and its energy balance closes.
    scene = scenes.bouncing_ball(restitution=0.05)
    assert round(scene.t_end / scene.dt) < 500_000
    traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end, save_every=100)
    assert len(traj.events[0]) == 3
    np.testing.assert_allclose(traj.q[-1], scene.reference.q, rtol=1e-8)
    np.testing.assert_allclose(scene.reference.q, 0.05**6, rtol=1e-15)
    assert varmech.check_conservation(traj).energy.verdict in ("bounded", "conserved to round-off")


def test_the_elastic_ball_scene_keeps_its_energy_and_an_explicit_contact_overrides_the_scenes():
    scene = scenes.bouncing_ball()
    g, h0, dt = 9.81, 1.0, scene.dt
    assert scene.invariants == {"H": g * h0}
    # The scene's floor (the variational law): H jumps by g²h²(1 − 2α)/8 at an impact at the
    # fraction α of a step. The scene's step puts the first impact at α = ¼ and the next near ¾,
    # ¼, … in turn (each jump moves the next impact by O(h) of a step), so the jumps cancel in
    # pairs and H stays within the first, g²h²/16, of gh₀.
    hits = varmech.integrate(scene, dt=dt, t_end=scene.t_end).events[0]
    energy = 0.5 * hits.p[:, 0] ** 2
    jump = g * g * dt * dt / 16
    assert energy[1] - g * h0 == pytest.approx(jump, rel=1e-8)
    assert np.max(np.abs(energy - g * h0)) <= jump * (1 + 1e-8)
    # The exact reflection instead: the exact reference, the apex back at h₀, to round-off.
    traj = varmech.integrate(scene, dt=dt, t_end=scene.t_end, contacts=[varmech.Contact.wall(0, law="reflect")])
    np.testing.assert_allclose(traj.q[-1], scene.reference.q, rtol=1e-12)
    assert abs(traj.p[-1, 0]) < 1e-11
    # No contacts: the ball falls through the floor.
    free = varmech.integrate(scene, dt=dt, steps=100, contacts=[])
    assert free.q[-1, 0] < 0 and free.events == ()


def test_the_billiard_scene_keeps_its_focal_invariant_over_ten_thousand_impacts():
    scene = scenes.elliptic_billiard(A=2.0, B=1.5, x0=-0.4, y0=0.2, px0=0.3, py0=-0.9)
    a, b = 2.0, 1.5
    c = math.sqrt(a * a - b * b)
    traj = varmech.integrate(scene, dt=0.2, steps=170_000, save_every=97)
    hits = traj.events[0]
    assert len(hits) > 10_000

    def focal(q, p):
        return ((q[:, 0] - c) * p[:, 1] - q[:, 1] * p[:, 0]) * ((q[:, 0] + c) * p[:, 1] - q[:, 1] * p[:, 0])

    start = scene.invariants["L1L2"]
    assert start == pytest.approx(focal(scene.q0[None, :], scene.p0[None, :])[0], rel=1e-15)
    assert np.max(np.abs(focal(traj.q, traj.p) - start)) < 1e-10
    assert np.max(np.abs(focal(hits.q, hits.p) - start)) < 1e-10
    assert np.max(np.abs(0.5 * np.sum(traj.p**2, axis=1) - scene.invariants["E"])) < 1e-12
    assert np.max((traj.q[:, 0] / a) ** 2 + (traj.q[:, 1] / b) ** 2) < 1 + 1e-12
    assert np.max(np.abs((hits.q[:, 0] / a) ** 2 + (hits.q[:, 1] / b) ** 2 - 1)) < 1e-12


@pytest.mark.parametrize("impact", [0.0, 0.3, 0.8])
def test_a_particle_scatters_off_a_disc_obstacle_at_the_hard_sphere_angle(impact):
    # A free particle at impact parameter b on a disc of radius R about (1, −2): deflected by
    # χ = π − 2 arcsin(b/R), its speed kept.
    radius, centre = 1.5, np.array([1.0, -2.0])
    obstacle = varmech.Contact.ellipsoid([radius, radius], centre=centre, inside=False, name="disc")
    free = examples.elliptic_billiard()
    q0 = centre + [-5.0, impact * radius]
    traj = varmech.integrate(free, q0, [1.0, 0.0], dt=0.01, steps=800, contacts=[obstacle])
    assert len(traj.events[0]) == 1
    chi = math.pi - 2 * math.asin(impact)
    np.testing.assert_allclose(traj.p[-1], [math.cos(chi), math.sin(chi)], atol=1e-12)
    assert np.linalg.norm(traj.events[0].q[0] - centre) == pytest.approx(radius, rel=1e-14)


def test_impact_scenes_carry_native_contacts_that_pickle_and_compare_by_value():
    ball, billiard = scenes.bouncing_ball(restitution=0.8), scenes.elliptic_billiard(A=3.0)
    assert ball.contacts == (varmech.Contact.wall(0, restitution=0.8, name="floor"),)
    assert billiard.contacts == (varmech.Contact.ellipsoid([3.0, 1.0], name="wall"),)
    assert pickle.loads(pickle.dumps(billiard)).contacts == billiard.contacts
    assert all(not scenes.get(name).contacts for name in scenes.CATALOGUE if DECLARED[name].contacts is None)


def test_bad_impact_scenes_and_shapes_are_named():
    with pytest.raises(ValueError, match="^restitution: must lie in"):
        scenes.bouncing_ball(restitution=0.0)
    with pytest.raises(ValueError, match="^h0: must be finite and positive"):
        scenes.bouncing_ball(h0=-1.0)
    with pytest.raises(ValueError, match="^x0: "):
        scenes.elliptic_billiard(x0=2.0)
    with pytest.raises(ValueError, match="^A: must be finite and at least B"):
        scenes.elliptic_billiard(A=1.0, B=2.0)
    with pytest.raises(ValueError, match="^semi_axes: must be finite and positive"):
        varmech.Contact.ellipsoid([1.0, -1.0])
    with pytest.raises(ValueError, match="^semi_axes: coordinates, centre and semi_axes"):
        varmech.Contact.ellipsoid([1.0, 1.0], coordinates=[0])
    free = examples.elliptic_billiard()
    with pytest.raises(ValueError, match=r"^contacts: .* \(contacts\[0\]\): coordinate 2 is not in 0 … 1"):
        varmech.integrate(free, [0.0, 0.0], [1.0, 0.0], dt=0.1, steps=10, contacts=[varmech.Contact.ellipsoid([1.0, 1.0], coordinates=[0, 2])])
    with pytest.raises(ValueError, match="^q0: outside the contact"):
        varmech.integrate(free, [2.0, 0.0], [1.0, 0.0], dt=0.1, steps=10, contacts=[varmech.Contact.ellipsoid([1.0, 1.0])])
