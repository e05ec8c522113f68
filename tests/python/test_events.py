"""Events: crossings located by the method's own partial step, checked against exact times.

The pendulum H = p²/2 − cos q from (q, p) = (0, 1) swings between ±π/3; its period is
T = 4K(k²) with k = sin(π/6) = 1/2 (K the complete elliptic integral of the first kind), so q
crosses 0 at t = jT/2 exactly. The located crossing is a state of the integrator: its time is off
by the method's error, O(hᵖ).
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.special import ellipk

import varmech
from conftest import Boom, raising_when
from varmech import sections
from varmech.events import Event, crossing, encounter, energy_error, escape

PENDULUM = varmech.scenes.pendulum()
PERIOD = 4 * ellipk(0.25)
REFERENCE = Path(__file__).parents[2] / "reference" / "henon_heiles_sections.json"


def pendulum_crossings(method, dt, t_end=20.0, **event):
    traj = varmech.integrate(PENDULUM, dt=dt, t_end=t_end, method=method, events=[crossing(0, 0.0, **event)])
    return traj, traj.events[0]


def crossing_time_error(method, dt):
    _, found = pendulum_crossings(method, dt)
    exact = np.arange(1, len(found) + 1) * PERIOD / 2
    return float(np.max(np.abs(found.t - exact)))


def test_pendulum_zero_crossings_match_its_exact_period():
    # t ∈ [0, 20] holds 5 half periods (T = 7.416).
    traj, found = pendulum_crossings("kahan_li6", 0.05)
    assert len(found) == 5
    np.testing.assert_array_equal(np.abs(found.q[:, 0]) <= 1e-16, True)
    # kahan_li6 at h = 0.05: phase error ~ h⁶ per unit time (measured 5.0e-11 by t = 18.5).
    np.testing.assert_allclose(found.t, np.arange(1, 6) * PERIOD / 2, rtol=0, atol=1e-10)
    # Verlet's phase drifts at h²/24 of the frequency per unit time: by t = 18.5 at h = 0.01,
    # about 18.5·1e-4/24 ≈ 8e-5 (measured 2.9e-5).
    assert crossing_time_error("verlet", 0.01) <= 1e-4
    # The events run steps one at a time and changes nothing else: its states are the plain run's.
    plain = varmech.integrate(PENDULUM, dt=0.05, t_end=20.0, method="kahan_li6")
    np.testing.assert_array_equal(traj.q, plain.q)
    np.testing.assert_array_equal(traj.p, plain.p)
    assert traj.status == 0 and plain.events == ()


@pytest.mark.parametrize(("method", "order", "dt"), [("verlet", 2, 0.05), ("yoshida4", 4, 0.1), ("kahan_li6", 6, 0.2), ("midpoint", 2, 0.05)])
def test_located_crossing_times_converge_at_the_methods_order(method, order, dt):
    # Measured slopes: verlet 2.00, yoshida4 3.99, kahan_li6 6.00, midpoint 2.00.
    coarse, fine = crossing_time_error(method, dt), crossing_time_error(method, dt / 2)
    slope = math.log2(coarse / fine)
    assert abs(slope - order) <= 0.3, (coarse, fine, slope)


def test_a_terminal_event_stops_after_the_step_of_its_crossing_with_status_1():
    dt = 0.05
    traj, found = pendulum_crossings("verlet", dt, terminal=True)
    assert traj.status == 1 and not traj.success
    assert traj.message.startswith("A termination event occurred: q[0] = 0 (occurrence 1)")
    (t_cross,) = found.t
    # The last saved state is the end of the step holding the crossing: a grid state.
    assert traj.t[-1] - dt < t_cross <= traj.t[-1]
    assert traj.steps == math.ceil(t_cross / dt) == len(traj.t) - 1
    plain = varmech.integrate(PENDULUM, dt=dt, steps=traj.steps, method="verlet")
    np.testing.assert_array_equal(traj.q, plain.q)
    np.testing.assert_array_equal(traj.p, plain.p)


def test_a_count_terminal_stops_at_the_third_occurrence():
    traj, found = pendulum_crossings("verlet", 0.01, t_end=100.0, terminal=3)
    assert traj.status == 1 and "occurrence 3" in traj.message
    assert len(found) == 3
    np.testing.assert_allclose(found.t, np.arange(1, 4) * PERIOD / 2, atol=1e-4)
    assert traj.t[-1] - 0.01 < found.t[-1] <= traj.t[-1]


def test_direction_keeps_only_the_crossings_of_its_sign():
    _, down = pendulum_crossings("verlet", 0.01, direction=-1)
    _, up = pendulum_crossings("verlet", 0.01, direction=+1)
    _, both = pendulum_crossings("verlet", 0.01)
    # q falls through 0 at T/2, 3T/2, … (p < 0 there) and rises at T, 2T.
    assert (len(down), len(up), len(both)) == (3, 2, 5)
    assert np.all(down.p[:, 0] < 0) and np.all(up.p[:, 0] > 0)
    np.testing.assert_array_equal(np.sort(np.r_[down.t, up.t]), both.t)


def test_velocity_events_and_plain_functions_with_solve_ivp_attributes():
    # The turning point q̇ = 0 at q = π/3: as g(t, q, v) and, for this model (v = p), g(t, q, p).
    turn = Event(lambda t, q, v: v[0], direction=-1, variables="v", name="turn")

    def momentum(t, q, p):
        return p[0]

    momentum.direction = -1  # type: ignore[attr-defined]
    momentum.terminal = 2  # type: ignore[attr-defined]
    traj = varmech.integrate(PENDULUM, dt=0.01, t_end=40.0, method="yoshida4", events=[turn, momentum])
    by_velocity, by_momentum = traj.events
    assert (by_velocity.name, by_momentum.name) == ("turn", "momentum")
    assert traj.status == 1 and "momentum (occurrence 2)" in traj.message
    np.testing.assert_array_equal(by_velocity.t, by_momentum.t)
    # At the turning points, t = T/4 + jT, q = π/3 up to the method's energy error (~1e-9).
    np.testing.assert_allclose(by_velocity.q[:, 0], math.pi / 3, atol=1e-8)
    np.testing.assert_allclose(by_velocity.t, PERIOD / 4 + PERIOD * np.arange(2), atol=1e-8)


def test_escape_of_a_hyperbolic_kepler_orbit_at_the_exact_time():
    # From pericentre r = 1 with speed 1.6: E = 0.28 > 0, a = 1/(2E), e = 1 + 1/a; the orbit
    # reaches r = R at t = √(a³)(e sinh F − F) with e cosh F = 1 + R/a.
    radius = 10.0
    traj = varmech.integrate(
        varmech.scenes.kepler().model, [1.0, 0.0], [0.0, 1.6], dt=0.01, t_end=100.0, method="kahan_li6", events=[escape(radius, dim=2)]
    )
    assert traj.status == 1 and "escape(10)" in traj.message
    (t,) = traj.events[0].t
    a = 1 / 0.56
    e = 1 + 1 / a
    F = math.acosh((1 + radius / a) / e)
    assert abs(t - math.sqrt(a**3) * (e * math.sinh(F) - F)) <= 1e-9
    assert abs(np.hypot(*traj.events[0].q[0]) - radius) <= 1e-13


def test_encounter_and_escape_on_an_nbody_scene():
    # A heavy body at rest, one on a circle of radius 1 and a light one on a hyperbola (E > 0,
    # angular momentum 0.6: pericentre 0.145) that passes the heavy body within 0.2 and leaves.
    scene = varmech.scenes.nbody([1.0, 1e-3, 1e-9], [[0, 0, 0], [1, 0, 0], [0.3, -3, 0]], [[0, 0, 0], [0, 1, 0], [0, 2.0, 0]])
    traj = varmech.integrate(scene, dt=1e-3, t_end=20.0, method="verlet", events=[encounter(0.2, terminal=False), escape(5.0)])
    close, away = traj.events
    assert traj.status == 1 and "escape(5)" in traj.message
    x = close.q.reshape(-1, 3, 3)
    # Every close pair found is at distance 0.2 to round-off; the escaping body is at r = 5.
    pairs = [np.linalg.norm(x[:, i] - x[:, j], axis=1) for i, j in ((0, 1), (0, 2), (1, 2))]
    assert len(close) == 1
    np.testing.assert_allclose(np.min(pairs, axis=0), 0.2, atol=1e-12)
    y = away.q.reshape(3, 3)
    assert abs(np.max(np.linalg.norm(y, axis=1)) - 5.0) <= 1e-12


def test_energy_error_stops_explicit_euler_where_its_energy_exceeds_the_bound():
    # Euler on q'' = −q multiplies E by (1 + h²) a step: E_n = ½(1 + h²)ⁿ from (0, 1).
    dt, bound = 0.01, 0.01
    traj = varmech.integrate(
        varmech.scenes.harmonic_oscillator(), dt=dt, t_end=100.0, method="explicit_euler", max_energy_error=None, events=[energy_error(bound)]
    )
    assert traj.status == 1
    n = math.log(1 + bound / 0.5) / math.log(1 + dt**2)
    assert traj.steps == math.ceil(n)
    q, p = traj.events[0].q[0], traj.events[0].p[0]
    assert abs(0.5 * (q[0] ** 2 + p[0] ** 2) - 0.5 - bound) <= 1e-14


def test_an_event_function_with_the_wrong_signature_is_a_type_error_naming_it():
    def two(t, q):
        return q[0]

    with pytest.raises(TypeError, match=r"events\[0\] \(two\): an event function takes \(t, q, p\)"):
        varmech.integrate(PENDULUM, dt=0.1, steps=10, events=[two])
    with pytest.raises(TypeError, match=r"events\[1\]"):
        varmech.integrate(PENDULUM, dt=0.1, steps=10, events=[crossing(0), 3.0])
    with pytest.raises(ValueError, match=r"events: q\[5\] = 0: coordinate 5 is not in 0 … 0"):
        varmech.integrate(PENDULUM, dt=0.1, steps=10, events=[crossing(5)])
    with pytest.raises(ValueError, match="terminal"):
        varmech.integrate(PENDULUM, dt=0.1, steps=10, events=[Event(lambda t, q, p: q[0], terminal=0.5)])


def test_an_event_that_raises_propagates_unchanged_with_the_partial_trajectory():
    late = raising_when(lambda t, q, p: t > 5.0, lambda t, q, p: q[0], "from the event")
    with pytest.raises(Boom, match="from the event") as info:
        varmech.integrate(PENDULUM, dt=0.01, t_end=20.0, events=[late])
    partial = info.value.partial  # type: ignore[attr-defined]
    assert partial.status == -1 and 5.0 <= partial.t[-1] <= 5.02
    # The crossing before the failure (T/2 = 3.7) was kept.
    assert len(partial.events[0]) == 1 and abs(partial.events[0].t[0] - PERIOD / 2) <= 1e-4

    with pytest.raises(varmech.VarmechError, match="event nan returned a non-finite value") as info:
        varmech.integrate(PENDULUM, dt=0.01, t_end=1.0, events=[Event(lambda t, q, p: math.nan if t > 0.5 else 1.0, name="nan")])
    assert info.value.partial.t[-1] <= 0.52  # type: ignore[attr-defined]


def test_henon_heiles_sections_match_the_partial_step_locator_they_replaced():
    """The sections, now built on events, against the rows the previous implementation (its own
    crossing search and Newton on partial steps through varmech.Stepper) gave: to 1e-12."""
    reference = json.loads(REFERENCE.read_text())
    hh = varmech.scenes.henon_heiles()
    for case in reference["cases"]:
        tab = sections.poincare_section(hh, case["energy"], **case["arguments"])
        assert list(tab.columns) == case["columns"]
        got = np.array([[row[c] for c in tab.columns] for row in tab])
        want = np.array(case["rows"])
        assert got.shape == want.shape
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_a_saved_trajectory_keeps_its_events(tmp_path):
    s = varmech.scenes.harmonic_oscillator()
    traj = varmech.integrate(s, dt=0.01, t_end=10.0, events=[crossing(0, 0.5, direction=+1), crossing(0, 0.0)])
    back = varmech.load(traj.save(tmp_path / "e.h5"))
    assert [o.name for o in back.events] == [o.name for o in traj.events]
    for a, b in zip(back.events, traj.events):
        for name in ("t", "q", "p"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
