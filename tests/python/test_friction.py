"""Coulomb friction on held contacts (issue 34): sliding under μ_k N against the slip, sticking
while the force that holds the slip is within μ_s N, each switch located on the held steps.

Exact references:
- a block on a slope of angle α stays for tan α ≤ μ_s and slides with a = g(sin α − μ_k cos α)
  otherwise; thrown up the slope it stops at t = v₀/(g(sin α + μ_k cos α)), and stays there or
  slides back;
- Byerly's billiard ball (Art. 10(b)), struck to slide without spin, rolls from t = 2v₀/(7μg) on at
  5v₀/7, having lost 2/7 of its energy to friction;
- a particle on a rough circle (radius a, no other force: N = mv²/a) keeps v = v₀/(1 + μv₀t/a),
  its angle θ = ln(1 + μv₀t/a)/μ, at the method's order;
- a ball rolling on a floor, tied by a spring, slips where the force that rolling needs,
  (2/7)k|x|, reaches μ_s mg: at x* = 7μ_s mg/(2k) on the rolling oscillation x = A sin ωt
  (ω² = 5k/(7m)), at the method's order.

The energy balance E − E₀ − W, W the discrete work of the sliding force (``traj.work``), is
round-off where the held step is exact (constant forces) and falls at the method's order
otherwise.
"""

import math

import numpy as np
import pytest

import varmech

G = 9.81
ALPHA = math.radians(30)
DOWN = np.array([-math.cos(ALPHA), -math.sin(ALPHA)])


def _block() -> varmech.Model:
    """A unit mass in the plane under gravity, V = g y."""
    return varmech.MechanicalSystem(2, lambda q: G * q[1], lambda q: np.array([0.0, G]), name="block")


#: Where the block starts, on the slope.
TOP = np.array([0.0, 1.0])


def _slope(mu_s: float, mu_k: float) -> varmech.Contact:
    """The plane through TOP at ALPHA, φ its signed distance, with friction (μ_s, μ_k)."""
    normal = np.array([-math.sin(ALPHA), math.cos(ALPHA)])
    friction = varmech.Friction(mu_s, mu_k)
    return varmech.Contact(lambda q: (q - TOP) @ normal, lambda q: normal, restitution=0.0, law="reflect", name="slope", friction=friction)


def _energy_balance(traj: varmech.Trajectory, mass: np.ndarray, height: np.ndarray) -> float:
    """max |E − E₀ − W| over the run, relative to the largest of |T|, |V| and |W|."""
    kinetic, potential = 0.5 * np.sum(traj.p**2 / mass, axis=1), G * height * mass[0]
    e = kinetic + potential
    scale = max(np.max(np.abs(kinetic)), np.max(np.abs(potential)), np.max(np.abs(traj.work)))
    return float(np.max(np.abs(e - e[0] - traj.work)) / scale)


@pytest.mark.parametrize("method", ["verlet", "yoshida4"])
def test_a_block_on_a_slope_stays_at_tan_alpha_below_mu_s_and_slides_at_g_sin_minus_mu_k_cos_otherwise(method):
    tan = math.tan(ALPHA)
    stays = varmech.integrate(_block(), TOP, [0.0, 0.0], dt=0.01, steps=200, method=method, contacts=[_slope(tan * (1 + 1e-9), 0.1)])
    np.testing.assert_allclose(stays.q, np.tile(TOP, (201, 1)), rtol=0, atol=1e-15)
    assert np.max(np.abs(stays.p)) < 1e-15 and np.max(np.abs(stays.work)) < 1e-30
    mu_k = 0.2
    slides = varmech.integrate(_block(), TOP, [0.0, 0.0], dt=0.01, steps=200, method=method, contacts=[_slope(tan * (1 - 1e-9), mu_k)])
    a = G * (math.sin(ALPHA) - mu_k * math.cos(ALPHA))
    np.testing.assert_allclose((slides.q - TOP) @ DOWN, a * slides.t**2 / 2, rtol=1e-13, atol=1e-13)
    assert all(len(e) == 0 for e in slides.events), "slides from the start, never sticks"
    # Sliding with constant force the held step is exact, and so is the balance with W = −μ_k N d.
    np.testing.assert_allclose(slides.work, -mu_k * G * math.cos(ALPHA) * ((slides.q - TOP) @ DOWN), rtol=1e-13, atol=1e-15)
    assert _energy_balance(slides, np.ones(2), slides.q[:, 1]) < 1e-13


@pytest.mark.parametrize(("mu_s", "sticks"), [(0.7, True), (0.5, False)])
def test_a_block_thrown_up_a_slope_stops_when_friction_and_gravity_take_its_speed_and_sticks_only_for_tan_alpha_at_most_mu_s(mu_s, sticks):
    v0, mu_k = 2.0, 0.4
    up = -DOWN
    traj = varmech.integrate(_block(), TOP, v0 * up, dt=0.01, steps=100, contacts=[_slope(mu_s, mu_k)])
    stop = v0 / (G * (math.sin(ALPHA) + mu_k * math.cos(ALPHA)))
    top = v0 * stop / 2
    _, _, _, stuck, slipped = traj.events
    assert len(slipped) == 0
    if sticks:
        assert len(stuck) == 1 and abs(stuck.t[0] - stop) < 1e-13
        after = traj.t > stop
        np.testing.assert_allclose((traj.q[after] - TOP) @ up, top, rtol=1e-13)
        assert np.all(traj.p[after] @ up == pytest.approx(0.0, abs=1e-15))
    else:
        # Stopped, it slides back down at g(sin α − μ_k cos α), without sticking.
        assert len(stuck) == 0
        back = G * (math.sin(ALPHA) - mu_k * math.cos(ALPHA))
        after = traj.t > stop
        np.testing.assert_allclose((traj.q[after] - TOP) @ up, top - back * (traj.t[after] - stop) ** 2 / 2, rtol=0, atol=1e-12)
    assert _energy_balance(traj, np.ones(2), traj.q[:, 1]) < 1e-13


R, M = 0.1, 1.0
INERTIA = 0.4 * M * R**2


def _ball(spring: float = 0.0) -> varmech.Model:
    """A uniform ball (x, y, θ) on a floor, tied to x = 0 by a spring k (none by default)."""
    return varmech.MechanicalSystem(
        3,
        lambda q: M * G * q[1] + spring * q[0] ** 2 / 2,
        lambda q: np.array([spring * q[0], M * G, 0.0]),
        mass=[M, M, INERTIA],
        name="ball",
    )


def _floor(mu_s: float, mu_k: float | None = None) -> varmech.Contact:
    """The floor y ≥ R under the ball, its contact point slipping at ẋ − Rθ̇."""
    return varmech.Contact.wall(1, R, restitution=0.0, law="reflect", name="floor", friction=varmech.Friction(mu_s, mu_k, slip=[[1.0, 0.0, -R]]))


@pytest.mark.parametrize("x0", [0.0, 2.5, 1e6])
@pytest.mark.parametrize("method", ["verlet", "yoshida4"])
def test_byerlys_billiard_ball_slides_and_then_rolls_at_five_sevenths_of_its_speed_after_2v0_over_7_mu_g(method, x0):
    # Wherever the table puts it: its x's rounding, spacing(x0), enters only the work's
    # F·(q₁ − q₀), relative spacing(x0)/(v₀ h) a step at most.
    v0, mu, dt = 2.0, 0.2, 0.01
    traj = varmech.integrate(_ball(), [x0, R, 0.0], [M * v0, 0.0, 0.0], dt=dt, steps=300, method=method, contacts=[_floor(mu)])
    _, closed, released, stuck, slipped = traj.events
    assert len(closed) == len(released) == len(slipped) == 0, "on the floor from the start, never leaves it"
    rolls = 2 * v0 / (7 * mu * G)
    assert len(stuck) == 1 and abs(stuck.t[0] - rolls) < 1e-13
    v, spin = traj.p[:, 0] / M, traj.p[:, 2] / INERTIA
    after = traj.t > rolls
    np.testing.assert_allclose(v[after], 5 * v0 / 7, rtol=1e-13)
    np.testing.assert_allclose(v[after] - R * spin[after], 0.0, atol=1e-13)
    np.testing.assert_allclose(v[~after], v0 - mu * G * traj.t[~after], rtol=1e-13)
    t = traj.t[~after]
    np.testing.assert_allclose(traj.q[~after, 0] - x0, v0 * t - mu * G * t**2 / 2, atol=1e-13 + 4 * np.spacing(x0))
    # It loses 2/7 of its energy, all of it the work of the sliding force.
    rounding = 1e-13 + np.spacing(x0) / (v0 * dt)
    np.testing.assert_allclose(traj.work[-1], -(2 / 7) * M * v0**2 / 2, rtol=rounding)
    assert _energy_balance(traj, np.array([M, M, INERTIA]), traj.q[:, 1]) < rounding


def test_a_rolling_ball_struck_slides_and_rolls_again_at_v_plus_five_sevenths_of_the_blow_over_m():
    # A blow P at the centre has no friction: the ball slides at slip P/m, which friction takes
    # at (7/2)μg, and rolls again at v + (5/7)P/m (its angular momentum about the contact point
    # kept while it slides).
    v, blow, mu, t_blow = 1.0, 0.7, 0.2, 0.5
    strike = varmech.Impulse(generalized=[blow, 0.0, 0.0], t=t_blow)
    traj = varmech.integrate(_ball(), [0.0, R, 0.0], [M * v, 0.0, INERTIA * v / R], dt=0.01, steps=150, contacts=[_floor(mu)], impulses=[strike])
    _, _, _, stuck, slipped = traj.events
    again = t_blow + 2 * blow / (7 * mu * G * M)
    assert len(slipped) == 1 and slipped.t[0] == t_blow
    assert len(stuck) == 1 and abs(stuck.t[0] - again) < 1e-13
    np.testing.assert_allclose(traj.p[-1, 0] / M, v + 5 / 7 * blow / M, rtol=1e-13)
    np.testing.assert_allclose(traj.p[traj.t < t_blow, 0], M * v, rtol=1e-15)


def _rough_circle(method: str, dt: float, mu: float = 0.5, t_end: float = 2.0) -> tuple[varmech.Trajectory, np.ndarray]:
    """A particle sliding inside a rough circle of radius 1 at speed 1, no other force: its angle."""
    free = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2), name="free")
    rim = varmech.Contact.ellipsoid([1.0, 1.0], restitution=0.0, law="reflect", name="rim", friction=varmech.Friction(mu))
    traj = varmech.integrate(free, [1.0, 0.0], [0.0, 1.0], dt=dt, t_end=t_end, method=method, contacts=[rim])
    return traj, np.unwrap(np.arctan2(traj.q[:, 1], traj.q[:, 0]))


@pytest.mark.parametrize(("method", "order"), [("verlet", 2), ("yoshida4", 4)])
def test_a_particle_on_a_rough_circle_slows_as_v0_over_1_plus_mu_v0_t_at_the_methods_order(method, order):
    mu, errors, balances = 0.5, [], []
    for dt in (0.02, 0.01):
        traj, theta = _rough_circle(method, dt, mu)
        assert all(len(e) == 0 for e in traj.events), "it slides all along"
        errors.append(np.max(np.abs(theta - np.log1p(mu * traj.t) / mu)))
        balances.append(_energy_balance(traj, np.ones(2), np.zeros(len(traj.t))))
        speed = np.hypot(traj.p[:, 0], traj.p[:, 1])
        np.testing.assert_allclose(speed, 1 / (1 + mu * traj.t), rtol=50 * errors[-1])
        assert np.max(np.abs(np.hypot(traj.q[:, 0], traj.q[:, 1]) - 1)) < 1e-14
    assert abs(math.log2(errors[0] / errors[1]) - order) < 0.05
    # The balance's error is the method's: it falls at its order too.
    assert balances[1] < balances[0] / 2 ** (order - 0.1)


@pytest.mark.parametrize(("method", "order"), [("verlet", 2), ("yoshida4", 4)])
def test_a_block_pushed_across_a_rough_slope_curves_and_stops_where_scipy_stops_it_at_the_methods_order(method, order):
    # A slip in two dimensions: the force turns with it, and the stop (|s| = 0, not a sign change)
    # is located where the slip turns against its direction at the step's start. Reference: the
    # sliding equations in the slope's plane by DOP853 at 1e-13, stopped where |v| = 1e-9.
    from scipy.integrate import solve_ivp

    alpha, mu = math.radians(20), 0.5
    normal, up = np.array([-math.sin(alpha), 0.0, math.cos(alpha)]), np.array([math.cos(alpha), 0.0, math.sin(alpha)])
    block = varmech.MechanicalSystem(3, lambda q: G * q[2], lambda q: np.array([0.0, 0.0, G]), name="block")
    slope = varmech.Contact(lambda q: q @ normal, lambda q: normal, restitution=0.0, law="reflect", name="slope", friction=varmech.Friction(0.6, mu))

    def sliding(t, y):
        v = y[2:]
        return [*v, *(np.array([-G * math.sin(alpha), 0.0]) - mu * G * math.cos(alpha) * v / np.linalg.norm(v))]

    def stops(t, y):
        return np.linalg.norm(y[2:]) - 1e-9

    stops.terminal = True  # type: ignore[attr-defined]
    exact = solve_ivp(sliding, (0.0, 2.0), [0.0, 0.0, 0.0, 2.0], method="DOP853", rtol=1e-13, atol=1e-15, events=stops)
    t_stop, (u_stop, w_stop, *_) = exact.t_events[0][0], exact.y_events[0][0]
    errors = []
    for dt in (0.01, 0.005):
        traj = varmech.integrate(block, [0.0, 0.0, 0.0], [0.0, 2.0, 0.0], dt=dt, t_end=1.5, method=method, contacts=[slope])
        stuck = traj.events[3]
        assert len(stuck) == 1 and len(traj.events[4]) == 0
        errors.append(max(abs(stuck.t[0] - t_stop), abs(stuck.q[0] @ up - u_stop), abs(stuck.q[0][1] - w_stop)))
        assert np.all(np.abs(traj.q[traj.t > stuck.t[0]] - stuck.q[0]) < 1e-15), "stuck to round-off"
    assert math.log2(errors[0] / errors[1]) > order - 0.25, errors


def test_a_bob_swinging_in_a_rough_bowl_turns_back_until_it_sticks_where_tan_theta_is_within_mu_s():
    # Each turn of the swing stops the slip and slides it back (|λ_t| > μ_s N there), until a
    # turn comes within tan θ ≤ μ_s: it sticks there for good. The energy only falls.
    mu = 0.1
    bowl = varmech.Contact.ellipsoid([1.0, 1.0], restitution=0.0, law="reflect", name="bowl", friction=varmech.Friction(mu))
    q0 = np.array([math.sin(1.0), -math.cos(1.0)])
    traj = varmech.integrate(_block(), q0 / np.hypot(*q0), [0.0, 0.0], dt=0.01, t_end=40.0, contacts=[bowl])
    _, closed, released, stuck, slipped = traj.events
    assert len(closed) == len(released) == len(slipped) == 0 and len(stuck) == 1
    x, y = stuck.q[0]
    assert abs(x / y) <= mu and abs(x / y) > mu / 3, "it stops at a turn, short of the bottom"
    assert np.all(np.abs(traj.q[traj.t > stuck.t[0]] - stuck.q[0]) < 1e-15)
    energy = 0.5 * np.sum(traj.p**2, axis=1) + G * traj.q[:, 1]
    assert np.all(np.diff(energy) <= 1e-12) and _energy_balance(traj, np.ones(2), traj.q[:, 1]) < 1e-3


@pytest.mark.parametrize(("method", "order"), [("verlet", 2), ("yoshida4", 4)])
def test_a_ball_rolling_on_a_spring_slips_where_rolling_needs_mu_s_mg_at_the_methods_order(method, order):
    k, v0, mu_s = 10.0, 1.0, 0.1
    omega = math.sqrt(5 * k / (7 * M))
    x_slip = 7 * mu_s * M * G / (2 * k)
    t_slip = math.asin(x_slip / (v0 / omega)) / omega
    errors = []
    for dt in (0.02, 0.01):
        traj = varmech.integrate(
            _ball(k), [0.0, R, 0.0], [M * v0, 0.0, INERTIA * v0 / R], dt=dt, t_end=0.6, method=method, contacts=[_floor(mu_s, mu_s / 2)]
        )
        _, _, _, stuck, slipped = traj.events
        assert len(stuck) == 0 and len(slipped) == 1
        errors.append(abs(slipped.t[0] - t_slip))
        rolling = traj.t < slipped.t[0]
        np.testing.assert_allclose(traj.p[rolling, 0] / M - R * traj.p[rolling, 2] / INERTIA, 0.0, atol=1e-13)
        assert np.all(traj.work[rolling] == 0.0) and traj.work[-1] < 0
    assert abs(math.log2(errors[0] / errors[1]) - order) < 0.1


def test_friction_composes_with_samples_files_and_their_resume_and_ensembles(tmp_path):
    v0, mu = 2.0, 0.2
    q0, p0 = [0.0, R, 0.0], [M * v0, 0.0, 0.0]
    rolls = 2 * v0 / (7 * mu * G)
    whole = varmech.integrate(_ball(), q0, p0, dt=0.01, steps=100, contacts=[_floor(mu)])
    # Samples across the switch: on the exact motion (constant forces, exact steps).
    times = np.linspace(0.0, 1.0, 37)
    sampled = varmech.integrate(_ball(), q0, p0, dt=0.01, t_end=1.0, t_eval=times, contacts=[_floor(mu)])
    speed = np.where(times < rolls, v0 - mu * G * times, 5 * v0 / 7)
    np.testing.assert_allclose(sampled.p[:, 0] / M, speed, rtol=1e-12)
    # A file and its resume, stopped while it slides: one run, its work and its switch.
    path = tmp_path / "ball.h5"
    varmech.integrate(_ball(), q0, p0, dt=0.01, steps=20, contacts=[_floor(mu)], output=path, checkpoint_every=7)
    resumed = varmech.resume(path, steps=80, model=_ball())
    for x, y in [(resumed.q, whole.q), (resumed.p, whole.p), (resumed.work, whole.work)]:
        np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(resumed.events[3].t, whole.events[3].t)
    # An ensemble of speeds, bit for bit its single runs, each rolling from 2v₀/(7μg).
    speeds = np.array([1.0, 2.0, 3.0])
    p0s = np.array([[M * v, 0.0, 0.0] for v in speeds])
    q0s = np.tile(q0, (3, 1))
    runs = varmech.ensemble(_ball(), q0s, p0s, dt=0.01, steps=150, contacts=[_floor(mu)], workers=2)
    for k, member in enumerate(runs):
        single = varmech.integrate(_ball(), q0s[k], p0s[k], dt=0.01, steps=150, contacts=[_floor(mu)])
        assert np.array_equal(member.q, single.q) and np.array_equal(member.work, single.work)
        assert abs(member.events[3].t[0] - 2 * speeds[k] / (7 * mu * G)) < 1e-13


def test_check_conservation_judges_the_balance_with_the_work_of_friction():
    traj, _ = _rough_circle("yoshida4", 0.01)
    report = varmech.check_conservation(traj, refine=False)
    assert report.energy.name == "energy balance"
    assert report.verdict in ("bounded", "conserved to round-off"), report


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"mu_s": -0.1}, "^mu_k: must be a finite number ≥ 0"),
        ({"mu_s": float("nan")}, "^mu_k: must be a finite number ≥ 0"),
        ({"mu_s": 0.2, "mu_k": 0.3}, "^mu_s: must be finite and at least mu_k"),
        ({"mu_s": 0.2, "mu_k": float("inf")}, "^mu_k: must be a finite number ≥ 0"),
        ({"mu_s": 0.2, "slip": [[1.0, float("nan"), 0.0]]}, "^slip: must be a finite"),
        ({"mu_s": 0.2, "slip": [[[1.0]]]}, "^slip: must be a finite"),
    ],
)
def test_bad_friction_is_a_value_error_naming_the_argument(kwargs, match):
    with pytest.raises(ValueError, match=match):
        varmech.Friction(**kwargs)
    # A string is no number: a TypeError, named likewise.
    with pytest.raises(TypeError, match="^mu_s: must be a number"):
        varmech.Friction(mu_s="0.2")


def test_friction_that_cannot_act_is_refused_naming_contacts():
    with pytest.raises(TypeError, match="^friction: expected a varmech.Friction"):
        varmech.Contact.wall(0, friction=0.3)  # type: ignore[arg-type]
    # A slip of the wrong width; a tangent plane asked of four coordinates.
    with pytest.raises(ValueError, match=r"^contacts: .*slip rows must be k × 3"):
        narrow = varmech.Contact.wall(1, R, friction=varmech.Friction(0.2, slip=[[1.0, -R]]))
        varmech.integrate(_ball(), [0.0, R, 0.0], [1.0, 0.0, 0.0], dt=0.01, steps=5, contacts=[narrow])
    four = varmech.MechanicalSystem(4, lambda q: 0.0, lambda q: np.zeros(4))
    with pytest.raises(ValueError, match=r"^contacts: .*give the slip rows J"):
        varmech.integrate(four, [1.0, 0, 0, 0], [0.0] * 4, dt=0.01, steps=5, contacts=[varmech.Contact.wall(0, friction=varmech.Friction(0.2))])
    # A method that cannot hold the contact friction acts on.
    with pytest.raises(ValueError, match=r"^contacts: friction acts on held contacts, which verlet .* not rk4"):
        varmech.integrate(_ball(), [0.0, R, 0.0], [1.0, 0.0, 0.0], dt=0.01, steps=5, method="rk4", contacts=[_floor(0.2)])


# A wheel (a disk held upright) on a rough floor, (x, y, z, φ, θ): its centre, heading and spin.
# Its contact point slips at s = (ẋ − rθ̇ cos φ, ẏ − rθ̇ sin φ), rows that turn with φ: while it
# sticks they are the nonholonomic rolling constraint, which gives way where rolling needs more
# than μ_s N. Rolling at spin w and turn rate Ω it keeps a circle of radius rw/Ω, needing the
# sideways force m(rw)Ω from friction.
WHEEL = 0.3
SPIN_INERTIA, TURN_INERTIA = 0.5 * M * WHEEL**2, 0.25 * M * WHEEL**2
WHEEL_MASS = np.array([M, M, M, TURN_INERTIA, SPIN_INERTIA])


def _wheel() -> varmech.Model:
    """The upright disk under gravity, V = mgz."""
    return varmech.MechanicalSystem(5, lambda q: M * G * q[2], lambda q: np.array([0.0, 0.0, M * G, 0.0, 0.0]), mass=WHEEL_MASS, name="wheel")


def _rolling_rows(q: np.ndarray) -> np.ndarray:
    c, s = math.cos(q[3]), math.sin(q[3])
    return np.array([[1.0, 0.0, 0.0, 0.0, -WHEEL * c], [0.0, 1.0, 0.0, 0.0, -WHEEL * s]])


def _ground(mu_s: float, mu_k: float | None = None) -> varmech.Contact:
    """The floor z ≥ 0 under the wheel, slipping along the rolling rows."""
    friction = varmech.Friction(mu_s, mu_k, slip=_rolling_rows, slip_count=2)
    return varmech.Contact.wall(2, 0.0, restitution=0.0, law="reflect", name="ground", friction=friction)


def _rolling(spin: float, turn: float) -> tuple[list[float], list[float]]:
    """The wheel at the origin rolling along x at spin w, turning at Ω."""
    return [0.0] * 5, [M * WHEEL * spin, 0.0, 0.0, TURN_INERTIA * turn, SPIN_INERTIA * spin]


@pytest.mark.parametrize(("method", "order"), [("verlet", 2), ("yoshida4", 4)])
def test_a_wheel_rolls_on_its_circle_at_the_methods_order_while_friction_holds_it(method, order):
    # The stuck rows J(q½)(q₁ − q₀) = 0 at each step's midpoint: the rolling constraint along
    # the chord keeps the step symmetric.
    spin, turn = 10.0, 2.0
    radius = WHEEL * spin / turn
    errors = []
    for dt in (0.02, 0.01):
        traj = varmech.integrate(_wheel(), *_rolling(spin, turn), dt=dt, t_end=2.0, method=method, contacts=[_ground(1.0)])
        assert all(len(e) == 0 for e in traj.events) and np.all(traj.work == 0.0)
        phi = turn * traj.t
        exact = np.column_stack([radius * np.sin(phi), radius * (1 - np.cos(phi)), 0 * phi, phi, spin * traj.t])
        errors.append(np.max(np.abs(traj.q - exact)))
        slip = (_rolling_rows(q) @ (p / WHEEL_MASS) for q, p in zip(traj.q, traj.p))
        assert max(np.max(np.abs(s)) for s in slip) < 1e-13
    assert abs(math.log2(errors[0] / errors[1]) - order) < 0.05, errors


@pytest.mark.parametrize(("margin", "skids"), [(1 + 1e-9, False), (1 - 1e-9, True)])
def test_a_wheel_skids_where_rolling_on_its_circle_needs_more_than_mu_s_mg(margin, skids):
    spin, turn = 10.0, 2.0
    needs = WHEEL * spin * turn / G
    traj = varmech.integrate(_wheel(), *_rolling(spin, turn), dt=0.01, steps=50, contacts=[_ground(needs * margin, needs * margin / 2)])
    radius = WHEEL * spin / turn
    off_circle = np.max(np.abs(np.hypot(traj.q[:, 0], traj.q[:, 1] - radius) - radius))
    if skids:
        assert traj.work[-1] < 0 and off_circle > 0.01
    else:
        assert np.all(traj.work == 0.0) and off_circle < 1e-3


@pytest.mark.parametrize(("method", "order"), [("verlet", 2), ("yoshida4", 4)])
def test_a_wheel_set_down_spinning_skids_then_rolls_as_scipy_integrates_its_sliding(method, order):
    # Set down spinning at w₀ without speed: friction drives it on and slows its spin, on a
    # straight line (Ω = 0: constant forces) until rw = v = rw₀/3 at t = rw₀/(3μg), exactly;
    # turning (Ω = 2) its sliding curves, and is the sliding equations' by DOP853 at 1e-13, the
    # method's order, up to the stop, located at order 2 (verlet; yoshida4 comes down from order
    # 2 to 6 between h = 0.01 and 0.00125): in the steps just before it the kick turns the slip
    # (the wheel's metric J M⁻¹ Jᵀ is anisotropic), and the force's direction is solved for in
    # the slip's metric.
    from scipy.integrate import solve_ivp

    mu, w0 = 0.5, 10.0
    straight = varmech.integrate(_wheel(), [0.0] * 5, [0, 0, 0, 0, SPIN_INERTIA * w0], dt=0.01, t_end=0.5, method=method, contacts=[_ground(mu)])
    stuck = straight.events[3]
    assert len(stuck) == 1 and abs(stuck.t[0] - WHEEL * w0 / (3 * mu * G)) < 1e-13
    np.testing.assert_allclose(straight.p[straight.t > stuck.t[0], 0] / M, WHEEL * w0 / 3, rtol=1e-13)
    assert _energy_balance(straight, WHEEL_MASS, straight.q[:, 2]) < 1e-13

    turn = 2.0

    def sliding(t, y):
        heading = np.array([math.cos(y[2]), math.sin(y[2])])
        slip = y[4:6] - WHEEL * y[7] * heading
        force = -mu * M * G * slip / np.linalg.norm(slip)
        return [*y[4:8], *(force / M), 0.0, -WHEEL * (force @ heading) / SPIN_INERTIA]

    def stops(t, y):
        return np.linalg.norm(y[4:6] - WHEEL * y[7] * np.array([math.cos(y[2]), math.sin(y[2])])) - 1e-9

    stops.terminal = True  # type: ignore[attr-defined]
    exact = solve_ivp(sliding, (0.0, 1.0), [0, 0, 0, 0, 0, 0, turn, w0], method="DOP853", rtol=1e-13, atol=1e-15, events=stops, dense_output=True)
    t_stop = exact.t_events[0][0]
    slides, stops_at = [], []
    for dt in (0.01, 0.005):
        p0 = [0, 0, 0, TURN_INERTIA * turn, SPIN_INERTIA * w0]
        traj = varmech.integrate(_wheel(), [0.0] * 5, p0, dt=dt, t_end=0.4, method=method, contacts=[_ground(mu)])
        at = np.searchsorted(traj.t, 0.2)
        slides.append(np.max(np.abs(traj.q[at][[0, 1, 3, 4]] - exact.sol(traj.t[at])[:4])))
        stuck = traj.events[3]
        assert len(stuck) == 1 and len(traj.events[4]) == 0
        stops_at.append(abs(stuck.t[0] - t_stop))
        assert np.all(np.diff(traj.work) <= 0.0)
    assert math.log2(slides[0] / slides[1]) > order - 0.3, slides
    assert math.log2(stops_at[0] / stops_at[1]) > 1.7 and stops_at[1] < 1e-3, stops_at


def test_slip_rows_given_as_a_function_are_checked_and_their_errors_propagate():
    with pytest.raises(ValueError, match="^slip_count: required with a slip function"):
        varmech.Friction(0.5, slip=_rolling_rows)
    with pytest.raises(ValueError, match="^slip_count: must be at least 1"):
        varmech.Friction(0.5, slip=_rolling_rows, slip_count=0)
    with pytest.raises(ValueError, match="^slip_count: only with a slip function"):
        varmech.Friction(0.5, slip=[[1.0, 0.0, -R]], slip_count=1)
    q0, p0 = _rolling(10.0, 2.0)
    wrong = varmech.Contact.wall(2, 0.0, restitution=0.0, law="reflect", friction=varmech.Friction(1.0, slip=_rolling_rows, slip_count=3))
    with pytest.raises(ValueError, match=r"slip returned an array of shape \[2, 5\], expected \[3, 5\]"):
        varmech.integrate(_wheel(), q0, p0, dt=0.01, steps=5, contacts=[wrong])

    class Mine(Exception):
        pass

    def broken(q):
        raise Mine("the user's own")

    own = varmech.Contact.wall(2, 0.0, restitution=0.0, law="reflect", friction=varmech.Friction(1.0, slip=broken, slip_count=2))
    with pytest.raises(Mine, match="the user's own"):
        varmech.integrate(_wheel(), q0, p0, dt=0.01, steps=5, contacts=[own])


def test_slip_functions_compose_with_files_resume_and_ensembles(tmp_path):
    # A file does not store the function: the resume is given the contact again, and goes on
    # bit for bit; the ensemble runs its members as single runs.
    q0, p0 = _rolling(10.0, 2.0)
    whole = varmech.integrate(_wheel(), q0, p0, dt=0.01, steps=60, contacts=[_ground(0.5, 0.3)])
    path = tmp_path / "wheel.h5"
    varmech.integrate(_wheel(), q0, p0, dt=0.01, steps=25, contacts=[_ground(0.5, 0.3)], output=path, checkpoint_every=10)
    with pytest.raises(ValueError, match="^contacts"):
        varmech.resume(path, steps=35, model=_wheel())
    resumed = varmech.resume(path, steps=35, model=_wheel(), contacts=[_ground(0.5, 0.3)])
    for x, y in [(resumed.q, whole.q), (resumed.p, whole.p), (resumed.work, whole.work)]:
        np.testing.assert_array_equal(x, y)
    runs = varmech.ensemble(_wheel(), np.tile(q0, (2, 1)), np.tile(p0, (2, 1)), dt=0.01, steps=60, contacts=[_ground(0.5, 0.3)], progress=False)
    for member in runs:
        np.testing.assert_array_equal(member.q, whole.q)


@pytest.mark.parametrize("method", ["verlet", "yoshida4"])
def test_events_on_byerlys_ball_are_located_where_it_slides_and_where_it_rolls_to_round_off(method):
    # Both motions are polynomials of degree ≤ 2, which the held steps follow exactly: the
    # crossings of x(0.2) (sliding) and x(1.0) (rolling) are at those times to round-off.
    v0, mu = 2.0, 0.2
    rolls = 2 * v0 / (7 * mu * G)

    def x(t: float) -> float:
        return v0 * t - mu * G * t * t / 2 if t <= rolls else x(rolls) + 5 * v0 / 7 * (t - rolls)

    run = {"dt": 0.01, "steps": 150, "method": method, "contacts": [_floor(mu)]}
    events = [varmech.events.crossing(0, x(0.2)), varmech.events.crossing(0, x(1.0))]
    watched = varmech.integrate(_ball(), [0.0, R, 0.0], [M * v0, 0.0, 0.0], events=events, **run)
    for crossing, t in zip(watched.events[:2], (0.2, 1.0)):
        assert len(crossing) == 1 and abs(crossing.t[0] - t) < 1e-14
        assert crossing.q[0][1] == R, "on the floor"
    plain = varmech.integrate(_ball(), [0.0, R, 0.0], [M * v0, 0.0, 0.0], **run)
    assert np.array_equal(watched.q, plain.q) and np.array_equal(watched.p, plain.p)
    assert np.array_equal(watched.events[5].t, plain.events[3].t), "its stick where it was"
