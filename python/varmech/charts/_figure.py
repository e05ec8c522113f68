"""matplotlib, imported on demand (the optional extra ``varmech[charts]``), and figure output."""

from __future__ import annotations

import textwrap
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

_F = TypeVar("_F", bound=Callable[..., Any])

# The docstring sections every chart shares (it writes ``path`` and returns it), put in for the
# placeholders ``{path}``, ``{returns}`` and ``{raises}`` by :func:`documented`, as matplotlib's
# and SciPy's docstring templates do. ``{raises}`` ends mid-sentence, for a chart's own cases.
_SECTIONS = {
    "{path}": """path : str or pathlib.Path
        The file to write, ending in ``.png`` or ``.svg``; its folder is created.""",
    "{returns}": """Returns
    -------
    pathlib.Path
        ``path``, written (the figure is closed).""",
    "{raises}": """Raises
    ------
    ImportError
        matplotlib is missing (``pip install 'varmech[charts]'``).
    ValueError
        ``path`` does not end in ``.png`` or ``.svg``""",
}


def documented(chart: _F) -> _F:
    """``chart`` with the shared sections put into its docstring for their placeholders."""
    doc = chart.__doc__ or ""
    for placeholder, section in _SECTIONS.items():
        doc = doc.replace(placeholder, section)
    chart.__doc__ = doc
    return chart


def pyplot() -> Any:
    """matplotlib.pyplot with the non-interactive Agg backend, or ImportError saying how to
    install it."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise ImportError("charts need matplotlib: pip install 'varmech[charts]'") from e
    return plt


#: What a chart of a ``--quick`` measurement says on its face (``meta["quick"]``).
QUICK_NOTE = "--quick: a short measurement (fewer settings, orbits and repeats), a first look, not a comparison"


def save(fig: Any, path: str | Path, meta: dict[str, Any] | None = None) -> Path:
    """Write ``fig`` to ``path`` (PNG or SVG by its suffix), creating the folder, and close it;
    a chart of a quick measurement (``meta["quick"]``) says so above its title."""
    path = Path(path)
    if path.suffix.lower() not in (".png", ".svg"):
        raise ValueError(f"path: must end in .png or .svg, got {path.name!r}")
    if meta and meta.get("quick"):
        # A figure's own suptitle (panels side by side) keeps its place, the note under it.
        own = fig._suptitle.get_text() if fig._suptitle is not None else ""
        fig.suptitle(f"{own}\n{QUICK_NOTE}" if own else QUICK_NOTE, fontsize=10 if own else 8, color="black" if own else "C3")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    pyplot().close(fig)
    return path


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
