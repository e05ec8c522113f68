"""Charts (matplotlib, the optional extra ``varmech[charts]``)."""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np

from .integrate import Trajectory


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise ImportError("charts need matplotlib: pip install 'varmech[charts]'") from e
    return plt


def energy_error(trajectories: Mapping[str, Trajectory], path: str | Path, title: str = "") -> Path:
    """Plot |H(t) − H₀|/|H₀| against t on log–log axes, one line per labelled trajectory, and
    write the figure to ``path`` (PNG or SVG by its suffix)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.2), layout="constrained")
    for label, traj in trajectories.items():
        h = traj.energy()
        scale = abs(h[0]) if h[0] != 0 else 1.0
        err = np.abs(h - h[0]) / scale
        keep = (traj.t > 0) & (err > 0)
        ax.loglog(traj.t[keep], err[keep], label=label, lw=0.8)
    ax.set_xlabel("t")
    ax.set_ylabel("relative energy error |H − H₀|/|H₀|")
    ax.set_title(title)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
