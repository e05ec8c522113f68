"""Chaos: the orbit diagram of :func:`varmech.orbit_diagram`, a stroboscopic section's
attractor (:func:`varmech.stroboscopic_section`) and the convergence of a
:class:`varmech.LyapunovSpectrum`."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

from ..analysis.lyapunov import LyapunovSpectrum
from ..table import Table
from ._figure import Canvas, documented, state_label

__all__ = [
    "lyapunov_chart",
    "orbit_diagram_chart",
    "strobe_chart",
]


@documented
def orbit_diagram_chart(table: Table, path: str | Path | None = None, coordinate: str = "p0", title: str = "", *, ax: Axes | None = None) -> Figure:
    """Dot each strobe point of an orbit diagram at its parameter value: one dot for a period-1
    orbit, two for period 2, a band where the strobe is chaotic. Writes ``path`` (PNG or SVG by
    its suffix).

    Parameters
    ----------
    table : Table
        The table of :func:`varmech.orbit_diagram`.
    {path}
    coordinate : str, optional
        The strobe's column drawn (default ``p0``, the first momentum).
    title : str, optional
        The figure's title (default: the table's).
    {ax}

    {returns}

    {raises}, or ``coordinate`` is not a column.

    Examples
    --------
    >>> import math
    >>> import varmech
    >>> from varmech.charts import orbit_diagram_chart
    >>> scene = varmech.scenes.get("damped_driven_pendulum")
    >>> table = varmech.orbit_diagram(scene, [-math.pi / 2], [0.0], parameter="amplitude",
    ...                               values=[1.06, 1.075], period=3 * math.pi, periods=8, transient=50)
    >>> fig = orbit_diagram_chart(table)   # a new figure: fig.savefig(...), or path= to write it
    >>> fig.axes[0].get_xlabel()
    'amplitude'
    """
    if coordinate not in table.columns[2:]:
        raise ValueError(f"coordinate: must be one of {', '.join(table.columns[2:])}, got {coordinate!r}")
    canvas = Canvas(ax, path, figsize=(7.0, 4.5))
    ax = canvas.ax
    ax.scatter(table.column("value"), table.column(coordinate), s=1.0, color="black", linewidths=0, rasterized=True)
    ax.set_xlabel(str(table.meta.get("parameter", "value")))
    ax.set_ylabel(f"{state_label(table.meta, coordinate)} at t₀ + kT")
    ax.set_title(title or table.title)
    return canvas.done(table.meta)


@documented
def strobe_chart(
    table: Table, path: str | Path | None = None, coordinate: int = 0, wrap: float | None = None, title: str = "", *, ax: Axes | None = None
) -> Figure:
    """Dot the states of a stroboscopic section in the (q, p) plane of one coordinate: a
    periodic orbit's few points, or a strange attractor's folded sheets. Writes ``path`` (PNG or
    SVG by its suffix).

    Parameters
    ----------
    table : Table
        The table of :func:`varmech.stroboscopic_section`.
    {path}
    coordinate : int, optional
        The coordinate drawn, its q against its p (default 0).
    wrap : float, optional
        A period to take q modulo, into [−wrap/2, wrap/2) (2π for an angle that turns over);
        default none.
    title : str, optional
        The figure's title (default: the table's, with the points' count).
    {ax}

    {returns}

    {raises}, or ``coordinate`` is not one of the table's, or ``wrap`` is not positive.

    Examples
    --------
    >>> import math
    >>> import matplotlib.pyplot as plt
    >>> import varmech
    >>> from varmech.charts import strobe_chart
    >>> scene = varmech.scenes.get("damped_driven_pendulum")
    >>> table = varmech.stroboscopic_section(scene, [-math.pi / 2], [0.0], period=3 * math.pi, periods=200)
    >>> fig, (left, right) = plt.subplots(1, 2)   # one's own figure: the chart draws into right
    >>> strobe_chart(table, wrap=2 * math.pi, ax=right) is fig
    True
    >>> plt.close(fig)
    """
    q, p = f"q{coordinate}", f"p{coordinate}"
    if q not in table.columns:
        count = sum(c.startswith("q") for c in table.columns)
        raise ValueError(f"coordinate: must be 0 … {count - 1} (the table's coordinates), got {coordinate!r}")
    x = np.asarray(table.column(q))
    if wrap is not None:
        if not wrap > 0:
            raise ValueError(f"wrap: must be a positive period, got {wrap!r}")
        x = (x + wrap / 2) % wrap - wrap / 2
    canvas = Canvas(ax, path, figsize=(6.5, 5.0))
    ax = canvas.ax
    ax.scatter(x, table.column(p), s=1.0, color="black", linewidths=0, rasterized=True)
    ax.set_xlabel(f"{state_label(table.meta, q)} at t₀ + kT" + (f" (mod {wrap:.4g})" if wrap is not None else ""))
    ax.set_ylabel(f"{state_label(table.meta, p)} at t₀ + kT")
    ax.set_title(title or f"{table.title} ({len(x)} points)")
    return canvas.done(table.meta)


@documented
def lyapunov_chart(spectrum: LyapunovSpectrum, path: str | Path | None = None, title: str = "", *, ax: Axes | None = None) -> Figure:
    """The running estimates λⱼ(t) of a Lyapunov spectrum against t (log-scaled), and their sum:
    converging exponents level off, a regular orbit's fall as ln t/t, and a Hamiltonian model's
    sum stays at round-off. Writes ``path`` (PNG or SVG by its suffix).

    Parameters
    ----------
    spectrum : LyapunovSpectrum
        The result of :func:`varmech.lyapunov_spectrum`.
    {path}
    title : str, optional
        The figure's title.
    {ax}

    {returns}

    {raises}.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import varmech
    >>> from varmech.charts import lyapunov_chart
    >>> hh = varmech.scenes.henon_heiles().model
    >>> s = varmech.lyapunov_spectrum(hh, [0.0, -0.25], [0.42, 0.0], dt=0.05, steps=2000)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "spectrum.png"
    ...     fig = lyapunov_chart(s, path)
    ...     print(path.name)
    spectrum.png
    """
    canvas = Canvas(ax, path, figsize=(7.0, 4.5))
    ax = canvas.ax
    elapsed = spectrum.t - spectrum.t0
    for j in range(spectrum.running.shape[1]):
        ax.plot(elapsed, spectrum.running[:, j], lw=1.0, label=f"λ{j + 1} = {spectrum.exponents[j]:.4g} ± {spectrum.stderr[j]:.1g}")
    ax.plot(elapsed, np.sum(spectrum.running, axis=1), lw=1.0, color="black", ls=":", label="Σλ")
    ax.set_xscale("log")
    ax.set_xlabel("t − t₀")
    ax.set_ylabel("λ(t)")
    ax.axhline(0.0, color="grey", lw=0.5)
    ax.legend(fontsize="small")
    ax.set_title(title or f"Lyapunov spectrum, {spectrum.method}, dt = {spectrum.dt:g}")
    return canvas.done()
