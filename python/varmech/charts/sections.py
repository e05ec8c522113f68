"""Poincaré sections and phase portraits, from the tables of :mod:`varmech.analysis.sections`."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

from ..table import Table
from ._figure import Canvas, colormap, draws, state_label


def _henon_heiles_boundary(energy: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The closed curve ½p_y² + ½y² − y³/3 = E bounding the section x = 0 (0 < E < 1/6)."""
    if not 0 < energy < 1 / 6:
        return None
    roots = np.sort(np.roots([-1.0 / 3.0, 0.5, 0.0, -energy]).real)
    y = np.linspace(roots[0], roots[1], 400)
    py = np.sqrt(np.maximum(2 * energy - y**2 + 2 * y**3 / 3, 0.0))
    return np.concatenate([y, y[::-1]]), np.concatenate([py, -py[::-1]])


@draws("varmech.analysis.sections.poincare_section")
def poincare_chart(
    table: Table | Sequence[Table], path: str | Path | None = None, title: str = "", *, ax: Axes | Sequence[Axes] | None = None
) -> Figure:
    """Scatter the section points of :func:`varmech.analysis.sections.poincare_section` in the table's
    plane (``meta["plane"]``, e.g. (y, p_y)), small dots, one colour per orbit, one panel per
    table (pass several tables, e.g. H = 1/12 and 1/8, for panels side by side). The boundary of
    the energy-allowed region is drawn for Hénon–Heiles' x = 0 section. Writes ``path`` (PNG or
    SVG by its suffix).

    Parameters
    ----------
    table : Table or sequence of Table
        Tables returned by :func:`~varmech.analysis.sections.poincare_section`, one panel each.
    {path}
    title : str, optional
        The figure's title (default none; each panel is titled with its energy).
    {ax}

    {returns}

    {raises}, or no table is given.

    {measures}
    >>> import varmech
    >>> tables = [poincare_section(varmech.scenes.henon_heiles(), energy, orbits=2, dt=0.1,
    ...                            t_end=60.0, progress=False) for energy in (1 / 12, 1 / 8)]
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "henon_heiles.png"
    ...     fig = poincare_chart(tables, path)
    ...     print(path.name, plt.imread(path).shape)   # two panels side by side
    henon_heiles.png (600, 1248, 4)
    """
    tables = [table] if isinstance(table, Table) else list(table)
    if not tables:
        raise ValueError("table: give at least one table")
    canvas = Canvas(ax, path, figsize=(5.2 * len(tables), 5.0), shape=(1, len(tables)))
    cmap = colormap("tab20")
    for panel, tab in zip(canvas.axes, tables):
        a_name, b_name = tab.meta.get("plane", ("y", "p_y"))
        a, b, orbit = tab.column(a_name), tab.column(b_name), tab.column("orbit")
        for i, o in enumerate(tab.unique("orbit")):
            sel = orbit == o
            panel.scatter(a[sel], b[sel], s=0.6, color=cmap(i % cmap.N), linewidths=0, rasterized=True)
        energy = tab.meta.get("energy")
        panel.set_xlabel(a_name)
        panel.set_ylabel(b_name)
        if tab.meta.get("model") == "henon_heiles" and tuple(tab.meta.get("section", ()))[:2] == (0, 0.0) and energy is not None:
            curve = _henon_heiles_boundary(float(energy))
            if curve is not None:
                panel.plot(*curve, color="0.3", lw=0.6)
            # y and p_y on one scale there, the allowed region's true shape.
            panel.set_aspect("equal", adjustable="datalim")
        label = f"E = {energy:.4g}" if energy is not None else ""
        if energy is not None:
            for frac in (12, 8, 6):
                if abs(float(energy) - 1 / frac) < 1e-12:
                    label = f"E = 1/{frac}"
        panel.set_title(label, fontsize=10)
    canvas.title(title)
    return canvas.done(tables[0].meta)


@draws("varmech.analysis.phase_portrait.phase_portrait")
def phase_portrait_chart(table: Table, path: str | Path | None = None, title: str = "", *, ax: Axes | None = None) -> Figure:
    """Draw the orbits of :func:`varmech.analysis.phase_portrait.phase_portrait` in the (q, p) plane:
    librations in blues, rotations in oranges (darker for higher energy), undetermined orbits
    in grey. When rotations are present q is taken modulo 2π into (−π, π]; for the pendulum the
    separatrix p = ±2cos(q/2) (energy 1) is drawn dashed. Writes ``path`` (PNG or SVG).

    Parameters
    ----------
    {table}
    {path}
    title : str, optional
        The figure's title (default none).
    {ax}

    {returns}

    {raises}.

    {measures}
    >>> import varmech
    >>> table = phase_portrait(varmech.scenes.pendulum(), [-0.5, 2.0], dt=0.05, t_end=20.0,
    ...                        progress=False)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "pendulum.png"
    ...     fig = phase_portrait_chart(table, path)
    ...     print(path.name, plt.imread(path).shape)
    pendulum.png (552, 900, 4)
    """
    canvas = Canvas(ax, path, figsize=(7.5, 4.6))
    ax = canvas.ax
    orbit, q, p, e = table.column("orbit"), table.column("q"), table.column("p"), table.column("energy")
    motions = table.column("motion")
    wrap = bool(np.any(motions == "rotation"))
    energies = {m: sorted({float(x) for x in e[motions == m]}) for m in ("libration", "rotation", "undetermined")}
    maps = {"libration": colormap("Blues"), "rotation": colormap("Oranges")}
    seen: set[str] = set()
    for o in table.unique("orbit"):
        sel = orbit == o
        qq, pp = q[sel], p[sel]
        motion = str(motions[sel][0])
        if wrap:
            qq = (qq + math.pi) % (2 * math.pi) - math.pi
            cut = np.nonzero(np.abs(np.diff(qq)) > math.pi)[0] + 1
            qq = np.insert(qq, cut, np.nan)
            pp = np.insert(pp, cut, np.nan)
        if motion in maps:
            levels = energies[motion]
            x = levels.index(float(e[sel][0])) / max(1, len(levels) - 1)
            color = maps[motion](0.4 + 0.5 * x)
        else:
            color = "0.6"
        ax.plot(qq, pp, color=color, lw=0.9, label=motion if motion not in seen else None)
        seen.add(motion)
    if table.meta.get("model") == "pendulum":
        s = np.linspace(-math.pi, math.pi, 400)
        ax.plot(s, 2 * np.cos(s / 2), "k--", lw=0.8, label="separatrix (H = 1)")
        ax.plot(s, -2 * np.cos(s / 2), "k--", lw=0.8)
    q_name, p_name = state_label(table.meta, "q0"), state_label(table.meta, "p0")
    ax.set_xlabel(f"{q_name} (mod 2π)" if wrap else q_name)
    ax.set_ylabel(p_name)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    canvas.legend(fontsize=8, ncol=3)
    return canvas.done(table.meta)


__all__ = ["phase_portrait_chart", "poincare_chart"]
