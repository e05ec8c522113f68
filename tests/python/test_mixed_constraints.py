"""Holonomic constraints g(q) = 0 and velocity constraints A(q)q̇ = 0 on one model: a knife edge
(a skate) on an inclined plane, its heading written redundantly as a unit vector (c, s) held to
the circle c² + s² = 1, q = (x, y, c, s): L = ½(ẋ² + ẏ²) + ½J(ċ² + ṡ²) + a x (a = g sin α, x
down the slope), g(q) = ½(c² + s² − 1), no sideways slip s ẋ − c ẏ = 0. Turned at ω from rest
heading down the slope, it follows Neimark & Fufaev's closed form (Bloch, *Nonholonomic
Mechanics and Control*, §1.6): φ = ωt, x = (a/2ω²) sin²ωt, y = (a/2ω²)(ωt − ½ sin 2ωt)."""

import numpy as np
import pytest

import varmech

SLOPE, INERTIA, OMEGA = 1.0, 0.5, 1.3
Q0, V0 = [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, OMEGA]


def circle(q):
    return np.array([0.5 * (q[2] ** 2 + q[3] ** 2 - 1.0)])


def circle_jacobian(q):
    return np.array([[0.0, 0.0, q[2], q[3]]])


def blade(q):
    return np.array([[q[3], -q[2], 0.0, 0.0]])


def skate(velocity_constraints=blade, constraints=circle, constraint_count=1, velocity_constraint_count=1):
    return varmech.MechanicalSystem(
        4, lambda q: -SLOPE * q[0], lambda q: np.array([-SLOPE, 0.0, 0.0, 0.0]), mass=[1.0, 1.0, INERTIA, INERTIA],
        constraints=constraints, constraint_jacobian=circle_jacobian, constraint_count=constraint_count,
        velocity_constraints=velocity_constraints, velocity_constraint_count=velocity_constraint_count, name="skate",
    )


def exact(t):
    s, c = np.sin(OMEGA * t), np.cos(OMEGA * t)
    k = SLOPE / (2 * OMEGA**2)
    return np.array([k * s * s, k * (OMEGA * t - s * c), c, s])


def test_the_skate_holds_both_constraints_at_round_off_with_a_bounded_energy():
    model = skate()
    assert model.kind.name == "nonholonomic" and model.kind.default_method == "midpoint"
    assert model.constraints == 1 and model.velocity_constraints == 1
    traj = varmech.integrate(model, Q0, v0=V0, dt=0.05, steps=20_000, save_every=10)
    position, velocity = traj.constraint_residuals()
    assert np.max(position) < 1e-14 and np.max(velocity) < 1e-13, (np.max(position), np.max(velocity))
    report = varmech.check_conservation(traj)
    assert report.energy.verdict == "bounded", str(report)
    assert [c.name for c in report.constraints] == ["|g(q)|", "|G q̇, A q̇ + b|"]
    assert all(c.verdict == "conserved to round-off" for c in report.constraints), str(report)
    # No drift: the energy error over the last tenth of the run as over the first (6.25e-4).
    e = report.energy
    energy = 0.5 * np.sum(traj.p**2 / np.array([1.0, 1.0, INERTIA, INERTIA]), axis=1) - SLOPE * traj.q[:, 0]
    first, last = (np.max(np.abs(part - energy[0])) for part in (energy[:200], energy[-200:]))
    assert 0 < first < 1e-3 and last <= 1.5 * first and e.max_abs_error <= 1.5 * first, (first, last)


@pytest.mark.parametrize("method, h0, order", [("midpoint", 0.1, 2.0), ("dla4", 0.2, 4.0)])
def test_the_skate_follows_the_closed_form_to_the_methods_order(method, h0, order):
    errors = []
    for h in (h0, h0 / 2, h0 / 4):
        traj = varmech.integrate(skate(), Q0, v0=V0, dt=h, t_end=4.0, method=method)
        errors.append(np.max(np.abs(traj.q[-1] - exact(traj.t[-1]))))
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(np.abs(orders - order) < 0.25), (errors, orders)


def test_symbolic_and_closure_skates_take_the_same_steps():
    sp = pytest.importorskip("sympy")
    import varmech.symbolic

    x, y, c, s, a = sp.symbols("x y c s a")
    v = sp.symbols("v_x v_y v_c v_s")
    model = varmech.symbolic.mechanical(
        -a * x, [x, y, c, s], sp.diag(1, 1, INERTIA, INERTIA), v=v, parameters={a: SLOPE},
        constraints=[(c**2 + s**2 - 1) / 2], velocity_constraints=[s * v[0] - c * v[1]],
    )
    assert model.constraints == 1 and model.velocity_constraints == 1 and model.kind.name == "nonholonomic"
    run = dict(dt=0.05, steps=2_000, save_every=100)
    compiled = varmech.integrate(model, Q0, v0=V0, **run)
    closure = varmech.integrate(skate(), Q0, v0=V0, **run)
    assert np.max(np.abs(compiled.q - closure.q)) < 1e-12 and np.max(np.abs(compiled.p - closure.p)) < 1e-12
    assert np.max(compiled.constraint_residuals()[0]) < 1e-14 and np.max(compiled.constraint_residuals()[1]) < 1e-13
    steeper = varmech.integrate(model.with_parameters(a=2.0), Q0, v0=V0, dt=0.05, t_end=4.0)
    # Twice the slope: x and y twice as far, the heading as before (to the method's O(h²)).
    assert np.max(np.abs(steeper.q[-1] - exact(4.0) * [2, 2, 1, 1])) < 2e-2


def test_a_mass_closure_skate_takes_the_closure_skates_steps():
    # The natural-system path (a mass closure M(q), here constant): the same states to round-off.
    natural = varmech.MechanicalSystem(
        4, lambda q: -SLOPE * q[0], lambda q: np.array([-SLOPE, 0.0, 0.0, 0.0]),
        mass=lambda q: np.diag([1.0, 1.0, INERTIA, INERTIA]), mass_derivative=lambda q: np.zeros((4, 4, 4)),
        constraints=circle, constraint_jacobian=circle_jacobian, constraint_count=1,
        velocity_constraints=blade, velocity_constraint_count=1,
    )
    assert (natural.kind.name, natural.constraints, natural.velocity_constraints) == ("nonholonomic", 1, 1)
    run = dict(dt=0.05, steps=2_000, save_every=100)
    a, b = varmech.integrate(natural, Q0, v0=V0, **run), varmech.integrate(skate(), Q0, v0=V0, **run)
    assert np.max(np.abs(a.q - b.q)) < 1e-12 and np.max(np.abs(a.p - b.p)) < 1e-12  # measured 8.8e-14
    assert np.max(a.constraint_residuals()[0]) < 1e-15 and np.max(a.constraint_residuals()[1]) < 1e-14
    assert "|G q̇, A q̇ + b| = " in str(varmech.check_conservation(a))


def test_a_height_held_at_zero_changes_nothing_in_the_plane():
    # The skate with its heading an angle, q = (x, y, φ), and the same skate lifted by a height
    # z that gravity pulls down and g(q) = z holds at 0: the same steps, to round-off.
    def knife(q):
        return np.array([[np.sin(q[2]), -np.cos(q[2]), 0.0] + [0.0] * (len(q) - 3)])

    flat = varmech.MechanicalSystem(
        3, lambda q: -SLOPE * q[0], lambda q: np.array([-SLOPE, 0.0, 0.0]), mass=[1.0, 1.0, INERTIA],
        velocity_constraints=knife, velocity_constraint_count=1,
    )
    lifted = varmech.MechanicalSystem(
        4, lambda q: -SLOPE * q[0] + 9.81 * 2.0 * q[3], lambda q: np.array([-SLOPE, 0.0, 0.0, 9.81 * 2.0]),
        mass=[1.0, 1.0, INERTIA, 2.0], constraints=lambda q: q[3:], constraint_jacobian=lambda q: np.array([[0.0, 0, 0, 1]]),
        constraint_count=1, velocity_constraints=knife, velocity_constraint_count=1,
    )
    a = varmech.integrate(flat, [0.0, 0.0, 0.0], v0=[0.0, 0.0, OMEGA], dt=0.05, steps=2_000)
    b = varmech.integrate(lifted, [0.0] * 4, v0=[0.0, 0.0, OMEGA, 0.0], dt=0.05, steps=2_000)
    assert np.max(np.abs(a.q - b.q[:, :3])) < 1e-13 and np.max(np.abs(a.p - b.p[:, :3])) < 1e-13
    assert np.max(np.abs(b.q[:, 3])) == 0.0 and np.max(np.abs(b.p[:, 3])) < 1e-15


def test_initial_data_off_either_constraint_is_refused_by_name_and_project_puts_it_on_both():
    model = skate()
    with pytest.raises(ValueError, match="^q0: is off the holonomic constraints"):
        varmech.integrate(model, [0.0, 0.0, 1.1, 0.0], v0=V0, dt=0.1, steps=3)
    with pytest.raises(ValueError, match="^v0: is off the velocity constraints"):
        varmech.integrate(model, Q0, v0=[0.0, 0.3, 0.0, OMEGA], dt=0.1, steps=3)
    with pytest.raises(ValueError, match="^p0: is off the constraints' velocities"):
        varmech.integrate(model, Q0, [0.0, 0.0, 0.2, INERTIA * OMEGA], dt=0.1, steps=3)
    with pytest.raises(ValueError, match="^method: rattle does not integrate velocity constraints"):
        varmech.integrate(model, Q0, v0=V0, dt=0.1, steps=3, method="rattle")
    q, p = varmech.project(model, [0.1, 0.2, 1.1, 0.1], [0.4, 0.3, 0.2, 0.6])
    v = p / np.array([1.0, 1.0, INERTIA, INERTIA])
    assert abs(circle(q)[0]) < 1e-15 and abs(blade(q)[0] @ v) < 1e-15 and abs(circle_jacobian(q)[0] @ v) < 1e-15
    assert len(varmech.integrate(model, q, p, dt=0.1, steps=3).t) == 4


def test_bad_mixed_input_is_named():
    with pytest.raises(ValueError, match="^velocity_constraint_count: with the 2 holonomic constraints, at most dim − 1 − 2 = 1"):
        skate(constraints=lambda q: np.array([circle(q)[0], q[1]]), constraint_count=2, velocity_constraint_count=2,
              velocity_constraints=lambda q: np.vstack([blade(q), blade(q)]))
    with pytest.raises(ValueError, match=r"velocity_constraints\(q\) returned an array of shape \[4\], expected \[1, 4\]"):
        varmech.integrate(skate(velocity_constraints=lambda q: np.zeros(4)), Q0, v0=V0, dt=0.1, steps=3)
    with pytest.raises(ValueError, match=r"constraints\(q\) returned"):
        varmech.integrate(skate(constraints=lambda q: np.zeros(2)), Q0, v0=V0, dt=0.1, steps=3)


def test_too_many_symbolic_constraints_together_are_named():
    sp = pytest.importorskip("sympy")
    import varmech.symbolic

    x, y, th = sp.symbols("x y theta")
    v = sp.symbols("v_x v_y v_theta")
    with pytest.raises(ValueError, match="^velocity_constraints: with the 1 holonomic constraints"):
        varmech.symbolic.mechanical(0 * x, [x, y, th], 1, v=v, constraints=[y], velocity_constraints=[v[0] - v[2], v[1] + x * v[2]])
