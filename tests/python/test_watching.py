"""What a run watches never changes what it computes: for every model kind, the states (and
Newton counts) of a run are the same bits with and without the energy monitor, saving every
state or every 10th, with a non-terminal event watched or not, through ``Stepper`` one step or
many at a time, and continued from a checkpoint (docs/user_guide/long_runs.md, the Stepper's
docstring: "bit for bit")."""

import numpy as np
import pytest

import varmech
from varmech import examples, scenes

STEPS = 60


def _same(a, b):
    """Bit for bit (so that -0.0 ≠ 0.0)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def _reduced(full, q0, p0):
    reduced = varmech.routh(full, [1], [p0[1]])
    x0, px0 = reduced.reduce(q0, p0)
    return reduced, x0, px0


def _compiled():
    pytest.importorskip("sympy")
    from varmech.symbolic.examples import double_pendulum

    return double_pendulum()


def _cases():
    kepler, chain, sleigh, solar = scenes.kepler(), scenes.planar_chain(3), scenes.chaplygin_sleigh(), scenes.outer_solar_system()
    dp, sp = scenes.double_pendulum(), scenes.spherical_pendulum()
    return [
        ("native separable", lambda: (kepler.model, kepler.q0, kepler.p0), "kahan_li8", 0.05),
        ("native general", lambda: (dp.model, dp.q0, dp.p0), "midpoint", 0.01),
        ("closure mechanical", lambda: (examples.kepler(), kepler.q0, kepler.p0), "midpoint", 0.05),
        ("closure lagrangian", lambda: (examples.double_pendulum(), dp.q0, dp.p0), "galerkin4", 0.01),
        ("compiled symbolic", lambda: (_compiled(), dp.q0, dp.p0), "midpoint", 0.01),
        ("constrained", lambda: (chain.model, chain.q0, chain.p0), "rattle", 0.01),
        ("constrained rattle4", lambda: (chain.model, chain.q0, chain.p0), "rattle4", 0.01),
        ("nonholonomic", lambda: (sleigh.model, sleigh.q0, sleigh.p0), "dla4", 0.01),
        ("routh native", lambda: _reduced(sp.model, sp.q0, sp.p0), "midpoint", 0.01),
        ("routh closure", lambda: _reduced(examples.spherical_pendulum(), sp.q0, sp.p0), "galerkin4", 0.05),
        ("n-body", lambda: (solar.model, solar.q0, solar.p0), "whc", 100.0),
        ("n-body verlet", lambda: (solar.model, solar.q0, solar.p0), "verlet", 100.0),
    ]


@pytest.mark.parametrize("build, method, dt", [pytest.param(*c[1:], id=c[0]) for c in _cases()])
def test_what_a_run_watches_never_changes_it(build, method, dt):
    model, q0, p0 = build()
    run = lambda **kw: varmech.integrate(model, q0, p0, dt=dt, steps=STEPS, method=method, **kw)  # noqa: E731
    watched = run()
    runs = {
        "without the energy monitor": run(max_energy_error=None),
        # A momentum's sign changes: located by partial steps on the run's model.
        "with an event": run(events=[varmech.events.crossing(0, float(np.mean(watched.q[:, 0])))]),
    }
    for why, other in runs.items():
        assert other.status == 0, (why, other.message)
        assert _same(other.t, watched.t) and _same(other.q, watched.q) and _same(other.p, watched.p), why
        assert other.newton_iterations == watched.newton_iterations, why
    assert len(runs["with an event"].events[0]) > 0
    sparse = run(save_every=10)
    assert _same(sparse.q, watched.q[::10]) and _same(sparse.p, watched.p[::10])
    assert sparse.newton_iterations == watched.newton_iterations

    one_by_one = varmech.Stepper(model, q0, p0, dt=dt, method=method)
    for _ in range(STEPS):
        one_by_one.step()
    chunks = varmech.Stepper(model, q0, p0, dt=dt, method=method)
    for n in (7, 1, STEPS - 8):
        chunks.advance(n)
    for stepper in (one_by_one, chunks):
        assert _same(stepper.q, watched.q[-1]) and _same(stepper.p, watched.p[-1])
        assert stepper.newton_iterations == watched.newton_iterations
        assert stepper.force_evaluations == watched.nfev or method == "whc"

    half = varmech.integrate(model, q0, p0, dt=dt, steps=STEPS // 2, method=method)
    rest = varmech.integrate(half, steps=STEPS - STEPS // 2)
    assert _same(rest.q, watched.q[STEPS // 2 :]) and _same(rest.p, watched.p[STEPS // 2 :])
    resumed = varmech.Stepper.from_checkpoint(model, half.checkpoint, method=method, dt=dt)
    resumed.advance(STEPS - STEPS // 2)
    assert _same(resumed.q, watched.q[-1]) and _same(resumed.p, watched.p[-1])
