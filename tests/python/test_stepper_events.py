"""A Stepper watches events (issue 33's matrix, Stepper × events): its crossings are a run's, to
the bit, one call at a time or many, with contacts, across a checkpoint and a pickle; a terminal
event stops the call after the step of its crossing and its count carries over to the next call,
as a run gone on from counts it; reset starts the events afresh."""

import pickle

import numpy as np
import pytest

import varmech
from varmech.events import crossing, energy_error, multiplier


def _same(found, expected):
    assert [o.name for o in found] == [o.name for o in expected]
    for a, b in zip(found, expected):
        np.testing.assert_array_equal(a.t, b.t)
        np.testing.assert_array_equal(a.q, b.q)
        np.testing.assert_array_equal(a.p, b.p)


def _python_event(t, q, p):
    return p[0] - 0.5


_python_event.direction = 1  # type: ignore[attr-defined]


# (model, q0, p0, method, dt, events, steps): native crossings and a Python function on the
# pendulum, an energy bound on explicit Euler, a multiplier on the Cartesian pendulum, and a
# height crossing on the bouncing ball through its floor's impacts.
CASES = {
    "pendulum": (varmech.scenes.pendulum, [1.0], [0.0], "verlet", 0.01, [crossing(0, 0.0), _python_event], 700),
    "energy": (varmech.scenes.harmonic_oscillator, [0.0], [1.0], "explicit_euler", 0.01, [energy_error(0.01, terminal=False)], 400),
    "multiplier": (varmech.scenes.cartesian_pendulum, [0.0, -1.0], [3.5**0.5, 0.0], "rattle", 0.01, [multiplier(0)], 500),
    "ball": (varmech.scenes.bouncing_ball, None, None, None, 0.01, [crossing(0, 0.5)], 400),
}


def _both(case):
    make, q0, p0, method, dt, events, steps = CASES[case]
    kw = dict(dt=dt, method=method, events=events)
    if case == "energy":
        kw["max_energy_error"] = None
    run = varmech.integrate(make(), q0, p0, steps=steps, **kw)
    kw.pop("max_energy_error", None)
    return run, varmech.Stepper(make(), q0, p0, **kw), steps


@pytest.mark.parametrize("case", CASES)
def test_a_steppers_crossings_are_the_runs_one_call_at_a_time_or_many(case):
    run, stepper, steps = _both(case)
    assert sum(len(o) for o in run.events) > 0
    stepper.advance(steps // 3)
    for _ in range(steps // 3):
        stepper.step()
    stepper.advance(steps - 2 * (steps // 3))
    # A run's events hold its contacts' impacts after its events.
    _same(stepper.events, run.events[: len(stepper.events)])
    assert stepper.terminated_by is None
    np.testing.assert_array_equal(stepper.q, run.q[-1])
    np.testing.assert_array_equal(stepper.p, run.p[-1])


def test_a_terminal_event_stops_the_call_and_its_count_carries_to_the_next():
    # terminal=2: the second crossing stops the stepper, wherever the calls split the steps; the
    # run stops at the same step.
    make = varmech.scenes.pendulum
    event = [crossing(0, 0.0, direction=-1, terminal=2)]
    run = varmech.integrate(make(), [1.0], [0.0], dt=0.01, t_end=100.0, events=event)
    stepper = varmech.Stepper(make(), [1.0], [0.0], dt=0.01, events=event)
    stepper.advance(500)  # past the first crossing (t = 1.67), before the second (8.37)
    assert stepper.terminated_by is None and len(stepper.events[0]) == 1
    stepper.advance(10_000)
    assert stepper.terminated_by == "q[0] = 0" and stepper.steps == run.steps
    _same(stepper.events, run.events)
    # The count reached, the next call goes on through later crossings.
    stepper.advance(1000)
    assert stepper.terminated_by is None and len(stepper.events[0]) == 3


def test_reset_starts_the_events_afresh():
    event = [crossing(0, 0.0, direction=-1, terminal=True), energy_error(1e-3, terminal=False)]
    stepper = varmech.Stepper(varmech.scenes.pendulum(), [1.0], [0.0], dt=0.01, events=event)
    stepper.advance(1000)
    assert stepper.terminated_by == "q[0] = 0"
    stepper.reset([1.0], [0.0], t0=0.0)
    assert [len(o) for o in stepper.events] == [0, 0] and stepper.terminated_by is None
    stepper.advance(1000)
    again = varmech.Stepper(varmech.scenes.pendulum(), [1.0], [0.0], dt=0.01, events=event)
    again.advance(1000)
    _same(stepper.events, again.events)
    assert stepper.terminated_by == "q[0] = 0"


def test_a_checkpoint_and_a_pickle_go_on_watching_bit_for_bit():
    scene = varmech.scenes.bouncing_ball()
    event = [crossing(0, 0.5)]
    whole = varmech.Stepper(scene, dt=0.01, events=event)
    whole.advance(400)
    first = varmech.Stepper(scene, dt=0.01, events=event)
    first.advance(150)
    resumed = varmech.Stepper.from_checkpoint(scene, first.checkpoint(), events=event)
    unpickled = pickle.loads(pickle.dumps(first))
    for stepper in (resumed, unpickled):
        stepper.advance(250)
        np.testing.assert_array_equal(stepper.q, whole.q)
        later = whole.events[0].t[whole.events[0].t > first.t]
        np.testing.assert_array_equal(stepper.events[0].t, later)


def test_malformed_events_are_refused_by_name():
    with pytest.raises(TypeError, match="events: expected a list"):
        varmech.Stepper(varmech.scenes.pendulum(), dt=0.01, events=crossing(0, 0.0))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"events\[0\].*the model has no constraints"):
        varmech.Stepper(varmech.scenes.pendulum(), dt=0.01, events=[multiplier(0)])
    with pytest.raises(TypeError, match=r"events\[0\] \(q\[0\] = 0\): direction must be a number"):
        varmech.Stepper(varmech.scenes.pendulum(), dt=0.01, events=[crossing(0, 0.0, direction="up")])  # type: ignore[arg-type]
