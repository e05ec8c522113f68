"""Checks of user-supplied derivatives against differences."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ._util import finite, returned, vector
from .model import Lagrangian, MechanicalSystem, Model

__all__ = [
    "DerivativeCheck",
    "check_derivatives",
]


@dataclass(frozen=True)
class DerivativeCheck:
    """The worst mismatch between each supplied derivative and central differences.

    The record :func:`check_derivatives` returns; printing it gives a table, a row a derivative.

    Attributes
    ----------
    mismatch : dict of str to float
        Each supplied derivative's name (``"gradient"``, ``"mass_derivative"``, ``"dl_dq"``,
        ``"dl_dv"``, ``"L_qq"``, ``"L_qv"``, ``"L_vv"``) mapped to
        max |supplied − differences| / max(1, max |differences|); inf for a wrong shape.
    rtol : float
        The largest mismatch called a match.
    ok : bool
        Every mismatch is at most ``rtol``.
    worst : (str, float)
        The name and mismatch of the worst derivative.

    See Also
    --------
    check_derivatives : Makes the record.

    Examples
    --------
    >>> import varmech
    >>> right = varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2, lambda q: q.copy())
    >>> check = varmech.check_derivatives(right, [0.3])
    >>> check.ok, check.worst[0], check.worst[1] < 1e-9
    (True, 'gradient', True)
    >>> print(check)  # doctest: +ELLIPSIS
    Derivative check (rtol 1e-06):
      gradient  ...e-...  ok
    """

    mismatch: dict[str, float]
    rtol: float

    @property
    def ok(self) -> bool:
        return all(m <= self.rtol for m in self.mismatch.values())

    @property
    def worst(self) -> tuple[str, float]:
        name = max(self.mismatch, key=self.mismatch.__getitem__)
        return name, self.mismatch[name]

    def __str__(self) -> str:
        rows = [f"  {n:<9} {m:.2e}  {'ok' if m <= self.rtol else 'MISMATCH'}" for n, m in self.mismatch.items()]
        return "\n".join([f"Derivative check (rtol {self.rtol:g}):", *rows])


def _central(call: str, f, x: np.ndarray) -> np.ndarray:
    """∂f/∂xᵢ stacked on the first axis, by central differences with steps ε^{1/3}·max(|xᵢ|, 1)
    (f scalar or array valued, named ``call`` when it returns something else)."""
    rows = []
    for i in range(len(x)):
        h = np.finfo(float).eps ** (1 / 3) * max(abs(x[i]), 1.0)
        e = np.zeros_like(x)
        e[i] = h
        rows.append((returned(call, f(x + e)) - returned(call, f(x - e))) / (2 * h))
    return np.array(rows)


def _mismatch(call: str, supplied: ArrayLike, differences: np.ndarray) -> float:
    s = returned(call, supplied)
    if s.shape != differences.shape:
        return float("inf")
    return float(np.max(np.abs(s - differences)) / max(1.0, float(np.max(np.abs(differences)))))


def check_derivatives(model: Model, q: ArrayLike, v: ArrayLike | None = None, t: float = 0.0, *, rtol: float = 1e-6) -> DerivativeCheck:
    """Compare the derivatives ``model`` supplies with central differences at (q, q̇, t).

    For a :class:`~varmech.MechanicalSystem`, its ``gradient`` against differences of its
    ``potential``, and its ``mass_derivative`` against differences of its ``mass`` closure; for
    a :class:`~varmech.Lagrangian`, its ``dl_dq`` and ``dl_dv`` against differences of L, and
    its ``hessians`` against differences of the first derivatives it supplies (second
    differences of L would be too coarse to judge them). Differences are accurate to about
    1e-10 relative, so a mismatch above ``rtol`` (default 1e-6) means a wrong derivative.

    Parameters
    ----------
    model
        A closure model that supplies some of its derivatives.
    q
        The configuration, shape (n,).
    v
        The velocities for a Lagrangian's derivatives (default: zeros).
    t
        The time.
    rtol
        The largest mismatch, relative to max(1, |differences|), called a match.

    Returns
    -------
    DerivativeCheck
        Each supplied derivative's worst mismatch (``mismatch``), ``ok``, ``worst``; printing
        it gives the table.

    Raises
    ------
    TypeError
        ``model`` is not a closure model, or one of its closures returns something other than
        numbers (the message names it).
    ValueError
        ``model`` supplies no derivatives, or ``q``, ``v``, ``t`` that are not finite numbers of
        the right shape.

    Examples
    --------
    A gradient with a sign error is caught:

    >>> import numpy as np, varmech
    >>> wrong = varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2, lambda q: -q.copy())
    >>> check = varmech.check_derivatives(wrong, [0.3])
    >>> check.ok, check.worst[0]
    (False, 'gradient')
    """
    n = model.dim
    q = vector("q", q, n)
    t = finite("t", t)
    mismatch: dict[str, float] = {}
    if isinstance(model, MechanicalSystem):
        if model.gradient is not None:
            mismatch["gradient"] = _mismatch("gradient(q)", model.gradient(q.copy()), _central("potential(q)", model.potential, q))
        if model.mass_derivative is not None:
            mismatch["mass_derivative"] = _mismatch(
                "mass_derivative(q)", model.mass_derivative(q.copy()), _central("mass(q)", model.mass, q)
            )
    elif isinstance(model, Lagrangian):
        v = vector("v", v if v is not None else np.zeros(n), n)
        L, H = "lagrangian(q, v, t)", "hessians(q, v, t)"
        if model.dl_dq is not None:
            mismatch["dl_dq"] = _mismatch("dl_dq(q, v, t)", model.dl_dq(q.copy(), v.copy(), t), _central(L, lambda x: model.lagrangian(x, v, t), q))
        if model.dl_dv is not None:
            mismatch["dl_dv"] = _mismatch("dl_dv(q, v, t)", model.dl_dv(q.copy(), v.copy(), t), _central(L, lambda x: model.lagrangian(q, x, t), v))
        if model.hessians is not None:
            lqq, lqv, lvv = model.hessians(q.copy(), v.copy(), t)
            # _central stacks ∂/∂xⱼ on the first axis: the transpose of (i, j) = ∂²L/∂·ᵢ∂xⱼ.
            if model.dl_dq is not None:
                mismatch["L_qq"] = _mismatch(H, lqq, _central("dl_dq(q, v, t)", lambda x: model.dl_dq(x, v, t), q).T)
                mismatch["L_qv"] = _mismatch(H, lqv, _central("dl_dq(q, v, t)", lambda x: model.dl_dq(q, x, t), v).T)
            if model.dl_dv is not None:
                mismatch["L_vv"] = _mismatch(H, lvv, _central("dl_dv(q, v, t)", lambda x: model.dl_dv(q, x, t), v).T)
    else:
        raise TypeError(f"model: expected a MechanicalSystem or Lagrangian of closures, got {type(model).__name__}")
    if not mismatch:
        raise ValueError("model: supplies no derivatives to check")
    return DerivativeCheck(mismatch, rtol)


def blame(model: Model, q: np.ndarray, v: np.ndarray, t: float, where: str) -> str | None:
    """Where a closure model's supplied derivatives disagree with differences of its functions at
    (q, q̇, t), the advice that says so: the run integrates other dynamics than its energy's, and
    no step mends that. None for a model whose derivatives agree, supplies none, is not made of
    closures, or whose closures fail there (nothing to blame). ``where`` names the state."""
    if not isinstance(model, (MechanicalSystem, Lagrangian)):
        return None
    try:
        check = check_derivatives(model, q, v, t)
    except Exception:
        return None
    if check.ok:
        return None
    name, mismatch = check.worst
    return (
        f"the model's {name} disagrees with central differences {where} by {mismatch:.2e} (relative, above "
        f"{check.rtol:g}), so reducing dt cannot help: mend {name} (varmech.check_derivatives(model, q) compares it at any q)"
    )
