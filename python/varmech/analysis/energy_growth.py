"""Long-run energy growth, measured in one run against the baselines.

:func:`energy_growth` follows the relative energy error |H(t) − H₀|/|H₀| over a long horizon,
sampled log-spaced in time, with the verdict of each method ("bounded" or "secular drift");
:func:`verdicts` lists the verdicts. The SciPy and REBOUND baselines come from
:mod:`.baselines` and are skipped with a note in ``table.meta["notes"]`` when their package is
missing. :func:`varmech.charts.work_precision.energy_growth_chart` plots the table. Ctrl-C stops
a sweep: the KeyboardInterrupt propagates, carrying the rows measured so far as ``err.partial``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._progress import progress as _progress
from .._util import positive
from ..conservation import InvariantStatistics, check_conservation, energy_statistics
from ..integrate import integrate
from ..model import Model
from ..scenes import Scene, as_scene
from ..table import Table
from . import baselines as _baselines
from ._energy import energy_of, relative_error
from ._interrupt import interruptible

__all__ = [
    "ENERGY_GROWTH_COLUMNS",
    "energy_growth",
    "verdicts",
]

ENERGY_GROWTH_COLUMNS = ("tool", "method", "t", "energy_error", "max_energy_error")


def _log_bins(t: np.ndarray, err: np.ndarray, samples: int, t_min: float, t_max: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """In each of ``samples`` log-spaced bins of (t_min, t_max], the sample with the largest
    error, and the largest error up to it over all samples: (t, error, running maximum), in
    order of t."""
    keep = (t > 0) & np.isfinite(err)
    t, err = t[keep], err[keep]
    order = np.argsort(t, kind="stable")
    t, err = t[order], err[order]
    if t.size == 0:
        return t, err, err
    running = np.maximum.accumulate(err)
    edges = np.geomspace(t_min, t_max * (1 + 1e-12), samples + 1)
    b = np.clip(np.searchsorted(edges, t, side="left") - 1, 0, samples - 1)
    by_bin = np.lexsort((err, b))  # by bin, then by error: the last of each bin is its largest
    last = np.r_[b[by_bin][1:] != b[by_bin][:-1], True]
    pick = np.sort(by_bin[last])
    return t[pick], err[pick], running[pick]


def _prime_at_least(k: int) -> int:
    while any(k % d == 0 for d in range(2, math.isqrt(k) + 1)):
        k += 1
    return k


def _varmech_series(scene: Scene, method: str, dt: float, n: int, uniform: int, per_level: int):
    """Energy errors of one run at log-spaced times: the whole run saved at ``uniform`` evenly
    spaced states (its conservation report gives the verdict), then the first tenth, hundredth, …
    of it again with ``per_level`` states each (the same steps, so the same trajectory), until
    every step is saved. About 1.11× the cost of the run."""
    traj = integrate(scene, dt=dt, steps=n, method=method, save_every=max(1, n // uniform), max_energy_error=None)
    report = check_conservation(traj)
    ts, es = [traj.t], [relative_error(traj.energy())]
    m = n
    while m > per_level and m > 1:
        m //= 10
        if m < 1:
            break
        part = integrate(scene, dt=dt, steps=m, method=method, save_every=max(1, m // per_level), max_energy_error=None)
        ts.append(part.t)
        es.append(relative_error(part.energy()))
    return np.concatenate(ts), np.concatenate(es), report.energy, es[0]


def _tenths(uniform: np.ndarray) -> tuple[float, float]:
    """The largest relative energy error over the first and the last tenth of an evenly
    sampled run: a bounded error is as large at the end as at the start."""
    k = max(1, len(uniform) // 10)
    return float(np.max(uniform[:k])), float(np.max(uniform[-k:]))


def energy_growth(
    scene: Scene | Model | str,
    methods: Iterable[str],
    *,
    q0: ArrayLike | None = None,
    p0: ArrayLike | None = None,
    v0: ArrayLike | None = None,
    t_end: float | None = None,
    dt: float | None = None,
    samples: int = 2000,
    baselines: Iterable[str] = ("DOP853",),
    rtol: float = 1e-10,
    atol: float | Sequence[float] | None = None,
    baseline_t_end: float | None = None,
    progress: bool | None = None,
) -> Table:
    """The relative energy error |H(t) − H₀|/|H₀| over a long run, log-spaced in t, with a
    verdict for each method.

    Rows are (tool, method, t, energy_error, max_energy_error): in each of ``samples``
    log-spaced bins of t, the sample with the largest error |ΔH/H₀|, and the largest error of
    all samples up to t (a monotone envelope; the samples are the evenly spaced states below
    plus denser ones early in the run, so it can miss a peak between late samples). The verdict
    of each method (see :class:`~varmech.InvariantStatistics`) comes from the same run sampled
    evenly in time: varmech runs from :func:`~varmech.check_conservation`, baselines from the
    same statistics of their series. ``table.meta["verdicts"]`` maps each method to a dict:
    tool, verdict, drift_rate (of the energy, per unit time) and its stderr, max_error (against
    the scale, the mean kinetic energy), scale, max_error_first_tenth and max_error_last_tenth
    (of |ΔH/H₀|, over the first and last tenth of the run), t_end, and dt or rtol.

    Parameters
    ----------
    scene
        A :class:`~varmech.Scene` whose energy is conserved (built-in, symbolic, or
        :meth:`~varmech.Scene.of` a model), a scene's name, or such a model with ``q0``, ``p0``
        or ``v0``, and ``t_end``.
    q0, p0, v0
        A model's initial state: positions, and momenta or velocities.
    methods
        varmech method names.
    t_end, dt
        The horizon (default the scene's long run, :attr:`~varmech.Scene.long_run`: 50 ×
        ``t_end`` for a built-in scene, 10⁴ periods for :func:`~varmech.scenes.kepler`; one's own
        scene's ``t_end``; a model's, as given) and the step (default ``scene.dt``; a model's from
        :meth:`~varmech.Scene.of`); the horizon is rounded to whole steps.
    samples
        Log-spaced bins of t per method (and the number of evenly spaced states for the
        verdicts, at least 1000).
    baselines, rtol, atol
        ``solve_ivp`` methods (default DOP853) at tolerance ``rtol`` (atol as in
        :func:`~varmech.work_precision`), sampled by their dense output; and REBOUND's
        integrators (``analysis.baselines.REBOUND_METHODS``) on N-body scenes, the
        fixed-step ones at step ``dt`` and ``"IAS15"`` at its default precision, with
        ``"leapfrog order=8"`` also on the Kepler scene. Skipped with a note in
        ``meta["notes"]`` when SciPy or REBOUND is missing, or the scene is not theirs.
    baseline_t_end
        The baselines' horizon (default ``t_end``/10: a Python-driven adaptive solver is slow
        over 10⁴ periods; ``meta["baseline_t_end"]`` records it).
    progress
        Show a progress bar: None on a terminal only, True or False to force it.

    Returns
    -------
    Table
        A :class:`~varmech.Table` with columns ``tool`` ("varmech", "scipy" or "rebound"),
        ``method``, ``t`` (in the scene's time unit), ``energy_error`` (the largest |ΔH/H₀| in
        that bin) and ``max_energy_error`` (its running maximum), one row a non-empty bin and
        method. ``meta`` holds ``"verdicts"`` (above), ``"notes"`` (skipped baselines and why),
        ``"scene"``, ``"time_unit"``, ``"dt"``, ``"t_end"``, ``"baseline_t_end"``, ``"rtol"``
        and ``"sampling"``.

    Raises
    ------
    ValueError
        The scene's energy is not conserved (L depends on t, or forces act); an unknown
        baseline; ``dt`` not positive and finite; ``samples`` below 10; or an unknown method,
        or one that does not fit the scene's model (from :func:`~varmech.integrate`).
    KeyboardInterrupt
        On Ctrl-C, with the rows measured so far as ``err.partial``.

    See Also
    --------
    verdicts : The verdicts of the table as a small Table.
    varmech.charts.work_precision.energy_growth_chart : Plots the table.
    varmech.check_conservation : The verdict of one trajectory.

    Notes
    -----
    Each varmech method costs about 1.11 runs over the horizon: one saving ``samples`` (at least
    1009, a prime) evenly spaced states, then its first tenth, hundredth, ... again with denser
    saving, which resolves the early, log-spaced times on the same trajectory. A symplectic
    method's error stays bounded (it conserves a modified energy H̃ = H + O(hᵖ) over
    exponentially long times); a non-symplectic one drifts secularly, linearly in t.

    References
    ----------
    .. [1] E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
       Springer (2006), chapter IX (backward error analysis, long-time energy conservation).

    Examples
    --------
    >>> import varmech
    >>> from varmech.analysis.energy_growth import energy_growth, verdicts
    >>> table = energy_growth(varmech.scenes.harmonic_oscillator(), ["verlet", "rk4"],
    ...                       t_end=100.0, samples=10, baselines=())
    >>> table.columns
    ('tool', 'method', 't', 'energy_error', 'max_energy_error')
    >>> {m: v["verdict"] for m, v in table.meta["verdicts"].items()}
    {'verlet': 'bounded', 'rk4': 'secular drift'}
    >>> verdicts(table).column("verdict").tolist()
    ['bounded', 'secular drift']
    """
    scene = as_scene(scene, q0=q0, p0=p0, v0=v0, t_end=t_end, dt=dt)
    if not scene.model.conserves_energy:
        raise ValueError(f"scene: the energy of {scene.name!r} is not conserved (L depends on t, or forces act)")
    methods = list(methods)
    baselines = list(baselines)
    bad = [b for b in baselines if b not in _baselines.SCIPY_METHODS + _baselines.REBOUND_METHODS]
    if bad:
        raise ValueError(f"baselines: unknown method(s) {bad}; choose from {_baselines.SCIPY_METHODS + _baselines.REBOUND_METHODS}")
    h = positive("dt", scene.dt if dt is None else dt)
    T = scene.long_run if t_end is None else positive("t_end", t_end)
    n = max(1, round(T / h))
    T = n * h
    Tb = T / 10 if baseline_t_end is None else float(baseline_t_end)
    samples = int(samples)
    if samples < 10:
        raise ValueError(f"samples: must be at least 10, got {samples}")
    # A prime count of evenly spaced states, so that their spacing is unlikely to be a whole
    # number of periods (which would sample every orbit at the same phase).
    uniform = _prime_at_least(max(samples, 1000))
    per_level = max(50, samples // max(1, math.ceil(math.log10(max(n, 10)))))
    table = Table(
        ENERGY_GROWTH_COLUMNS,
        title=f"Energy error against time: {scene.name}, dt = {h:g}, t = 0 … {T:g}",
        meta={
            "scene": scene.name,
            "time_unit": scene.time_unit,
            "dt": h,
            "t_end": T,
            "baseline_t_end": Tb,
            "rtol": rtol,
            "sampling": f"max |ΔH/H0| in each of {samples} log-spaced bins of t, and its running maximum; "
            f"verdicts from {uniform} evenly spaced states",
            "verdicts": {},
            "notes": [],
        },
    )
    notes: list[str] = table.meta["notes"]
    verdicts: dict[str, dict[str, Any]] = table.meta["verdicts"]

    scipy_names = [b for b in baselines if b in _baselines.SCIPY_METHODS]
    rebound_names = [b for b in baselines if b in _baselines.REBOUND_METHODS]
    solve_ivp, scipy_names = _baselines.scipy_baselines(scene, scipy_names, notes)
    if scipy_names and Tb != T:
        notes.append(f"solve_ivp baselines run to t = {Tb:g} (the varmech methods to {T:g})")
    rb, rebound_names = _baselines.rebound_baselines(scene, rebound_names, notes, asked=True)

    def record(
        tool: str, method: str, t: np.ndarray, err: np.ndarray, report: InvariantStatistics, uniform: np.ndarray, horizon: float, **setting: float
    ) -> None:
        tb, eb, mb = _log_bins(t, err, samples, min(h, horizon / 1e6), horizon)
        first, last = _tenths(uniform)
        for ti, ei, mi in zip(tb, eb, mb):
            table.append(tool, method, float(ti), float(ei), float(mi))
        verdicts[method] = {
            "tool": tool,
            "verdict": report.verdict,
            "drift_rate": report.drift_rate,
            "drift_rate_stderr": report.drift_rate_stderr,
            "max_error": report.max_rel_error,
            "scale": report.scale,
            "max_error_first_tenth": first,
            "max_error_last_tenth": last,
            "t_end": horizon,
            **setting,
        }

    def run_scipy(method: str) -> None:
        even = np.linspace(0.0, Tb, uniform + 1)
        logs = np.geomspace(min(h, Tb / 1e6), Tb, samples * 2)
        t_eval = np.unique(np.concatenate([even, logs]))
        t_eval = t_eval[t_eval <= Tb]
        sol, _ = _baselines.solve(solve_ivp, scene, method, Tb, rtol, atol, t_eval=t_eval)
        k = scene.model.dim
        energies = energy_of(scene.model, sol.t, sol.y[:k].T, sol.y[k:].T)
        on_grid = np.isin(sol.t, even)
        report = energy_statistics(scene.model, sol.t[on_grid], sol.y[:k, on_grid].T, sol.y[k:, on_grid].T, steps=sol.t.size)
        err = relative_error(energies)
        record("scipy", method, sol.t, err, report, err[on_grid], Tb, rtol=rtol)

    def run_rebound(method: str) -> None:
        sim = _baselines.rebound_sim(rb, scene, method, dt=h, epsilon=None)
        # Every saved time is a whole number of steps: evenly spaced, and log-spaced below.
        marks = np.unique(np.concatenate([np.linspace(0, n, uniform + 1).round(), np.geomspace(1, n, samples * 2).round()])).astype(np.int64)
        ts, qs, ps, done = [], [], [], 0
        try:
            for k in marks:
                if not _baselines.REBOUND_BASELINES[method].adaptive:
                    if k > done:
                        sim.steps(int(k - done))
                        sim.synchronize()
                        done = int(k)
                else:
                    sim.integrate(k * h, exact_finish_time=1)
                a, b = _baselines.rebound_state(sim, scene)
                ts.append(k * h)
                qs.append(a)
                ps.append(b)
        finally:
            _baselines.restore_sigint()
        t = np.array(ts)
        energies = energy_of(scene.model, t, np.array(qs), np.array(ps))
        on_grid = np.isin(marks, np.linspace(0, n, uniform + 1).round().astype(np.int64))
        report = energy_statistics(scene.model, t[on_grid], np.array(qs)[on_grid], np.array(ps)[on_grid], steps=n)
        err = relative_error(energies)
        record("rebound", method, t, err, report, err[on_grid], T, dt=h)

    plan = [("varmech", m) for m in methods] + [("scipy", b) for b in scipy_names] + [("rebound", b) for b in rebound_names]

    def body() -> None:
        for tool, method in _progress(plan, total=len(plan), desc=f"energy growth {scene.name}", enabled=progress):
            if tool == "varmech":
                t, err, report, even = _varmech_series(scene, method, h, n, uniform, per_level)
                record("varmech", method, t, err, report, even, T, dt=h)
            elif tool == "scipy":
                run_scipy(method)
            else:
                run_rebound(method)

    return interruptible(table, body)


def verdicts(table: Table) -> Table:
    """The verdicts of an :func:`energy_growth` table as a small Table.

    Parameters
    ----------
    table : Table
        A table returned by :func:`energy_growth`.

    Returns
    -------
    Table
        One row a method: ``tool``, ``method``, ``verdict`` ("bounded" or "secular drift"),
        ``drift_rate`` (of the energy, per unit time) and ``drift_rate_stderr``, ``max_error``
        (against the mean kinetic energy) and ``t_end``.

    Examples
    --------
    >>> import varmech
    >>> from varmech.analysis.energy_growth import energy_growth, verdicts
    >>> table = energy_growth(varmech.scenes.harmonic_oscillator(), ["verlet"], t_end=100.0,
    ...                       samples=10, baselines=())
    >>> verdicts(table).column("verdict").tolist()
    ['bounded']
    """
    out = Table(
        ("tool", "method", "verdict", "drift_rate", "drift_rate_stderr", "max_error", "t_end"),
        title=f"Energy verdicts: {table.meta.get('scene', '')}",
    )
    for method, v in table.meta.get("verdicts", {}).items():
        out.append(v["tool"], method, v["verdict"], v["drift_rate"], v["drift_rate_stderr"], v["max_error"], v["t_end"])
    return out
