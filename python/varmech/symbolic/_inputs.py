"""The user's symbols: coordinates, velocities and time (plain SymPy symbols, or the
``dynamicsymbols`` of ``sympy.physics.mechanics`` with q̇ = q.diff(t)), and the parameters with
their default values."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp
from sympy.core.function import AppliedUndef

from .._util import finite


@dataclass(frozen=True)
class Variables:
    """The coordinates q, velocities v and time t as plain symbols, and the map that turns a
    user's expression into one of them (dynamicsymbols q(t) → q, q(t).diff(t) → v)."""

    q: tuple[sp.Symbol, ...]
    v: tuple[sp.Symbol, ...]
    t: sp.Symbol
    derivatives: dict[sp.Expr, sp.Symbol]
    functions: dict[sp.Expr, sp.Symbol]

    @property
    def slots(self) -> dict[sp.Symbol, int]:
        """The input slot of each symbol: qᵢ → i, q̇ᵢ → n + i, t → 2n."""
        return {s: i for i, s in enumerate([*self.q, *self.v, self.t])}

    def plain(self, expr: Any, what: str) -> sp.Expr:
        """``expr`` as a SymPy expression in the plain symbols; TypeError naming ``what`` for
        anything that is not a scalar expression, ValueError for a higher derivative."""
        if isinstance(expr, (sp.MatrixBase, sp.NDimArray, list, tuple, np.ndarray)):
            shape = getattr(expr, "shape", (len(expr),))
            raise TypeError(f"{what}: must be a scalar SymPy expression, got a {type(expr).__name__} of shape {shape}")
        try:
            value = sp.sympify(expr, strict=True)
        except sp.SympifyError:
            raise TypeError(f"{what}: must be a scalar SymPy expression, got {type(expr).__name__}: {expr!r}") from None
        if not isinstance(value, sp.Expr):
            raise TypeError(f"{what}: must be a scalar SymPy expression, got {type(value).__name__}: {value}")
        value = value.xreplace(self.derivatives)
        for derivative in value.atoms(sp.Derivative):
            raise ValueError(
                f"{what}: {derivative} cannot be compiled: only the coordinates and their first time derivatives "
                "(the velocities) may appear"
            )
        return value.xreplace(self.functions)


def _dynamic(x: Any) -> bool:
    """Whether ``x`` is a dynamicsymbol, an undefined function of one symbol, q(t)."""
    return isinstance(x, AppliedUndef) and len(x.args) == 1 and x.args[0].is_Symbol


def _symbols(name: str, values: Any, n: int | None = None) -> list[sp.Expr]:
    """The entries of ``values``: symbols or dynamicsymbols, distinct, ``n`` of them if given."""
    if isinstance(values, (sp.Symbol, AppliedUndef)):
        values = [values]
    if isinstance(values, sp.MatrixBase):
        values = list(values)
    if not isinstance(values, Iterable) or isinstance(values, (str, sp.Expr)):
        raise TypeError(f"{name}: expected a list of SymPy symbols, got {type(values).__name__}: {values!r}")
    entries = list(values)
    for x in entries:
        if not (isinstance(x, sp.Symbol) or _dynamic(x)):
            raise TypeError(f"{name}: expected SymPy symbols or dynamicsymbols, got {type(x).__name__}: {x!r}")
    if n is not None and len(entries) != n:
        raise ValueError(f"{name}: needs one symbol per coordinate ({n}), got {len(entries)}: {entries}")
    if not entries:
        raise ValueError(f"{name}: needs at least one coordinate")
    if len(set(entries)) != len(entries):
        raise ValueError(f"{name}: symbols must be distinct, got {entries}")
    return entries


def _plain(x: sp.Expr) -> sp.Symbol:
    return sp.Symbol(x.func.__name__) if _dynamic(x) else x


def variables(q: Any, v: Any, t: Any, *, fresh_velocities: bool = False) -> Variables:
    """The plain symbols of the coordinates ``q``, velocities ``v`` and time ``t`` (the
    dynamicsymbols' time by default, else a symbol that no expression holds: L does not depend
    on t). Omitted velocities are fresh ``<name>_dot`` symbols, for dynamicsymbols or where
    ``fresh_velocities`` says the expressions hold none (the mechanical form's V(q) and
    M(q))."""
    qs = _symbols("q", q)
    times = {x.args[0] for x in qs if _dynamic(x)}
    if len(times) > 1 or (times and t is not None and t not in times):
        raise ValueError(f"t: the dynamicsymbols q are functions of {sorted(map(str, times))}, t is {t}")
    if t is None:
        t = times.pop() if times else sp.Dummy("t")
    if not isinstance(t, sp.Symbol):
        raise TypeError(f"t: expected a SymPy symbol, got {type(t).__name__}: {t!r}")
    if v is None:
        if not (fresh_velocities or all(_dynamic(x) for x in qs)):
            raise ValueError("v: give the velocity symbols (one per coordinate), or use dynamicsymbols for q")
        v = [sp.Symbol(f"{x.func.__name__ if _dynamic(x) else x}_dot") for x in qs]
    vs = _symbols("v", v, len(qs))
    q_plain, v_plain = tuple(map(_plain, qs)), tuple(map(_plain, vs))
    every = [*q_plain, *v_plain, t]
    if len(set(every)) != len(every):
        raise ValueError(
            f"q, v, t: coordinates, velocities and time must be distinct symbols, got {q_plain}, {v_plain}, {t}"
        )
    derivatives = {x.diff(t): w for x, w in zip(qs, v_plain) if _dynamic(x)}
    functions = {x: p for x, p in zip([*qs, *vs], [*q_plain, *v_plain]) if _dynamic(x)}
    return Variables(q_plain, v_plain, t, derivatives, functions)


def check_symbols(expr: sp.Expr, what: str, variables: Variables, parameters: Iterable[sp.Symbol]) -> None:
    """ValueError naming a free symbol of ``expr`` (called ``what``) that is neither a
    coordinate, a velocity, t, nor a parameter."""
    known = {*variables.q, *variables.v, variables.t, *parameters}
    for s in sorted(expr.free_symbols - known, key=str):
        hint = " (pass t=... if it is time)" if s.name == "t" else ""
        raise ValueError(
            f"{what}: symbol {s} is neither a coordinate, a velocity, t, nor a parameter; "
            f"declare it in parameters={{...}}{hint}"
        )


@dataclass(frozen=True)
class Parameters:
    """The parameters in the order of the parameter vector: their names, default values, and
    the index of every symbol that stands for one."""

    names: tuple[str, ...]
    values: np.ndarray
    index: dict[sp.Symbol, int]


def parameters(given: Mapping[Any, Any] | None, symbols: Iterable[sp.Symbol], variables: Variables) -> Parameters:
    """The parameters ``given`` as {symbol or name: default value}, in their order. A name
    stands for every symbol of that name among ``symbols`` (the free symbols of the model's
    expressions)."""
    if given is None:
        given = {}
    if not isinstance(given, Mapping):
        raise TypeError(f"parameters: expected a dict {{symbol or name: value}}, got {type(given).__name__}")
    by_name: dict[str, list[sp.Symbol]] = {}
    for s in symbols:
        by_name.setdefault(s.name, []).append(s)
    names: list[str] = []
    values: list[float] = []
    index: dict[sp.Symbol, int] = {}
    taken = {*variables.q, *variables.v, variables.t}
    for key, value in given.items():
        if not isinstance(key, (sp.Symbol, str)):
            raise TypeError(f"parameters: keys must be SymPy symbols or names, got {type(key).__name__}: {key!r}")
        name = str(key)
        # A symbol also stands for the symbols of its name with other assumptions.
        stands_for = list(dict.fromkeys([sp.Symbol(key) if isinstance(key, str) else key, *by_name.get(name, [])]))
        if name in names:
            raise ValueError(f"parameters: {name} is given twice")
        if taken.intersection(stands_for):
            raise ValueError(f"parameters: {name} is a coordinate, a velocity or t, not a parameter")
        values.append(finite(f"parameters: {name}", value))
        index.update(dict.fromkeys(stands_for, len(names)))
        names.append(name)
    return Parameters(tuple(names), np.array(values, dtype=np.float64), index)


def expressions(values: Any, what: str, variables: Variables) -> list[sp.Expr]:
    """A list of scalar expressions in the plain symbols, from a list, a SymPy Matrix (a row
    or a column) or one expression; ValueError naming ``what`` for a matrix of another shape."""
    if isinstance(values, sp.MatrixBase):
        if min(values.shape) > 1:
            raise ValueError(f"{what}: must be a list or a column, got a matrix of shape {values.shape}")
        values = list(values)
    elif not isinstance(values, (list, tuple, np.ndarray)):
        values = [values]
    return [variables.plain(x, f"{what}[{i}]") for i, x in enumerate(values)]
