"""The Routhian in closed form: the Lagrangian of the coordinates that remain when cyclic ones
are ignored at fixed momenta, R = L − μ·ċ with ċ solved from ∂L/∂ċ = μ."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp
from numpy.typing import ArrayLike

from .._util import vector
from ..reduction import cyclic_indices
from ._derive import vanishes
from ._model import SymbolicModel


@dataclass(frozen=True)
class Routhian:
    """R(x, ẋ, t; μ) on the shape coordinates x, and the symbols and default values of the
    momenta μ (parameters ``mu_<coordinate>``) next to the full model's parameters."""

    R: sp.Expr
    q: tuple[sp.Symbol, ...]
    v: tuple[sp.Symbol, ...]
    parameters: dict[sp.Symbol | str, float]


def routhian(model: SymbolicModel, cyclic: Sequence[int], momenta: ArrayLike) -> Routhian:
    """R = L − μ·ċ of ``model`` with the coordinates ``cyclic`` ignored at the momenta
    ``momenta`` (see :func:`varmech.symbolic.routh`)."""
    if not isinstance(model, SymbolicModel):
        raise TypeError(f"model: expected a SymbolicModel (varmech.symbolic), got {type(model).__name__}")
    n = model.dim
    indices = cyclic_indices(cyclic, n)
    mu_values = vector("momenta", momenta, len(indices))
    if model.forced or model.constraints:
        raise ValueError(
            f"model: {model.name} is {'forced' if model.forced else 'constrained'}; Routh reduction needs an "
            "unforced, unconstrained Lagrangian"
        )
    L, q, v = model.L, model.q, model.v
    for i in indices:
        if i not in model.cyclic:
            raise ValueError(f"cyclic: coordinate {q[i]} is not cyclic: ∂L/∂{q[i]} = {sp.diff(L, q[i])} is not 0")
    c, cdot = [q[i] for i in indices], [v[i] for i in indices]
    taken = {s.name for s in L.free_symbols} | set(model.parameters)
    mu = [sp.Symbol(f"mu_{s.name}") for s in c]
    for s in mu:
        if s.name in taken:
            raise ValueError(f"model: the momentum parameter {s.name} would shadow a symbol of L of that name")
    # ∂L/∂ċ = μ must be linear in ċ: ∂L/∂ċ = b + Aċ with A and b free of ċ.
    p = sp.Matrix([sp.diff(L, s) for s in cdot])
    A = p.jacobian(cdot)
    for k, j in np.ndindex(*A.shape):
        moving = [s for s in cdot if not vanishes(sp.diff(A[k, j], s))]
        if moving:
            raise ValueError(
                f"model: ∂L/∂{cdot[k]} = {p[k]} is not linear in {', '.join(map(str, cdot))} "
                f"(∂²L/∂{cdot[k]}∂{cdot[j]} = {A[k, j]} depends on {', '.join(map(str, moving))}); the closed-form "
                "Routhian needs it linear (varmech.routh solves the general case numerically)"
            )
    determinant = sp.simplify(A.det())
    if determinant == 0:
        raise ValueError(f"model: ∂²L/∂ċ² = {A.tolist()} is singular: ∂L/∂ċ = μ has no unique solution ċ")
    b = p.xreplace(dict.fromkeys(cdot, sp.Integer(0)))
    solved = A.LUsolve(sp.Matrix(mu) - b)
    at_momenta = dict(zip(cdot, solved))
    R = L.xreplace(at_momenta) - sum(m * x for m, x in zip(mu, solved))
    # L does not depend on c; the reference c = 0 removes any spelling of it.
    R = sp.simplify(R.xreplace(dict.fromkeys(c, sp.Integer(0))))
    shape = [i for i in range(n) if i not in indices]
    parameters: dict[sp.Symbol | str, float] = dict(model.parameters)
    parameters.update({s: float(x) for s, x in zip(mu, mu_values)})
    return Routhian(R, tuple(q[i] for i in shape), tuple(v[i] for i in shape), parameters)
