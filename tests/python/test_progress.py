"""Progress: the binding reports the steps completed at the Ctrl-C check's stride, an exception
from the report stops the run unchanged with its partial trajectory, and integrate(progress=True)
draws a tqdm bar that ends at the run's steps."""

import importlib
import io

import numpy as np
import pytest

import varmech
from varmech import _core

integrate_module = importlib.import_module("varmech.integrate")


def test_the_binding_reports_increasing_step_counts_without_changing_the_run():
    s = varmech.scenes.kepler()
    steps = 5_000_000
    calls = []
    reported = _core.integrate(
        s.model._core, s.q0, s.p0, dt=s.dt, steps=steps, method="verlet", save_every=steps, progress=calls.append
    )
    silent = _core.integrate(s.model._core, s.q0, s.p0, dt=s.dt, steps=steps, method="verlet", save_every=steps)
    # Polled every 10–40 ms over a run of about 0.2 s: several reports, increasing, within the run.
    assert len(calls) >= 2 and calls == sorted(set(calls)) and 0 <= calls[0] and calls[-1] < steps
    np.testing.assert_array_equal(reported.q, silent.q)


class Stop(Exception):
    pass


def test_an_exception_from_the_report_stops_the_run_unchanged_with_its_partial_trajectory():
    s = varmech.scenes.kepler()

    def report(steps):
        if steps > 0:
            raise Stop(steps)

    with pytest.raises(Stop) as info:
        _core.integrate(
            s.model._core, s.q0, s.p0, dt=s.dt, steps=50_000_000, method="verlet", save_every=1000, progress=report
        )
    partial = info.value._varmech_partial
    assert 0 < partial.steps < 50_000_000 and partial.steps == info.value.args[0]


def test_integrate_draws_a_bar_that_ends_at_the_runs_steps(monkeypatch):
    out = io.StringIO()
    shown = integrate_module.progress_bar

    bars = []

    def immediate(**kwargs):
        bars.append(shown(**kwargs, file=out, delay=0.0))
        return bars[-1]

    monkeypatch.setattr(integrate_module, "progress_bar", immediate)
    s = varmech.scenes.kepler()
    steps = 5_000_000
    traj = varmech.integrate(s, dt=s.dt, steps=steps, save_every=steps, progress=True)
    assert traj.steps == steps
    text = out.getvalue()
    # Drawn while the run went on (steps and steps/s), and counted to the end before closing.
    assert f"/{steps} [" in text and "step/s" in text and text.startswith("\rverlet"), text
    assert bars[0].n == steps


def test_no_bar_off_a_terminal_by_default(monkeypatch):
    bars = []
    shown = integrate_module.progress_bar

    def record(**kwargs):
        bars.append(shown(**kwargs))
        return bars[-1]

    monkeypatch.setattr(integrate_module, "progress_bar", record)
    s = varmech.scenes.kepler()
    varmech.integrate(s, dt=s.dt, steps=1000)
    assert len(bars) == 1 and bars[0].disable  # pytest's stderr is not a terminal
