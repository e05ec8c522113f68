"""Argument checks shared by the public functions."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike


def vector(name: str, x: ArrayLike, n: int) -> np.ndarray:
    """``x`` as a contiguous float64 array (n,), or ValueError naming ``name``."""
    try:
        a = np.array(x, dtype=float)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: must be an array of {n} numbers ({e})") from None
    if a.shape != (n,):
        raise ValueError(f"{name}: must have shape ({n},), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: must be finite, got {a}")
    return np.ascontiguousarray(a)


def positive(name: str, x: float) -> float:
    """``x`` as a finite positive float, or ValueError naming ``name``."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: must be a number, got {x!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name}: must be finite and positive, got {x!r}")
    return v


def finite(name: str, x: float) -> float:
    """``x`` as a finite float, or ValueError naming ``name``."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: must be a number, got {x!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name}: must be finite, got {v}")
    return v


def positive_int(name: str, x: int) -> int:
    """``x`` as a positive int, or ValueError naming ``name``."""
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)) or x < 1:
        raise ValueError(f"{name}: must be a positive integer, got {x!r}")
    return int(x)
