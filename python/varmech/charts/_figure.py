"""matplotlib, imported on demand (the optional extra ``varmech[charts]``), and figure output."""

from __future__ import annotations

from pathlib import Path
from typing import Any


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


def save(fig: Any, path: str | Path) -> Path:
    """Write ``fig`` to ``path`` (PNG or SVG by its suffix), creating the folder, and close it."""
    path = Path(path)
    if path.suffix.lower() not in (".png", ".svg"):
        raise ValueError(f"path: must end in .png or .svg, got {path.name!r}")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    pyplot().close(fig)
    return path
