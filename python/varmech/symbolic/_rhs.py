"""The first-order system of a symbolic model, lambdified: the right-hand side a SciPy user would
write from the same Lagrangian, which the work–precision tools run solve_ivp on."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import sympy as sp

if TYPE_CHECKING:
    from ._model import SymbolicModel


class FirstOrder:
    """ẏ = f(t, y) for y = (q, p): q̇ from the inverse Legendre transform, solved symbolically
    (L quadratic in q̇, so ∂L/∂q̇ = A(q, t)q̇ + b(q, t) = p gives q̇ = A⁻¹(p − b)), and
    ṗ = ∂L/∂q(q, q̇, t); one function lambdified for Python's ``math`` module with shared
    subexpressions, the parameters substituted. A call takes y of shape (2n,), or (2n, k)
    columns (``vectorized=True``); ``count`` counts the states evaluated.

    :meth:`build` returns None for a model whose ∂L/∂q̇ is not linear in q̇, or that is forced
    or constrained (its first-order system is not this one).
    """

    def __init__(self, function):
        self._f = function
        self.count = 0

    @classmethod
    def build(cls, model: SymbolicModel) -> FirstOrder | None:
        if model.forced or model.constraints:
            return None
        q, v, t, L = list(model.q), list(model.v), model.t, model.L
        p = sp.symbols(f"p_0:{len(q)}")
        momentum = sp.Matrix([sp.diff(L, x) for x in v])
        A = momentum.jacobian(v)
        if any(s in A.free_symbols for s in v):
            return None
        b = momentum.subs(dict.fromkeys(v, 0))
        qdot = A.LUsolve(sp.Matrix(p) - b)
        pdot = sp.Matrix([sp.diff(L, x) for x in q]).subs(dict(zip(v, qdot)))
        values = model.parameters
        by_name = {s: values[s.name] for s in L.free_symbols if s.name in values}
        field = [sp.sympify(e).subs(by_name) for e in [*qdot, *pdot]]
        return cls(sp.lambdify([t, *q, *p], field, modules="math", cse=True))

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        if y.ndim == 2:
            self.count += y.shape[1]
            return np.array([self._f(t, *column) for column in y.T]).T
        self.count += 1
        return np.array(self._f(t, *y))
