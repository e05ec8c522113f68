"""Models from sympy.physics.mechanics: a double pendulum (LagrangesMethod, and a System with
uniform gravity) and a rolling disk (KanesMethod, velocity constraints) give the trajectories of
the same models written as L for symbolic.lagrangian, bit for bit where the expressions are the
same and to round-off where they are written by hand; SymPy's own rolling disc, whose kinematics
embed the rolling, is imported with its contact's coordinates and runs as Kane's equations do; a
model that does not give its source's equations is refused naming the first differing one; what
varmech cannot take is refused with the reason."""

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


def bead_on_circle():
    """A point mass on a circle of radius l1 in Cartesian coordinates, its gravity its
    potential_energy, a damping load on it (KanesMethod, a configuration constraint)."""
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
    return kane, c


def test_a_kanes_method_with_a_configuration_constraint_drops_its_derivative():
    kane, c = bead_on_circle()
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
    examples = re.findall(r"```python\n(.*?)```\n\n```text\n(.*?)```", page, flags=re.S)
    assert len(examples) == 2
    for code, shown in examples:
        exec(compile(code, "coming_from.md", "exec"), {})
        assert capsys.readouterr().out == shown


def sympys_rolling_disc(centre_rolls=True):
    """SymPy's rolling disc as its own tests build it (sympy/physics/mechanics/tests/test_kane.py,
    test_rolling_disc): body-fixed speeds u (ω of the disc in the lean frame L), the rolling
    built into the kinematics by the contact point C's velocity set to zero and the centre's
    velocity ω × r from it; gravity a load. ``centre_rolls=False``: the centre set to move at
    r·u2 along L.x instead, a constraint that is no rolling (ω × r adds −r·u1 L.y)."""
    q1, q2, q3, u1, u2, u3 = me.dynamicsymbols("q1 q2 q3 u1 u2 u3")
    r, m = sp.symbols("r m")
    N = me.ReferenceFrame("N")
    Y = N.orientnew("Y", "Axis", [q1, N.z])
    L = Y.orientnew("L", "Axis", [q2, Y.x])
    R = L.orientnew("R", "Axis", [q3, L.y])
    w_R_N_qd = R.ang_vel_in(N)
    R.set_ang_vel(N, u1 * L.x + u2 * L.y + u3 * L.z)
    C = me.Point("C")
    C.set_vel(N, 0)
    Dmc = C.locatenew("Dmc", r * L.z)
    if centre_rolls:
        Dmc.v2pt_theory(C, N, R)
    else:
        Dmc.set_vel(N, r * u2 * L.x)
    inertia = me.inertia(L, m / 4 * r**2, m / 2 * r**2, m / 4 * r**2)
    kd = [(R.ang_vel_in(N) - w_R_N_qd).dot(e) for e in L]
    disc = me.RigidBody("BodyD", Dmc, R, m, (inertia, Dmc))
    kane = me.KanesMethod(N, q_ind=[q1, q2, q3], u_ind=[u1, u2, u3], kd_eqs=kd, bodies=[disc], forcelist=[(Dmc, -m * g * Y.z)])
    return kane, {r: 1.0, m: 1.0, g: 1.0}


def kanes_run(kane, values, x0, t_end):
    """Kane's equations (kane.rhs()) and the contact's rolling ẋ = r q̇3 cos q1, ẏ = r q̇3 sin q1
    (r = 1) under SciPy's DOP853 at rtol 1e-12: (q1, q2, q3, x, y) at t_end."""
    from scipy.integrate import solve_ivp

    q1 = kane.q[0]
    kane.kanes_equations()
    rhs = kane.rhs().xreplace(values)
    f = sp.lambdify([*kane.q, *kane.u], [*rhs, rhs[2] * sp.cos(q1), rhs[2] * sp.sin(q1)])
    sol = solve_ivp(lambda t, s: np.asarray(f(*s[:6]), float), (0, t_end), [*x0, 0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14)
    return sol.y[[0, 1, 2, 6, 7], -1]


def test_sympys_rolling_disc_gets_its_contact_coordinates_and_runs_as_kanes_equations():
    kane, values = sympys_rolling_disc()
    model = varmech.symbolic.from_mechanics(kane, parameters=values)
    assert model.coordinates == ("q1", "q2", "q3", "C_x", "C_y") and model.velocity_constraints
    # Heading q1, lean q2, spin q3; u = (0, 2, 0.3): spinning fast enough to stay up (the
    # critical u2 is 1/√3), leaning 0.2 rad; q̇ by the kinematic equations, the contact's rates
    # by the rolling.
    q0, (u1, u2, u3) = [0.0, 0.2, 0.0], (0.0, 2.0, 0.3)
    rates = [u3 / np.cos(0.2), u1, u2 - u3 * np.tan(0.2)]
    v0 = [*rates, rates[2], 0.0]
    exact = kanes_run(kane, values, [*q0, u1, u2, u3], 10.0)
    errors = []
    for dt in (0.005, 0.0025):
        traj = varmech.integrate(model, [*q0, 0.0, 0.0], v0=v0, dt=dt, t_end=10.0)
        errors.append(np.abs(traj.q[-1] - exact).max())
    # The midpoint rule's O(h²): the largest error at t = 10 (of q and the contact's C) falls 4
    # times as h halves, 6.7e-5 → 1.7e-5 (the lean 0.28037 to 1.3e-5). Taken as L = T − V with
    # the rolling in T (before the check), the lean at t = 10 was 0.2610.
    assert 3.8 < errors[0] / errors[1] < 4.2 and errors[1] < 2e-5
    report = varmech.check_conservation(traj)
    assert report.energy.verdict == "bounded" and not report.momenta


def test_the_check_catches_the_rolling_taken_into_t(monkeypatch):
    # The import before the contact was given its coordinates: L = T − V with the rolling in T.
    from varmech.symbolic import _contact

    monkeypatch.setattr(_contact, "find", lambda *args: (None, ""))
    kane, values = sympys_rolling_disc()
    message = r"^system: the model from_mechanics builds .* du2/dt: Kane's equations fr \+ fr\* give -0.06111676\d+, the model \S+ \("
    with pytest.raises(ValueError, match=message + r"tolerance .*other dynamics$"):
        varmech.symbolic.from_mechanics(kane, parameters=values)


def test_kinematics_embedding_another_constraint_are_refused_naming_the_first_differing_equation():
    kane, values = sympys_rolling_disc(centre_rolls=False)
    with pytest.raises(ValueError, match=(
        r"^system: the model from_mechanics builds .* does not give its equations of motion: at \(q1 = .*\), du1/dt: "
        r"Kane's equations fr \+ fr\* give -0.0599857\d+, the model -0.0771352\d+ .*; its kinematics embed a velocity "
        r"constraint: body BodyD's centre has a velocity that is not the rate of its position from C .*velocity_constraints"
    )):  # fmt: skip
        varmech.symbolic.from_mechanics(kane, parameters=values)


@pytest.mark.parametrize("source", ["KanesMethod", "LagrangesMethod"])
def test_the_check_catches_a_load_the_import_drops(monkeypatch, source):
    from varmech.symbolic import _mechanics

    if source == "KanesMethod":
        system, c = bead_on_circle()
        values, first = {**VALUES, c: 0.1}, r"du1/dt: Kane's equations fr \+ fr\*"
    else:
        (q1, q2), N, O, bodies = double_pendulum_bodies()
        push = (bodies[1].point, -0.5 * bodies[1].point.vel(N))
        system = me.LagrangesMethod(me.Lagrangian(N, *bodies), [q1, q2], forcelist=[push], frame=N)
        values, first = VALUES, "d²q1/dt²: the LagrangesMethod's equations"
    assert varmech.symbolic.from_mechanics(system, parameters=values).forced
    monkeypatch.setattr(_mechanics, "_generalized_forces", lambda *args, **kwargs: None)
    with pytest.raises(ValueError, match=f"^system: the model from_mechanics builds .*, {first} give "):
        varmech.symbolic.from_mechanics(system, parameters=values)


def test_a_source_whose_equations_cannot_be_formed_is_refused():
    # SymPy's rolling disc without its bodies: there is no fr* to form.
    kane, _ = sympys_rolling_disc()
    bare = me.KanesMethod(kane._inertial, q_ind=kane.q, u_ind=kane.u, kd_eqs=[rate - u for rate, u in kane.kindiffdict().items()])
    message = r"^system: Kane's equations fr \+ fr\* could not be formed \(TypeError: Bodies must be supplied in an iterable.\); "
    with pytest.raises(ValueError, match=message + ".*takes no model it cannot check$"):
        varmech.symbolic.from_mechanics(bare, parameters={"r": 1.0, "m": 1.0, "g": 1.0})


def test_a_system_of_sympys_rolling_disc_is_its_kanes_method():
    kane, values = sympys_rolling_disc()
    # The System's own fixed point has no path to the disc: its gravity stays a load.
    system = me.System(kane._inertial)
    system.add_coordinates(*kane.q)
    system.add_speeds(*kane.u)
    system.add_kdes(*[rate - u for rate, u in kane.kindiffdict().items()])
    system.add_bodies(*kane.bodies)
    system.add_loads(*kane.loads)
    model = varmech.symbolic.from_mechanics(system, parameters=values)
    assert model.coordinates == ("q1", "q2", "q3", "C_x", "C_y") and model.forced
    rates = [0.3 / np.cos(0.2), 0.0, 2.0 - 0.3 * np.tan(0.2)]
    mine, its = same_run(model, varmech.symbolic.from_mechanics(kane, parameters=values), [0.0, 0.2, 0.0, 0.0, 0.0], [*rates, rates[2], 0.0])
    assert np.array_equal(mine.q, its.q) and np.array_equal(mine.p, its.p)
