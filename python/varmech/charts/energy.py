"""Energy error against time, from trajectories."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

from ..conservation import BALANCE, check_conservation
from ..trajectory import Trajectory
from ._figure import Canvas, documented, time_label

__all__ = [
    "energy_error",
]


@documented
def energy_error(
    trajectories: Mapping[str, Trajectory], path: str | Path | None = None, title: str = "", time_unit: str = "time units", *, ax: Axes | None = None
) -> Figure:
    """Plot the energy error |H(t) − H₀| against t on log–log axes, relative to the energy's
    scale (the run's mean kinetic energy; see :class:`~varmech.InvariantStatistics`), one line
    per labelled trajectory with its verdict in the legend, and write the figure to ``path``
    (PNG or SVG by its suffix). A forced run's line is its balance E − W. The t axis is in
    ``time_unit`` (a scene's :attr:`~varmech.scenes.Scene.time_unit`).

    Parameters
    ----------
    trajectories : mapping of str to Trajectory
        The runs to draw, by legend label.
    {path}
    title : str, optional
        The figure's title (default none).
    time_unit : str, default "time units"
        The unit of the t axis.
    {ax}

    {returns}

    {raises}.

    See Also
    --------
    varmech.check_conservation : The verdict in the legend.
    varmech.charts.work_precision.energy_growth_chart : The same over a long run, from a table.

    {examples}
    >>> import varmech
    >>> from varmech.charts import energy_error
    >>> scene = varmech.scenes.harmonic_oscillator()
    >>> runs = {m: varmech.integrate(scene, dt=0.1, steps=200, method=m) for m in ("verlet", "rk4")}
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "energy.png"
    ...     fig = energy_error(runs, path, title="harmonic oscillator")
    ...     print(path.name, plt.imread(path).shape)   # 7 × 4.2 inches at 120 dpi, RGBA
    energy.png (504, 840, 4)
    """
    canvas = Canvas(ax, path, figsize=(7, 4.2))
    ax = canvas.ax
    for label, traj in trajectories.items():
        report = check_conservation(traj, generators=())
        stats = report.energy
        h = traj.energy() - (traj.work if stats.name == BALANCE else 0.0)
        scale = stats.scale if stats.scale > 0 else 1.0
        err = np.abs(h - h[0]) / scale
        keep = (traj.t > 0) & (err > 0)
        ax.loglog(traj.t[keep], err[keep], label=f"{label}: {report.verdict}", lw=0.8)
    ax.set_xlabel(time_label({"time_unit": time_unit}))
    ax.set_ylabel("energy error |H − H₀| / mean kinetic energy")
    ax.set_title(title)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8)
    return canvas.done()
