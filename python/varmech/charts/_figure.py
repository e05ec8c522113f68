"""matplotlib, imported on demand (the optional extra ``varmech[charts]``), and figure output."""

from __future__ import annotations

import textwrap
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from .._util import with_sections

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

_F = TypeVar("_F", bound=Callable[..., Any])

# The docstring sections every chart shares, put in for the placeholders ``{path}``, ``{ax}``,
# ``{returns}``, ``{raises}`` and ``{examples}`` by :func:`documented`, as matplotlib's and SciPy's
# docstring templates do. ``{raises}`` ends mid-sentence, for a chart's own cases; ``{examples}``
# opens the Examples with the imports of an example that writes its figure to a temporary folder.
_SECTIONS = {
    "{path}": """path : str or pathlib.Path, optional
        A file to write the figure to, ending in ``.png`` or ``.svg`` (its folder is created);
        default: none written.""",
    "{ax}": """ax : matplotlib.axes.Axes, optional
        The axes to draw into, in the user's own figure (a sequence of them, one a panel, for a
        chart of several panels); default: a new figure's, made without pyplot. The chart never
        chooses or changes matplotlib's backend.""",
    "{returns}": """Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into (``ax``'s own where given), written to ``path`` where given.""",
    "{raises}": """Raises
    ------
    ImportError
        matplotlib is missing (``pip install 'varmech[charts]'``).
    TypeError
        ``ax`` is not a matplotlib Axes.
    ValueError
        ``path`` does not end in ``.png`` or ``.svg``, or ``ax`` holds another number of Axes
        than the chart has panels""",
    "{examples}": """Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import matplotlib.pyplot as plt""",
}


def documented(chart: _F) -> _F:
    """``chart`` with the shared sections put into its docstring for their placeholders."""
    return with_sections(chart, _SECTIONS)


def draws(measurement: str) -> Callable[[_F], _F]:
    """:func:`documented`, for a chart of the table of one analysis function, ``measurement``
    (its dotted name), with two placeholders more that each such chart wrote alike: ``{table}``,
    the parameter ``table`` returned by that function, and ``{measures}``, the See Also to it and
    the Examples' opening that imports it and the chart."""

    def decorate(chart: _F) -> _F:
        module, name = measurement.rsplit(".", 1)
        table = f"""table : Table
        A table returned by :func:`~{measurement}`."""
        section = f"""See Also
    --------
    {measurement} : The measurements.

    {{examples}}
    >>> from {module} import {name}
    >>> from varmech.charts import {chart.__name__}"""
        return documented(with_sections(chart, {"{table}": table, "{measures}": section}))

    return decorate


def colormap(name: str) -> Any:
    """matplotlib's colour map ``name``, from its registry (no pyplot)."""
    import matplotlib

    return matplotlib.colormaps[name]


#: What a chart of a ``--quick`` measurement says on its face (``meta["quick"]``).
QUICK_NOTE = "--quick: a short measurement (fewer settings, orbits and repeats), a first look, not a comparison"


class Canvas:
    """Where a chart draws: the user's Axes (``ax``), or a new Figure of ``figsize`` with
    ``shape`` (rows, columns), ``panels`` of them drawn (all by default; the user gives as many
    Axes). A new figure is made without pyplot, so that no backend is chosen or changed and
    nothing is left open in pyplot's list of figures; ``path`` is checked before anything is
    drawn."""

    def __init__(
        self, ax: Any, path: str | Path | None, figsize: tuple[float, float], shape: tuple[int, int] = (1, 1), panels: int | None = None
    ):
        if path is not None:
            path = Path(path)
            if path.suffix.lower() not in (".png", ".svg"):
                raise ValueError(f"path: must end in .png or .svg, got {path.name!r}")
        self.path = path
        rows, cols = shape
        panels = rows * cols if panels is None else panels
        try:
            from matplotlib.axes import Axes
            from matplotlib.figure import Figure
        except ImportError as e:
            raise ImportError("charts need matplotlib: pip install 'varmech[charts]'") from e
        self.own = ax is None
        self.figure: Figure
        self.axes: list[Axes]
        if ax is None:
            self.figure = Figure(figsize=figsize, layout="constrained")
            grid = list(self.figure.subplots(rows, cols, squeeze=False).flat)
            for spare in grid[panels:]:
                spare.set_visible(False)
            self.axes = grid[:panels]
            return
        if isinstance(ax, Axes):
            given = [ax]
        elif isinstance(ax, (list, tuple, np.ndarray)):
            given = list(np.ravel(np.asarray(ax, dtype=object)))
        else:
            given = [ax]  # refused just below, by its type
        if not all(isinstance(a, Axes) for a in given):
            raise TypeError(f"ax: expected a matplotlib Axes (or a sequence of them), got {type(ax).__name__}")
        if len(given) != panels:
            raise ValueError(f"ax: this chart draws {panels} panels, got {len(given)} Axes")
        # A subfigure's Axes: the root figure is the one written.
        self.figure = given[0].figure.figure
        self.axes = given

    @property
    def ax(self) -> Axes:
        """The first (or only) panel."""
        return self.axes[0]

    def title(self, text: str) -> None:
        """The chart's title over all its panels: the figure's own where the chart made it,
        else over the first of the user's panels, above its own title."""
        if not text:
            return
        if self.own:
            self.figure.suptitle(text, fontsize=10)
        else:
            own = self.ax.get_title()
            self.ax.set_title(f"{text}\n{own}" if own else text, fontsize=10)

    def legend(self, **kwargs: Any) -> None:
        """A legend under all the panels where the chart made the figure, else in the first
        of the user's panels."""
        if self.own:
            self.figure.legend(loc="outside lower center", **kwargs)
        else:
            self.ax.legend(**kwargs)

    def done(self, meta: dict[str, Any] | None = None) -> Figure:
        """The figure, written to ``path`` where given; a chart of a quick measurement
        (``meta["quick"]``) says so above its title."""
        if meta and meta.get("quick"):
            if self.own:
                # A figure's own suptitle (panels side by side) keeps its place, the note under it.
                own = self.figure.get_suptitle()
                self.figure.suptitle(f"{own}\n{QUICK_NOTE}" if own else QUICK_NOTE, fontsize=10 if own else 8, color="black" if own else "C3")
            else:
                self.ax.set_title(f"{QUICK_NOTE}\n{self.ax.get_title()}", fontsize=8)
        if self.path is not None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.figure.savefig(self.path, dpi=120)
        return self.figure


def time_label(meta: dict[str, Any], name: str = "t") -> str:
    """The axis label of a time (or step) ``name`` in the unit of its table's scene:
    ``meta["time_unit"]`` (:data:`varmech.scenes.TIME_UNITS`), "time units" without one."""
    return f"{name} ({meta.get('time_unit', 'time units')})"


def state_label(meta: dict[str, Any], column: str) -> str:
    """The axis label of a state column (``q0``, ``p1``): the name the model gives it
    (``meta["coordinates"]``, ``meta["momenta"]``), else the column's."""
    names = meta.get({"q": "coordinates", "p": "momenta"}.get(column[:1], ""))
    index = column[1:]
    return str(names[int(index)]) if names and index.isdigit() and int(index) < len(names) else column


def measurement_notes(ax: Any, notes: list[str]) -> None:
    """Write the measurement's notes (``meta["notes"]``: skipped or shortened baselines, a
    computed reference, stopped sweeps) under the legend at the right of ``ax``, so that the
    chart says what the console said."""
    if notes:
        text = "\n".join(textwrap.fill(f"note: {note}", 44) for note in notes)
        ax.text(1.01, 0.0, text, transform=ax.transAxes, fontsize=6, va="bottom", ha="left", color="0.25")
