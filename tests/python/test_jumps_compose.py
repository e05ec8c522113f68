"""Contacts compose with every other feature of a run (issue 33): the core resolves the impacts
in its one step loop, so events, output files with their checkpoints, ``resume``, continued
runs, ensembles and progress bars take them as they take any run, and each gives the run that
one uninterrupted run in memory gives, to the bit. The matrix runs on a native scene, a compiled
symbolic model and a closure model, each a ball bouncing on a floor (e = 0.9) with its own
surface kind: a native wall, and φ = q from Python functions."""

import numpy as np
import pytest
import sympy as sp

import varmech

G = 9.81
DT, STEPS = 1e-2, 600


def _symbolic() -> varmech.Model:
    x, v = sp.symbols("x v")
    return varmech.symbolic.lagrangian(v**2 / 2 - G * x, [x], [v])


def _closure() -> varmech.Model:
    return varmech.MechanicalSystem(1, lambda q: G * q[0], lambda q: np.array([G]))


def _floor(kind: str) -> varmech.Contact:
    if kind == "wall":
        return varmech.Contact.wall(0, restitution=0.9, name="floor")
    return varmech.Contact(lambda q: q[0], lambda q: [1.0], restitution=0.9, name="floor")


MODELS = {"native": lambda: varmech.scenes.bouncing_ball().model, "symbolic": _symbolic, "closure": _closure}
CASES = [(m, s) for m in MODELS for s in ("wall", "functions")]


def _run(model, floor, **kw):
    steps = kw.pop("steps", STEPS)
    return varmech.integrate(model, [1.0], [0.0], dt=DT, steps=steps, contacts=[floor], progress=False, **kw)


def _same(a: varmech.Trajectory, b: varmech.Trajectory) -> None:
    for x, y in [(a.t, b.t), (a.q, b.q), (a.p, b.p)]:
        np.testing.assert_array_equal(x, y)
    assert [o.name for o in a.events] == [o.name for o in b.events]
    for x, y in zip(a.events, b.events, strict=True):
        np.testing.assert_array_equal(x.t, y.t)
        np.testing.assert_array_equal(x.q, y.q)
        np.testing.assert_array_equal(x.p, y.p)


@pytest.mark.parametrize(("model", "surface"), CASES)
def test_a_ball_on_its_floor_bounces_as_e_squared_whatever_the_model_and_surface(model, surface):
    traj = _run(MODELS[model](), _floor(surface))
    hits = traj.events[0]
    # The first impact at √(2h₀/g); each bounce's apex e² times the last.
    assert len(hits) >= 4 and abs(hits.t[0] - np.sqrt(2 / G)) < 1e-12
    speeds = -hits.p[:, 0]
    np.testing.assert_allclose(speeds[1:] / speeds[:-1], 0.9, rtol=1e-9)
    assert traj.q.min() > -1e-12


@pytest.mark.parametrize(("model", "surface"), CASES)
def test_contacts_with_events_count_both(model, surface):
    # A crossing of q = 0.5, both ways: twice a bounce, and the impacts after it in traj.events.
    half = varmech.events.crossing(0, 0.5)
    traj = _run(MODELS[model](), _floor(surface), events=[half])
    crossings, hits = traj.events[:2]
    assert hits.name == "floor" and len(hits) >= 4
    # Every step is saved: the crossings are the sign changes of q − 0.5 between saved rows
    # (none at an impact's two rows, both at q = 0), one in each step that has one.
    changes = np.count_nonzero(np.diff(np.sign(traj.q[:, 0] - 0.5)))
    assert len(crossings) == changes == 7
    # The crossings lie on the ball's exact parabolas (Verlet is exact on them).
    assert np.max(np.abs(crossings.q[:, 0] - 0.5)) < 1e-12
    alone = _run(MODELS[model](), _floor(surface))
    np.testing.assert_array_equal(alone.events[0].t, hits.t)


@pytest.mark.parametrize(("model", "surface"), CASES)
def test_a_run_with_contacts_goes_on_as_one_run(model, surface, tmp_path):
    # Issue 32 refused these paths (the ball fell through the floor); now each goes on with the
    # contacts and gives one run's states and impacts, to the bit.
    m, floor = MODELS[model](), _floor(surface)
    whole = _run(m, floor)
    short = _run(m, floor, steps=STEPS // 3)
    assert short.contacts == (floor,)
    _same(varmech.integrate(short, steps=STEPS - STEPS // 3, progress=False), _tail(whole, short))
    # Streamed to a file in segments, resumed from it.
    path = tmp_path / "ball.h5"
    streamed = _run(m, floor, steps=STEPS // 3, output=path, checkpoint_every=37)
    _same(streamed, short)
    given = None if surface == "wall" else [floor]
    resumed = varmech.resume(path, steps=STEPS - STEPS // 3, model=m, contacts=given)
    _same(resumed, whole)


def _struck_ball(t: np.ndarray, t_star: float, kick: float, e: float = 0.9) -> tuple[np.ndarray, np.ndarray]:
    """The ball dropped from 1 at rest, struck up by Δp = ``kick`` at t* (before its first impact),
    bouncing with restitution e: its exact height and momentum at the times t."""
    q, p, t0 = 1.0 - G * t_star**2 / 2, -G * t_star + kick, t_star
    flights = []  # (start, height, momentum) of each free flight after the blow
    for _ in range(40):
        flights.append((t0, q, p))
        s = (p + np.sqrt(p * p + 2 * G * q)) / G  # q + p s − g s²/2 = 0
        t0, q, p = t0 + s, 0.0, -e * (p - G * s)
    out = []
    for ti in t:
        if ti <= t_star:
            out.append((1.0 - G * ti**2 / 2, -G * ti))
            continue
        start, q0, p0 = max(f for f in flights if f[0] < ti)
        s = ti - start
        out.append((q0 + p0 * s - G * s * s / 2, p0 - G * s))
    exact = np.array(out)
    return exact[:, 0], exact[:, 1]


@pytest.mark.parametrize(("model", "surface"), CASES)
def test_a_ball_struck_in_flight_and_sampled_follows_its_exact_motion_through_the_bounces(model, surface):
    # Impulses, t_eval and contacts together: the blow splits its step, each sample is the
    # method's partial step from the last jump before it, and Verlet is exact on the parabolas.
    m, floor = MODELS[model](), _floor(surface)
    times = np.linspace(0.013, 5.9, 97)
    blow = varmech.Impulse(generalized=[2.0], t=0.3047)
    traj = _run(m, floor, impulses=[blow], t_eval=times)
    np.testing.assert_array_equal(traj.t, times)
    q, p = _struck_ball(times, blow.t, 2.0)
    assert np.max(np.abs(traj.q[:, 0] - q)) < 1e-10 and np.max(np.abs(traj.p[:, 0] - p)) < 1e-9
    # The run itself is the run without samples, to the bit (its energy check, which a run of
    # samples makes at other steps, aside).
    plain = _run(m, floor, impulses=[blow])
    ends = [varmech.Stepper.from_checkpoint(m, r.checkpoint, contacts=[floor]) for r in (traj, plain)]
    assert ends[0].steps == ends[1].steps and (ends[0].q == ends[1].q).all() and (ends[0].p == ends[1].p).all()
    np.testing.assert_array_equal(traj.events[0].t, plain.events[0].t)


@pytest.mark.parametrize(("model", "surface"), CASES)
def test_a_struck_run_with_contacts_streamed_and_resumed_is_one_run(model, surface, tmp_path):
    m, floor = MODELS[model](), _floor(surface)
    blows = [varmech.Impulse(generalized=[2.0], t=0.3047), varmech.Impulse(generalized=[-1.0], t=1.5)]
    whole = _run(m, floor, impulses=blows)
    path = tmp_path / "struck.h5"
    _same(_run(m, floor, steps=STEPS // 3, impulses=blows, output=path, checkpoint_every=37), _run(m, floor, steps=STEPS // 3, impulses=blows))
    given = None if surface == "wall" else [floor]
    _same(varmech.resume(path, steps=STEPS - STEPS // 3, model=m, contacts=given), whole)


def _tail(whole: varmech.Trajectory, short: varmech.Trajectory) -> varmech.Trajectory:
    """The part of ``whole`` from ``short``'s last state on, as a continued run reports it."""
    k = len(short.t) - 1
    events = tuple(
        varmech.events.Occurrences(o.name, o.t[o.t > short.t[-1]], o.q[o.t > short.t[-1]], o.p[o.t > short.t[-1]]) for o in whole.events
    )
    return varmech.Trajectory(whole.t[k:], whole.q[k:], whole.p[k:], whole.model, whole.method, whole.dt, whole.steps, 0, events=events)


def test_a_file_of_python_contacts_resumes_only_with_them_given_again(tmp_path):
    floor = _floor("functions")
    path = tmp_path / "ball.h5"
    _run(_closure(), floor, steps=100, output=path)
    assert varmech.load(path, model=_closure()).contacts == ("floor",)
    with pytest.raises(ValueError, match=r"^contacts: the run's contacts 'floor' were given by Python functions"):
        varmech.resume(path, steps=10, model=_closure())
    with pytest.raises(ValueError, match=r"^contacts: the run has the contacts \['floor'\], not \['wall'\]"):
        varmech.resume(path, steps=10, model=_closure(), contacts=[varmech.Contact.wall(0, name="wall")])
    before = varmech.load(path, model=_closure())
    with pytest.raises(ValueError):
        varmech.resume(path, steps=10, model=_closure())
    assert len(varmech.load(path, model=_closure())) == len(before)   # the file is left as it was


@pytest.mark.parametrize("model", ["native", "symbolic"])
def test_an_ensemble_of_billiards_is_each_members_single_run(model):
    # Native and compiled models run their members on threads, each with its own contacts.
    table = varmech.Contact.ellipsoid([2.0, 1.0], name="table")
    free = varmech.scenes.elliptic_billiard(A=2.0, B=1.0).model if model == "native" else _free_symbolic()
    rng = np.random.default_rng(1)
    q0 = rng.uniform(-0.5, 0.5, (6, 2))
    p0 = rng.normal(size=(6, 2))
    runs = varmech.ensemble(free, q0, p0, dt=0.05, steps=400, contacts=[table], workers=2, progress=False)
    assert runs.failed == []
    for i in range(6):
        single = varmech.integrate(free, q0[i], p0[i], dt=0.05, steps=400, contacts=[table])
        _same(runs[i], single)
        assert len(single.events[0]) >= 3


def _free_symbolic() -> varmech.Model:
    x, y, u, v = sp.symbols("x y u v")
    return varmech.symbolic.lagrangian((u**2 + v**2) / 2 + 0 * x * y, [x, y], [u, v])


def test_an_ensemble_of_a_closure_model_with_python_contacts_runs_its_members_in_turn():
    floor = _floor("functions")
    runs = varmech.ensemble(_closure(), [[1.0], [0.5]], [[0.0], [0.0]], dt=DT, steps=200, contacts=[floor], progress=False)
    for i, h in enumerate((1.0, 0.5)):
        _same(runs[i], varmech.integrate(_closure(), [h], [0.0], dt=DT, steps=200, contacts=[floor]))


def test_a_scenes_contacts_run_in_its_ensembles_by_default():
    scene = varmech.scenes.bouncing_ball()
    runs = varmech.ensemble(scene, [[1.0], [2.0]], [[0.0], [0.0]], dt=DT, steps=300, progress=False)
    # Members with more impacts have more rows (two at each); the others are padded with NaN.
    assert all(len(t.events[0]) >= 2 for t in runs) and np.nanmin(runs.q) > -1e-12


def test_progress_does_not_change_a_run_with_contacts():
    scene = varmech.scenes.bouncing_ball()
    _same(varmech.integrate(scene, dt=DT, steps=STEPS, progress=True), varmech.integrate(scene, dt=DT, steps=STEPS, progress=False))
