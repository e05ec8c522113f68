"""The energy of sampled states, its relative error and its verdict, shared by the measurements."""

from __future__ import annotations

import numpy as np

from .. import _core
from ..conservation import InvariantStatistics, _statistics
from ..model import Model


def energy_of(model: Model, t: np.ndarray, q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """H(q, p, t) = p·q̇ − L for rows t (N,), q and p (N, n)."""
    return _core.energy_terms(
        model._core,
        np.ascontiguousarray(t, dtype=float),
        np.ascontiguousarray(q, dtype=float),
        np.ascontiguousarray(p, dtype=float),
    )[0]


def energy_statistics(model: Model, t: np.ndarray, q: np.ndarray, p: np.ndarray, *, steps: int) -> InvariantStatistics:
    """The energy's statistics and verdict for states sampled from any integrator's run of
    ``steps`` steps (see :class:`~varmech.InvariantStatistics`)."""
    t, q, p = (np.ascontiguousarray(x, dtype=float) for x in (t, q, p))
    e, kinetic, potential = _core.energy_terms(model._core, t, q, p)
    record = _core.energy_statistics(t, e, kinetic, potential, np.zeros(len(t)), int(steps))
    return _statistics(record, "energy", e[0], "mean kinetic energy", t)


def relative_error(h: np.ndarray) -> np.ndarray:
    """|H − H₀|/|H₀| (absolute when H₀ = 0)."""
    scale = abs(h[0]) if h[0] != 0 else 1.0
    return np.abs(h - h[0]) / scale


def conserves_energy(model: Model) -> bool:
    """H is a first integral: L does not depend on t and no force acts."""
    return not (model.time_dependent or model.forced)
