"""Work–precision diagrams and energy growth over long runs, from the tables of
:mod:`varmech.analysis.work_precision` and
:mod:`varmech.analysis.energy_growth`."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

from ..table import Table
from ._figure import Canvas, documented, measurement_notes, time_label

__all__ = [
    "energy_growth_chart",
    "work_precision_chart",
]

_AXIS_LABELS = {
    "seconds": "wall time (s)",
    "evaluations": "force evaluations",
    "steps": "steps",
    "final_error": "error at the final time ‖(q, p) − reference‖",
    "max_energy_error": "max relative energy error |ΔH/H₀|",
}
# Line styles by tool, so that baselines read apart from varmech's methods at a glance.
_STYLE = {"varmech": dict(ls="-", marker="o"), "scipy": dict(ls="--", marker="s"), "rebound": dict(ls=":", marker="^")}


@documented
def work_precision_chart(
    table: Table, path: str | Path | None = None, *, x: str = "seconds", y: str = "final_error", title: str = "", ax: Axes | None = None
) -> Figure:
    """Plot ``y`` (``"final_error"`` or ``"max_energy_error"``) against ``x`` (``"seconds"`` or
    ``"evaluations"``) on log–log axes, one line per (tool, method) of a
    :func:`~varmech.work_precision` table, and write the figure to ``path`` (PNG or SVG).

    Lower left is better: less work for a smaller error. Each line follows its sweep (steps, or
    tolerances); points with a non-finite or zero value are left out. The measurement's notes
    (``meta["notes"]``: skipped baselines, a computed reference, stopped sweeps) are written beside
    the legend; so is what one evaluation is for each family of methods
    (``meta["evaluation_units"]``) when ``x`` is ``"evaluations"``, and a computed reference's
    tolerance is drawn as a line (errors below it are not measured).

    Parameters
    ----------
    table : Table
        A table returned by :func:`~varmech.work_precision`.
    {path}
    x : str, default "seconds"
        The column of the horizontal axis (work).
    y : str, default "final_error"
        The column of the vertical axis (error).
    title : str, optional
        The figure's title (default: the scene and the horizon).
    {ax}

    {returns}

    {raises}, or ``x`` or ``y`` is not a column of ``table``.

    See Also
    --------
    varmech.work_precision : The measurements.

    {examples}
    >>> import varmech
    >>> from varmech.charts import work_precision_chart
    >>> table = varmech.work_precision(varmech.scenes.harmonic_oscillator(), ["verlet"],
    ...                                steps=[64, 128], baselines=(), rebound=(), repeat=1)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "work_precision.png"
    ...     fig = work_precision_chart(table, path, x="evaluations")
    ...     print(path.name, plt.imread(path).shape)
    work_precision.png (576, 1020, 4)
    """
    for name in (x, y):
        if name not in table.columns:
            raise ValueError(f"x, y: no column {name!r} in {table.columns}")
    canvas = Canvas(ax, path, figsize=(8.5, 4.8))
    ax = canvas.ax
    for tool in table.unique("tool"):
        sub = table.where(tool=tool)
        for method in sub.unique("method"):
            rows = sub.where(method=method)
            xs, ys = rows.column(x), rows.column(y)
            keep = np.isfinite(xs) & np.isfinite(ys) & (xs > 0) & (ys > 0)
            if not keep.any():
                continue
            order = np.argsort(xs[keep])
            label = method if tool == "varmech" else f"{method} ({tool})"
            ax.loglog(xs[keep][order], ys[keep][order], label=label, lw=1.0, ms=3.5, **_STYLE.get(tool, {}))
    ax.set_xlabel(_AXIS_LABELS.get(x, x))
    ax.set_ylabel(_AXIS_LABELS.get(y, y))
    t_end = table.meta.get("t_end")
    unit = table.meta.get("time_unit", "time units")
    ax.set_title(title or (f"{table.meta.get('scene', '')}, t = 0 … {t_end:g} {unit}" if t_end else table.title), fontsize=10)
    tolerance = table.meta.get("reference_tolerance")
    if y == "final_error" and tolerance:
        # A computed reference is known to its tolerance: errors below it are not measured.
        ax.axhline(tolerance, color="0.4", ls="-.", lw=0.8, label=f"reference tolerance {tolerance:.1e}")
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    notes = list(table.meta.get("notes", []))
    if x == "evaluations":
        units = table.meta.get("evaluation_units", {})
        notes += [f"{family}: {unit}" for family, unit in units.items()]
    measurement_notes(ax, notes)
    return canvas.done(table.meta)


@documented
def energy_growth_chart(table: Table, path: str | Path | None = None, title: str = "", *, samples: bool = True, ax: Axes | None = None) -> Figure:
    """Plot the energy error of an :func:`~varmech.energy_growth` table against t on log–log
    axes, one line per method with its verdict in the legend, and write the figure to ``path``
    (PNG or SVG).

    Each method's line is the largest |ΔH/H₀| up to t (column ``max_energy_error``): bounded
    methods reach their band within the first orbits and run flat; drifting ones keep climbing.
    With ``samples`` the sampled errors themselves (column ``energy_error``, the largest in each
    log-spaced bin) are drawn faintly behind, showing the oscillation. A dashed √t line (Brouwer's
    law, the growth of random round-off) and a dotted ∝ t line go through the first drifting curve
    (the first with the verdict "secular drift"), two decades before its end, so that its slope
    reads against them. A baseline run to a shorter horizon (``meta["baseline_t_end"]``) ends at a
    dotted vertical line that says so; the measurement's notes (``meta["notes"]``) are written
    beside the legend.

    Parameters
    ----------
    table : Table
        A table returned by :func:`~varmech.energy_growth`.
    {path}
    title : str, optional
        The figure's title (default: the scene and the step).
    samples : bool, default True
        Also draw the sampled errors, faintly.
    {ax}

    {returns}

    {raises}.

    See Also
    --------
    varmech.energy_growth : The measurements.

    References
    ----------
    .. [1] D. Brouwer, "On the accumulation of errors in numerical integration",
       *Astron. J.* 46, 149–153 (1937).

    {examples}
    >>> import varmech
    >>> from varmech.charts import energy_growth_chart
    >>> table = varmech.energy_growth(varmech.scenes.harmonic_oscillator(), ["verlet", "rk4"],
    ...                               t_end=100.0, samples=10, baselines=())
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "energy_growth.png"
    ...     fig = energy_growth_chart(table, path)
    ...     print(path.name, plt.imread(path).shape)
    energy_growth.png (576, 1140, 4)
    """
    verdicts = table.meta.get("verdicts", {})
    canvas = Canvas(ax, path, figsize=(9.5, 4.8))
    ax = canvas.ax
    anchor = None
    for tool in table.unique("tool"):
        sub = table.where(tool=tool)
        for method in sub.unique("method"):
            rows = sub.where(method=method)
            t, e, m = rows.column("t"), rows.column("energy_error"), rows.column("max_energy_error")
            keep = (t > 0) & (m > 0) & np.isfinite(m)
            if not keep.any():
                continue
            v = verdicts.get(method, {})
            label = method if tool == "varmech" else f"{method} ({tool}, rtol {v['rtol']:g})" if "rtol" in v else f"{method} ({tool})"
            if v.get("t_end") and table.meta.get("t_end") and v["t_end"] < 0.999 * table.meta["t_end"]:
                label += f", run to t = {v['t_end']:g} only"
            if v:
                label += f": {v['verdict']}"
                if v["verdict"] == "secular drift":
                    label += f", {abs(v['drift_rate']):.1e} per {table.meta.get('time_unit', 'time unit').removesuffix('s')}"
            (line,) = ax.loglog(t[keep], m[keep], lw=1.2, label=label, ls="-" if tool == "varmech" else "--")
            if samples:
                faint = (t > 0) & (e > 0) & np.isfinite(e)
                ax.loglog(t[faint], e[faint], lw=0.4, color=line.get_color(), alpha=0.3)
            if anchor is None and v.get("verdict") == "secular drift":
                tk, mk = t[keep], m[keep]
                k = int(np.argmin(np.abs(np.log(tk / max(tk[0], tk[-1] / 100)))))
                anchor = (tk[k], mk[k], tk[0], tk[-1])
    if anchor is not None:
        ta, ea, t0, t1 = anchor
        tt = np.geomspace(max(t0, ta / 1e3), t1, 50)
        ax.loglog(tt, ea * np.sqrt(tt / ta), "k--", lw=0.8, alpha=0.7, label="∝ √t (Brouwer's law)")
        ax.loglog(tt, ea * (tt / ta), "k:", lw=0.8, alpha=0.7, label="∝ t")
    meta = table.meta
    short = meta.get("baseline_t_end")
    if short and meta.get("t_end") and short < meta["t_end"] and any(tool != "varmech" for tool in table.unique("tool")):
        ax.axvline(short, color="0.4", ls=":", lw=0.9)
        ax.annotate(
            f"baselines end at t = {short:g}", (short, 1.0), xycoords=("data", "axes fraction"), rotation=90,
            va="top", ha="right", fontsize=7, color="0.3",
        )  # fmt: skip
    ax.set_xlabel(time_label(meta))
    ax.set_ylabel("relative energy error |H − H₀|/|H₀|, max up to t")
    default = f"{meta.get('scene', '')}, dt = {meta['dt']:g} {meta.get('time_unit', 'time units')}" if "dt" in meta else table.title
    ax.set_title(title or default, fontsize=10)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=7.5, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    measurement_notes(ax, meta.get("notes", []))
    return canvas.done(table.meta)
