"""Contacts that hold (issue 34): a body resting, sliding or swinging on a contact is held on it
by RATTLE while the contact pushes, and released where its multiplier crosses 0.

- a particle sliding from rest near the top of a smooth sphere leaves it where
  cos θ = (2/3)cos θ₀, at the method's order, and then flies as a projectile;
- a pendulum on a string whirled too slowly goes slack where cos θ = (2gl − v₀²)/(3gl), flies
  on the parabola and is caught by the string again where the parabola meets the circle;
- samples (``t_eval``), files and their resume, ensembles and steppers go through holds as
  through impacts; events are located on a held contact's motion, on its held partial steps, at
  the method's order, and watching them changes no bit of the run;
- a particle in a trap under gravity, pressed on a floor above its equilibrium, bounces to rest
  at the limit of its Zeno series and is held there at every step (issue 64).
"""

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

import varmech

G = 9.81


def _particle() -> varmech.Model:
    """A unit mass in the plane under gravity, V = g y."""
    return varmech.MechanicalSystem(2, lambda q: G * q[1], lambda q: np.array([0.0, G]), name="particle")


def _on_circle(theta: float, radius: float = 1.0) -> np.ndarray:
    """(sin θ, cos θ)·r, nudged outwards onto the floating-point circle's outside."""
    q = radius * np.array([math.sin(theta), math.cos(theta)])
    while q @ q < radius * radius:
        q *= 1 + np.finfo(float).eps
    return q


SPHERE = varmech.Contact.ellipsoid([1.0, 1.0], inside=False, restitution=0.0, law="reflect", name="sphere")


def _leaves(method: str, dt: float, theta0: float = 0.3, **kwargs):
    traj = varmech.integrate(_particle(), _on_circle(theta0), [0.0, 0.0], method=method, dt=dt, t_end=1.6, contacts=[SPHERE], **kwargs)
    impacts, closed, released, stuck, slipped = traj.events[-5:]  # after the run's own events
    assert len(stuck) == len(slipped) == 0, "no friction, no friction switches"
    assert len(impacts) == len(closed) == 0 and len(released) == 1
    return traj, released


@pytest.mark.parametrize(("method", "order", "dt"), [("verlet", 2, 0.01), ("yoshida4", 4, 0.04)])
def test_a_particle_leaves_a_smooth_sphere_where_cos_theta_is_two_thirds_of_cos_theta0_at_the_methods_order(method, order, dt):
    theta0 = 0.3
    exact = 2 / 3 * math.cos(theta0)
    errors = []
    for h in (dt, dt / 2, dt / 4):
        traj, released = _leaves(method, h, theta0)
        (x, y) = released.q[0]
        assert abs(math.hypot(x, y) - 1) < 1e-13
        errors.append(abs(y - exact))
        # On the sphere up to lift-off (held: |q| = 1 to round-off), off it after.
        radius = np.hypot(traj.q[:, 0], traj.q[:, 1])
        on = traj.t <= released.t[0]
        assert np.max(np.abs(radius[on] - 1)) < 1e-13 and np.all(radius[~on] > 1)
        # No work is done by the smooth sphere: H is the method's, O(h^order).
        energy = 0.5 * np.sum(traj.p**2, axis=1) + G * traj.q[:, 1]
        assert np.max(np.abs(energy - G * math.cos(theta0))) < 50 * h**order
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - order) < 0.25), (orders, errors)


def test_samples_and_a_stepper_go_through_a_hold_and_its_release_as_the_run_does():
    # t_eval off the grid: each sample the held (or, after lift-off, free) partial step from the
    # last state before it, on the sphere to round-off while held.
    times = np.linspace(0.0, 1.6, 97)
    traj, released = _leaves("verlet", 0.01, t_eval=times)
    assert np.array_equal(traj.t, times)
    radius = np.hypot(traj.q[:, 0], traj.q[:, 1])
    on = traj.t <= released.t[0]
    assert np.max(np.abs(radius[on] - 1)) < 1e-13 and np.all(radius[~on] > 1)
    # A spring across the flight (V = gy + x²/2: no parabola, which a partial step of any size
    # would follow exactly): each sample after lift-off is the partial step from its own step's
    # start, within O(h²) of the states saved at every step around it.
    spring = varmech.MechanicalSystem(2, lambda q: G * q[1] + q[0] ** 2 / 2, lambda q: np.array([q[0], G]), name="spring")
    off_grid = np.arange(0.005, 1.6, 0.01)
    sampled = varmech.integrate(spring, _on_circle(0.3), [0.0, 0.0], dt=0.01, t_end=1.6, contacts=[SPHERE], t_eval=off_grid)
    saved = varmech.integrate(spring, _on_circle(0.3), [0.0, 0.0], dt=0.01, t_end=1.6, contacts=[SPHERE])
    after = off_grid > sampled.events[2].t[0] + 0.01
    for k in np.flatnonzero(after):
        row = np.searchsorted(saved.t, off_grid[k])
        midpoint = (saved.q[row - 1] + saved.q[row]) / 2
        assert np.max(np.abs(sampled.q[k] - midpoint)) < 2.5e-4, (off_grid[k], sampled.q[k], midpoint)
    whole, released = _leaves("verlet", 0.01)
    stepper = varmech.Stepper(_particle(), _on_circle(0.3), [0.0, 0.0], dt=0.01, contacts=[SPHERE])
    while stepper.steps < whole.steps:
        stepper.advance(min(7, whole.steps - stepper.steps))
        stepper = varmech.Stepper.from_checkpoint(_particle(), stepper.checkpoint(), contacts=[SPHERE])
    assert np.array_equal(stepper.q, whole.q[-1]) and np.array_equal(stepper.p, whole.p[-1])


def test_a_string_whirled_too_slowly_goes_slack_and_is_caught_again_where_the_parabola_meets_the_circle():
    # The string |q| ≤ l as a contact that holds (e = 0: it catches the bob without rebound).
    # From the bottom with v₀² = 3.5gl the bob rises past the horizontal and the tension
    # m(v²/l + g cos θ), θ from the downward vertical, falls to 0 where v² = −gl cos θ:
    # cos θ = (2gl − v₀²)/(3gl). It then flies on the parabola until |q| = l again.
    length, v0 = 1.0, math.sqrt(3.5 * G)
    string = varmech.Contact.ellipsoid([length, length], restitution=0.0, law="reflect", name="string")
    q0 = np.array([0.0, -length])
    traj = varmech.integrate(_particle(), q0, [v0, 0.0], method="yoshida4", dt=1e-3, t_end=1.6, contacts=[string])
    impacts, closed, released, stuck, slipped = traj.events[-5:]  # after the run's own events
    assert len(stuck) == len(slipped) == 0, "no friction, no friction switches"
    assert len(released) == 1 and len(impacts) == 1 and len(closed) == 1
    (x, y) = released.q[0]
    cos_slack = (2 * G * length - v0**2) / (3 * G * length)
    assert abs(-y / length - cos_slack) < 1e-9 and abs(math.hypot(x, y) - length) < 1e-13
    # The flight: the parabola from the slack point, with the velocity there, meets the circle.
    (vx, vy), t_slack = released.p[0], released.t[0]

    def radius(s: float) -> float:
        return math.hypot(x + vx * s, y + vy * s - G * s * s / 2) - length

    flight = brentq(radius, 1e-3, 2.0, xtol=1e-15)
    assert abs(impacts.t[0] - (t_slack + flight)) < 1e-9
    np.testing.assert_allclose(impacts.q[0], [x + vx * flight, y + vy * flight - G * flight**2 / 2], atol=1e-9)
    # Caught: the radial velocity lost (Carnot), the contact closed at once, held after.
    assert closed.t[0] == impacts.t[0]
    after = traj.t > impacts.t[0]
    assert np.max(np.abs(np.hypot(traj.q[after, 0], traj.q[after, 1]) - length)) < 1e-13


def test_held_steps_in_the_holds_own_loop_are_the_one_at_a_time_loops_bit_for_bit():
    # Without samples the held steps run in the hold's own loop, which leaves the step that
    # releases or crosses a contact to the general loop; a sample at every step's end takes
    # every step in the general loop. One motion, through the slack string's release, its
    # flight and the catch that holds it again.
    length, v0, dt = 1.0, math.sqrt(3.5 * G), 1e-3
    string = varmech.Contact.ellipsoid([length, length], restitution=0.0, law="reflect", name="string")
    run = {"method": "yoshida4", "dt": dt, "steps": 1600, "contacts": [string]}
    whole = varmech.integrate(_particle(), [0.0, -length], [v0, 0.0], **run)
    grid = np.arange(1601) * dt
    stepwise = varmech.integrate(_particle(), [0.0, -length], [v0, 0.0], t_eval=grid, **run)
    on_grid = np.isin(whole.t, grid)
    assert np.array_equal(whole.t[on_grid], grid)
    assert np.array_equal(whole.q[on_grid], stepwise.q) and np.array_equal(whole.p[on_grid], stepwise.p)
    for ours, theirs in zip(whole.events, stepwise.events):
        assert np.array_equal(ours.t, theirs.t) and np.array_equal(ours.q, theirs.q)
    assert [len(e) for e in whole.events] == [1, 1, 1, 0, 0]


def test_an_ensemble_of_sliders_leaves_at_each_members_angle_bit_for_bit_its_single_runs():
    thetas = np.array([0.1, 0.2, 0.3, 0.4])
    q0 = np.array([_on_circle(t) for t in thetas])
    p0 = np.zeros_like(q0)
    runs = varmech.ensemble(_particle(), q0, p0, dt=0.01, t_end=1.5, contacts=[SPHERE], workers=2)
    for k, member in enumerate(runs):
        single = varmech.integrate(_particle(), q0[k], p0[k], dt=0.01, t_end=1.5, contacts=[SPHERE])
        assert np.array_equal(member.q, single.q) and np.array_equal(member.p, single.p)
        released = member.events[2]
        assert len(released) == 1 and abs(released.q[0][1] - 2 / 3 * math.cos(thetas[k])) < 1e-3


@pytest.mark.parametrize(("method", "order", "dt"), [("verlet", 2, 0.01), ("yoshida4", 4, 0.04)])
def test_an_event_on_a_held_motion_is_located_on_the_surface_at_the_methods_order_and_changes_no_bit(method, order, dt):
    # x = 1/2 on the sphere (θ* = π/6, before the release at cos θ = (2/3)cos θ₀), reached at
    # t* = ∫ dθ/θ̇, θ̇² = 2g(cos θ₀ − cos θ); θ = θ₀ + u² takes the root singularity out.
    theta0, x = 0.3, 0.5

    def dt_du(u: float) -> float:
        if u == 0:
            return 2 / math.sqrt(2 * G * math.sin(theta0))
        return 2 * u / math.sqrt(2 * G * (math.cos(theta0) - math.cos(theta0 + u * u)))

    exact, _ = quad(dt_du, 0.0, math.sqrt(math.pi / 6 - theta0), epsabs=1e-14, epsrel=1e-14)
    errors = []
    for h in (dt, dt / 2, dt / 4):
        watched, released = _leaves(method, h, theta0, events=[varmech.events.crossing(0, x)])
        crossing = watched.events[0]
        assert len(crossing) == 1 and crossing.t[0] < released.t[0]
        assert abs(crossing.q[0][0] - x) < 1e-13 and abs(math.hypot(*crossing.q[0]) - 1) < 1e-13, "on the sphere"
        errors.append(abs(crossing.t[0] - exact))
        plain, left = _leaves(method, h, theta0)
        for ours, theirs in [(watched.q, plain.q), (watched.p, plain.p), (released.t, left.t), (released.q, left.q)]:
            assert np.array_equal(ours, theirs), "what a run watches changes nothing it computes"
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - order) < 0.25), (orders, errors)


def test_a_slider_streamed_to_a_file_and_resumed_is_one_run_with_its_release(tmp_path):
    # Killed (here: stopped) while held on the sphere, resumed from the file's checkpoint: the
    # held state is recognised as resting there, and the run goes on bit for bit, its release
    # stored in the file with the impacts.
    whole, released = _leaves("verlet", 0.01)
    path = tmp_path / "slider.h5"
    varmech.integrate(_particle(), _on_circle(0.3), [0.0, 0.0], dt=0.01, steps=40, contacts=[SPHERE], output=path, checkpoint_every=7)
    resumed = varmech.resume(path, steps=whole.steps - 40, model=_particle())
    for x, y in [(resumed.t, whole.t), (resumed.q, whole.q), (resumed.p, whole.p)]:
        np.testing.assert_array_equal(x, y)
    assert [o.name for o in resumed.events] == ["sphere", "sphere.closed", "sphere.released", "sphere.stuck", "sphere.slipped"]
    np.testing.assert_array_equal(resumed.events[2].t, released.t)
    np.testing.assert_array_equal(varmech.load(path, model=_particle()).events[2].q, released.q)


#: Issue 64's cases: a trap ½kx² under gravity g (mass m) above the floor x ≥ −a, restitution
#: e, from (x₀, v₀), at the step h of its property test.
TRAPPED = {
    "falls from rest": (3.3575621915367484, 1.6898067384630384, 6.283483229136442, 0.5889668115537644, 0.5458215677524878,
                        0.0, 1.3036067969625391e-55, 0.8356555558181492),
    "thrown up": (0.3653746425055403, 0.8756114838428447, 0.99999, 1.3264414980520427, 0.3413037757262099,
                  1.7857279646163263e-190, 1.8163818877974123, 0.04871056203162395),
}


def _trapped_rest(k: float, m: float, g: float, a: float, e: float, x0: float, v0: float) -> float:
    """When the trapped particle comes to rest on the floor: its first impact, then flights
    harmonic about the equilibrium −gm/k, each from the floor (d = gm/k − a above it) at speed
    v back to it after (2/ω)·atan(v/(ωd)), v falling by e at each."""
    w, below = math.sqrt(k / m), g * m / k
    y0, d = x0 + below, below - a
    amplitude = math.hypot(y0, v0 / w)
    t = (math.atan2(v0, w * y0) + math.acos(d / amplitude)) / w
    v = e * w * math.sqrt(amplitude**2 - d**2)
    while v > 1e-300:
        t += 2 / w * math.atan(v / (w * d))
        v *= e
    return t


@pytest.mark.parametrize("exact", [True, False], ids=["gradient", "differences"])
@pytest.mark.parametrize(("method", "order"), [("verlet", 2), ("yoshida4", 4)])
@pytest.mark.parametrize("name", list(TRAPPED))
def test_a_trapped_particle_pressed_on_a_floor_above_its_equilibrium_bounces_to_rest_held_at_every_step(name, method, order, exact):
    # Each closing leaves the normal velocity's round-off, ε|q̇⁻|, which was read as the body
    # leaving the floor again: released, it crossed it at once, "a smaller step helps", and
    # none did (issue 64). Held, it rests from the Zeno limit on, the balance E − W of its
    # losses converging at the method's order.
    k, m, g, a, e, x0, v0, h = TRAPPED[name]
    k_, m_ = np.array([k]), np.array([m])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # derivatives by differences, as asked
        model = varmech.MechanicalSystem(
            1, lambda q: float(0.5 * np.sum(k_ * q**2) + g * m * q[-1]), (lambda q: k_ * q + g * m) if exact else None, mass=m_, name="trap"
        )
    floor = varmech.Contact.wall(0, -a, restitution=e, law="reflect", name="floor")
    t_rest = _trapped_rest(k, m, g, a, e, x0, v0)
    balance = []
    for div in (1, 2, 4, 16):
        dt = h / div
        traj = varmech.integrate(model, [x0], [m * v0], method=method, dt=dt, steps=math.ceil((t_rest + h) / dt), contacts=[floor])
        impacts, closed, released, _, _ = traj.events
        assert len(closed) == 1 and len(released) == 0 and len(impacts) >= 2, (div, closed.t, released.t)
        # Closed at the Zeno limit, within the method's error (the series' rest taken as
        # parabolas' from the closing impact: O(h³) of the harmonic flights').
        assert abs(closed.t[0] - t_rest) <= 0.5 * dt ** min(order, 3) * t_rest, (div, closed.t[0], t_rest)
        # Resting from there: on the floor, at rest.
        after = traj.t > closed.t[0]
        assert np.count_nonzero(after) >= 2
        assert np.max(np.abs(traj.q[after, 0] + a)) <= 4 * np.finfo(float).eps * a, div
        assert np.max(np.abs(traj.p[after, 0])) <= 1e-15 * m, div
        energy = 0.5 * traj.p[:, 0] ** 2 / m + 0.5 * k * traj.q[:, 0] ** 2 + g * m * traj.q[:, 0]
        balance.append(abs(energy[-1] - energy[0] - traj.work[-1]))
    # The losses' account: E − W at rest is the method's error, which falls at its order.
    assert balance[3] <= balance[2] / 4 ** (order - 1), balance
    assert varmech.check_conservation(traj).energy.verdict in ("conserved to round-off", "bounded")
