"""The energy error of the discrete Lagrange–d'Alembert integrators against a naive projection
method over a long run (:func:`varmech.analysis.nonholonomic.nonholonomic_energy`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

from ..table import Table
from ._figure import Canvas, draws, time_label

__all__ = [
    "nonholonomic_energy_chart",
]

#: What each line is, in the legend.
LABELS = {
    "midpoint": "midpoint (reversible DLA)",
    "dla4": "dla4 (its triple jump, order 4)",
    "cortes_martinez": "cortes_martinez (non-reversible DLA)",
    "rk4_projection": "RK4 + velocity projection",
}


@draws("varmech.analysis.nonholonomic.nonholonomic_energy")
def nonholonomic_energy_chart(table: Table, path: str | Path | None = None, title: str = "", *, ax: Axes | None = None) -> Figure:
    """Plot the relative energy error |E − E₀|/E₀ of a
    :func:`~varmech.analysis.nonholonomic.nonholonomic_energy` table against t on log–log axes,
    one line per method with its verdict in the legend, and a dotted ∝ t line through the end of
    the naive method's, against which its linear drift reads; write the figure to ``path`` (PNG
    or SVG). Errors of exactly 0 (the start) are left out.

    Parameters
    ----------
    {table}
    {path}
    title : str, optional
        The figure's title (default the table's title).
    {ax}

    {returns}

    {raises}.

    {measures}
    >>> import varmech
    >>> table = nonholonomic_energy(steps=200, samples=10)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "rolling_disk.png"
    ...     fig = nonholonomic_energy_chart(table, path)
    ...     print(path.name, plt.imread(path).shape)
    rolling_disk.png (552, 960, 4)
    """
    verdicts = table.meta.get("verdicts", {})
    canvas = Canvas(ax, path, figsize=(8, 4.6))
    ax = canvas.ax
    for method in table.unique("method"):
        rows = table.where(method=method)
        t, e = rows.column("t"), rows.column("energy_error")
        keep = (t > 0) & (e > 0) & np.isfinite(e)
        label = LABELS.get(method, method) + (f": {verdicts[method]}" if method in verdicts else "")
        ax.loglog(t[keep], e[keep], lw=1.0, label=label)
        if method == "rk4_projection" and keep.any():
            t1, e1 = t[keep][-1], e[keep][-1]
            guide = np.array([t1 / 100, t1])
            ax.loglog(guide, e1 * guide / t1, "k:", lw=0.8, label="∝ t")
    ax.set_xlabel(time_label(table.meta))
    ax.set_ylabel("relative energy error |E − E₀| / E₀")
    ax.set_title(title or table.title)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8)
    return canvas.done(table.meta)
