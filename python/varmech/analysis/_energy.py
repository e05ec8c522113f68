"""The energy of sampled states and its relative error, shared by the measurements."""

from __future__ import annotations

import numpy as np

from .. import _core
from ..model import Model


def energy_of(model: Model, t: np.ndarray, q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """H(q, p, t) = p·q̇ − L for rows t (N,), q and p (N, n)."""
    return _core.energy_terms(
        model._core,
        np.ascontiguousarray(t, dtype=float),
        np.ascontiguousarray(q, dtype=float),
        np.ascontiguousarray(p, dtype=float),
    )[0]


def relative_error(h: np.ndarray) -> np.ndarray:
    """|H − H₀|/|H₀| (absolute when H₀ = 0)."""
    scale = abs(h[0]) if h[0] != 0 else 1.0
    return np.abs(h - h[0]) / scale
