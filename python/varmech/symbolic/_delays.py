"""Delayed forces: a generalized force of the state now and of the state τ ago, f(q, q̇,
q(t − τ), q̇(t − τ), t), whose past the run's own history gives (the core's
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
    """A force of the past: f(q, q̇, q(t − τ), q̇(t − τ), t), a feedback from measured (hence
    delayed) positions and velocities, as in the source's pendulum in a controlled wind.

    ``q_past`` and ``v_past`` are the symbols that stand for q(t − τ) and q̇(t − τ) in
    ``force``. The run reads them from its own history: exactly the method's own state τ ago
    when τ is a whole number of steps, its cubic Hermite interpolant otherwise. As the source
    insists, the term acts only once its past exists, from t₀ + τ on, unless the model is
    given its state before the run (``history=`` of :func:`~varmech.symbolic.lagrangian`: then
    the past before the run's first node is the history's). The delayed forces take the two-point rules (``midpoint``, ``trapezoid``) and a
    step no longer than τ.

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


def delayed_forces(delayed: Any, variables: Variables) -> tuple[tuple[float, ...], list[sp.Expr], list[sp.Symbol], list[sp.Symbol]]:
    """The delays, the forces (n a delay, in the plain symbols) and the symbols standing for
    the past positions and velocities (n a delay, fresh where not given) of ``delayed`` (a
    :class:`Delayed` or a list of them); TypeError or ValueError naming ``delayed`` and the part
    at fault."""
    if isinstance(delayed, Delayed):
        delayed = [delayed]
    if not isinstance(delayed, Sequence) or not delayed or not all(isinstance(d, Delayed) for d in delayed):
        raise TypeError(f"delayed: expected a varmech.symbolic.Delayed or a list of them, got {delayed!r}")
    n = len(variables.q)
    taus, forces, q_past, v_past = [], [], [], []
    taken = {*variables.q, *variables.v, variables.t}
    for j, term in enumerate(delayed):
        name = f"delayed[{j}]"
        if isinstance(term.tau, bool) or not isinstance(term.tau, (int, float)):
            raise TypeError(f"{name}.tau: expected a number, got {type(term.tau).__name__}: {term.tau!r}")
        if not (math.isfinite(term.tau) and term.tau > 0):
            raise ValueError(f"{name}.tau: must be positive and finite, got {term.tau}")
        past = []
        for what, given in (("q_past", term.q_past), ("v_past", term.v_past)):
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
        q_past += past[0]
        v_past += past[1]
    return tuple(taus), forces, q_past, v_past


def history_functions(history: Any, variables: Variables) -> list[sp.Expr]:
    """q(s) and q̇(s) = dq/ds of ``history`` (n expressions of t and the parameters: the state
    before the run), 2n; ValueError naming ``history`` for the wrong number or an expression of
    the coordinates or velocities."""
    n = len(variables.q)
    q = expressions(history, "history", variables)
    if len(q) != n:
        raise ValueError(f"history: must give q(t) for each coordinate ({n}), got {len(q)}: {q}")
    state = {*variables.q, *variables.v}
    for i, x in enumerate(q):
        if state & x.free_symbols:
            raise ValueError(f"history[{i}]: the state before the run is a function of t alone, got {x}")
        check_compilable(x, f"history[{i}]")
    return [*q, *(sp.diff(x, variables.t) for x in q)]


def history_tape(history: list[sp.Expr], variables: Variables, parameters: dict[sp.Symbol, int]) -> Tape:
    """The tape of the history (q(s), q̇(s)), of the one slot [s]."""
    return lower(history, {variables.t: 0}, parameters)


def delayed_tape(
    forces: list[sp.Expr], q_past: list[sp.Symbol], v_past: list[sp.Symbol], variables: Variables,
    parameters: dict[sp.Symbol, int],
) -> Tape:
    """The tape of ``forces`` (Q, then the delayed terms), of the slots [q, q(t − τ₁) …, q̇,
    q̇(t − τ₁) …, t]."""
    q = [*variables.q, *q_past]
    v = [*variables.v, *v_past]
    slots = {s: i for i, s in enumerate([*q, *v, variables.t])}
    return lower(forces, slots, parameters)
