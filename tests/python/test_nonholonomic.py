"""Velocity constraints A(q)q̇ = 0 from Python closures, integrated by the reversible discrete
Lagrange–d'Alembert integrator (reference/impulses_and_rolling.md, "Rolling without
slipping"): the vertical rolling disk, Byerly's sphere on a rough incline, a particle held to a
circle by x ẋ + y ẏ = 0 against RATTLE, the Chaplygin sleigh, and bad input."""

import numpy as np
import pytest

import varmech

MASS = np.array([1.0, 1.0, 0.25, 0.5])  # the disk: m, m, I about a diameter, J about the axle


def rolling(q):
    """The disk of radius 1 rolling upright, q = (x, y, θ, φ): ẋ = φ̇cosθ, ẏ = φ̇sinθ."""
    return np.array([[1.0, 0.0, 0.0, -np.cos(q[2])], [0.0, 1.0, 0.0, -np.sin(q[2])]])


def disk(velocity_constraints=rolling, count=2):
    return varmech.MechanicalSystem(
        4, lambda q: 0.0, lambda q: np.zeros(4), mass=MASS,
        velocity_constraints=velocity_constraints, velocity_constraint_count=count, name="rolling disk",
    )


THETA0, OMEGA, SPIN = 0.3, 0.7, 2.0
V0 = [SPIN * np.cos(THETA0), SPIN * np.sin(THETA0), OMEGA, SPIN]


def test_the_rolling_disk_keeps_its_rates_and_its_energy_and_rolls_on_a_circle():
    model = disk()
    assert model.kind.name == "nonholonomic" and model.kind.default_method == "midpoint"
    assert model.velocity_constraints == 2 and model.constraints == 0
    traj = varmech.integrate(model, [0, 0, THETA0, 0], v0=V0, dt=0.05, steps=10_000, save_every=10)
    assert traj.method == "midpoint"
    v = traj.p / MASS
    assert np.max(np.abs(v[:, 2] - OMEGA)) < 1e-11 and np.max(np.abs(v[:, 3] - SPIN)) < 1e-10
    energy = 0.5 * np.sum(traj.p * v, axis=1)
    assert np.max(np.abs(energy - energy[0])) / energy[0] < 1e-10
    _, rolling_residual = traj.constraint_residuals()
    assert np.max(rolling_residual) < 1e-12  # round-off: θ grows to 350 rad, ε|θ||q̇| ≈ 1.6e-13
    # The contact point on the circle of radius Rφ̇/θ̇ about its centre, to order 2.
    radius = SPIN / OMEGA
    centre = np.array([-radius * np.sin(THETA0), radius * np.cos(THETA0)])
    off = []
    for h in (0.1, 0.05):
        traj = varmech.integrate(model, [0, 0, THETA0, 0], v0=V0, dt=h, t_end=20.0)
        off.append(np.max(np.abs(np.hypot(*(traj.q[:, :2] - centre).T) - radius)) / radius)
    assert abs(np.log2(off[0] / off[1]) - 2.0) < 0.1, off


SLOPE = 9.81 * np.sin(0.5)  # g sin α
INERTIA = 0.4  # (2/5)ma² with m = a = 1


def sphere():
    """The sphere on the rough incline, q = (x, y, φ, θ, ψ) with ZXZ Euler angles and x down
    the slope: L = ½(ẋ² + ẏ²) + ½I(φ̇² + θ̇² + ψ̇² + 2φ̇ψ̇cosθ) + g sinα x, rolling
    ẋ = aω_y, ẏ = −aω_x with ω = (θ̇cosφ + ψ̇sinθsinφ, θ̇sinφ − ψ̇sinθcosφ, ·)."""

    def lagrangian(q, v, t):
        spin = v[2] ** 2 + v[3] ** 2 + v[4] ** 2 + 2 * v[2] * v[4] * np.cos(q[3])
        return 0.5 * (v[0] ** 2 + v[1] ** 2) + 0.5 * INERTIA * spin + SLOPE * q[0]

    def dl_dq(q, v, t):
        return np.array([SLOPE, 0.0, 0.0, -INERTIA * v[2] * v[4] * np.sin(q[3]), 0.0])

    def dl_dv(q, v, t):
        c = np.cos(q[3])
        return np.array([v[0], v[1], INERTIA * (v[2] + v[4] * c), INERTIA * v[3], INERTIA * (v[4] + v[2] * c)])

    def contact(q):
        (sp, cp), st = (np.sin(q[2]), np.cos(q[2])), np.sin(q[3])
        return np.array([[1.0, 0.0, 0.0, -sp, st * cp], [0.0, 1.0, 0.0, cp, st * sp]])

    return varmech.Lagrangian(
        5, lagrangian, dl_dq=dl_dq, dl_dv=dl_dv, velocity_constraints=contact, velocity_constraint_count=2,
        name="sphere on a rough incline",
    )


def test_the_sphere_on_a_rough_incline_runs_down_a_parabola_at_order_two():
    # Byerly: the centre accelerates at (5/7)g sin α down the slope and moves uniformly across
    # it; from (0, 0) with velocity (1, 0.3), the axis along y (φ = π, θ = π/2).
    model = sphere()
    q0, v0 = [0.0, 0.0, np.pi, np.pi / 2, 0.0], [1.0, 0.3, 0.0, 0.3, 1.0]
    exact = np.array([1.0 + 0.5 * 5 / 7 * SLOPE, 0.3])
    errors = []
    for h in (0.1, 0.05, 0.025):
        traj = varmech.integrate(model, q0, v0=v0, dt=h, t_end=1.0)
        errors.append(np.hypot(*(traj.q[-1, :2] - exact)))
        assert np.max(traj.constraint_residuals()[1]) < 1e-14
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(np.abs(orders - 2.0) < 0.1), (errors, orders)
    assert errors[-1] < 2e-5


# Integrable on purpose (the circle's derivative): the warning that says so is tested below.
@pytest.mark.filterwarnings("ignore::varmech.IntegrableConstraintsWarning")
def test_a_particle_held_to_a_circle_by_x_xdot_plus_y_ydot_matches_rattle_to_order_two():
    def potential(q):
        return q[1] + q[0] ** 2

    def gradient(q):
        return np.array([2 * q[0], 1.0])

    rolling_model = varmech.MechanicalSystem(
        2, potential, gradient, velocity_constraints=lambda q: np.array([[q[0], q[1]]]), velocity_constraint_count=1
    )
    held = varmech.MechanicalSystem(
        2, potential, gradient, constraints=lambda q: np.array([0.5 * (q @ q - 1)]),
        constraint_jacobian=lambda q: np.array([q]), constraint_count=1,
    )
    q0 = [np.sin(2.0), -np.cos(2.0)]
    gaps = []
    for h in (0.1, 0.05, 0.025):
        a = varmech.integrate(rolling_model, q0, [0.0, 0.0], dt=h, t_end=10.0)
        b = varmech.integrate(held, q0, [0.0, 0.0], dt=h, t_end=10.0, method="rattle")
        gaps.append(np.max(np.abs(np.concatenate([a.q[-1] - b.q[-1], a.p[-1] - b.p[-1]]))))
        # q̄·δq = ½(|q₁|² − |q₀|²) = 0: the radius is kept to round-off.
        assert np.max(np.abs(np.hypot(*a.q.T) - 1.0)) < 1e-13
    orders = np.log2(np.array(gaps[:-1]) / gaps[1:])
    assert np.all(np.abs(orders - 2.0) < 0.1), (gaps, orders)


def test_the_chaplygin_sleigh_keeps_a_bounded_energy_and_relaxes_to_a_straight_line():
    # q = (x, y, θ), m = I = 1, blade b = 1 behind the centre: −ẋ sinθ + ẏ cosθ − bθ̇ = 0.
    sleigh = varmech.MechanicalSystem(
        3, lambda q: 0.0, lambda q: np.zeros(3),
        velocity_constraints=lambda q: np.array([[-np.sin(q[2]), np.cos(q[2]), -1.0]]), velocity_constraint_count=1,
    )
    traj = varmech.integrate(sleigh, [0.0, 0.0, 0.0], v0=[0.0, 1.0, 1.0], dt=0.01, steps=20_000, save_every=20)
    report = varmech.check_conservation(traj)
    assert report.verdict == "bounded" and report.energy.max_abs_error < 1e-5
    speed = np.hypot(traj.p[-1, 0], traj.p[-1, 1])
    assert abs(traj.p[-1, 2]) < 1e-10 and abs(speed - np.sqrt(2.0)) < 1e-5  # E = 1 all forward
    # Round-off: the end condition is solved to 4ε of the size of |A q̇|'s terms (about 2.8 here).
    assert np.max(traj.constraint_residuals()[1]) < 4 * np.finfo(float).eps * 2.8
    # The report judges |A(q)q̇| against ‖A‖‖q̇‖: at round-off.
    assert report.constraint_residuals == (0.0, np.max(traj.constraint_residuals()[1]))
    assert report.constraints[0].verdict == "conserved to round-off" and "max |A q̇|" in str(report)


def test_initial_data_off_the_rolling_is_refused_naming_v0_or_p0_and_project_repairs_it():
    model = disk()
    q0 = [0.0, 0.0, THETA0, 0.0]
    with pytest.raises(ValueError, match="^v0: is off the velocity constraints"):
        varmech.integrate(model, q0, v0=[1.0, 0.0, 0.0, 0.0], dt=0.1, steps=3)
    with pytest.raises(ValueError, match="^p0: is off the velocity constraints"):
        varmech.integrate(model, q0, [1.0, 0.0, 0.0, 0.0], dt=0.1, steps=3)
    with pytest.raises(ValueError, match="^method: verlet does not integrate velocity constraints; use midpoint"):
        varmech.integrate(model, q0, v0=V0, dt=0.1, steps=3, method="verlet")
    q, p = varmech.project(model, q0, v0=[1.0, 0.0, 0.0, 0.0])
    assert np.array_equal(q, q0)
    assert np.max(np.abs(rolling(q) @ (p / MASS))) < 1e-15
    # M-orthogonal: the correction p0 − p lies in the span of the rows of A.
    correction = np.array([1.0, 0.0, 0.0, 0.0]) - p
    mu = np.linalg.lstsq(rolling(q).T, correction, rcond=None)[0]
    assert np.allclose(rolling(q).T @ mu, correction, atol=1e-15)


def test_bad_velocity_constraints_are_named():
    with pytest.raises(ValueError, match="^velocity_constraints: give velocity_constraints"):
        varmech.MechanicalSystem(4, lambda q: 0.0, lambda q: np.zeros(4), velocity_constraints=rolling)
    with pytest.raises(ValueError, match="^velocity_constraint_count: must be between 1 and dim − 1"):
        disk(count=4)
    q0 = [0.0, 0.0, THETA0, 0.0]
    with pytest.raises(ValueError, match=r"velocity_constraints\(q\) returned an array of shape \[4\], expected \[2, 4\]"):
        varmech.integrate(disk(lambda q: np.zeros(4)), q0, V0, dt=0.1, steps=3)
    with pytest.raises(ValueError, match=r"velocity_constraints\(q\) returned non-finite values"):
        varmech.integrate(disk(lambda q: np.full((2, 4), np.nan)), q0, V0, dt=0.1, steps=3)

    class Boom(Exception):
        pass

    def raising(q):
        if q[3] > 0.5:  # after a few steps
            raise Boom("no more rolling")
        return rolling(q)

    with pytest.raises(Boom, match="no more rolling") as info:
        varmech.integrate(disk(raising), q0, v0=V0, dt=0.1, steps=100)
    assert info.value.step >= 2 and len(info.value.partial) == info.value.step
    with pytest.raises(Boom, match="no more rolling"):
        varmech.integrate(disk(raising), [0.0, 0.0, THETA0, 1.0], v0=V0, dt=0.1, steps=3)


def test_frobenius_tells_integrable_velocity_constraints_from_rolling():
    # x ẋ + y ẏ = 0 is the circle's derivative and a constant A integrates to A q = const: both
    # warn (give g(q) = 0); the disk, the sphere and the sleigh twist ker A and do not.
    import warnings

    circle = varmech.MechanicalSystem(
        2, lambda q: q[1], lambda q: np.array([0.0, 1.0]),
        velocity_constraints=lambda q: np.array([[q[0], q[1]]]), velocity_constraint_count=1, name="circle",
    )
    constant = varmech.MechanicalSystem(
        3, lambda q: 0.0, lambda q: np.zeros(3),
        velocity_constraints=lambda q: np.array([[1.0, 2.0, 0.5]]), velocity_constraint_count=1,
    )
    sleigh = varmech.MechanicalSystem(
        3, lambda q: 0.0, lambda q: np.zeros(3),
        velocity_constraints=lambda q: np.array([[-np.sin(q[2]), np.cos(q[2]), -1.0]]), velocity_constraint_count=1,
    )
    for model, q0 in ((circle, [1.0, 0.0]), (constant, [0.3, -0.2, 1.0])):
        assert varmech.constraints.integrable_near(model, q0)
        with pytest.warns(varmech.IntegrableConstraintsWarning, match="^velocity_constraints: .* integrate to holonomic"):
            varmech.integrate(model, q0, np.zeros(model.dim), dt=0.1, steps=3)
    # Rolling's curvature is of order one: sin of the angle between ker A and its bracket.
    assert varmech._core.constraint_curvature(disk()._core, np.array([[0.0, 0.0, 0.3, 0.0]]))[0] > 0.5
    for model, q0, v0 in ((disk(), [0, 0, THETA0, 0], V0), (sphere(), [0.0, 0.0, np.pi, np.pi / 2, 0.0], [1.0, 0.3, 0.0, 0.3, 1.0]),
                          (sleigh, [0.0, 0.0, 0.0], [0.0, 1.0, 1.0])):
        assert not varmech.constraints.integrable_near(model, q0)
        with warnings.catch_warnings():
            warnings.simplefilter("error", varmech.IntegrableConstraintsWarning)
            varmech.integrate(model, q0, v0=v0, dt=0.1, steps=3)
    # A model without velocity constraints has nothing to test.
    with pytest.raises(ValueError, match="^model"):
        varmech.constraints.integrable_near(varmech.scenes.pendulum().model, [0.1])


def test_symbolic_velocity_constraints_derive_a_and_run_natively_as_the_closures_do():
    # The disk from SymPy: A = ∂c/∂q̇ and ∂A/∂q derived, compiled; θ's column of A is 0, so its
    # momentum (the spin about the vertical) is cyclic, while x, y, φ are moved by the rolling.
    sp = pytest.importorskip("sympy")
    import varmech.symbolic

    x, y, th, ph, R = sp.symbols("x y theta phi R")
    q = [x, y, th, ph]
    v = sp.symbols("v_x v_y v_theta v_phi")
    T = (v[0] ** 2 + v[1] ** 2) / 2 + MASS[2] * v[2] ** 2 / 2 + MASS[3] * v[3] ** 2 / 2
    rolling_rows = [v[0] - R * sp.cos(th) * v[3], v[1] - R * sp.sin(th) * v[3]]
    model = varmech.symbolic.lagrangian(T, q, v, velocity_constraints=rolling_rows, parameters={R: 1.0})
    assert model.velocity_constraints == 2 and model.kind.name == "nonholonomic" and model.cyclic == (2,)
    assert model.expressions["velocity_constraints"] == (1, 0, 0, -R * sp.cos(th), 0, 1, 0, -R * sp.sin(th))
    run = dict(dt=0.05, steps=2000, save_every=100)
    compiled = varmech.integrate(model, [0, 0, THETA0, 0], v0=V0, **run)
    closure = varmech.integrate(disk(), [0, 0, THETA0, 0], v0=V0, **run)
    assert np.max(np.abs(compiled.q - closure.q)) < 1e-12 and np.max(np.abs(compiled.p - closure.p)) < 1e-12
    assert np.max(compiled.constraint_residuals()[1]) < 1e-13  # Newton's tolerance 1e-14 on O(1) momenta
    report = varmech.check_conservation(compiled)
    assert report.verdict in ("bounded", "conserved to round-off") and report.momenta[0].name == "p_theta"
    assert report.momenta[0].verdict == "conserved to round-off"
    # Frobenius with the exact ∂A: the rolling twists; a radius 2 disk is another run.
    assert not varmech.constraints.integrable_near(model, [0, 0, THETA0, 0])
    bigger = varmech.integrate(model.with_parameters(R=2.0), [0, 0, THETA0, 0], v0=[2 * V0[0], 2 * V0[1], OMEGA, SPIN], **run)
    assert np.max(bigger.constraint_residuals()[1]) < 1e-13


@pytest.mark.parametrize(
    "rows, message",
    [
        (lambda v, q, t: [v[0] ** 2 - v[1]], "not linear in the velocities"),
        (lambda v, q, t: [v[0] - q[1] * v[2] + 1], "part free of the velocities"),
        (lambda v, q, t: [v[0] - t * v[2]], "depends on t"),
    ],
)
def test_symbolic_velocity_constraints_that_are_not_a_q_qdot_are_named(rows, message):
    sp = pytest.importorskip("sympy")
    import varmech.symbolic

    q, v, t = sp.symbols("x y z"), sp.symbols("u v w"), sp.Symbol("t")
    T = sum(s**2 for s in v) / 2
    with pytest.raises(ValueError, match=rf"^velocity_constraints\[0\]: .*{message}"):
        varmech.symbolic.lagrangian(T, q, v, t=t, velocity_constraints=rows(v, q, t))
    # Beside holonomic constraints they are taken too (issue 18: tests/python/test_mixed_constraints.py).
    both = varmech.symbolic.lagrangian(T, q, v, constraints=[q[0]], velocity_constraints=[v[1] - q[0] * v[2]])
    assert (both.constraints, both.velocity_constraints, both.kind.name) == (1, 1, "nonholonomic")
