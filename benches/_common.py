"""What several bench scripts share: their command line, their report's output and REBOUND's copy
of an N-body scene. Imported by the scripts as ``from _common import ...`` (``python
benches/<script>.py`` puts this folder first on the path)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np


def quick_arguments(doc: str | None, quick: str, markdown: str = "also write the table to this file") -> argparse.Namespace:
    """The command line of a bench with ``--quick`` (its help ``quick``) and ``--markdown FILE``,
    described by the script's docstring ``doc``."""
    parser = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help=quick)
    parser.add_argument("--markdown", type=Path, help=markdown)
    return parser.parse_args()


def publish(report: str, markdown: Path | None) -> None:
    """Prints ``report`` and, where ``--markdown`` named a file, writes it there ending in a newline."""
    print(report)
    if markdown:
        markdown.write_text(report if report.endswith("\n") else report + "\n")


def rebound_simulation(G: float, masses: Any, q0: np.ndarray, p0: np.ndarray, integrator: str) -> Any:
    """REBOUND's copy of an N-body state (positions ``q0`` and momenta ``p0``, three a body) under
    ``integrator``; the caller sets its step. Needs the ``bench`` extra (rebound)."""
    import rebound

    sim = rebound.Simulation()
    sim.G = G
    for m, x, p in zip(masses, q0.reshape(-1, 3), p0.reshape(-1, 3)):
        v = p / m
        sim.add(m=m, x=x[0], y=x[1], z=x[2], vx=v[0], vy=v[1], vz=v[2])
    sim.integrator = integrator
    return sim
