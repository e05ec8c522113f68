"""Delayed forces: a generalized force of the state now and of the state τ ago, f(q, q̇,
q(t − τ), q̇(t − τ), q̈(t − τ), t), whose past the run's own history gives (the core's
integrators/del/history.rs)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import sympy as sp

from ._inputs import Variables, expressions
from ._lower import Tape, check_compilable, lower

__all__ = ["Delayed"]


@dataclass(frozen=True)
class Delayed:
    """A force of the past: f(q, q̇, q(t − τ), q̇(t − τ), q̈(t − τ), t), a feedback from measured
    (hence delayed) positions, velocities and accelerations, as in the source's pendulum in a
    controlled wind.

    ``q_past``, ``v_past`` and ``a_past`` are the symbols that stand for q(t − τ), q̇(t − τ) and
    q̈(t − τ) in ``force``. The run reads them from its own history: exactly the method's own
    state τ ago when τ is a whole number of steps, its cubic Hermite interpolant otherwise; the
    acceleration is the derivative of the parabola through the method's velocities at the three
    steps nearest t − τ (its second differences (qₖ₊₁ − 2qₖ + qₖ₋₁)/h², interpolated: O(h²)). As
    the source insists, the term acts only once its past exists, from t₀ + τ on (a step later
    for one that reads the acceleration, whose past needs a step either side), unless the model
    is given its state before the run (``history=`` of :func:`~varmech.symbolic.lagrangian`:
    then the past before the run's first nodes is the history's). The delayed forces take the
    two-point rules (``midpoint``, ``trapezoid``) and a step no longer than τ (τ/1.5 for a term
    that reads the acceleration).

    Attributes
    ----------
    tau
        The delay τ > 0.
    force
        f, one expression per coordinate, of q, q̇, t and the past symbols.
    q_past
        The symbols standing for q(t − τ), one per coordinate (default: none used).
    v_past
        The symbols standing for q̇(t − τ), one per coordinate (default: none used).
    a_past
        The symbols standing for q̈(t − τ), one per coordinate (default: none used).

    Examples
    --------
    An oscillator damped by the velocity it had τ = 0.5 ago, q̈ + q = −0.4 q̇(t − τ):

    >>> import sympy as sp
    >>> import varmech
    >>> q, w, w_past = sp.symbols("q w w_past")
    >>> model = varmech.symbolic.lagrangian(
    ...     (w**2 - q**2) / 2, [q], [w],
    ...     delayed=varmech.symbolic.Delayed(0.5, [-0.4 * w_past], v_past=[w_past]))
    >>> traj = varmech.integrate(model, [1.0], v0=[0.0], dt=0.01, t_end=40.0)
    >>> bool(abs(traj.q[-400:, 0]).max() < 0.05)     # it decays
    True
    """

    tau: float
    force: Any
    q_past: Any = None
    v_past: Any = None
    a_past: Any = None


def delayed_forces(delayed: Any, variables: Variables) -> tuple[tuple[float, ...], list[sp.Expr], list[list[sp.Symbol]]]:
    """The delays, the forces (n a delay, in the plain symbols) and the symbols standing for
    the past positions, velocities and accelerations (three lists of n a delay, fresh where not
    given) of ``delayed`` (a :class:`Delayed` or a list of them); TypeError or ValueError naming
    ``delayed`` and the part at fault."""
    if isinstance(delayed, Delayed):
        delayed = [delayed]
    if not isinstance(delayed, Sequence) or not delayed or not all(isinstance(d, Delayed) for d in delayed):
        raise TypeError(f"delayed: expected a varmech.symbolic.Delayed or a list of them, got {delayed!r}")
    n = len(variables.q)
    taus: list[float] = []
    forces: list[sp.Expr] = []
    pasts: list[list[sp.Symbol]] = [[], [], []]
    taken = {*variables.q, *variables.v, variables.t}
    for j, term in enumerate(delayed):
        name = f"delayed[{j}]"
        if isinstance(term.tau, bool) or not isinstance(term.tau, (int, float)):
            raise TypeError(f"{name}.tau: expected a number, got {type(term.tau).__name__}: {term.tau!r}")
        if not (math.isfinite(term.tau) and term.tau > 0):
            raise ValueError(f"{name}.tau: must be positive and finite, got {term.tau}")
        past = []
        for what, given in (("q_past", term.q_past), ("v_past", term.v_past), ("a_past", term.a_past)):
            symbols = [sp.Dummy(f"{what}{j}_{i}") for i in range(n)] if given is None else list(given)
            if len(symbols) != n or not all(isinstance(s, sp.Symbol) for s in symbols):
                raise ValueError(f"{name}.{what}: needs one SymPy symbol per coordinate ({n}), got {given!r}")
            if taken.intersection(symbols):
                raise ValueError(f"{name}.{what}: {symbols} must be new symbols, not the coordinates, velocities or t")
            taken.update(symbols)
            past.append(symbols)
        f = expressions(term.force, f"{name}.force", variables)
        if len(f) != n:
            raise ValueError(f"{name}.force: must have one component per coordinate ({n}), got {len(f)}: {f}")
        for i, x in enumerate(f):
            check_compilable(x, f"{name}.force[{i}]")
        taus.append(float(term.tau))
        forces += f
        for kept, symbols in zip(pasts, past):
            kept += symbols
    return tuple(taus), forces, pasts


def history_functions(history: Any, variables: Variables) -> list[sp.Expr]:
    """q(s), q̇(s) and q̈(s), the derivatives in s, of ``history`` (n expressions of t and the
    parameters: the state before the run), 3n; ValueError naming ``history`` for the wrong
    number or an expression of the coordinates or velocities."""
    n = len(variables.q)
    q = expressions(history, "history", variables)
    if len(q) != n:
        raise ValueError(f"history: must give q(t) for each coordinate ({n}), got {len(q)}: {q}")
    state = {*variables.q, *variables.v}
    for i, x in enumerate(q):
        if state & x.free_symbols:
            raise ValueError(f"history[{i}]: the state before the run is a function of t alone, got {x}")
        check_compilable(x, f"history[{i}]")
    return [*q, *(sp.diff(x, variables.t) for x in q), *(sp.diff(x, variables.t, 2) for x in q)]


def history_tape(history: list[sp.Expr], variables: Variables, parameters: dict[sp.Symbol, int]) -> Tape:
    """The tape of the history (q(s), q̇(s), q̈(s)), of the one slot [s]."""
    return lower(history, {variables.t: 0}, parameters)


def delayed_tape(
    forces: list[sp.Expr], pasts: list[list[sp.Symbol]], variables: Variables, parameters: dict[sp.Symbol, int],
) -> Tape:
    """The tape of ``forces`` (Q, then the delayed terms), of the slots [q, q(t − τ₁) …],
    [q̇, q̇(t − τ₁) …], [q̈, q̈(t − τ₁) …], t: m = n(1 + d) each, where q̈ now (unknown where the
    step evaluates its force) is no symbol's."""
    q_past, v_past, a_past = pasts
    n = len(variables.q)
    m = n + len(q_past)
    slots = {s: i for i, s in enumerate([*variables.q, *q_past, *variables.v, *v_past])}
    slots |= {s: 2 * m + n + i for i, s in enumerate(a_past)}
    slots[variables.t] = 3 * m
    return lower(forces, slots, parameters)
