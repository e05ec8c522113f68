"""A Stepper goes through impacts (issue 33): its steps with contacts are a run's steps with
them, to the bit, one call at a time or many, across a checkpoint and a pickle; it reports the
run's impacts, refuses what a run refuses with the run's messages, and stops at an impact it
cannot resolve with its last good state, as the run does."""

import pickle
import re

import numpy as np
import pytest

import varmech

G = 9.81


def _closure() -> varmech.Model:
    return varmech.MechanicalSystem(1, lambda q: G * q[0], lambda q: np.array([G]))


def _python_floor(restitution: float = 0.9, law: str = "variational") -> varmech.Contact:
    return varmech.Contact(lambda q: q[0], lambda q: [1.0], restitution=restitution, name="floor", law=law)


# (model or scene, its stepper's and run's arguments, steps): the bouncing ball's native floor
# (variational law), the elliptic billiard's native table, a closure ball on a floor of
# Python functions φ = q, ∇φ = 1 (e = 0.9, reflection), and the ball with e = 0.5, which comes
# to rest at t = 1.35 and rests on its floor, held.
CASES = {
    "ball": (varmech.scenes.bouncing_ball, {"dt": 1e-2}, 600),
    "billiard": (varmech.scenes.elliptic_billiard, {"dt": 0.1}, 600),
    "closure": (_closure, {"q0": [1.0], "p0": [0.0], "dt": 1e-2, "contacts": [_python_floor()]}, 500),
    "resting": (lambda: varmech.scenes.bouncing_ball(restitution=0.5), {"dt": 1e-2}, 300),
}


def _after_impacts(traj: varmech.Trajectory) -> np.ndarray:
    """The momenta just after each impact: the second of a run's two rows at an impact's time."""
    return traj.p[np.flatnonzero(np.diff(traj.t) == 0) + 1]


@pytest.mark.parametrize("case", CASES)
def test_a_stepper_with_contacts_is_the_run_with_them_bit_for_bit(case):
    make, args, steps = CASES[case]
    traj = varmech.integrate(make(), steps=steps, **args)
    single, many = varmech.Stepper(make(), **args), varmech.Stepper(make(), **args)
    for _ in range(steps):
        single.step()
    many.advance(steps)
    hits = traj.events[0]
    assert len(hits) >= 5
    for stepper in (single, many):
        assert stepper.steps == steps and stepper.t == traj.t[-1]
        assert np.array_equal(stepper.q, traj.q[-1]) and np.array_equal(stepper.p, traj.p[-1])
        # The run's impacts: times, contact configurations, momenta before and after.
        (before,), (after,) = stepper.impacts, stepper.impacts_after
        assert before.name == after.name == hits.name
        for x, y in [(before.t, hits.t), (before.q, hits.q), (before.p, hits.p), (after.t, hits.t)]:
            assert np.array_equal(x, y)
        assert np.array_equal(after.p, _after_impacts(traj))
        # Its closures and releases, as the run's.
        for mine, theirs in zip(stepper.switches, traj.events[1:], strict=True):
            assert mine.name == theirs.name and np.array_equal(mine.t, theirs.t) and np.array_equal(mine.p, theirs.p)
        # The impacts' partial steps are counted, as the run counts them.
        assert stepper.force_evaluations == traj.nfev


@pytest.mark.parametrize("case", CASES)
def test_a_stepper_checkpointed_or_pickled_with_its_contacts_goes_on_bit_for_bit(case):
    make, args, steps = CASES[case]
    whole = varmech.Stepper(make(), **args)
    whole.advance(steps)
    stepper = varmech.Stepper(make(), **args)
    contacts = {"contacts": args["contacts"]} if "contacts" in args else {}
    # Stopped at every 37th step (some just after an impact), rebuilt, and stepped on.
    while stepper.steps < steps:
        stepper.advance(min(37, steps - stepper.steps))
        stepper = varmech.Stepper.from_checkpoint(make(), stepper.checkpoint(), **contacts)
    assert np.array_equal(stepper.q, whole.q) and np.array_equal(stepper.p, whole.p)
    if case != "closure":  # Python lambdas do not pickle
        half = varmech.Stepper(make(), **args)
        half.advance(steps // 2)
        copy = pickle.loads(pickle.dumps(half))
        assert copy.contacts == half.contacts
        copy.advance(steps - steps // 2)
        assert np.array_equal(copy.q, whole.q) and np.array_equal(copy.p, whole.p)
        # Its impacts counted from the copy on: the whole's after half the steps.
        (mine,), (theirs,) = copy.impacts, whole.impacts
        assert np.array_equal(mine.t, theirs.t[theirs.t > half.t])


def test_a_run_checkpoint_goes_on_in_a_stepper_with_the_scenes_contacts():
    ball = varmech.scenes.bouncing_ball()
    first = varmech.integrate(ball, dt=1e-2, steps=250)
    whole = varmech.integrate(ball, dt=1e-2, steps=500)
    stepper = varmech.Stepper.from_checkpoint(ball, first.checkpoint)
    assert stepper.contacts == ball.contacts
    stepper.advance(250)
    assert np.array_equal(stepper.q, whole.q[-1]) and np.array_equal(stepper.p, whole.p[-1])
    (hits,) = stepper.impacts
    assert np.array_equal(hits.t, whole.events[0].t[whole.events[0].t > first.t[-1]])
    # contacts=[]: the bare model, which falls through the floor.
    bare = varmech.Stepper.from_checkpoint(ball, first.checkpoint, contacts=[])
    bare.advance(250)
    assert bare.contacts == () and bare.impacts == () and bare.q[0] < -10


def test_contacts_given_override_the_scenes_and_none_steps_the_bare_model():
    ball = varmech.scenes.bouncing_ball()
    bare = varmech.Stepper(ball, dt=1e-2, contacts=[])
    bare.advance(100)
    alone = varmech.Stepper(ball.model, ball.q0, ball.p0, dt=1e-2)
    alone.advance(100)
    assert np.array_equal(bare.q, alone.q) and bare.q[0] < 0
    lossy = [varmech.Contact.wall(0, restitution=0.5, law="reflect", name="floor")]
    stepper = varmech.Stepper(ball, dt=1e-2, contacts=lossy)
    stepper.advance(100)
    run = varmech.integrate(ball, dt=1e-2, steps=100, contacts=lossy)
    assert np.array_equal(stepper.q, run.q[-1]) and np.array_equal(stepper.p, run.p[-1])


def test_an_unresolvable_impact_raises_contact_error_with_the_stepper_at_its_last_good_state():
    # e = 0.5 under rk4, which cannot hold the floor: the bounces accumulate and the run fails
    # at a step whose impact cannot be resolved, its partial trajectory ending at that step's start.
    lossy = {"q0": [1.0], "p0": [0.0], "dt": 0.01, "method": "rk4", "contacts": [_python_floor(0.5, "reflect")]}
    with pytest.raises(varmech.ContactError) as run:
        varmech.integrate(_closure(), t_end=2.0, **lossy)
    partial = run.value.partial
    for advancing in (True, False):
        stepper = varmech.Stepper(_closure(), **lossy)
        with pytest.raises(varmech.ContactError) as info:
            if advancing:
                stepper.advance(200)
            else:
                for _ in range(200):
                    stepper.step()
        err = info.value
        assert (err.step, err.time) == (run.value.step, run.value.time)
        assert stepper.steps == err.step - 1 and stepper.t == err.time == partial.t[-1]
        assert np.array_equal(stepper.q, partial.q[-1]) and np.array_equal(stepper.p, partial.p[-1])
        assert np.array_equal(stepper.impacts[0].t, partial.events[0].t)
        # It stays there: the next step fails again, the state unchanged.
        with pytest.raises(varmech.ContactError):
            stepper.step()
        assert np.array_equal(stepper.q, partial.q[-1]) and stepper.steps == err.step - 1


def _bent(contact: varmech.Contact) -> varmech.Contact:
    """The contact with restitution 1.5, set past its own check (as a crafted object would)."""
    object.__setattr__(contact, "restitution", 1.5)
    return contact


def _message(call, *args, **kw) -> str:
    with pytest.raises((ValueError, TypeError)) as info:
        call(*args, **kw)
    return f"{type(info.value).__name__}: {info.value}"


def test_bad_contacts_and_states_outside_them_are_refused_as_integrate_refuses_them():
    ball = varmech.scenes.bouncing_ball()
    cases = [
        # a state below the floor, naming q0 and the contact
        ({"q0": [-0.1], "p0": [0.0]}, r'^ValueError: q0: outside the contact "floor": φ = -0.1 < 0$'),
        # a wall on a coordinate the model does not have
        ({"contacts": [varmech.Contact.wall(3, name="far")]}, r"^ValueError: contacts: \"far\" \(contacts\[0\]\): coordinate 3"),
        # the variational law on a method without a discrete energy
        ({"method": "rk4"}, r"^ValueError: contacts: \"floor\" \(contacts\[0\]\): the variational collision integrator needs"),
        # a restitution outside [0, 1] past the Contact's own check: the core's refusal
        (
            {"contacts": [_bent(varmech.Contact.wall(0, name="floor"))]},
            r'^ValueError: contacts: "floor" \(contacts\[0\]\): restitution must lie in \[0, 1\], got 1.5$',
        ),
        # not a Contact
        ({"contacts": ["floor"]}, r"^TypeError: contacts\[0\]: expected a varmech.Contact, got str$"),
    ]
    for kw, pattern in cases:
        stepped = _message(varmech.Stepper, ball, dt=1e-2, **kw)
        assert stepped == _message(varmech.integrate, ball, dt=1e-2, steps=1, **kw)
        assert re.match(pattern, stepped), stepped
    # A restitution outside [0, 1] is the Contact's own refusal, before any stepper.
    with pytest.raises(ValueError, match=r"^restitution: must lie in \[0, 1\], got 1.5$"):
        varmech.Contact.wall(0, restitution=1.5)
    # A checkpoint outside the floor names checkpoint; a reset outside it names q0, and the
    # stepper is left as it was.
    below = varmech.Stepper(ball, [-0.1], [0.0], dt=1e-2, contacts=[]).checkpoint()
    with pytest.raises(ValueError, match=r'^checkpoint: outside the contact "floor": φ = -0.1 < 0$'):
        varmech.Stepper.from_checkpoint(ball, below)
    stepper = varmech.Stepper(ball, dt=1e-2)
    stepper.advance(60)
    q, p, t, steps = stepper.q, stepper.p, stepper.t, stepper.steps
    with pytest.raises(ValueError, match=r'^q0: outside the contact "floor"'):
        stepper.reset([-0.1], [0.0])
    assert np.array_equal(stepper.q, q) and np.array_equal(stepper.p, p) and (stepper.t, stepper.steps) == (t, steps)
    assert len(stepper.impacts[0]) == 1
    # A reset inside starts afresh, its impacts forgotten, and steps as a new stepper.
    stepper.reset([1.0], [0.0], t0=0.0)
    assert len(stepper.impacts[0]) == 0
    stepper.advance(100)
    fresh = varmech.Stepper(ball, dt=1e-2)
    fresh.advance(100)
    assert np.array_equal(stepper.q, fresh.q) and np.array_equal(stepper.impacts[0].t, fresh.impacts[0].t)


def test_a_python_contacts_exception_propagates_unchanged_with_the_stepper_where_the_run_ends():
    class Boom(Exception):
        pass

    def phi(q):
        if q[0] < 0.5:
            raise Boom("phi")
        return q[0]

    def floor():
        return [varmech.Contact(phi, lambda q: [1.0])]

    with pytest.raises(Boom) as run:
        varmech.integrate(_closure(), [1.0], [0.0], dt=1e-2, steps=100, contacts=floor())
    stepper = varmech.Stepper(_closure(), [1.0], [0.0], dt=1e-2, contacts=floor())
    with pytest.raises(Boom, match="^phi$") as info:
        stepper.advance(100)
    # At the step's end, where φ raised: the run's last saved state.
    assert (info.value.step, info.value.time) == (run.value.step, run.value.time)
    assert np.array_equal(stepper.q, run.value.partial.q[-1]) and stepper.t == run.value.partial.t[-1]
