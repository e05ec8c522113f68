"""Linear stability and the failure regions of the implicit methods, from the tables of
:mod:`varmech.analysis.stability`."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

from ..analysis.stability import OUTCOMES, REFERENCE_LIMITS
from ..table import Table
from ._figure import Canvas, documented, draws, time_label

# Outcome colours of the implicit-regions map, in the order of OUTCOMES.
_OUTCOME_COLOURS = {
    "ok": "#4daf4a",
    "energy": "#ffd92f",
    "spurious branch": "#984ea3",
    "newton failure": "#e41a1c",
    "diverged": "#222222",
}


#: Markers of the growth chart's methods, in turn: staggered along coincident curves (every
#: symplectic method on ρ = 1), they tell each apart.
_MARKERS = "osD^vPX*<>"
_LINESTYLES = ("-", "--", "-.", (0, (3, 1, 1, 1, 1, 1)), ":")


@draws("varmech.analysis.stability.growth_table")
def stability_chart(
    table: Table, path: str | Path | None = None, title: str = "", limits: Mapping[str, float] | None = None, *, ax: Axes | None = None
) -> Figure:
    """Plot the growth factor ρ against hω, one line per method, from a
    :func:`~varmech.analysis.stability.growth_table`, on a logarithmic ρ axis (ρ = 1 is the dotted
    horizontal line: symplectic methods lie on it inside their stability interval, RK4 dips
    below it, everything leaves it upwards where it is unstable). Each method has its own
    colour, line style and markers, the markers staggered so that coincident curves (every
    stable symplectic method on ρ = 1) stay apart; a method whose curve is another's throughout
    says so in the legend (symplectic Euler's is Verlet's). Each stability limit is a dashed
    vertical line in its method's colour, labelled with the methods and hω on a top axis: ``limits``
    if given, else the table's measured ``meta["limits"]``, else the reference limits
    (:data:`~varmech.analysis.stability.REFERENCE_LIMITS`); an infinite limit is said in the
    legend ("stable for every hω"). Writes ``path`` (PNG or SVG).

    Parameters
    ----------
    {table}
    {path}
    title : str, optional
        The figure's title (default: what is plotted).
    limits : mapping of str to float, optional
        The stability limit hω_max of each method to mark.
    {ax}

    {returns}

    {raises}.

    {measures}
    >>> table = growth_table(["verlet", "rk4"], [0.5, 1.0, 2.5, 3.0], limits=False)
    >>> with tempfile.TemporaryDirectory() as folder:   # the reference limits are marked
    ...     path = Path(folder) / "stability.png"
    ...     fig = stability_chart(table, path)
    ...     print(path.name, plt.imread(path).shape)
    stability.png (624, 1140, 4)
    """
    if limits is None:
        limits = table.meta.get("limits") or REFERENCE_LIMITS
    canvas = Canvas(ax, path, figsize=(9.5, 5.2))
    ax = canvas.ax
    h_all = table.column("h_omega")
    top = float(np.nanmax(h_all)) if len(h_all) else 1.0
    lowest = 1.0
    names = table.unique("method")
    curves: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    at_limit: dict[float, list[tuple[str, Any]]] = {}
    for i, name in enumerate(names):
        rows = table.where(method=name)
        h, g = rows.column("h_omega"), rows.column("growth")
        order = np.argsort(h)
        h, g = h[order], g[order]
        finite = np.isfinite(g) & (g > 0)
        if finite.any():
            lowest = min(lowest, float(np.min(g[finite])))
        twin = next((m for m, (hh, gg) in curves.items() if hh.shape == h.shape and np.allclose(gg, g, rtol=1e-9, equal_nan=True)), None)
        curves[name] = (h, g)
        limit = limits.get(name)
        label = name + (f" (the same ρ as {twin})" if twin else "")
        if limit is not None and math.isinf(limit):
            label += ": stable for every hω"
        every = max(1, int(finite.sum()) // 6)
        (line,) = ax.plot(
            h[finite], g[finite], lw=1.1, label=label, ls=_LINESTYLES[i % len(_LINESTYLES)],
            marker=_MARKERS[i % len(_MARKERS)], ms=4.5, markevery=(i * every // max(1, len(names)), every), mfc="none",
        )  # fmt: skip
        if limit is not None and math.isfinite(limit) and 0 < limit <= top:
            at_limit.setdefault(round(limit, 4), []).append((name, line.get_color()))
    # The limits' labels on a top axis, tilted, clear of the curves.
    top_axis = ax.secondary_xaxis("top")
    ticks = sorted(at_limit)
    words = [f"{', '.join(m for m, _ in at_limit[x])} {x:g}" for x in ticks]
    top_axis.set_xticks(ticks, words, rotation=75, ha="left", rotation_mode="anchor", fontsize=7)
    for x, tick in zip(ticks, top_axis.get_xticklabels()):
        tick.set_color(at_limit[x][0][1])
        ax.axvline(x, color=at_limit[x][0][1], ls="--", lw=0.8, alpha=0.8)
    ax.axhline(1.0, color="0.3", ls=":", lw=0.8)
    ax.set_yscale("log")
    ax.set_ylim(max(min(0.9 * lowest, 0.9), 1e-3), 10.0)
    ax.set_xlim(0.0, top)
    ax.set_xlabel("hω (step × angular frequency, dimensionless)")
    ax.set_ylabel("growth factor ρ(Ψ) per step")
    default = "Linear stability on q'' = −ω²q: growth factor ρ per step against hω (dashed: stability limits)"
    ax.set_title(title or default, fontsize=10, pad=10)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=7.5, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return canvas.done(table.meta)


@draws("varmech.analysis.implicit.implicit_regions")
def implicit_regions_chart(table: Table, path: str | Path | None = None, title: str = "", *, ax: Axes | Sequence[Axes] | None = None) -> Figure:
    """A categorical map of the outcome over step size h (columns) and initial angle q₀ (rows),
    one panel per method, from :func:`~varmech.analysis.implicit.implicit_regions`. Writes ``path``
    (PNG or SVG).

    Parameters
    ----------
    {table}
    {path}
    title : str, optional
        The figure's title (default: the scene and the number of steps).
    {ax}

    {returns}

    {raises}.

    {measures}
    >>> table = implicit_regions("midpoint", h_values=(0.5, 3.0), q0_values=(1.0, 3.0))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "implicit.png"
    ...     fig = implicit_regions_chart(table, path)
    ...     print(path.name, plt.imread(path).shape)
    implicit.png (432, 624, 4)
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    names = table.unique("method")
    hs = sorted(set(float(x) for x in table.column("h")))
    q0s = sorted(set(float(x) for x in table.column("q0")))
    code = {o: i for i, o in enumerate(OUTCOMES)}
    cmap = ListedColormap([_OUTCOME_COLOURS[o] for o in OUTCOMES])
    norm = BoundaryNorm(np.arange(len(OUTCOMES) + 1) - 0.5, cmap.N)
    cols = min(len(names), 2) or 1
    rows_n = max(1, math.ceil(len(names) / cols))
    canvas = Canvas(ax, path, figsize=(5.2 * cols, 3.6 * rows_n), shape=(rows_n, cols), panels=len(names))
    for panel, name in zip(canvas.axes, names):
        grid = np.full((len(q0s), len(hs)), np.nan)
        for row in table.where(method=name):
            grid[q0s.index(float(row["q0"])), hs.index(float(row["h"]))] = code[row["outcome"]]
        panel.imshow(np.ma.masked_invalid(grid), cmap=cmap, norm=norm, origin="lower", aspect="auto", interpolation="nearest")
        panel.set_xticks(range(len(hs)), [f"{h:g}" for h in hs], fontsize=7)
        panel.set_yticks(range(len(q0s)), [f"{q:g}" for q in q0s], fontsize=7)
        panel.set_xlabel(time_label(table.meta, "step h"))
        panel.set_ylabel("initial angle q₀ (from rest)")
        panel.set_title(name, fontsize=9)
    present = [o for o in OUTCOMES if o in set(table.column("outcome"))]
    canvas.legend(handles=[Patch(color=_OUTCOME_COLOURS[o], label=o) for o in present], ncol=len(present), fontsize=8)
    scene = table.meta.get("scene", "")
    steps = table.meta.get("steps", "")
    canvas.title(title or f"Implicit methods on the {scene}: outcome of {steps} steps")
    return canvas.done(table.meta)


__all__ = ["implicit_regions_chart", "stability_chart"]


@documented
def spectrum_chart(table: Table, path: str | Path | None = None, title: str = "", *, ax: Axes | None = None) -> Figure:
    """A model's spectrum against each method's stability interval, from
    :func:`~varmech.analysis.stability.spectrum`: one row per method, its interval 0 < hω < h_ω
    a bar (green where the step dt takes the model's fastest mode inside it, red where not), and
    each mode's h|λ| at the table's dt a vertical line across all of them, so that which methods
    take that step is read off; the top axis gives the same positions as frequencies ω and the
    right one each method's largest stable step h_ω/ω_max. An unconditionally stable method's bar
    runs off the chart, with an arrow. Writes ``path`` (PNG or SVG).

    Parameters
    ----------
    table : Table
        A table returned by :func:`~varmech.analysis.stability.spectrum`.
    {path}
    title : str, optional
        The figure's title (default: the table's).
    {ax}

    {returns}

    {raises}.

    See Also
    --------
    varmech.analysis.stability.spectrum : The measurements.
    varmech.suggest_dt : The step from the same modes.

    {examples}
    >>> import varmech
    >>> from varmech.charts import spectrum_chart
    >>> table = varmech.analysis.stability.spectrum(varmech.scenes.fermi_pasta_ulam(), ["verlet", "yoshida4", "midpoint"])
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "spectrum.png"
    ...     fig = spectrum_chart(table, path)
    ...     print(path.name, plt.imread(path).shape)
    spectrum.png (354, 1080, 4)
    """
    dt = float(table.meta["dt"])
    frequencies = np.asarray(table.meta["frequencies"], dtype=float)
    names = [row["method"] for row in table]
    limits = [float(row["h_omega_max"]) for row in table]
    finite = [x for x in limits if math.isfinite(x)]
    fastest = dt * float(table.meta["omega_max"])
    right = 1.15 * max([fastest, *finite, 1e-300])
    canvas = Canvas(ax, path, figsize=(9.0, 1.6 + 0.45 * max(len(names), 2)))
    ax = canvas.ax
    for i, (row, limit) in enumerate(zip(table, limits)):
        colour = "#4daf4a" if row["stable"] else "#e41a1c"
        ax.barh(i, min(limit, right), height=0.55, color=colour, alpha=0.55, edgecolor=colour)
        if math.isinf(limit):
            ax.annotate("", xy=(right, i), xytext=(0.93 * right, i), arrowprops={"arrowstyle": "->", "color": colour})
        else:
            ax.text(limit, i, f" {limit:g}", va="center", ha="left", fontsize=7.5, color="0.2")
    for x in dt * frequencies:
        if 0 < x <= right:
            ax.axvline(x, color="#377eb8", lw=1.4 if x == fastest else 0.7, alpha=0.9 if x == fastest else 0.5)
    ax.set_yticks(range(len(names)), names)
    ax.invert_yaxis()
    ax.set_xlim(0.0, right)
    ax.set_xlabel(f"hω at dt = {dt:g} (blue: the modes, the fastest bold)")
    top_axis = ax.secondary_xaxis("top", functions=(lambda x: np.asarray(x) / dt, lambda w: np.asarray(w) * dt))
    top_axis.set_xlabel("ω (angular frequency)")
    steps = ax.secondary_yaxis("right")
    words = [f"dt < {row['stable_dt']:.4g}" if math.isfinite(row["stable_dt"]) else "any dt" for row in table]
    steps.set_yticks(range(len(names)), words, fontsize=7.5)
    ax.set_title(title or table.title, fontsize=10)
    ax.grid(True, axis="x", alpha=0.3)
    return canvas.done(table.meta)
