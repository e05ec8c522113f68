"""A reference solution computed where none is known: the model's most accurate method at steps
refined until two successive runs agree.

:func:`reference_solution` is what :func:`varmech.work_precision` uses (``reference="auto"``) for
a user's own model, and a scene's at another horizon than its published one.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from numpy.typing import ArrayLike

from .. import _core
from .._util import positive, positive_int
from .._warnings import VarmechWarning
from ..integrate import integrate
from ..model import Model
from ..scenes import Reference, Scene, as_scene

__all__ = ["ReferenceWarning", "reference_solution"]


class ReferenceWarning(VarmechWarning):
    """A computed reference did not reach the tolerance asked for (round-off or the step budget
    came first): its ``tolerance`` says what it did reach.

    Examples
    --------
    >>> import warnings, varmech
    >>> from varmech.analysis.reference import ReferenceWarning, reference_solution
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     ref = reference_solution(varmech.scenes.pendulum(), t_end=100.0, max_steps=2048)
    >>> caught[0].category is ReferenceWarning, ref.source
    (True, 'computed: kahan_li6 at 2048 steps, agreeing with 1024 steps to 1.5e-08')
    """


def _final_state(scene: Scene, method: str, t_end: float, n: int) -> np.ndarray | None:
    """(q, p) at t_end after n steps, or None where the run failed (too coarse a step)."""
    try:
        traj = integrate(scene, dt=t_end / n, steps=n, method=method, save_every=n, max_energy_error=None, progress=False)
    except (_core.DivergenceError, _core.ConvergenceError, _core.SpuriousBranchError):
        return None
    x = np.concatenate([traj.q[-1], traj.p[-1]])
    return x if np.all(np.isfinite(x)) else None


def reference_solution(
    scene: Scene | Model | str,
    *,
    q0: ArrayLike | None = None,
    p0: ArrayLike | None = None,
    v0: ArrayLike | None = None,
    t_end: float | None = None,
    method: str | None = None,
    tolerance: float = 1e-10,
    max_steps: int = 2**24,
) -> Reference:
    """The state at ``t_end`` to within ``tolerance``, computed: the most accurate method of the
    model at steps halved until two successive final states agree.

    Runs of n = n₀, 2n₀, 4n₀, … steps over [0, ``t_end``] (n₀ the power of 2 nearest the
    scene's own ``dt``) end at states x_n; once ‖x_n − x_{n/2}‖₂ ≤ ``tolerance``·max(1, ‖x_n‖₂),
    x_n is the reference, with that difference as its stated ``tolerance`` (for a method of
    order p the error of x_n is about 1/(2ᵖ − 1) of it: the statement is conservative). Where
    the differences stop falling (round-off) or ``max_steps`` would be passed first, the closest
    agreement reached is returned, with a :class:`ReferenceWarning`.

    Parameters
    ----------
    scene : Scene, Model or str
        A scene, a scene's name, or a model with ``q0``, ``p0`` or ``v0``, and ``t_end``.
    q0, p0, v0 : array_like, optional
        A model's initial state (see :meth:`varmech.Scene.of`).
    t_end : float, optional
        The time of the reference (default: the scene's horizon).
    method : str, optional
        Default: the model's most accurate method (``model.kind.accurate_method``:
        ``kahan_li6`` for a separable model, ``galerkin6`` for a general L).
    tolerance : float, default 1e-10
        The agreement asked for, relative to max(1, ‖x‖₂).
    max_steps : int, default 2**24
        The most steps of one run.

    Returns
    -------
    Reference
        ``t``, ``q``, ``p``, ``tolerance`` (absolute, ‖x_n − x_{n/2}‖₂) and ``source`` =
        "computed: METHOD at N steps, agreeing with N/2 steps to X".

    Raises
    ------
    TypeError
        A model without ``q0`` or ``t_end``.
    ValueError
        A malformed argument, named; no two runs finished (every step too coarse for the method).

    Warns
    -----
    ReferenceWarning
        The tolerance was not reached.

    Examples
    --------
    The pendulum's published state at t = 2π, computed again:

    >>> import numpy as np, varmech
    >>> from varmech.analysis.reference import reference_solution
    >>> scene = varmech.scenes.pendulum()
    >>> ref = reference_solution(scene, t_end=scene.reference.t)
    >>> ref.source
    'computed: kahan_li6 at 256 steps, agreeing with 128 steps to 1.2e-11'
    >>> bool(np.abs(ref.q - scene.reference.q).max() < ref.tolerance)
    True
    """
    sc = as_scene(scene, q0=q0, p0=p0, v0=v0, t_end=t_end)
    horizon = sc.t_end if t_end is None else positive("t_end", t_end)
    tolerance = positive("tolerance", tolerance)
    max_steps = positive_int("max_steps", max_steps)
    name = sc.model.kind.accurate_method if method is None else method
    if not isinstance(name, str):
        raise TypeError(f"method: expected a method's name, got {type(name).__name__}")
    n = 2 ** max(4, round(math.log2(max(horizon / sc.dt, 1.0))))
    if 2 * n > max_steps:
        raise ValueError(
            f"max_steps: two runs from the scene's own {n} steps over t_end = {horizon:g} need {2 * n}, got {max_steps}; raise it"
        )
    k = sc.model.dim

    def reference(d: float, n: int, x: np.ndarray) -> Reference:
        source = f"computed: {name} at {n} steps, agreeing with {n // 2} steps to {d:.1e}"
        return Reference(horizon, x[:k].copy(), x[k:].copy(), source, d)

    previous = _final_state(sc, name, horizon, n)
    best: tuple[float, int, np.ndarray] | None = None
    reason = "max_steps"
    while 2 * n <= max_steps:
        n *= 2
        x = _final_state(sc, name, horizon, n)
        if x is not None and previous is not None:
            d = float(np.linalg.norm(x - previous))
            scale = max(1.0, float(np.linalg.norm(x)))
            if d <= tolerance * scale:
                return reference(d, n, x)
            last = best[0] if best is not None else math.inf
            if d < last:
                best = (d, n, x)
            # Round-off: no longer falling (less than 2x over a doubling) once far below 1e-6.
            if d < 1e-6 * scale and d > last / 2:
                reason = "round-off"
                break
        previous = x
    if best is None:
        raise ValueError(
            f"method: {name} did not finish two runs of up to {n} steps over t_end = {horizon:g}; "
            "give a reference, another method, or a larger max_steps"
        )
    warnings.warn(
        f"the computed reference agrees only to {best[0]:.1e} (asked: {tolerance:.0e} relative): {reason} came first; "
        "errors below it are not measured",
        ReferenceWarning,
        stacklevel=2,
    )
    return reference(*best)
