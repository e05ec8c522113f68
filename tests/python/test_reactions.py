"""Forces of constraint (Trajectory.reactions): the multipliers λ of ṗ = ∂L/∂q + Cᵀλ against
closed forms — the pendulum's tension, a particle on a cone (circular orbit, and a general orbit
against SciPy on the reduced equations), a disk rolling on a circle, a skate on a slope with its
heading held to a circle — for every model source, with the power Cᵀλ·q̇ at round-off."""

import numpy as np
import pytest

import varmech

G = 9.81


def tension(traj):
    """λ of the unit pendulum (m = l = g = 1) on ½(x² + y² − 1) = 0 at each saved state: the
    string pulls with −Tx, T = g cos θ + v², cos θ = −y, so λ = −T."""
    return -(-traj.q[:, 1] + np.sum(traj.p**2, axis=1))


def pendulum(jacobian=True):
    return varmech.MechanicalSystem(
        2, lambda q: q[1], lambda q: np.array([0.0, 1.0]),
        constraints=lambda q: np.array([0.5 * (q @ q - 1.0)]),
        constraint_jacobian=(lambda q: q[None, :].copy()) if jacobian else None, constraint_count=1,
    )


def symbolic_pendulum():
    sp = pytest.importorskip("sympy")
    x, y, vx, vy = sp.symbols("x y v_x v_y")
    return varmech.symbolic.mechanical(y, [x, y], 1, v=[vx, vy], constraints=[(x**2 + y**2 - 1) / 2])


@pytest.mark.parametrize(
    "source, tolerance",
    [
        ("native", 1e-11),
        ("closure", 1e-11),
        ("symbolic", 1e-11),
        # G by differences of g: its rounding (2e-11), differenced again along the motion.
        ("closure without its jacobian", 1e-6),
    ],
)
def test_the_multiplier_is_the_pendulums_tension_for_every_model_source(source, tolerance):
    q0 = [np.sin(2.0), -np.cos(2.0)]
    makers = {
        "native": lambda: varmech.scenes.cartesian_pendulum(),
        "closure": lambda: pendulum(),
        "symbolic": symbolic_pendulum,
        "closure without its jacobian": lambda: pendulum(jacobian=False),
    }
    if "without" in source:
        with pytest.warns(UserWarning, match="no constraint_jacobian given"):
            model = makers[source]()
    else:
        model = makers[source]()
    for method in ("rattle", "rattle4", "shake"):
        traj = varmech.integrate(model, q0, v0=[0.0, 0.0], dt=0.01, steps=400, save_every=20, method=method)
        r = traj.reactions()
        assert r.multipliers.shape == (21, 1) and r.force.shape == (21, 2) and r.power.shape == (21,)
        error = np.max(np.abs(r.multipliers[:, 0] - tension(traj)) / np.maximum(np.abs(tension(traj)), 1.0))
        assert error < tolerance, (method, error)
        # Gᵀλ with G = q, or G by differences (about 1e-10).
        np.testing.assert_allclose(r.force, r.multipliers * traj.q, rtol=0, atol=1e-9 if "without" in source else 1e-14)


def test_the_power_of_the_constraint_force_is_round_off_for_rattle_and_not_for_shake():
    scene = varmech.scenes.cartesian_pendulum()
    for method, verdict in (("rattle", "conserved to round-off"), ("rattle4", "conserved to round-off")):
        report = varmech.check_conservation(varmech.integrate(scene, dt=0.05, steps=4000, save_every=10, method=method))
        assert report.constraint_power.verdict == verdict, str(report)
        assert report.constraint_power in report.quantities and "Cᵀλ·q̇" in str(report)
    # SHAKE leaves the momenta off the hidden constraint G M⁻¹p = 0, and the force does work.
    shake = varmech.integrate(scene, dt=0.05, steps=4000, save_every=10, method="shake")
    power = shake.reactions().power
    velocity = shake.constraint_residuals()[1]
    assert np.max(np.abs(power)) > 1e-6 and np.max(velocity) > 1e-6
    assert varmech.check_conservation(shake).constraint_power.verdict != "conserved to round-off"


A, M = 1.0, 1.0  # the cone x² + y² = a²z² (half-angle 45°), unit mass


def cone():
    return varmech.MechanicalSystem(
        3, lambda q: M * G * q[2], lambda q: np.array([0.0, 0.0, M * G]), mass=M,
        constraints=lambda q: np.array([0.5 * (q[0] ** 2 + q[1] ** 2 - A**2 * q[2] ** 2)]),
        constraint_jacobian=lambda q: np.array([[q[0], q[1], -(A**2) * q[2]]]), constraint_count=1,
    )


def test_a_circular_orbit_on_a_cone_is_held_by_its_closed_form_multiplier():
    # Horizontal: λr = −mrω²; vertical: −λa²z = mg; so ω² = g/(ar), λ = −mg/(ar), constant.
    r = 1.5
    omega = np.sqrt(G / (A * r))
    traj = varmech.integrate(cone(), [r, 0.0, r / A], v0=[0.0, r * omega, 0.0], dt=1e-3, steps=5000, save_every=100, method="rattle4")
    radius = np.hypot(traj.q[:, 0], traj.q[:, 1])
    assert np.max(np.abs(radius - r)) < 1e-10
    np.testing.assert_allclose(traj.reactions().multipliers[:, 0], -M * G / (A * r), rtol=1e-10)


def test_a_general_orbit_on_a_cone_follows_the_reduced_equations():
    integrate = pytest.importorskip("scipy.integrate")
    r0, rdot0, phidot0 = 1.0, 0.8, 0.7 * np.sqrt(G / A)
    ell = M * r0**2 * phidot0

    def reduced(t, s):  # (r, ṙ): m(1 + 1/a²)r̈ = ℓ²/(mr³) − mg/a
        return [s[1], (ell**2 / (M**2 * s[0] ** 3) - G / A) / (1 + 1 / A**2)]

    t = np.linspace(0.0, 4.0, 41)
    ref = integrate.solve_ivp(reduced, (0, 4.0), [r0, rdot0], t_eval=t, rtol=1e-12, atol=1e-12, method="DOP853")
    r = ref.y[0]
    rddot = np.array([reduced(0, s)[1] for s in ref.y.T])
    expected = M * (rddot - r * (ell / (M * r**2)) ** 2) / r  # the horizontal balance λr = m(r̈ − rφ̇²)
    traj = varmech.integrate(cone(), [r0, 0.0, r0 / A], v0=[rdot0, r0 * phidot0, rdot0 / A], dt=1e-3, steps=4000, save_every=100, method="rattle4")
    np.testing.assert_allclose(traj.t, t, atol=1e-12)
    np.testing.assert_allclose(np.hypot(traj.q[:, 0], traj.q[:, 1]), r, atol=1e-9)
    np.testing.assert_allclose(traj.reactions().multipliers[:, 0], expected, rtol=1e-8)
    assert np.all(expected < 0)  # the surface pushes inwards and up: the particle stays on it


def test_the_rolling_disks_contact_force_is_the_centripetal_force_of_its_circle():
    # The rows of A are the contact point's velocity, so λ is the horizontal contact force:
    # m·Rφ̇θ̇ towards the centre of the circle, (−sin θ, cos θ) for θ̇ > 0.
    scene = varmech.scenes.rolling_disk(radius=1.0, turn=0.7, roll=2.0)
    traj = varmech.integrate(scene, dt=scene.dt, steps=2000, save_every=100)
    theta = traj.q[:, 2]
    r = traj.reactions()
    np.testing.assert_allclose(r.multipliers, 1.0 * 2.0 * 0.7 * np.stack([-np.sin(theta), np.cos(theta)], axis=1), atol=1e-11)
    assert np.max(np.abs(r.power)) < 1e-12
    assert varmech.check_conservation(traj).constraint_power.verdict == "conserved to round-off"


def test_the_skates_blade_and_heading_forces_follow_the_closed_form():
    # Neimark & Fufaev's skate on a slope (tests/test_mixed_constraints.py): heading (c, s) on
    # c² + s² = 1 turning at ω, blade s ẋ − c ẏ = 0. J(c̈, s̈) = λ₁(c, s) gives λ₁ = −Jω²; ẍ = a +
    # λ₂s and ÿ = −λ₂c with ẍ = a cos 2ωt, ÿ = a sin 2ωt give λ₂ = −2a sin ωt.
    slope, inertia, omega = 1.0, 0.5, 1.3
    model = varmech.MechanicalSystem(
        4, lambda q: -slope * q[0], lambda q: np.array([-slope, 0.0, 0.0, 0.0]), mass=[1.0, 1.0, inertia, inertia],
        constraints=lambda q: np.array([0.5 * (q[2] ** 2 + q[3] ** 2 - 1.0)]),
        constraint_jacobian=lambda q: np.array([[0.0, 0.0, q[2], q[3]]]), constraint_count=1,
        velocity_constraints=lambda q: np.array([[q[3], -q[2], 0.0, 0.0]]), velocity_constraint_count=1,
    )
    traj = varmech.integrate(model, [0.0, 0.0, 1.0, 0.0], v0=[0.0, 0.0, 0.0, omega], dt=0.0025, t_end=4.0, save_every=40, method="dla4")
    r = traj.reactions()
    expected = np.stack([np.full(len(traj.t), -inertia * omega**2), -2 * slope * np.sin(omega * traj.t)], axis=1)
    np.testing.assert_allclose(r.multipliers, expected, atol=1e-8)
    assert np.max(np.abs(r.power)) < 1e-12


def test_reactions_read_from_a_file_and_at_dense_times_are_the_runs(tmp_path):
    pytest.importorskip("h5py")
    scene = varmech.scenes.cartesian_pendulum()
    traj = varmech.integrate(scene, dt=0.01, steps=300, save_every=30)
    again = varmech.load(traj.save(tmp_path / "run.h5"))
    np.testing.assert_array_equal(again.reactions().multipliers, traj.reactions().multipliers)
    dense = varmech.integrate(scene, dt=0.01, steps=300, t_eval=np.linspace(0, 3, 7))
    # Interpolated states sit off the circle by the interpolant's error; λ follows the tension.
    np.testing.assert_allclose(dense.reactions().multipliers[:, 0], tension(dense), atol=1e-4)


def test_reactions_name_the_model_without_constraints_and_pass_a_closures_error_on():
    with pytest.raises(ValueError, match="model: has no holonomic constraints"):
        varmech.integrate(varmech.scenes.pendulum(), dt=0.1, steps=10).reactions()

    class Boom(Exception):
        pass

    calls = {"n": 0}

    def jacobian(q):
        calls["n"] += 1
        if calls["n"] > 10_000:
            raise Boom("the user's own")
        return q[None, :].copy()

    model = varmech.MechanicalSystem(
        2, lambda q: q[1], lambda q: np.array([0.0, 1.0]),
        constraints=lambda q: np.array([0.5 * (q @ q - 1.0)]), constraint_jacobian=jacobian, constraint_count=1,
    )
    traj = varmech.integrate(model, [0.0, -1.0], v0=[1.0, 0.0], dt=0.01, steps=10)
    calls["n"] = 10_000
    with pytest.raises(Boom, match="the user's own"):
        traj.reactions()
