"""Routh reduction: finding the cyclic coordinates a model can ignore."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ._util import vector
from .model import Model


def cyclic_coordinates(
    model: Model, q: ArrayLike, *, spread: float = 1.0, samples: int = 64, seed: int = 0, rtol: float = 1e-9
) -> list[int]:
    """The coordinates i with ∂L/∂qᵢ ≡ 0, found numerically: ∂L/∂q is evaluated at ``samples``
    random states, positions within ``spread`` of ``q`` and velocities of size up to ``spread``
    (and at t in [0, 1] for time-dependent models), and coordinate i is a candidate when
    |∂L/∂qᵢ| ≤ ``rtol``·max(1, ‖∂L/∂q‖∞) at every one of them.

    Sampling can miss a dependence that vanishes on the samples, so the result is a list of
    candidates (Routh reduction needs ∂L/∂qᵢ = 0 everywhere); derivatives from differences
    (closures without ``dl_dq``) are accurate to about 1e-10, within the default ``rtol``.
    """
    n = model.dim
    q = vector("q", q, n)
    if not (np.isfinite(spread) and spread > 0):
        raise ValueError(f"spread: must be finite and positive, got {spread!r}")
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise ValueError(f"samples: must be a positive integer, got {samples!r}")
    rng = np.random.default_rng(seed)
    qs = q + spread * rng.uniform(-1.0, 1.0, (samples, n))
    vs = spread * rng.uniform(-1.0, 1.0, (samples, n))
    ts = rng.uniform(0.0, 1.0, samples) if model.time_dependent else np.zeros(samples)
    gradients = model._derivative("dl_dq", qs, vs, ts)
    scale = np.maximum(1.0, np.max(np.abs(gradients), axis=1, keepdims=True))
    ignorable = np.all(np.abs(gradients) <= rtol * scale, axis=0)
    return [int(i) for i in np.flatnonzero(ignorable)]
