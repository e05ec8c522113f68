"""Dense output: the state between saved states, by cubic Hermite interpolation
(``hermite``, ``traj.sol``); and the requested times of ``integrate(t_eval=)`` checked
(``eval_times``: the core takes the states there, by the method's own partial steps).

On each interval [tₖ, tₖ₊₁] of a trajectory's saved states, q(t) is the cubic that matches qₖ,
q̇ₖ and qₖ₊₁, q̇ₖ₊₁, with q̇ from the inverse Legendre transform of (qₖ, pₖ); p(t) the cubic
that matches pₖ, ṗₖ and pₖ₊₁, ṗₖ₊₁, with ṗ = ∂L/∂q + f along the Euler–Lagrange flow. Its
error is O(Δ⁴) in the spacing Δ of the saved states (measured in ``tests/python/test_dense.py``),
on top of the method's own error at the saved states; save every step (``save_every=1``) for
values between steps. Constrained models are refused: there ṗ also holds the constraint forces,
which the saved states do not carry.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from ._util import floats

if TYPE_CHECKING:
    from .trajectory import Trajectory

__all__: list[str] = []  # internal: importable, not part of the public API


def hermite(traj: Trajectory, t: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(q(t), p(t)) of a trajectory at times ``t`` within its saved span, shapes (..., n).

    Examples
    --------
    >>> import numpy as np, varmech
    >>> s = varmech.scenes.harmonic_oscillator()
    >>> traj = varmech.integrate(s, dt=0.01, steps=1000, save_every=10, method="kahan_li8")
    >>> q, p = traj.sol(np.pi / 4)  # from q = 0, p = 1: q = sin t
    >>> bool(abs(q[0] - np.sin(np.pi / 4)) < 1e-7)
    True
    """
    times = floats("t", t)
    if traj.model.constraints:
        raise ValueError("t: dense output needs ṗ, which on a constrained model holds the constraint forces")
    if len(traj.t) < 2:
        raise ValueError("t: dense output needs at least two saved states")
    if not np.all(np.isfinite(times)):
        raise ValueError("t: must be finite")
    lo, hi = traj.t[0], traj.t[-1]
    if np.any((times < min(lo, hi)) | (times > max(lo, hi))):
        raise ValueError(f"t: must lie within the saved span [{lo}, {hi}]")
    flat = times.reshape(-1)
    # Saved times are monotonic; a backward run's are decreasing.
    order = 1.0 if hi >= lo else -1.0
    k = np.clip(np.searchsorted(order * traj.t, order * flat, side="right") - 1, 0, len(traj.t) - 2)
    delta = traj.t[k + 1] - traj.t[k]
    s = ((flat - traj.t[k]) / delta)[:, None]
    h00, h10 = (1 + 2 * s) * (1 - s) ** 2, s * (1 - s) ** 2
    h01, h11 = s**2 * (3 - 2 * s), s**2 * (s - 1)
    v = traj.v
    pdot = _core.derivative(traj.model._core, "dp_dt", *traj._arrays()[:2], v)
    d = delta[:, None]

    def cubic(x: np.ndarray, dx: np.ndarray) -> np.ndarray:
        return h00 * x[k] + h10 * d * dx[k] + h01 * x[k + 1] + h11 * d * dx[k + 1]

    shape = (*times.shape, traj.q.shape[1])
    return cubic(traj.q, v).reshape(shape), cubic(traj.p, pdot).reshape(shape)


def eval_times(t_eval: ArrayLike, t0: float, t_end: float) -> np.ndarray:
    """``t_eval`` checked: finite, increasing, within [t0, t_end] (ValueError naming it)."""
    times = floats("t_eval", t_eval).reshape(-1)
    if times.size == 0 or not np.all(np.isfinite(times)):
        raise ValueError("t_eval: must be a non-empty array of finite times")
    if np.any(np.diff(times) < 0):
        raise ValueError("t_eval: must be sorted in increasing order")
    if times[0] < t0 or times[-1] > t_end:
        raise ValueError(f"t_eval: must lie within the run's span [{t0}, {t_end}], got [{times[0]}, {times[-1]}]")
    return times
