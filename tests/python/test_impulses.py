"""Impulses and sudden constraints against Byerly's closed forms (Generalized Coordinates, 1916,
ch. III; reference/impulses_and_rolling.md): a rod struck at one end, a lamina's centre of
percussion, a spinning sphere set down on a rough wedge, and Carnot's theorem."""

import math
import pickle

import numpy as np
import pytest

import varmech


def _body(m, k2):
    """A lamina (or rod) on a smooth table: (x, y, φ), T = ½m(ẋ² + ẏ²) + ½mk²φ̇²."""
    return varmech.MechanicalSystem(3, lambda q: 0.0, lambda q: np.zeros(3), mass=[m, m, m * k2])


def _point(r, beta):
    """The body point at distance r and angle β from the centre, in the body frame, and its
    Jacobian."""

    def x(q):
        return q[:2] + r * np.array([math.cos(q[2] + beta), math.sin(q[2] + beta)])

    def jac(q):
        s, c = math.sin(q[2] + beta), math.cos(q[2] + beta)
        return np.array([[1.0, 0.0, -r * s], [0.0, 1.0, r * c]])

    return x, jac


def _velocity_of(v, q, r, beta):
    """The velocity of the body point (r, β): v_c + ω × r."""
    angle = q[2] + beta
    return v[:2] + v[2] * r * np.array([-math.sin(angle), math.cos(angle)])


def test_a_rod_struck_at_one_end_moves_off_as_byerly_says():
    # Rod of length 2a along its body x-axis, at angle φ₀, struck at the end (a, 0) by P across it.
    m, a, p_blow, phi0 = 2.0, 1.5, 0.7, 0.4
    rod = _body(m, a * a / 3)
    q = np.array([0.3, -0.2, phi0])
    x, jac = _point(a, 0.0)
    across = p_blow * np.array([-math.sin(phi0), math.cos(phi0)])
    after = varmech.impulse_response(rod, q, np.zeros(3), varmech.Impulse(point=x, jacobian=jac, impulse=across))
    np.testing.assert_allclose(after.v[:2], across / m, rtol=0, atol=1e-15)
    assert after.v[2] == pytest.approx(3 * p_blow / (m * a), rel=1e-14)
    # The struck end at 4P/m, the other at −2P/m, both across the rod.
    unit = across / p_blow
    assert _velocity_of(after.v, q, a, 0.0) @ unit == pytest.approx(4 * p_blow / m, rel=1e-14)
    assert _velocity_of(after.v, q, a, math.pi) @ unit == pytest.approx(-2 * p_blow / m, rel=1e-14)
    expected = 0.5 * m * (p_blow / m) ** 2 + 0.5 * m * (a * a / 3) * (3 * p_blow / (m * a)) ** 2
    assert after.kinetic_change == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize(("b", "k2"), [(0.3, 0.25), (0.8, (1.2**2 + 0.5**2) / 12), (1.1, 0.05)])
def test_the_centre_of_percussion_is_at_k2_over_b_and_does_not_move(b, k2):
    # An impulse along y acting on the line x = b (body frame, φ = 0): the point (−k²/b, 0) on
    # the far side of the centre starts at rest.
    m, p_blow = 1.7, 0.9
    body = _body(m, k2)
    q = np.zeros(3)
    x, jac = _point(b, 0.0)
    after = varmech.impulse_response(body, q, np.zeros(3), varmech.Impulse(point=x, jacobian=jac, impulse=[0.0, p_blow]))
    assert after.v[2] == pytest.approx(p_blow * b / (m * k2), rel=1e-14)
    still = _velocity_of(after.v, q, k2 / b, math.pi)
    assert np.max(np.abs(still)) <= 1e-15 * p_blow / m


@pytest.mark.parametrize("alpha", [0.3, math.pi / 4, 1.1])
def test_a_spinning_sphere_set_down_on_a_rough_wedge_rolls_off_as_byerly_says(alpha):
    # Byerly Art. 28 (b): wedge of mass M on a smooth plane (x), the contact point down the face
    # (y), the sphere's rotation (θ); T = ½Mẋ² + ½m[(ẋ − ẏ cos α)² + ẏ² sin² α] + ½mk²θ̇².
    big, m, a, spin = 3.0, 1.2, 0.4, 5.0
    k2 = 2 * a * a / 5
    c = math.cos(alpha)
    mass = np.array([[big + m, -m * c, 0.0], [-m * c, m, 0.0], [0.0, 0.0, m * k2]])
    model = varmech.MechanicalSystem(3, lambda q: 0.0, lambda q: np.zeros(3), mass=mass)
    q = np.zeros(3)
    before = np.array([0.0, 0.0, spin])
    # Rolling without slipping engages: ẏ − aθ̇ = 0.
    after = varmech.engage(model, q, v=before, velocity_constraints=lambda q: [[0.0, 1.0, -a]])
    ydot = 2 * a * spin * (big + m) / (7 * big + 2 * m + 5 * m * math.sin(alpha) ** 2)
    assert after.v[1] == pytest.approx(ydot, rel=1e-13)
    assert after.v[0] == pytest.approx(m * ydot * c / (big + m), rel=1e-13)
    assert after.v[1] == pytest.approx(a * after.v[2], rel=1e-14)
    # Horizontal momentum stays zero; the energy lost is Carnot's, to round-off.
    assert abs(after.p[0]) <= 1e-15 * m * spin * a
    assert after.energy_lost > 0
    assert after.energy_lost == pytest.approx(after.carnot, rel=1e-13)


def test_carnots_theorem_holds_for_holonomic_constraints_on_a_general_lagrangian():
    # The double pendulum (mass matrix depending on q): engaging "the two rods stay aligned",
    # g = θ₂ − θ₁, loses exactly ½Δq̇ᵀMΔq̇, and the momenta jump along Gᵀ only.
    s = varmech.scenes.double_pendulum()
    q, v = np.array([0.7, -0.4]), np.array([1.3, -0.8])
    after = varmech.engage(s.model, q, v=v, constraints=lambda q: [q[1] - q[0]], jacobian=lambda q: [[-1.0, 1.0]])
    assert after.v[0] == pytest.approx(after.v[1], rel=1e-13)
    assert after.energy_lost == pytest.approx(after.carnot, rel=1e-12)
    jump = after.p - s.model.momentum(q, v, 0.0)
    assert jump[0] == pytest.approx(-jump[1], rel=1e-13)


def test_an_impulse_on_a_general_lagrangian_solves_m_dv_equals_p():
    s = varmech.scenes.double_pendulum()
    q, p = np.array([0.7, -0.4]), np.array([0.2, 0.1])
    blow = np.array([0.5, -0.3])
    after = varmech.impulse_response(s.model, q, p, varmech.Impulse(generalized=blow))
    minv = varmech.impulses.inverse_mass(s.model, q)
    np.testing.assert_allclose(np.linalg.solve(minv, after.v - after.v_before), blow, rtol=1e-12, atol=1e-14)


def test_bad_impulses_are_named():
    rod = _body(1.0, 1 / 3)
    q = np.zeros(3)
    with pytest.raises(ValueError, match="^impulse: give exactly one"):
        varmech.impulse_response(rod, q, np.zeros(3), varmech.Impulse())
    with pytest.raises(ValueError, match="^impulse: a point struck needs"):
        varmech.impulse_response(rod, q, np.zeros(3), varmech.Impulse(point=lambda q: q[:2]))
    with pytest.raises(ValueError, match="^generalized: "):
        varmech.impulse_response(rod, q, np.zeros(3), varmech.Impulse(generalized=[1.0, 2.0]))
    with pytest.raises(ValueError, match=r"^jacobian returned an array of shape \[3, 3\], expected \[2, 3\]"):
        varmech.impulse_response(rod, q, np.zeros(3), varmech.Impulse(point=lambda q: q[:2], jacobian=lambda q: np.eye(3), impulse=[1.0, 0.0]))
    with pytest.raises(TypeError, match="^impulse: expected a varmech.Impulse"):
        varmech.impulse_response(rod, q, np.zeros(3), [1.0, 0.0, 0.0])
    with pytest.warns(varmech.DerivativeWarning, match="central differences"):
        after = varmech.impulse_response(rod, q, np.zeros(3), varmech.Impulse(point=lambda q: q[:2], impulse=[0.0, 1.0]))
    np.testing.assert_allclose(after.v, [0.0, 1.0, 0.0], atol=1e-9)
    with pytest.raises(ValueError, match="^constraints, velocity_constraints: give exactly one"):
        varmech.engage(rod, q, np.zeros(3))
    with pytest.raises(ValueError, match="^velocity_constraints: expected a matrix with 3 columns"):
        varmech.engage(rod, q, np.zeros(3), velocity_constraints=lambda q: [[1.0, 0.0]])


def _oscillator_after_blow(t, t_star, blow):
    """The harmonic oscillator from q = 0, p = 1, struck at t* by Δp = blow: exact (q, p) at t."""
    q_star, p_star = math.sin(t_star), math.cos(t_star) + blow
    s = t - t_star
    return q_star * math.cos(s) + p_star * math.sin(s), -q_star * math.sin(s) + p_star * math.cos(s)


@pytest.mark.parametrize(("method", "order", "h"), [("verlet", 2, 0.02), ("kahan_li6", 6, 0.2), ("midpoint", 2, 0.02)])
def test_an_impulse_between_grid_points_keeps_the_methods_order(method, order, h):
    s = varmech.scenes.harmonic_oscillator()
    t_star, blow, t_end = 1.2345, 0.7, 6.0
    exact = _oscillator_after_blow(t_end, t_star, blow)
    errors = []
    for dt in (h, h / 2, h / 4):
        steps = round(t_end / dt)
        traj = varmech.integrate(s, [0.0], [1.0], dt=dt, steps=steps, method=method, impulses=[varmech.Impulse(generalized=[blow], t=t_star)])
        assert traj.t[-1] == pytest.approx(t_end, abs=1e-12) and traj.steps == steps
        errors.append(max(abs(traj.q[-1, 0] - exact[0]), abs(traj.p[-1, 0] - exact[1])))
        # The jump is saved: two rows at t*, the momenta differing by the blow.
        at = np.flatnonzero(traj.t == t_star)
        assert len(at) == 2 and traj.p[at[1], 0] - traj.p[at[0], 0] == pytest.approx(blow, rel=1e-14)
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(np.abs(orders - order) < 0.3), (errors, orders)


def test_an_impulse_on_the_grid_jumps_there_and_the_run_goes_on_as_a_new_one():
    s = varmech.scenes.harmonic_oscillator()
    dt, blow = 0.05, [0.4]
    traj = varmech.integrate(s, [0.0], [1.0], dt=dt, steps=200, impulses=[varmech.Impulse(generalized=blow, t=40 * dt)])
    before = varmech.integrate(s, [0.0], [1.0], dt=dt, steps=40)
    after = varmech.integrate(s, before.q[-1], before.p[-1] + blow, dt=dt, steps=160, t0=float(before.t[-1]))
    np.testing.assert_array_equal(traj.q[:41], before.q)
    np.testing.assert_array_equal(traj.q[-1], after.q[-1])
    np.testing.assert_array_equal(traj.p[-1], after.p[-1])


def test_an_impulse_on_a_constrained_model_keeps_the_constraints():
    # A blow on the Cartesian pendulum's bob: the rod's constraint impulse takes the radial part.
    s = varmech.scenes.cartesian_pendulum()
    blow = varmech.Impulse(generalized=[0.3, 0.2], t=0.5)
    traj = varmech.integrate(s, dt=0.01, steps=200, impulses=[blow])
    g, gv = traj.constraint_residuals()
    assert np.max(g) < 1e-12 and np.max(gv) < 1e-12


def test_bad_impulse_times_are_named():
    s = varmech.scenes.harmonic_oscillator()
    with pytest.raises(ValueError, match="^impulses: a time 50.0 outside"):
        varmech.integrate(s, dt=0.1, steps=100, impulses=[varmech.Impulse(generalized=[1.0], t=50.0)])
    with pytest.raises(TypeError, match=r"^impulses\[0\]: expected a varmech.Impulse"):
        varmech.integrate(s, dt=0.1, steps=100, impulses=[[1.0]])
    with pytest.raises(ValueError, match=r"^impulses: impulses\[0\]: 2 components of impulse for 1 coordinates"):
        varmech.integrate(s, dt=0.1, steps=100, impulses=[varmech.Impulse(generalized=[1.0, 2.0], t=1.0)])
    with pytest.raises(ValueError, match="^impulse: give exactly one"):
        varmech.integrate(s, dt=0.1, steps=100, impulses=[varmech.Impulse(t=1.0)])


def test_a_users_exception_in_a_blow_propagates_unchanged_with_the_partial_run():
    s = varmech.scenes.harmonic_oscillator()

    def broken(q):
        raise KeyError("mine")

    with pytest.raises(KeyError, match="mine") as caught:
        varmech.integrate(s, dt=0.1, steps=100, impulses=[varmech.Impulse(generalized=broken, t=2.05)])
    assert caught.value.partial.t[-1] == pytest.approx(2.0)


@pytest.mark.parametrize("method", ["verlet", "kahan_li6"])
def test_samples_after_a_blow_follow_the_struck_motion_at_the_methods_order(method):
    # t_eval and impulses compose: each sample is a partial step from the last jump before it.
    s = varmech.scenes.harmonic_oscillator()
    t_star, blow = 1.2345, 0.7
    times = np.linspace(0.0137, 5.9, 40)
    exact = np.array([_oscillator_after_blow(t, t_star, blow) if t > t_star else (math.sin(t), math.cos(t)) for t in times])
    errors = []
    for dt in (0.1, 0.05):
        traj = varmech.integrate(
            s, [0.0], [1.0], dt=dt, steps=round(6.0 / dt), method=method, impulses=[varmech.Impulse(generalized=[blow], t=t_star)], t_eval=times
        )
        np.testing.assert_array_equal(traj.t, times)
        errors.append(np.max(np.abs(np.column_stack([traj.q[:, 0], traj.p[:, 0]]) - exact)))
    order = {"verlet": 2, "kahan_li6": 6}[method]
    assert abs(math.log2(errors[0] / errors[1]) - order) < 0.4, errors


def test_an_event_after_a_blow_is_located_on_the_struck_motion():
    # The oscillator at rest at q = 1 (p = 0), struck at t* = 0.3 by Δp = 1: the event q = 0 comes
    # at the exact crossing of the struck motion.
    s = varmech.scenes.harmonic_oscillator()
    t_star = 0.3
    q_star, p_star = math.cos(t_star), -math.sin(t_star) - 1.0
    # q(t) = q* cos s + p* sin s = 0 at s = atan2(q*, −p*).
    exact = t_star + math.atan2(q_star, -p_star)

    def height(t, q, p):
        return q[0]

    height.terminal = True  # type: ignore[attr-defined]
    traj = varmech.integrate(
        s, [1.0], [0.0], dt=1e-3, steps=2000, method="kahan_li8", impulses=[varmech.Impulse(generalized=[-1.0], t=t_star)], events=[height]
    )
    assert traj.events[0].t[0] == pytest.approx(exact, abs=1e-10)
    assert traj.status == 1


def test_a_run_with_impulses_goes_on_with_those_still_to_come_in_memory_and_from_its_file(tmp_path):
    # A terminal event stops the run before its second blow; the continued run applies it, bit
    # for bit the run that was never stopped (watching never changes what a run computes).
    s = varmech.scenes.harmonic_oscillator()
    blows = [varmech.Impulse(generalized=[0.5], t=0.1234), varmech.Impulse(generalized=lambda q: [q[0]], t=3.0005)]

    def falling(t, q, p):
        return q[0] - 0.5

    falling.terminal, falling.direction = True, -1  # type: ignore[attr-defined]
    whole = varmech.integrate(s, [0.0], [1.0], dt=0.01, steps=400, impulses=blows)
    half = varmech.integrate(s, [0.0], [1.0], dt=0.01, steps=400, impulses=blows, events=[falling])
    assert half.status == 1 and half.t[-1] < 3.0005
    assert [imp.t for imp in half.impulses] == [0.1234, 3.0005]
    more = varmech.integrate(half, t_end=4.0)
    np.testing.assert_array_equal(more.q[-1], whole.q[-1])
    np.testing.assert_array_equal(more.p[-1], whole.p[-1])
    path = tmp_path / "struck.h5"
    varmech.integrate(s, [0.0], [1.0], dt=0.01, steps=400, impulses=blows, events=[falling], output=path)
    with pytest.raises(ValueError, match=r"^impulses: the run's impulses at t = 3.0005 were given by Python functions"):
        varmech.resume(path, t_end=4.0)
    resumed = varmech.resume(path, t_end=4.0, impulses=blows)
    np.testing.assert_array_equal(resumed.q[-1], whole.q[-1])
    np.testing.assert_array_equal(resumed.p[-1], whole.p[-1])


def test_a_stepper_applies_its_impulses_as_a_run_does_bit_for_bit():
    s = varmech.scenes.bouncing_ball()
    blows = [varmech.Impulse(generalized=[1.0], t=0.0), varmech.Impulse(generalized=[2.0], t=0.3047), varmech.Impulse(generalized=[-1.0], t=1.5)]
    run = varmech.integrate(s, dt=0.01, steps=300, impulses=blows)
    stepper = varmech.Stepper(s, dt=0.01, impulses=blows)
    assert stepper.p[0] == run.p[1]  # the blow at t0 acts at once
    for _ in range(100):
        stepper.step()
    stepper.advance(50)
    # Pickled and checkpointed steppers go on with the impulses still to come.
    again = pickle.loads(pickle.dumps(stepper))
    resumed = varmech.Stepper.from_checkpoint(s, stepper.checkpoint(), impulses=blows)
    for each in (stepper, again, resumed):
        each.advance(150)
        np.testing.assert_array_equal(each.q, run.q[-1])
        np.testing.assert_array_equal(each.p, run.p[-1])
    with pytest.raises(ValueError, match=r"^impulses: a time -1.0 outside the run's span \[0.0, inf\]"):
        varmech.Stepper(s, dt=0.01, impulses=[varmech.Impulse(generalized=[1.0], t=-1.0)])


@pytest.mark.parametrize("model", ["native", "closure"])
def test_an_ensemble_with_impulses_and_t_eval_is_each_members_single_run(model):
    # Native models run on threads (their impulses given as numbers), closures member by member.
    s = varmech.scenes.harmonic_oscillator()
    m = s.model if model == "native" else varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2, lambda q: q.copy())
    q0 = np.array([[0.0], [0.5], [1.0]])
    blows = [varmech.Impulse(generalized=[0.7], t=1.2345)]
    times = np.linspace(0.01, 2.9, 13)
    ens = varmech.ensemble(m, q0, np.ones((3, 1)), dt=0.01, steps=300, impulses=blows, t_eval=times, progress=False)
    for i, traj in enumerate(ens.trajectories):
        single = varmech.integrate(m, q0[i], [1.0], dt=0.01, steps=300, impulses=blows, t_eval=times, progress=False)
        np.testing.assert_array_equal(traj.t, times)
        np.testing.assert_array_equal(traj.q, single.q)
        np.testing.assert_array_equal(traj.p, single.p)
