"""Models from sympy.physics.mechanics: a double pendulum (LagrangesMethod, and a System with
uniform gravity) and a rolling disk (KanesMethod, velocity constraints) give the trajectories of
the same models written as L for symbolic.lagrangian, bit for bit where the expressions are the
same and to round-off where they are written by hand; what varmech cannot take is refused with
the reason."""

from __future__ import annotations

import numpy as np
import pytest

import varmech

sp = pytest.importorskip("sympy")
me = pytest.importorskip("sympy.physics.mechanics")

m1, m2, l1, l2, g = sp.symbols("m1 m2 l1 l2 g", positive=True)
VALUES = {m1: 1.0, m2: 2.0, l1: 1.5, l2: 1.0, g: 9.81}


def same_run(a, b, q0, v0, *, dt=0.01, steps=400, method="midpoint"):
    """The two models' runs from (q0, q̇0): their states, to compare."""
    runs = [varmech.integrate(model, q0, v0=v0, dt=dt, steps=steps, method=method) for model in (a, b)]
    return runs


def double_pendulum_bodies():
    """The double pendulum of point masses, both angles from the downward vertical."""
    q1, q2 = me.dynamicsymbols("q1 q2")
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    P1 = O.locatenew("P1", l1 * (sp.sin(q1) * N.x - sp.cos(q1) * N.y))
    P2 = P1.locatenew("P2", l2 * (sp.sin(q2) * N.x - sp.cos(q2) * N.y))
    for P in (P1, P2):
        P.set_vel(N, P.pos_from(O).dt(N))
    bodies = [me.Particle("b1", P1, m1), me.Particle("b2", P2, m2)]
    return (q1, q2), N, O, bodies


def hand_written_double_pendulum():
    q1, q2, w1, w2 = sp.symbols("q1 q2 w1 w2")
    L = ((m1 + m2) * l1**2 * w1**2 / 2 + m2 * l2**2 * w2**2 / 2 + m2 * l1 * l2 * w1 * w2 * sp.cos(q1 - q2)
         + (m1 + m2) * g * l1 * sp.cos(q1) + m2 * g * l2 * sp.cos(q2))  # fmt: skip
    return varmech.symbolic.lagrangian(L, [q1, q2], [w1, w2], parameters=VALUES)


def test_a_lagranges_method_double_pendulum_is_its_l_bit_for_bit_and_the_hand_written_one_to_round_off():
    (q1, q2), N, O, bodies = double_pendulum_bodies()
    for body in bodies:
        body.potential_energy = body.mass * g * body.point.pos_from(O).dot(N.y)
    L = me.Lagrangian(N, *bodies)
    model = varmech.symbolic.from_mechanics(me.LagrangesMethod(L, [q1, q2]), parameters=VALUES)
    assert model.coordinates == ("q1", "q2") and not model.forced
    as_l = varmech.symbolic.lagrangian(L, [q1, q2], parameters=VALUES)
    mine, its = same_run(model, as_l, [1.0, 0.5], [0.0, 0.3])
    assert np.array_equal(mine.q, its.q) and np.array_equal(mine.p, its.p)
    mine, hand = same_run(model, hand_written_double_pendulum(), [1.0, 0.5], [0.0, 0.3])
    np.testing.assert_allclose(mine.q, hand.q, rtol=0, atol=1e-10)
    assert varmech.check_conservation(mine).verdict == "bounded"


def test_a_system_with_uniform_gravity_is_conservative_as_its_potential_says():
    (q1, q2), N, O, bodies = double_pendulum_bodies()
    u1, u2 = me.dynamicsymbols("u1 u2")
    system = me.System(N, O)
    system.add_coordinates(q1, q2)
    system.add_speeds(u1, u2)
    system.add_kdes(u1 - q1.diff(), u2 - q2.diff())
    system.add_bodies(*bodies)
    system.apply_uniform_gravity(-g * N.y)
    model = varmech.symbolic.from_mechanics(system, parameters=VALUES)
    # Gravity is a potential −F·r from the fixed point, not a force whose work is tracked.
    assert not model.forced and model.kind_name == "lagrangian"
    mine, hand = same_run(model, hand_written_double_pendulum(), [2.0, -1.0], [0.5, 0.0], method="galerkin4")
    np.testing.assert_allclose(mine.q, hand.q, rtol=0, atol=1e-10)
    np.testing.assert_allclose(mine.p, hand.p, rtol=0, atol=1e-10)


def rolling_disk(speeds_in_rates: bool):
    """The upright disk rolling without slipping, q = (x, y, θ heading, φ spin): its bodies'
    velocities in Kane's speeds u, or directly in the rates q̇."""
    x, y, th, ph = q = me.dynamicsymbols("x y th ph")
    R, m = sp.symbols("R m", positive=True)
    u = me.dynamicsymbols("u1:5")
    rates = [c.diff() for c in q]
    w = rates if speeds_in_rates else u
    N = me.ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [th, N.z])
    B = A.orientnew("B", "Axis", [ph, A.y])
    B.set_ang_vel(N, w[2] * N.z + w[3] * A.y)
    O = me.Point("O")
    O.set_vel(N, 0)
    C = O.locatenew("C", x * N.x + y * N.y + R * N.z)
    C.set_vel(N, w[0] * N.x + w[1] * N.y)
    P = C.locatenew("P", -R * N.z)
    P.v2pt_theory(C, N, B)
    disk = me.RigidBody("disk", C, B, m, (me.inertia(A, m * R**2 / 4, m * R**2 / 2, m * R**2 / 4), C))
    rolling = [P.vel(N).dot(N.x), P.vel(N).dot(N.y)]
    return q, u, N, disk, rolling, {R: 0.5, m: 2.0}


def test_a_kanes_method_rolling_disk_is_its_l_and_velocity_constraints_bit_for_bit():
    q, u, N, disk, rolling, values = rolling_disk(speeds_in_rates=False)
    kane = me.KanesMethod(
        N, q_ind=q, u_ind=u[2:], u_dependent=u[:2], kd_eqs=[s - c.diff() for s, c in zip(u, q)],
        velocity_constraints=rolling, bodies=[disk],
    )  # fmt: skip
    model = varmech.symbolic.from_mechanics(kane, parameters=values)
    assert model.coordinates == ("x", "y", "th", "ph") and model.velocity_constraints
    # The same disk with its velocities written in q̇, as L and constraints for lagrangian.
    q, _, N, disk, rolling, values = rolling_disk(speeds_in_rates=True)
    as_l = varmech.symbolic.lagrangian(me.Lagrangian(N, disk), q, parameters=values, velocity_constraints=rolling)
    q0, v0 = [0.0, 0.0, 0.3, 0.0], [0.5 * np.cos(0.3), 0.5 * np.sin(0.3), 0.4, 1.0]
    mine, its = same_run(model, as_l, q0, v0)
    assert np.array_equal(mine.q, its.q) and np.array_equal(mine.p, its.p)
    # It rolls: a circle of radius Rφ̇/θ̇ = 1.25 (to the midpoint rule's O(h²)), the contact's
    # speed Rφ̇ kept.
    centre = 1.25 * np.array([-np.sin(0.3), np.cos(0.3)])
    np.testing.assert_allclose(np.hypot(*(mine.q[:, :2] - centre).T), 1.25, atol=1e-5)
    np.testing.assert_allclose(np.hypot(*mine.v[:, :2].T), 0.5, atol=1e-9)


def test_a_kanes_method_with_a_configuration_constraint_drops_its_derivative():
    # A point mass on a circle of radius l1 in Cartesian coordinates, a damping load on it.
    x, y = me.dynamicsymbols("x y")
    u = me.dynamicsymbols("u1 u2")
    c = sp.symbols("c", positive=True)
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    P = O.locatenew("P", x * N.x + y * N.y)
    P.set_vel(N, u[0] * N.x + u[1] * N.y)
    bob = me.Particle("bob", P, m1)
    bob.potential_energy = m1 * g * y
    kane = me.KanesMethod(
        N, q_ind=[x], u_ind=[u[0]], kd_eqs=[u[0] - x.diff(), u[1] - y.diff()], q_dependent=[y], u_dependent=[u[1]],
        configuration_constraints=[x**2 + y**2 - l1**2], velocity_constraints=[x * u[0] + y * u[1]],
        bodies=[bob], forcelist=[(P, -c * P.vel(N))],
    )  # fmt: skip
    model = varmech.symbolic.from_mechanics(kane, parameters={**VALUES, c: 0.1})
    assert model.constraints == 1 and not model.velocity_constraints and model.forced
    X, Y, VX, VY = sp.symbols("X Y VX VY")
    hand = varmech.symbolic.lagrangian(
        m1 * (VX**2 + VY**2) / 2 - m1 * g * Y, [X, Y], [VX, VY], constraints=[X**2 + Y**2 - l1**2],
        force=[-c * VX, -c * VY], parameters={**VALUES, c: 0.1},
    )  # fmt: skip
    q0 = [1.5 * np.sin(0.5), -1.5 * np.cos(0.5)]
    mine, its = same_run(model, hand, q0, [0.0, 0.0])
    np.testing.assert_allclose(mine.q, its.q, rtol=0, atol=1e-12)
    # Damped: the balance E − W is kept, the energy is not.
    assert mine.work[-1] < 0 and varmech.check_conservation(mine).energy.name == "energy balance"


def test_what_varmech_cannot_take_is_refused_with_the_reason():
    (q1, q2), N, O, bodies = double_pendulum_bodies()
    with pytest.raises(TypeError, match="^system: expected a LagrangesMethod, KanesMethod or System"):
        varmech.symbolic.from_mechanics(bodies[0])
    # A body whose mass changes: it needs the reactive force of what it sheds.
    u1, u2 = me.dynamicsymbols("u1 u2")
    burning = me.Particle("rocket", bodies[0].point, me.dynamicsymbols("mass"))
    system = me.System(N, O)
    system.add_coordinates(q1, q2)
    system.add_speeds(u1, u2)
    system.add_kdes(u1 - q1.diff(), u2 - q2.diff())
    system.add_bodies(burning, bodies[1])
    with pytest.raises(ValueError, match="^system: body rocket's mass or inertia changes with t .*mass_flow"):
        varmech.symbolic.from_mechanics(system, parameters=VALUES)
    # A velocity constraint that is not affine in q̇.
    method = me.LagrangesMethod(me.Lagrangian(N, *bodies), [q1, q2], nonhol_coneqs=[q1.diff() ** 2 - q2.diff()])
    with pytest.raises(ValueError, match="^system: the velocity constraint .* is not affine"):
        varmech.symbolic.from_mechanics(method, parameters=VALUES)
    # A load of the accelerations is added mass.
    method = me.LagrangesMethod(me.Lagrangian(N, *bodies), [q1, q2], forcelist=[(bodies[0].point, -q1.diff(me.dynamicsymbols._t, 2) * N.x)], frame=N)
    with pytest.raises(ValueError, match="depends on the accelerations.*added_mass"):
        varmech.symbolic.from_mechanics(method, parameters=VALUES)


def test_the_coming_from_pydy_page_runs_and_prints_what_it_shows(capsys):
    import re
    from pathlib import Path

    page = (Path(__file__).resolve().parents[2] / "docs" / "coming_from.md").read_text()
    (code, shown), = re.findall(r"```python\n(.*?)```\n\n```text\n(.*?)```", page, flags=re.S)
    exec(compile(code, "coming_from.md", "exec"), {})
    assert capsys.readouterr().out == shown
