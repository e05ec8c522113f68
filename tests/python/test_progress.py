"""Progress: the binding reports the steps completed at the Ctrl-C check's stride, an exception
from the report stops the run unchanged with its partial trajectory, and integrate(progress=True)
draws a tqdm bar that ends at the run's steps."""

import importlib
import io
import sys

import numpy as np
import pytest

import varmech
from varmech import _core

integrate_module = importlib.import_module("varmech.integrate")


def test_the_binding_reports_increasing_step_counts_without_changing_the_run():
    s = varmech.scenes.kepler()
    steps = 5_000_000
    calls = []
    spec = _core.RunSpec(dt=s.dt, steps=steps, method="verlet", save_every=steps)
    reported = _core.integrate(s.model._core, s.q0, s.p0, spec, progress=calls.append)
    silent = _core.integrate(s.model._core, s.q0, s.p0, spec)
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
        spec = _core.RunSpec(dt=s.dt, steps=50_000_000, method="verlet", save_every=1000)
        _core.integrate(s.model._core, s.q0, s.p0, spec, progress=report)
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


class ZMQInteractiveShell:
    """Stands for a Jupyter kernel's shell, by its class's name as IPython's is."""


def test_a_notebook_shows_bars_by_default_and_tqdm_disable_turns_them_off(monkeypatch):
    from varmech import _progress

    monkeypatch.delenv("TQDM_DISABLE", raising=False)
    assert not _progress._shown(None)   # pytest's stderr is not a terminal, and no kernel runs
    fake = type(sys)("IPython")
    fake.get_ipython = ZMQInteractiveShell
    monkeypatch.setitem(sys.modules, "IPython", fake)
    assert _progress._shown(None) and not _progress._shown(False)
    monkeypatch.setenv("TQDM_DISABLE", "1")
    assert not _progress._shown(None) and _progress._shown(True)


def test_an_ensemble_draws_no_bar_into_a_log_by_default(monkeypatch):
    ensemble_module = importlib.import_module("varmech.ensemble")
    disabled = []
    shown = ensemble_module.progress_bar

    def record(**kwargs):
        bar = shown(**kwargs)
        disabled.append(bar.disable)   # as made: closing a bar disables it
        return bar

    monkeypatch.setattr(ensemble_module, "progress_bar", record)
    s = varmech.scenes.pendulum()
    varmech.ensemble(s, np.zeros((2, 1)), np.full((2, 1), 0.5), dt=0.01, steps=100)
    varmech.ensemble(s, np.zeros((2, 1)), np.full((2, 1), 0.5), dt=0.01, steps=100, progress=True)
    assert disabled == [True, False]
