"""Impacts with unilateral constraints (reference/impulses_and_rolling.md): the bouncing ball's
exact bounce times and heights, its restitution law, and the elliptic billiard's focal invariant."""

import functools
import math

import numpy as np
import pytest

import varmech

G = 9.81


def _ball():
    return varmech.MechanicalSystem(1, lambda q: G * q[0], lambda q: np.array([G]), name="ball")


def test_an_elastic_ball_reflected_exactly_bounces_at_the_exact_times_for_ten_thousand_bounces():
    # Dropped from h₀: impacts at t₁(2k + 1), t₁ = √(2h₀/g). Verlet is exact on the parabolas
    # between impacts, each impact is located to round-off, and law="reflect" conserves H there.
    h0, dt = 1.0, 1e-3
    t1 = math.sqrt(2 * h0 / G)
    # The native wall (no Python call per step); the same floor from closures gives the same
    # impacts over the first bounces.
    floor = varmech.Contact.wall(0, name="floor", law="reflect")
    closures = varmech.Contact(lambda q: q[0], lambda q: [1.0], name="floor", law="reflect")
    short = round(20 * t1 / dt)
    native = varmech.integrate(_ball(), [h0], [0.0], dt=dt, steps=short, contacts=[floor]).events[0]
    python = varmech.integrate(_ball(), [h0], [0.0], dt=dt, steps=short, contacts=[closures]).events[0]
    np.testing.assert_array_equal(native.t, python.t)
    steps = round((t1 * 2e4 + t1 / 2) / dt)
    # The native ball (g = 9.81) for the 9·10⁶ steps.
    traj = varmech.integrate(varmech.scenes.bouncing_ball().model, [h0], [0.0], dt=dt, steps=steps, save_every=10**9, contacts=[floor])
    hits = traj.events[0]
    k = np.arange(len(hits))
    assert len(hits) == 10_000
    assert np.max(np.abs(hits.t - t1 * (2 * k + 1))) < 1e-9 * hits.t[-1]
    # On the floor to round-off, and the energy at every impact h₀ (T + V with V = 0 there).
    assert np.max(np.abs(hits.q)) < 1e-12
    assert np.max(np.abs(0.5 * hits.p[:, 0] ** 2 - G * h0)) < 1e-10 * G * h0


@pytest.mark.parametrize("method", ["verlet", "midpoint", "trapezoid"])
def test_the_variational_impact_keeps_the_discrete_energy_so_h_moves_by_g2h2_times_1_minus_2alpha_over_8(method):
    # Verlet's discrete energy on an exact parabola of duration τ is E_d = H − g²τ²/8; the VCI
    # makes E_d(τ₁ = αh) = E_d(τ₂ = (1 − α)h) at the impact, so H jumps by g²h²(1 − 2α)/8 there.
    # With the first impact at the fraction α = 1/4 of a step, the jump and the second impact's
    # time error (2Δv/g) fall at exactly order 2. The implicit midpoint and trapezoidal rules
    # are exact on the parabola too, with the same E_d (H at the mean state, and the mean of
    # the energies at the ends, of a step with v = p₀ − gτ/2).
    t1, alpha = math.sqrt(2 / G), 0.25
    errors = []
    for m in (100, 200, 400):
        dt = t1 / (m + alpha)
        wall = [varmech.Contact.wall(0)]
        hits = varmech.integrate(_ball(), [1.0], [0.0], dt=dt, steps=3 * m + 10, method=method, contacts=wall).events[0]
        assert len(hits) == 2 and abs(hits.t[0] - t1) < 1e-14
        jump = 0.5 * hits.p[1, 0] ** 2 - G
        np.testing.assert_allclose(jump, G * G * dt * dt * (1 - 2 * alpha) / 8, rtol=1e-8)
        errors.append(hits.t[1] - 3 * t1)
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(np.abs(orders - 2.0) < 0.02), (errors, orders)


def test_an_elastic_ball_under_the_variational_impact_keeps_a_bounded_energy_over_ten_thousand_bounces():
    # The jumps g²h²(1 − 2αₖ)/8 do not accumulate: over 10⁴ bounces at h = 1e-3 the energy stays
    # within 8e-6 of gh₀ (one jump is at most 1.2e-6 of it) and no larger in the last half than in
    # the first 1 %, and the bounce times are off by 1.5e-6 of the run at the end (a phase error,
    # from the O(h²) energy offset, as for any symplectic method).
    h0, dt = 1.0, 1e-3
    t1 = math.sqrt(2 * h0 / G)
    steps = round((t1 * 2e4 + t1 / 2) / dt)
    ball = varmech.scenes.bouncing_ball().model  # native, g = 9.81, for the 9·10⁶ steps
    traj = varmech.integrate(ball, [h0], [0.0], dt=dt, steps=steps, save_every=10**9, contacts=[varmech.Contact.wall(0)])
    hits = traj.events[0]
    assert len(hits) == 10_000
    error = np.abs(0.5 * hits.p[:, 0] ** 2 - G * h0) / (G * h0)
    assert error.max() < 8e-6
    assert error[5000:].max() < 1.01 * error[:100].max()
    k = np.arange(len(hits))
    assert np.max(np.abs(hits.t - t1 * (2 * k + 1))) < 1.5e-6 * hits.t[-1]
    assert np.max(np.abs(hits.q)) < 1e-12


@pytest.mark.parametrize("method", ["yoshida4", "suzuki4", "mclachlan4", "kahan_li6"])
def test_a_composition_of_order_four_or_more_keeps_a_balls_energy_to_round_off_through_its_impacts(method):
    # On a parabola a Verlet substep of γτ has E_d = H − g²γ²τ²/8, so a composition's
    # E_d = Σγᵢ E_dᵢ = H − g²τ²Σγᵢ³/8, and Σγᵢ³ = 0 is an order condition of order 4: the discrete
    # energy the VCI keeps is H itself.
    t1 = math.sqrt(2 / G)
    steps = round(2000 * t1 / 1e-2)
    traj = varmech.integrate(_ball(), [1.0], [0.0], dt=1e-2, steps=steps, save_every=10**9, method=method, contacts=[varmech.Contact.wall(0)])
    hits = traj.events[0]
    assert len(hits) == 1000
    assert np.max(np.abs(0.5 * hits.p[:, 0] ** 2 - G)) < 1e-12 * G
    assert np.max(np.abs(hits.t - t1 * (2 * np.arange(1000) + 1))) < 1e-9


@pytest.mark.parametrize(("method", "order", "steps"), [("verlet", 2, (40, 80, 160)), ("yoshida4", 4, (10, 20, 40)), ("kahan_li6", 6, (5, 10, 20))])
def test_the_methods_order_survives_an_impact(method, order, steps):
    # Dropped from rest at y = 1 onto a spring floor force, ÿ = −g − κy: y = −g/κ + (1 + g/κ)cos ωt
    # meets the floor at t = arccos(g/(g + κ))/ω. With the impact at the fraction 0.3 of every
    # run's step, H just after it errs at the method's order (E_d − H = O(h^r) on each side).
    kappa = 4.0
    model = varmech.MechanicalSystem(1, lambda q: G * q[0] + 0.5 * kappa * q[0] ** 2, lambda q: np.array([G + kappa * q[0]]))
    t_hit = math.acos(G / (G + kappa)) / math.sqrt(kappa)
    errors = []
    for m in steps:
        dt = t_hit / (m + 0.3)
        traj = varmech.integrate(model, [1.0], [0.0], dt=dt, steps=m + 3, method=method, contacts=[varmech.Contact.wall(0)], max_energy_error=None)
        assert len(traj.events[0]) == 1
        q, p = traj.q[-1, 0], traj.p[-1, 0]
        errors.append(abs(0.5 * p * p + G * q + 0.5 * kappa * q * q - (G + 0.5 * kappa)))
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert abs(orders[-1] - order) < 0.5, (errors, orders)


def test_an_elastic_balls_bounce_times_converge_at_order_two_under_a_varying_force():
    # A spring floor force makes the flight non-parabolic: V = gy + ½κy², no closed form; the
    # time of the fifth impact converges at Verlet's order against a fine run. With the exact
    # reflection: the variational law's error constants vary with each impact's fraction of the
    # step (its order is measured at a fixed fraction, above).
    kappa = 4.0
    model = varmech.MechanicalSystem(1, lambda q: G * q[0] + 0.5 * kappa * q[0] ** 2, lambda q: np.array([G + kappa * q[0]]))
    floor = varmech.Contact(lambda q: q[0], lambda q: [1.0], law="reflect")

    def fifth(dt):
        traj = varmech.integrate(model, [1.0], [0.0], dt=dt, steps=round(4.0 / dt), save_every=10**9, contacts=[floor])
        return traj.events[0].t[4]

    reference = fifth(1e-5)
    errors = [abs(fifth(dt) - reference) for dt in (4e-3, 2e-3, 1e-3)]
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(np.abs(orders - 2.0) < 0.3), (errors, orders)


@pytest.mark.parametrize("e", [0.9, 0.5])
def test_an_inelastic_balls_heights_fall_by_e_squared_per_bounce(e):
    # Up to 0.97 of the time t₁(1 + 2e/(1 − e)) at which the bounces accumulate (the ball comes
    # to rest): the last steps each hold several impacts.
    floor = varmech.Contact(lambda q: q[0], lambda q: [1.0], restitution=e)
    rest = math.sqrt(2 / G) * (1 + 2 * e / (1 - e))
    traj = varmech.integrate(_ball(), [1.0], [0.0], dt=1e-3, steps=min(3000, round(0.97 * rest / 1e-3)), contacts=[floor])
    hits = traj.events[0]
    speeds = np.abs(hits.p[:, 0])
    assert len(hits) >= 4
    # Apex heights v⁺²/2g after the k-th impact: v⁺ = e v⁻, and v⁻ of the next is v⁺ of this.
    heights = (e * speeds) ** 2 / (2 * G)
    np.testing.assert_allclose(heights[1:] / heights[:-1], e**2, rtol=1e-12)


@pytest.mark.parametrize(("gap", "tolerance"), [(1e-4, 1e-9), (1e-6, 1e-8), (1e-8, 1e-7)])
def test_grazing_impacts_in_an_elliptic_billiard_follow_the_exact_billiard_map_with_no_spurious_bounce(gap, tolerance):
    # A particle sent along the bottom of x²/4 + y² ≤ 1, a gap above it, glances off the wall
    # at an angle of order √gap: chords of 0.057, 0.0057 and 0.00057 against steps of 0.01, so
    # up to 18 impacts fall in one step. The exact billiard map (chords solved exactly, normals
    # reflected) gives each impact; the run finds the same ones, in order, none doubled or lost.
    a, b = 2.0, 1.0
    d = np.diag([1 / a**2, 1 / b**2])
    free = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2), name="free")
    q0, v = np.array([0.0, -(1 - gap)]), np.array([1.0, 0.0])
    point, t = q0.copy(), 0.0
    s = (-2 * point @ d @ v + math.sqrt((2 * point @ d @ v) ** 2 - 4 * (v @ d @ v) * (point @ d @ point - 1))) / (2 * v @ d @ v)
    exact = []
    for _ in range(400):
        point, t = point + s * v, t + s
        exact.append((t, *point))
        normal = d @ point
        v = v - 2 * (v @ normal) / (normal @ normal) * normal
        s = -2 * (point @ d @ v) / (v @ d @ v)
    exact = np.array(exact)
    dt = 0.01
    traj = varmech.integrate(free, q0, [1.0, 0.0], dt=dt, steps=int(exact[-1, 0] / dt), save_every=1000, contacts=[varmech.Contact.ellipsoid([a, b])])
    hits = traj.events[0]
    n = len(hits)
    assert n == np.sum(exact[:, 0] <= traj.t[-1])
    np.testing.assert_allclose(hits.t, exact[:n, 0], rtol=0, atol=tolerance)
    np.testing.assert_allclose(hits.q, exact[:n, 1:], rtol=0, atol=tolerance)


def _trapped():
    # V = ½q² + q: ω = 1, at rest from 0 its lowest point is −2.
    return varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2 + q[0], lambda q: q + 1.0, name="trapped")


@pytest.mark.parametrize("law", ["reflect", "variational"])
def test_a_graze_whose_momentum_already_leaves_the_floor_takes_no_impulse(law):
    # Above the floor q ≥ −2 + δ, Verlet at hω = 1.2–1.6 dips through it near the turning point
    # with the momentum already pointing out (∇φ·q̇ > 0), where Newton's λ < 0 kicked the body
    # into the floor and the run ended ("crosses it again at once") in 36 of the 252 runs of
    # both laws.
    # A surface only pushes: such a crossing takes no impulse, and the body stays above it.
    for h in (1.2, 1.4, 1.6):
        for e in (1.0, 0.5):
            for delta in np.linspace(-0.05, 0.05, 21):
                floor = -2.0 + delta
                wall = varmech.Contact.wall(0, floor, restitution=e, law=law)
                traj = varmech.integrate(_trapped(), [0.0], [0.0], dt=h, steps=60, method="verlet", contacts=[wall])
                assert traj.status == 0 and np.min(traj.q) >= floor - 1e-12, (h, e, delta)


def test_a_run_through_grazes_converges_as_its_step_is_refined():
    # The reproducer of the test above (hω = 1.4, δ = 0.015) refined: q(84) converges.
    wall = [varmech.Contact.wall(0, -1.985)]
    ends = [varmech.integrate(_trapped(), [0.0], [0.0], dt=1.4 / 2**k, steps=60 * 2**k, method="verlet", contacts=wall).q[-1, 0] for k in (3, 5, 7)]
    assert abs(ends[1] - ends[2]) < abs(ends[0] - ends[2]) / 4


def test_a_ball_with_e_below_1_comes_to_rest_at_the_zeno_limit_and_then_rests_on_the_floor():
    # The bounces' flights 2eᵏt₁ sum to t∞ = t₁(1 + e)/(1 − e): the floor closes at the impact
    # whose rebounds would last less than a step, at that limit, and holds the ball at rest.
    e = 0.5
    rest = math.sqrt(2 / G) * (1 + e) / (1 - e)
    floor = varmech.Contact(lambda q: q[0], lambda q: [1.0], restitution=e, name="floor")
    traj = varmech.integrate(_ball(), [1.0], [0.0], dt=1e-3, steps=3000, contacts=[floor])
    impacts, closed, released, stuck, slipped = traj.events
    assert len(stuck) == len(slipped) == 0, "no friction, no friction switches"
    assert (closed.name, released.name) == ("floor.closed", "floor.released")
    assert len(closed) == 1 and len(released) == 0 and abs(closed.t[0] - rest) < 1e-12
    np.testing.assert_allclose(impacts.t[:3], math.sqrt(2 / G) * np.array([1, 1 + 2 * e, 1 + 2 * e + 2 * e * e]), rtol=1e-12)
    # Closed at the last impact (its state), within a step of the limit; at rest from there.
    assert rest - 1e-3 < impacts.t[-1] <= rest
    after = traj.t > impacts.t[-1]
    assert np.sum(after) > 1000 and np.max(np.abs(traj.q[after])) < 1e-15 and np.all(traj.p[after] == 0)
    assert traj.status == 0 and np.min(traj.q) > -1e-12


@pytest.mark.parametrize("method", ["verlet", "rk4", "midpoint"])
def test_a_flight_that_ends_exactly_at_a_steps_end_is_an_impact_at_the_next_steps_start(method):
    # Dropped from 1/2 under g = 1 onto a floor with e = 1/2, the ball lands at t = 1, 2, 2.5,
    # 2.75, …, t∞ = 3; at dt = 1/4 each of these is a step's end, which every method here
    # reaches exactly (q quadratic in t), with φ = 0 there: no crossing of the piece that left
    # the floor, so the next step starts on it moving in, and the impact is there (it was
    # taken for a body resting on the floor, which impacts cannot resolve).
    ball = varmech.MechanicalSystem(1, lambda q: q[0], lambda q: np.array([1.0]), name="ball")
    floor = varmech.Contact.wall(0, 0.0, restitution=0.5, law="reflect")
    run = functools.partial(varmech.integrate, ball, [0.5], [0.0], dt=0.25, method=method, contacts=[floor])
    if method == "verlet":
        # It holds the floor once the rebounds would last less than a step: at rest from t∞.
        traj = run(steps=20)
        impacts, closed = traj.events[:2]
        np.testing.assert_allclose(impacts.t[:4], [1.0, 2.0, 2.5, 2.75], rtol=0, atol=1e-15)
        assert len(closed) == 1 and closed.t[0] == 3.0
        assert np.all(traj.q[traj.t >= 3.0] == 0.0) and traj.status == 0
    else:
        # The others cannot hold it: their impacts go on into the accumulation in the step
        # from 2.75 (to t's resolution: flights of 0 are its limit, not a chatter a shorter
        # step resolves), which stops the run with the advice to hold the contact.
        np.testing.assert_allclose(run(steps=11).events[0].t[:3], [1.0, 2.0, 2.5], rtol=0, atol=1e-15)
        with pytest.raises(varmech.ContactError, match="cannot resolve|shrinking to an accumulation at t ≈ 3.0") as info:
            run(steps=20)
        assert info.value.time == 2.75 and "hold such a contact closed" in str(info.value)


def test_symplectic_euler_under_newtons_law_drifts_at_order_one_by_the_same_amount_at_each_impact():
    # Its modified energy H − (h/2)q̇·∇V + O(h²) is odd in p: each reflection moves it by O(h),
    # alike at every impact (15 in t = 60 of a trapped particle on an elastic floor), so the
    # error grows with the impacts and halves with h; Verlet's is even in p, bounded at order 2.
    trap = varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2 + q[0], lambda q: np.array([q[0] + 1.0]), name="trap")
    floor = varmech.Contact.wall(0, -1.5, restitution=1.0, law="reflect")

    def error(method, dt):
        traj = varmech.integrate(trap, [0.0], [1.0], dt=dt, steps=round(60 / dt), method=method, contacts=[floor],
                                 save_every=round(0.5 / dt), max_energy_error=None)
        energy = 0.5 * traj.p[:, 0] ** 2 + 0.5 * traj.q[:, 0] ** 2 + traj.q[:, 0]
        assert len(traj.events[0]) == 15
        return traj.t, np.abs(energy - energy[0])

    t, drift = error("symplectic_euler", 0.01)
    thirds = [np.max(drift[t <= end]) for end in (20, 40, 60)]
    np.testing.assert_allclose(np.array(thirds) / thirds[0], [1, 2, 3], rtol=0.05)
    assert 1.9 < np.max(error("symplectic_euler", 0.02)[1]) / np.max(drift) < 2.1
    t, band = error("verlet", 0.01)
    assert np.max(band) < 1.01 * np.max(band[t <= 20]) and 3.9 < np.max(error("verlet", 0.02)[1]) / np.max(band) < 4.1
    # At a coarse step the drift stops the run, and the advice names its cause and remedies.
    with pytest.raises(varmech.DivergenceError, match="symplectic_euler is not symmetric") as info:
        varmech.integrate(trap, [0.0], [1.0], dt=0.5, steps=2000, method="symplectic_euler", contacts=[floor])
    assert 'take a symmetric method, whose energy stays bounded across impacts: verlet, or law="variational"' in str(info.value)
    for remedy in (dict(method="verlet", contacts=[floor]),
                   dict(method="symplectic_euler", contacts=[varmech.Contact.wall(0, -1.5, law="variational")])):
        assert varmech.integrate(trap, [0.0], [1.0], dt=0.5, steps=2000, **remedy).status == 0


def test_a_method_that_cannot_hold_a_contact_ends_an_accumulation_of_impacts_with_a_contact_error():
    # rk4 cannot hold the floor: past the accumulation time the impacts cannot go on, a typed
    # error with the step and time, and the whole run up to that step, impacts included.
    e = 0.5
    rest = math.sqrt(2 / G) * (1 + 2 * e / (1 - e))
    floor = varmech.Contact(lambda q: q[0], lambda q: [1.0], restitution=e, law="reflect")
    with pytest.raises(varmech.ContactError, match="cannot resolve|more than 64 impacts") as info:
        varmech.integrate(_ball(), [1.0], [0.0], dt=1e-3, steps=3000, contacts=[floor], method="rk4")
    err = info.value
    assert "verlet and its compositions" in str(err)
    assert 0.97 * rest < err.time < rest and err.step == round(err.time / 1e-3) + 1
    partial = err.partial
    assert partial.status == -1 and partial.t[-1] <= err.time and len(partial.events[0]) > 10
    np.testing.assert_allclose(partial.events[0].t[:3], math.sqrt(2 / G) * np.array([1, 1 + 2 * e, 1 + 2 * e + 2 * e * e]), rtol=1e-9)
    assert np.min(partial.q) > -1e-12


@pytest.mark.parametrize("e", [0.95, 0.98, 0.99])
def test_an_accumulation_of_impacts_names_its_time_and_what_helps(e):
    # At e near 1 the bounces shrink slowly and 64 fall within one step before the Zeno time
    # t∞ = t₁(1 + 2e/(1 − e)), whatever the step: the error sums the flights' geometric series
    # to t∞, advises stopping before it or a method that holds the contact, and each holds.
    rest = math.sqrt(2 / G) * (1 + 2 * e / (1 - e))
    floor = varmech.Contact(lambda q: q[0], lambda q: [1.0], restitution=e, law="reflect")
    for method, dt in (("rk4", 0.05), ("midpoint", 0.5), ("midpoint", 0.05 / 16)):
        with pytest.raises(varmech.ContactError, match="more than 64 impacts in one step, their flights shrinking") as info:
            varmech.integrate(_ball(), [1.0], [0.0], dt=dt, steps=round(2 * rest / dt), contacts=[floor], method=method)
        message = str(info.value)
        assert float(message.split("t ≈ ")[1].split(" ")[0]) == pytest.approx(rest, rel=1e-6)
        assert "which no step resolves: stop the run before it, or hold the contact: verlet" in message
        before = varmech.integrate(_ball(), [1.0], [0.0], dt=dt, steps=int(0.99 * rest / dt), contacts=[floor], method=method)
        assert before.status == 0
    held = varmech.integrate(_ball(), [1.0], [0.0], dt=0.05, steps=round(2 * rest / 0.05), contacts=[floor], method="verlet")
    assert held.status == 0 and np.max(np.abs(held.q[held.t > 1.01 * rest])) < 1e-12


def test_a_particle_in_a_box_crosses_two_walls_in_one_step_at_its_corners():
    # A free particle in the unit square, steps of 0.5 against flights of about 1: many steps
    # cross two walls. The exact motion unfolds to a straight line: x = fold(x₀ + vt), with
    # fold(u) = 1 − |1 − (u mod 2)|, and each wall is met where u crosses an integer.
    walls = [
        varmech.Contact.wall(0, name="left"),
        varmech.Contact(lambda q: 1 - q[0], lambda q: [-1.0, 0.0], name="right"),
        varmech.Contact.wall(1, name="bottom"),
        varmech.Contact(lambda q: 1 - q[1], lambda q: [0.0, -1.0], name="top"),
    ]
    free = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2), name="free")
    q0, v = np.array([0.3, 0.6]), np.array([0.9 * math.sqrt(2), 0.7 * math.sqrt(3)])
    dt, steps = 0.5, 2000
    traj = varmech.integrate(free, q0, v, dt=dt, steps=steps, save_every=1, contacts=walls)
    grid = np.isclose((traj.t / dt) % 1, 0) | np.isclose((traj.t / dt) % 1, 1)
    t = traj.t[grid][::1]
    t, index = np.unique(t, return_index=True)
    q = traj.q[grid][index]
    u = q0 + np.outer(t, v)
    exact = 1 - np.abs(1 - np.mod(u, 2))
    assert np.max(np.abs(q - exact)) < 1e-9
    crossings = np.floor(q0 + v * dt * steps)
    assert len(traj.events[0]) + len(traj.events[1]) == int(crossings[0])
    assert len(traj.events[2]) + len(traj.events[3]) == int(crossings[1])
    both = sum(np.sum(np.diff(np.floor(u[:, k])) > 0) for k in (0, 1))
    assert both == int(crossings.sum())
    steps_with_two = np.sum((np.diff(np.floor(u[:, 0])) > 0) & (np.diff(np.floor(u[:, 1])) > 0))
    assert steps_with_two > 100


def _billiard(steps, **options):
    """The elliptic billiard x²/A² + y²/B² ≤ 1 run for ``steps`` steps of 0.2 (``options`` to
    integrate): the run, and over its saved states the largest change of the focal invariant
    L₁L₂, Lᵢ = (x ∓ c)ẏ − yẋ (conserved across elastic impacts), and of the energy ½|p|², and the
    largest x²/A² + y²/B²."""
    a, b = 2.0, 1.0
    c = math.sqrt(a * a - b * b)
    free = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2), name="billiard")
    wall = varmech.Contact(lambda q: 1 - (q[0] / a) ** 2 - (q[1] / b) ** 2, lambda q: [-2 * q[0] / a**2, -2 * q[1] / b**2], name="wall")
    q0, p0 = np.array([0.3, 0.1]), np.array([0.6, 0.8])

    def invariant(q, p):
        return ((q[:, 0] - c) * p[:, 1] - q[:, 1] * p[:, 0]) * ((q[:, 0] + c) * p[:, 1] - q[:, 1] * p[:, 0])

    traj = varmech.integrate(free, q0, p0, dt=0.2, steps=steps, contacts=[wall], **options)
    start = invariant(q0[None, :], p0[None, :])[0]
    return (
        traj,
        np.max(np.abs(invariant(traj.q, traj.p) - start)),
        np.max(np.abs(0.5 * np.sum(traj.p**2, axis=1) - 0.5)),
        np.max((traj.q[:, 0] / a) ** 2 + (traj.q[:, 1] / b) ** 2),
    )


def test_the_elliptic_billiard_keeps_its_focal_invariant_over_ten_thousand_impacts():
    # x²/A² + y²/B² ≤ 1; L₁L₂ with Lᵢ = (x ∓ c)ẏ − yẋ is conserved across elastic impacts.
    traj, invariant, energy, inside = _billiard(105_000, save_every=97)
    hits = traj.events[0]
    assert len(hits) > 10_000
    assert invariant < 1e-10
    assert energy < 1e-12
    assert inside < 1 + 1e-12


def test_bad_contacts_are_named():
    floor = varmech.Contact(lambda q: q[0], lambda q: [1.0])
    with pytest.raises(ValueError, match="^q0: outside the contact"):
        varmech.integrate(_ball(), [-0.1], [0.0], dt=1e-3, steps=10, contacts=[floor])
    with pytest.raises(ValueError, match="^restitution: must lie in"):
        varmech.Contact(lambda q: q[0], lambda q: [1.0], restitution=1.5)
    with pytest.raises(TypeError, match=r"^contacts\[0\]: expected a varmech.Contact"):
        varmech.integrate(_ball(), [1.0], [0.0], dt=1e-3, steps=10, contacts=[lambda q: q[0]])


def _trap():
    # A particle in a harmonic trap under gravity, an oblique floor y + 0.3x ≥ 0.
    kappa = 4.0
    return varmech.MechanicalSystem(
        2, lambda q: G * q[1] + 0.5 * kappa * (q[0] ** 2 + q[1] ** 2), lambda q: np.array([kappa * q[0], G + kappa * q[1]])
    )


def _step_defects(method, law, model=None):
    """‖ΨᵀJΨ − J‖ of one step of h = 0.1, 0.05, 0.025 that crosses the floor at about 0.4 of the
    step (on the trap; at about 0.2 on the double pendulum) (Ψ by fourth-order central
    differences)."""
    model = _trap() if model is None else model
    floor = varmech.Contact(lambda q: q[1] + 0.3 * q[0], lambda q: [0.3, 1.0], law=law)
    j = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.eye(2), np.zeros((2, 2))]])

    def step(z, h):
        traj = varmech.integrate(model, z[:2], z[2:], dt=h, steps=1, method=method, contacts=[floor], max_energy_error=None)
        assert len(traj.events[0]) == 1
        return np.concatenate([traj.q[-1], traj.p[-1]])

    defects = []
    for h in (0.1, 0.05, 0.025):
        z0 = np.array([0.2, -0.06 + 0.4 * h, 0.3, -1.0])
        eps = 1e-4
        psi = np.stack(
            [(-step(z0 + 2 * e, h) + 8 * step(z0 + e, h) - 8 * step(z0 - e, h) + step(z0 - 2 * e, h)) / (12 * eps) for e in np.eye(4) * eps],
            axis=1,
        )
        defects.append(np.linalg.norm(psi.T @ j @ psi - j))
    return np.array(defects)


@pytest.mark.parametrize("method", ["verlet", "yoshida4", "mclachlan8", "blanes_moan4", "aba864", "mclachlan8_dkd", "symplectic_euler"])
def test_a_step_across_an_elastic_impact_is_symplectic_under_the_variational_collision_integrator(method):
    # Fetecau et al. (2003): the contact point and fraction make the action stationary, so the
    # step map is symplectic; measured to the differences' round-off, at every h.
    defects = _step_defects(method, "variational")
    assert np.all(defects < 1e-9), defects


def test_a_step_across_an_impact_reflected_exactly_is_symplectic_only_to_the_methods_order():
    # The exact reflection conserves H, not the discrete energy: verlet's defect falls as h².
    defects = _step_defects("verlet", "reflect")
    orders = np.log2(defects[:-1] / defects[1:])
    assert defects[0] > 1e-3 and np.all(np.abs(orders - 2.0) < 0.3), (defects, orders)


def test_the_variational_law_needs_a_kick_drift_method():
    floor = varmech.Contact(lambda q: q[0], lambda q: [1.0])
    with pytest.raises(ValueError, match=r"^contacts: .* \(contacts\[0\]\): the variational collision integrator needs a kick–drift method"):
        varmech.integrate(_ball(), [1.0], [0.0], dt=1e-3, steps=10, method="rk4", contacts=[floor])
    reflected = varmech.Contact(lambda q: q[0], lambda q: [1.0], law="reflect")
    traj = varmech.integrate(_ball(), [1.0], [0.0], dt=1e-3, steps=1000, method="midpoint", contacts=[reflected])
    assert len(traj.events[0]) == 1
    with pytest.raises(ValueError, match="^law: 'variational' or 'reflect'"):
        varmech.Contact(lambda q: q[0], lambda q: [1.0], law="bounce")


def _mass(q):
    c = math.cos(q[0] - q[1])
    return np.array([[2.0, c], [c, 1.0]])


def _mass_derivative(q):
    d = math.sin(q[0] - q[1]) * np.array([[0.0, -1.0], [-1.0, 0.0]])
    return np.array([d, -d])


def _pendulum_potential(q):
    return -G * (2 * math.cos(q[0]) + math.cos(q[1]))


def _pendulum_gradient(q):
    return G * np.array([2 * math.sin(q[0]), math.sin(q[1])])


def _double_pendulum(kind):
    # Unit masses and lengths: M(q) = [[2, cos(θ₁ − θ₂)], [cos(θ₁ − θ₂), 1]], a natural system,
    # or the same L given as a general Lagrangian (its velocities by the core's Legendre solve).
    if kind == "natural":
        return varmech.MechanicalSystem(2, _pendulum_potential, _pendulum_gradient, mass=_mass, mass_derivative=_mass_derivative)

    def dl_dq(q, v, t):
        return 0.5 * np.einsum("i,kij,j->k", v, _mass_derivative(q), v) - _pendulum_gradient(q)

    return varmech.Lagrangian(
        2,
        lambda q, v, t: 0.5 * v @ _mass(q) @ v - _pendulum_potential(q),
        dl_dq=dl_dq,
        dl_dv=lambda q, v, t: _mass(q) @ v,
    )


@pytest.mark.parametrize("method", ["midpoint", "trapezoid"])
@pytest.mark.parametrize("model", ["trap", "natural", "lagrangian"])
def test_a_step_across_an_elastic_impact_is_symplectic_for_the_two_point_rules(method, model):
    # The rules' discrete energies (midpoint: H at the mean state; trapezoid: the mean of E at
    # the ends) kept across the impact: symplectic to the differences' round-off, on the
    # separable trap and on the double pendulum's M(q), where the exact reflection is not.
    system = None if model == "trap" else _double_pendulum(model)
    defects = _step_defects(method, "variational", system)
    assert np.all(defects < 1e-9), defects
    if model == "natural":
        reflected = _step_defects(method, "reflect", system)
        assert np.all(reflected > 1e-3), reflected


@pytest.mark.parametrize("method", ["galerkin4", "galerkin6"])
def test_a_step_across_an_elastic_impact_is_symplectic_for_the_galerkin_rules(method):
    # E_d at the step's control points (Σᵢ bᵢE at the Gauss nodes), kept across the impact on
    # the double pendulum given as a general Lagrangian: measured 2e-11 to 8e-11, where the
    # exact reflection's defect falls with the order (galerkin4 1.7e-3, 7.3e-5, 3.6e-6;
    # galerkin6 2.4e-5, 1.8e-7, 2.0e-9).
    system = _double_pendulum("lagrangian")
    defects = _step_defects(method, "variational", system)
    assert np.all(defects < 1e-9), defects
    assert _step_defects(method, "reflect", system)[0] > 1e-6


@pytest.mark.parametrize("method", ["midpoint", "trapezoid"])
@pytest.mark.parametrize("alpha", [1e-9, 1 - 1e-9])
def test_an_impact_at_the_very_start_or_end_of_a_step_keeps_the_jump_to_round_off(method, alpha):
    # A floor at height 10: velocities from position differences (q₁ − q₀)/τ would keep only
    # τ|v|/|q| ≈ 1e-11 of their digits at τ = 1e-9·h (a jump off by ~1e-3 of g); the rules' E_d
    # take them from the momenta and keep the jump g²h²(1 − 2α)/8 to round-off of H.
    t1 = math.sqrt(2 / G)
    dt = t1 / (100 + alpha)
    wall = [varmech.Contact.wall(0, 10.0)]
    hits = varmech.integrate(_ball(), [11.0], [0.0], dt=dt, steps=310, method=method, contacts=wall).events[0]
    assert len(hits) == 2
    jump = 0.5 * hits.p[1, 0] ** 2 - G
    assert abs(jump - G * G * dt * dt * (1 - 2 * alpha) / 8) < 1e-14 * G


@pytest.mark.parametrize("method", ["midpoint", "trapezoid"])
def test_the_elliptic_billiard_keeps_its_focal_invariant_under_the_two_point_rules(method):
    # Both rules are exact on the free flight: the focal invariant and the energy are kept
    # across 10³ impacts as under the kick–drift methods (measured 3.4e-14 and 8.1e-15).
    traj, invariant, energy, inside = _billiard(10_500, method=method)
    assert len(traj.events[0]) > 1000
    assert invariant < 1e-12
    assert energy < 1e-13
    assert inside < 1 + 1e-12


def _falling(**options):
    """The ball as a general Lagrangian (closures), for the implicit rules."""
    return varmech.Lagrangian(
        1, lambda q, v, t: 0.5 * v @ v - G * q[0], dl_dq=lambda q, v, t: np.array([-G]), dl_dv=lambda q, v, t: v, **options
    )


@pytest.mark.parametrize("method", ["galerkin4", "galerkin6"])
def test_the_variational_impact_under_a_galerkin_rule_is_exact_on_the_ball(method):
    # Both Galerkin rules reproduce the parabola and integrate L along it exactly: L_d is the
    # exact discrete Lagrangian, E_d = H, so the VCI's impact keeps H to round-off (where
    # Verlet's moves it by g²h²(1 − 2α)/8, the test above) and the bounces fall at (2k + 1)t₁.
    t1, alpha, m = math.sqrt(2 / G), 0.25, 100
    dt = t1 / (m + alpha)
    hits = varmech.integrate(
        _falling(), [1.0], [0.0], dt=dt, steps=3 * m + 10, method=method, contacts=[varmech.Contact.wall(0)]
    ).events[0]
    assert len(hits) == 2
    np.testing.assert_allclose(hits.t, [t1, 3 * t1], rtol=1e-12)
    assert np.max(np.abs(0.5 * hits.p[:, 0] ** 2 - G)) < 1e-11 * G


def test_the_variational_law_still_refuses_the_other_methods_and_non_conservative_models():
    floor = varmech.Contact(lambda q: q[0], lambda q: [1.0])
    # rk4 has no discrete energy.
    refused = r"^contacts: .* \(contacts\[0\]\): the variational collision integrator needs a kick–drift method, a two-point rule .*, not rk4"
    with pytest.raises(ValueError, match=refused):
        varmech.integrate(_ball(), [1.0], [0.0], dt=1e-3, steps=10, method="rk4", contacts=[floor])
    damped = _falling(rayleigh=0.1)
    with pytest.raises(ValueError, match=r"^contacts: .* \(contacts\[0\]\): the variational collision integrator keeps the discrete energy"):
        varmech.integrate(damped, [1.0], [0.0], dt=1e-3, steps=10, method="midpoint", contacts=[floor])


def test_a_failed_run_goes_on_with_its_contacts():
    # A run that failed at a resting contact (rk4 cannot hold it) goes on with its floor, and
    # fails there again (a Stepper with contacts: tests/python/test_stepper_contacts.py).
    floor = varmech.Contact.wall(0, law="reflect", restitution=0.5, name="floor")
    with pytest.raises(varmech.ContactError) as info:
        varmech.integrate(_ball(), [1.0], [0.0], dt=0.01, t_end=2.0, contacts=[floor], method="rk4")
    assert info.value.partial.contacts == (floor,)
    with pytest.raises(varmech.ContactError):
        varmech.integrate(info.value.partial, steps=10)


def test_a_run_without_contacts_still_goes_on_and_its_model_steps_alone():
    # The same scene run with contacts=[] is continued bit for bit, and its bare model (the
    # user's choice) steps.
    scene = varmech.scenes.bouncing_ball()
    traj = varmech.integrate(scene, dt=1e-2, steps=50, contacts=[])
    assert traj.contacts == ()
    whole = varmech.integrate(scene, dt=1e-2, steps=100, contacts=[])
    more = varmech.integrate(traj, steps=50)
    assert np.array_equal(more.q[-1], whole.q[-1]) and np.array_equal(more.p[-1], whole.p[-1])
    stepper = varmech.Stepper(scene.model, scene.q0, scene.p0, dt=1e-2)
    stepper.advance(100)
    assert np.array_equal(stepper.q, whole.q[-1])


def test_a_run_with_impulses_goes_on_with_none_left_to_come():
    # Impulses lie within their run, so its end has none to come: going on from it is one run of
    # the whole length with the same blows, bit for bit.
    ball = _ball()
    blow = varmech.Impulse(generalized=[3.0], t=0.2345)
    short = varmech.integrate(ball, [1.0], [0.0], dt=1e-2, steps=50, impulses=[blow])
    whole = varmech.integrate(ball, [1.0], [0.0], dt=1e-2, steps=100, impulses=[blow])
    more = varmech.integrate(short, steps=50)
    assert np.array_equal(more.q[-1], whole.q[-1]) and np.array_equal(more.p[-1], whole.p[-1])
    assert more.t[-1] == pytest.approx(whole.t[-1], abs=1e-14)


def test_a_contact_errors_time_is_the_start_of_its_step_as_documented():
    # ContactError.time is "the time tₙ at the start of that step" (step 1 the first), as for the
    # core's errors, and the partial trajectory ends there; it was the impact's time.
    dt = 1e-3
    floor = varmech.Contact(lambda q: q[0], lambda q: [1.0], restitution=0.5, law="reflect")
    with pytest.raises(varmech.ContactError) as info:
        varmech.integrate(_ball(), [1.0], [0.0], dt=dt, steps=3000, contacts=[floor], method="rk4")
    err = info.value
    assert err.time == err.partial.t[-1]
    assert err.time == pytest.approx((err.step - 1) * dt, abs=1e-12)


def test_rattle_goes_through_an_impact_reflected_on_its_constraint_as_the_angle_twin_does():
    # Issue 32: RATTLE with law="reflect" failed at its first impact, blaming p0: ∇φ's jump took
    # the momenta off the hidden constraint. With the constraint's own workless impulse the
    # jump reflects the velocity along the circle, as the pendulum in its angle θ reflects θ̇ at
    # the wall θ = −π/6 (x = −1/2): the same impact times, H and the constraints kept.
    scene = varmech.scenes.cartesian_pendulum()   # released from rest at θ = 2, g = l = 1
    wall = varmech.Contact.wall(0, -0.5, law="reflect", name="wall")
    dt, steps = 1e-3, 20000
    traj = varmech.integrate(scene, dt=dt, steps=steps, contacts=[wall])
    angle = varmech.MechanicalSystem(1, lambda q: -math.cos(q[0]), lambda q: np.array([math.sin(q[0])]), name="pendulum")
    stop = varmech.Contact(lambda q: q[0] + math.pi / 6, lambda q: [1.0], law="reflect")
    twin = varmech.integrate(angle, [2.0], [0.0], dt=dt, steps=steps, contacts=[stop])
    hits, twin_hits = traj.events[0].t, twin.events[0].t
    assert len(hits) == len(twin_hits) >= 3
    np.testing.assert_allclose(hits, twin_hits, rtol=0, atol=1e-5)
    position, velocity = traj.constraint_residuals()
    assert position.max() < 1e-12 and velocity.max() < 1e-12
    E = traj.energy()
    assert abs(E - E[0]).max() < 1e-5 and traj.q[:, 0].min() > -0.5 - 1e-12
