"""Dense output: the state between saved states, by cubic Hermite interpolation
(``hermite``, ``traj.sol``); and the states at requested times, by the method's own partial
step (``at_times``, ``integrate(t_eval=)``).

On each interval [tₖ, tₖ₊₁] of a trajectory's saved states, q(t) is the cubic that matches qₖ,
q̇ₖ and qₖ₊₁, q̇ₖ₊₁, with q̇ from the inverse Legendre transform of (qₖ, pₖ); p(t) the cubic
that matches pₖ, ṗₖ and pₖ₊₁, ṗₖ₊₁, with ṗ = ∂L/∂q + f along the Euler–Lagrange flow. Its
error is O(Δ⁴) in the spacing Δ of the saved states (measured in ``tests/python/test_dense.py``),
on top of the method's own error at the saved states; save every step (``save_every=1``) for
values between steps. Constrained models are refused: there ṗ also holds the constraint forces,
which the saved states do not carry.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from ._util import floats

if TYPE_CHECKING:
    from .model import Model
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


def grid_step(t: float, t0: float, dt: float, steps: int, at_least: int = 0) -> int:
    """The last grid step n ≤ ``steps`` (and ≥ ``at_least``) whose time tₙ = t0 + n·dt, as the
    core's clock computes it, is at or before t."""
    n = min(int(np.floor((t - t0) / dt)), steps)
    while n > at_least and t0 + n * dt > t:
        n -= 1
    return max(n, at_least)


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


def at_times(
    first: Callable[[int], Any], model: Model, times: np.ndarray, t0: float, dt: float, steps: int, report: Callable[[int], None]
) -> tuple[dict[str, Any], Any]:
    """The states at ``times`` of a run of ``steps`` steps of ``dt`` from ``t0``, whose first
    (zero-step) record ``first(0)`` makes: the run goes from grid state to grid state
    (``_core.resume``, bit for bit one run), and a time between tₙ and tₙ₊₁ is reached by one step
    of the same method of size τ = t − tₙ from (tₙ, qₙ, pₙ), so each state has the method's own
    error, of its order (``tests/python/test_dense.py``). Returns the columns at ``times`` (t, q,
    p, newton, work, the counts at the grid state before each) and the record of the run's end.
    """
    record = first(0)
    rows: dict[str, list[Any]] = {"t": [], "q": [], "p": [], "newton": [], "work": []}
    at = 0
    for t in times:
        n = grid_step(t, t0, dt, steps)
        if n > at:
            record = _core.resume(model._core, record.checkpoint, steps=n - at, save_every=n - at)
            at = n
            report(record.steps)
        tau = t - record.t[-1]
        if tau > 0:
            stepper = _core.Stepper.from_checkpoint(model._core, record.checkpoint)
            stepper.dt = tau
            stepper.step()
            q, p = stepper.q, stepper.p
        else:
            q, p = record.q[-1], record.p[-1]
        for name, value in (("t", t), ("q", q), ("p", p), ("newton", record.newton[-1]), ("work", record.work[-1])):
            rows[name].append(value)
    if steps > at:
        record = _core.resume(model._core, record.checkpoint, steps=steps - at, save_every=steps - at)
        report(record.steps)
    return {name: np.array(values) for name, values in rows.items()}, record
