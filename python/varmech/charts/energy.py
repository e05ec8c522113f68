"""Energy error against time, from trajectories."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..integrate import Trajectory
from ._figure import pyplot, save


def energy_error(trajectories: Mapping[str, Trajectory], path: str | Path, title: str = "") -> Path:
    """Plot |H(t) − H₀|/|H₀| against t on log–log axes, one line per labelled trajectory, and
    write the figure to ``path`` (PNG or SVG by its suffix)."""
    plt = pyplot()
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
    return save(fig, path)
