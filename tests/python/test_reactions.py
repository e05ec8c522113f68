"""Forces of constraint (Trajectory.reactions): the multipliers λ of ṗ = ∂L/∂q + Cᵀλ against
closed forms — the pendulum's tension, a particle on a cone and on a paraboloid (circular orbits,
and general orbits against SciPy on the reduced equations), a disk rolling on a circle, a skate on a slope with its
heading held to a circle — for every model source, with the power Cᵀλ·q̇ at round-off."""

import numpy as np
import pytest

import varmech
from conftest import Boom, raising_after

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
        with pytest.warns(varmech.DerivativeWarning, match="no constraint_jacobian given"):
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


A, M = 1.0, 1.0
# Surfaces of revolution z(r) about the vertical, g = 1 … 9.81, each as (constraint g(q), its
# Jacobian, z(r), z'(r), z''(r)): the cone x² + y² = a²z² (the lecture's §4.1, half-angle 45°)
# and the paraboloid x² + y² = az (the formula).
SURFACES = {
    "cone": (
        lambda q: np.array([0.5 * (q[0] ** 2 + q[1] ** 2 - A**2 * q[2] ** 2)]),
        lambda q: np.array([[q[0], q[1], -(A**2) * q[2]]]),
        lambda r: r / A, lambda r: 1 / A + 0 * r, lambda r: 0 * r,
    ),
    "paraboloid": (
        lambda q: np.array([0.5 * (q[0] ** 2 + q[1] ** 2 - A * q[2])]),
        lambda q: np.array([[q[0], q[1], -A / 2]]),
        lambda r: r**2 / A, lambda r: 2 * r / A, lambda r: 2 / A + 0 * r,
    ),
}


def surface(name):
    g, jacobian, *_ = SURFACES[name]
    return varmech.MechanicalSystem(
        3, lambda q: M * G * q[2], lambda q: np.array([0.0, 0.0, M * G]), mass=M,
        constraints=g, constraint_jacobian=jacobian, constraint_count=1,
    )


def reduced(name, ell):
    """(r, ṙ)' of a particle on z(r) with angular momentum ℓ: from L = ½m(ṙ²(1 + z'²) + r²φ̇²) − mgz,
    m r̈ (1 + z'²) = mrφ̇² − mgz' − m z'z''ṙ²."""
    _, _, _, dz, ddz = SURFACES[name]

    def f(t, s):
        r, rdot = s
        return [rdot, (ell**2 / (M**2 * r**3) - G * dz(r) - dz(r) * ddz(r) * rdot**2) / (1 + dz(r) ** 2)]

    return f


@pytest.mark.parametrize("name", SURFACES)
def test_a_circular_orbit_on_a_surface_of_revolution_is_held_by_its_closed_form_multiplier(name):
    # Horizontal λr·(∂g/∂x scale 1) = −mrω², vertical λ·∂g/∂z = mg: on the cone ω² = g/(ar),
    # λ = −mg/(ar); on the paraboloid ω² = 2g/a, λ = −2mg/a, whatever r.
    r = 1.5
    _, jacobian, z, _, _ = SURFACES[name]
    lam = M * G / jacobian([r, 0.0, z(r)])[0, 2]
    omega = np.sqrt(-lam / M)
    traj = varmech.integrate(surface(name), [r, 0.0, z(r)], v0=[0.0, r * omega, 0.0], dt=1e-3, steps=5000, save_every=100, method="rattle4")
    # rattle4's error at hω ≈ 0.005 (the paraboloid's ω = 4.4): about 1e-10.
    assert np.max(np.abs(np.hypot(traj.q[:, 0], traj.q[:, 1]) - r)) < 1e-9
    np.testing.assert_allclose(traj.reactions().multipliers[:, 0], lam, rtol=1e-9)
    np.testing.assert_allclose(lam, {"cone": -M * G / (A * r), "paraboloid": -2 * M * G / A}[name], rtol=1e-15)


@pytest.mark.parametrize("name", SURFACES)
def test_a_general_orbit_on_a_surface_of_revolution_follows_the_reduced_equations(name):
    integrate = pytest.importorskip("scipy.integrate")
    _, _, z, dz, _ = SURFACES[name]
    r0, rdot0, phidot0 = 1.0, 0.8, 0.7 * np.sqrt(G / A)
    ell = M * r0**2 * phidot0
    f = reduced(name, ell)
    t = np.linspace(0.0, 4.0, 41)
    ref = integrate.solve_ivp(f, (0, 4.0), [r0, rdot0], t_eval=t, rtol=1e-12, atol=1e-12, method="DOP853")
    r = ref.y[0]
    rddot = np.array([f(0, s)[1] for s in ref.y.T])
    expected = M * (rddot - r * (ell / (M * r**2)) ** 2) / r  # the horizontal balance λr = m(r̈ − rφ̇²)
    v0 = [rdot0, r0 * phidot0, dz(r0) * rdot0]
    traj = varmech.integrate(surface(name), [r0, 0.0, z(r0)], v0=v0, dt=1e-3, steps=4000, save_every=100, method="rattle4")
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

    jacobian = raising_after(10_000, lambda q: q[None, :].copy(), "the user's own")
    model = varmech.MechanicalSystem(
        2, lambda q: q[1], lambda q: np.array([0.0, 1.0]),
        constraints=lambda q: np.array([0.5 * (q @ q - 1.0)]), constraint_jacobian=jacobian, constraint_count=1,
    )
    traj = varmech.integrate(model, [0.0, -1.0], v0=[1.0, 0.0], dt=0.01, steps=10)
    jacobian.calls = 10_000
    with pytest.raises(Boom, match="the user's own"):
        traj.reactions()


def on_sphere():
    """A particle on the outside of a smooth unit sphere (x, z), g = 1: held by ½(x² + z² − 1) = 0,
    whose force λ(x, z) pushes outwards while λ > 0."""
    return varmech.MechanicalSystem(
        2, lambda q: q[1], lambda q: np.array([0.0, 1.0]),
        constraints=lambda q: np.array([0.5 * (q @ q - 1.0)]), constraint_jacobian=lambda q: q[None, :].copy(), constraint_count=1,
    )


@pytest.mark.parametrize("method, steps, order", [("rattle", (0.01, 0.005, 0.0025), 2.0), ("rattle4", (0.04, 0.02, 0.01), 4.0)])
def test_a_particle_leaves_the_sphere_where_cos_theta_is_two_thirds_of_its_start_to_the_methods_order(method, steps, order):
    # From rest at θ₀: v² = 2g(cos θ₀ − cos θ), and N = mg cos θ − mv² = mg(3 cos θ − 2 cos θ₀) = 0.
    theta0 = 0.1
    leave = varmech.events.multiplier(0, direction=-1, terminal=True)
    errors = []
    for h in steps:
        traj = varmech.integrate(on_sphere(), [np.sin(theta0), np.cos(theta0)], v0=[0.0, 0.0], dt=h, t_end=20.0, method=method, events=[leave])
        assert traj.status == 1 and len(traj.events[0].t) == 1
        errors.append(abs(traj.events[0].q[0, 1] - 2 / 3 * np.cos(theta0)))
    measured = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(np.abs(measured - order) < 0.2), (errors, measured)


def test_a_string_whirled_too_slowly_goes_slack_where_its_tension_reaches_zero():
    # The unit pendulum from the bottom at v₀² = 3.5: T = 3 cos θ + v₀² − 2 = 0 at cos θ = −1/2.
    # λ = −T crosses 0 upwards there.
    slack = varmech.events.multiplier(0, direction=+1, terminal=True)
    errors = []
    for h in (0.02, 0.01, 0.005):
        start = dict(v0=[np.sqrt(3.5), 0.0], dt=h, t_end=10.0, method="rattle4", events=[slack])
        traj = varmech.integrate(varmech.scenes.cartesian_pendulum(), [0.0, -1.0], **start)
        q = traj.events[0].q[0]
        assert traj.status == 1 and q[0] > 0, q
        errors.append(abs(-q[1] - (-0.5)))
        # Before it, the string pulled (λ < 0) at every saved state.
        assert np.all(traj.reactions().multipliers[:-1, 0] < 0)
    measured = np.log2(np.array(errors[:-1]) / errors[1:])
    assert errors[-1] < 1e-8 and np.all(np.abs(measured - 4.0) < 0.2), (errors, measured)


def test_multiplier_events_name_what_the_model_lacks():
    with pytest.raises(ValueError, match=r"events\[0\] \(lambda\[1\] = 0\): the model has 1 constraint rows"):
        varmech.integrate(varmech.scenes.cartesian_pendulum(), dt=0.01, steps=10, events=[varmech.events.multiplier(1)])
    with pytest.raises(ValueError, match="the model has no constraints"):
        varmech.integrate(varmech.scenes.pendulum(), dt=0.01, steps=10, events=[varmech.events.multiplier(0)])
    with pytest.raises(ValueError, match="k: must be an integer ≥ 0"):
        varmech.events.multiplier(-1)


def test_a_slack_string_flies_as_a_projectile_until_taut_again_and_loses_carnots_energy():
    # The unit pendulum from the bottom at v₀² = 3.5 goes slack at r₀ = (√3/2, 1/2) with speed
    # √(1/2) along the circle's tangent (−1/2, √3/2); the projectile r₀ + vt − ½gt²ŷ meets
    # |r| = 1 again where t²/4 − v_y t + (v² − y₀) = 0, and v² = y₀ = 1/2: t = 4v_y. Taut, the
    # string takes the radial velocity: Carnot's loss ½(v·r̂)².
    slack = varmech.events.multiplier(0, direction=+1, terminal=True)
    start = dict(v0=[np.sqrt(3.5), 0.0], dt=1e-3, t_end=10.0, method="rattle4", events=[slack])
    held = varmech.integrate(varmech.scenes.cartesian_pendulum(), [0.0, -1.0], **start)
    q0, p0, t0 = held.events[0].q[0], held.events[0].p[0], held.events[0].t[0]
    r0, v0 = np.array([np.sqrt(3) / 2, 0.5]), np.sqrt(0.5) * np.array([-0.5, np.sqrt(3) / 2])
    np.testing.assert_allclose(q0, r0, atol=1e-12)
    np.testing.assert_allclose(p0, v0, atol=1e-12)

    def inside(t, q, p):
        return 1.0 - q @ q

    inside.direction = -1  # type: ignore[attr-defined]
    inside.terminal = True  # type: ignore[attr-defined]
    free = varmech.MechanicalSystem(2, lambda q: q[1], lambda q: np.array([0.0, 1.0]))
    flight = varmech.integrate(free, q0, p0, t0=t0, dt=1e-3, t_end=t0 + 5.0, events=[inside])
    t_flight = 4 * v0[1]
    q1, p1 = flight.events[0].q[0], flight.events[0].p[0]
    np.testing.assert_allclose(flight.events[0].t[0] - t0, t_flight, atol=1e-10)
    np.testing.assert_allclose(q1, r0 + v0 * t_flight - [0.0, t_flight**2 / 2], atol=1e-10)
    taut = varmech.engage(free, q1, p1, constraints=lambda q: [0.5 * (q @ q - 1)], jacobian=lambda q: q[None, :].copy())
    radial = p1 @ q1
    np.testing.assert_allclose(taut.carnot, radial**2 / 2, rtol=1e-12)
    np.testing.assert_allclose(taut.p, p1 - radial * q1, atol=1e-12)
    # On the circle again, the string pulls with the tension of the state.
    again = varmech.integrate(varmech.scenes.cartesian_pendulum(), q1, taut.p, t0=flight.events[0].t[0], dt=1e-3, steps=10)
    np.testing.assert_allclose(again.reactions().multipliers[0, 0], -(-q1[1] + taut.p @ taut.p), rtol=1e-10)


@pytest.mark.parametrize("workers", [1, 2])
def test_an_ensemble_of_whirled_strings_goes_slack_where_each_single_run_does(workers):
    # From the bottom at v₀²: slack at cos θ = −(v₀² − 2)/3 while 2 < v₀² < 5; at v₀² ≥ 5 the
    # string stays taut all round. Each member bit for bit its single run (threads: native scene).
    scene = varmech.scenes.cartesian_pendulum()
    speeds = np.sqrt([2.5, 3.0, 3.5, 4.0, 4.5, 5.5])
    q0 = np.tile([0.0, -1.0], (len(speeds), 1))
    v0 = np.stack([speeds, np.zeros_like(speeds)], axis=1)
    run = dict(dt=0.005, t_end=6.0, method="rattle4", events=[varmech.events.multiplier(0, direction=+1, terminal=True)])
    runs = varmech.ensemble(scene, q0, v0=v0, workers=workers, progress=False, **run)
    for i, v in enumerate(speeds):
        single = varmech.integrate(scene, q0[i], v0=v0[i], **run)
        np.testing.assert_array_equal(runs[i].events[0].q, single.events[0].q)
        np.testing.assert_array_equal(runs[i].reactions().multipliers, single.reactions().multipliers)
        if v**2 < 5:
            assert runs[i].status == 1 and abs(-runs[i].events[0].q[0, 1] + (v**2 - 2) / 3) < 1e-7
        else:
            assert runs[i].status == 0 and len(runs[i].events[0]) == 0
