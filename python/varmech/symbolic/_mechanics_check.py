"""The check of :func:`~varmech.symbolic.from_mechanics`: the accelerations that the model it
builds gives (its Euler–Lagrange equations with its loads' generalized forces and its
constraints' forces, solved for q̈ and the multipliers) against those of the source's own
equations (Kane's fr + fr* solved for u̇, or the LagrangesMethod's equations solved for q̈), at
random states drawn with a fixed seed, evaluated to 30 digits."""

from __future__ import annotations

import copy
import random
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp
from sympy.physics import mechanics as me

#: The states compared, and the most drawn to find them (a state where either side's equations do
#: not determine the accelerations is drawn again).
STATES, DRAWS = 3, 12
#: Two accelerations agree to RTOL times the larger of the two sides' accelerations and their
#: equations' own size |f|/|M| (the floor where the accelerations cancel): the expressions are
#: evaluated to DIGITS digits, so that what is left is the float64 solve's round-off, ~1e-14 for
#: the mass matrices of mechanics.
RTOL, DIGITS = 1e-8, 30


class Draw:
    """Random values, from one seed: the coordinates in (0.2, 1.2) (away from 0 and from π/2,
    where the usual angles are singular), speeds in (−1, 1), the symbols without a given value
    in (0.5, 1.5), the given parameters as they are."""

    def __init__(self, parameters: Mapping[Any, float] | None, seed: int = 0) -> None:
        self.rng = random.Random(seed)
        self.given = {str(k): sp.Float(float(v), DIGITS) for k, v in (parameters or {}).items()}
        self.symbols: dict[sp.Symbol, sp.Float] = {}

    def number(self, low: float, high: float) -> sp.Float:
        return sp.Float(self.rng.uniform(low, high), DIGITS)

    def point(self, exprs: Sequence[Any], state: Mapping[sp.Expr, Any]) -> dict[sp.Expr, sp.Expr]:
        """The values of everything in ``exprs``: ``state`` (dynamicsymbols and their
        derivatives: q, q̇, u), t, a fresh random value for any other function of t (an input)
        and its derivatives, and one value per other free symbol."""
        t = me.dynamicsymbols._t
        at: dict[sp.Expr, sp.Expr] = {k: sp.Float(float(v), DIGITS) for k, v in state.items()}
        for e in exprs:
            for f in sorted(me.find_dynamicsymbols(sp.sympify(e)) - set(at), key=str):
                at[f] = self.number(-1.0, 1.0)
        for e in exprs:
            for s in sorted(sp.sympify(e).free_symbols - {t} - set(self.symbols), key=str):
                self.symbols[s] = self.given.get(s.name, self.number(0.5, 1.5))
        return {**at, **self.symbols, t: self.number(0.0, 1.0)}


def value(expr: Any, at: Mapping[sp.Expr, sp.Expr]) -> np.ndarray:
    """``expr`` (a Matrix) at ``at``, as floats; ValueError naming ``system`` where a symbol is left."""
    numbers = sp.Matrix(expr).xreplace(dict(at)).evalf(DIGITS)
    try:
        return np.array(numbers.tolist(), dtype=np.float64).reshape(numbers.shape)
    except TypeError:
        left = sorted(map(str, numbers.free_symbols | me.find_dynamicsymbols(numbers)))
        raise ValueError(f"system: its equations hold {left}, which from_mechanics cannot evaluate to check its model") from None


def _solve(mass: np.ndarray, rhs: np.ndarray) -> np.ndarray | None:
    """The solution of mass·x = rhs, None where mass is singular (to working precision)."""
    if np.linalg.cond(mass) > 1e10:
        return None
    return np.linalg.solve(mass, rhs)


def _size(mass: np.ndarray, rhs: np.ndarray) -> float:
    """The acceleration scale of equations mass·x = rhs, |rhs|∞/|mass|∞ (mass not 0: solved)."""
    return float(np.abs(rhs).max()) / float(np.abs(mass).max())


def _jacobian(rows: Sequence[sp.Expr], by: Sequence[Sequence[sp.Expr]], n: int) -> sp.Matrix:
    """The matrix of each row's derivatives by its ``n`` variables ``by[i]``."""
    return sp.Matrix(len(rows), n, lambda i, j: sp.diff(rows[i], by[i][j]))


def rates(q: Sequence[sp.Expr]) -> list[sp.Expr]:
    """The coordinates' rates q̇, their derivatives in t."""
    return [x.diff(me.dynamicsymbols._t) for x in q]


class ModelEquations:
    """The model's equations: d/dt ∂L/∂q̇ − ∂L/∂q − Q = Gᵀμ + Aᵀλ, with G q̈ + … = 0 from
    g(q, t) = 0 and A q̈ + … = 0 from A q̇ + b = 0, linear in (q̈, μ, λ); and the source's
    accelerations (u̇ = d/dt of the speeds in q̇, or q̈) in q̈."""

    def __init__(self, L: sp.Expr, q: Sequence[sp.Expr], force: Sequence[sp.Expr] | None,
                 holonomic: Sequence[sp.Expr], velocity: Sequence[sp.Expr], outputs: Sequence[sp.Expr]) -> None:  # fmt: skip
        t = me.dynamicsymbols._t
        self.q, self.qdot = list(q), rates(q)
        qddot = rates(self.qdot)
        zero = dict.fromkeys(qddot, sp.S.Zero)
        Q = list(force) if force else [sp.S.Zero] * len(q)
        rows = sp.Matrix([sp.diff(L, v).diff(t) - sp.diff(L, x) - f for x, v, f in zip(self.q, self.qdot, Q)])
        g, c = list(holonomic), list(velocity)
        self.level = sp.Matrix([*(x.diff(t) for x in g), *c])  # the constraints on q̇, affine in it
        levels = [*(x.diff(t, 2) for x in g), *(x.diff(t) for x in c)]
        directions = _jacobian([*g, *c], [*[self.q] * len(g), *[self.qdot] * len(c)], len(q))
        m = len(levels)
        self.mass = rows.jacobian(qddot).row_join(-directions.T).col_join(_jacobian(levels, [qddot] * m, len(q)).row_join(sp.zeros(m, m)))
        self.rhs = -sp.Matrix([*rows.xreplace(zero), *(x.xreplace(zero) for x in levels)])
        out = sp.Matrix(list(outputs))
        self.out_map, self.out_rest = out.jacobian(qddot), out.xreplace(zero)
        self.exprs = [self.level, self.mass, self.rhs, self.out_map, self.out_rest]

    def accelerations(self, at: dict[sp.Expr, sp.Expr]) -> tuple[np.ndarray, float] | None:
        """The outputs at ``at`` and the equations' acceleration scale; None where singular."""
        mass, rhs = value(self.mass, at), value(self.rhs, at).ravel()
        x = _solve(mass, rhs)
        if x is None:
            return None
        out = value(self.out_map, at) @ x[: len(self.q)] + value(self.out_rest, at).ravel()
        return out, _size(mass, rhs)


@dataclass
class SourceState:
    """A state of the source: its values (q, q̇ and the speeds), its accelerations (u̇ or q̈)
    and their equations' scale |f|/|M|."""

    state: dict[sp.Expr, sp.Expr]
    accelerations: np.ndarray
    size: float


def formed(what: str, form: Any) -> Any:
    """``form()``; ValueError naming ``system`` where SymPy cannot form the equations."""
    try:
        return form()
    except Exception as err:  # noqa: BLE001 - SymPy raises many kinds; each means: no equations to check against
        raise ValueError(
            f"system: {what} could not be formed ({type(err).__name__}: {err}); from_mechanics checks the model it "
            "builds against them, and takes no model it cannot check"
        ) from None


class KaneEquations:
    """Kane's equations fr + fr* = 0 of a KanesMethod (formed on a copy, the user's untouched),
    with the generalized forces −∂V/∂q of the bodies' ``potential_energy`` that varmech takes
    into L (and KanesMethod ignores), solved with the differentiated velocity constraints for
    the speeds' derivatives u̇."""

    label = "Kane's equations fr + fr*"

    def __init__(self, method: Any) -> None:
        km = copy.copy(method)
        formed(self.label, lambda: km.kanes_equations(method.bodies, method.loads))
        self.q, self.u = list(km.q), list(km.u)
        kinematics = km.kindiffdict()
        self.qdot = sp.Matrix([kinematics[x] for x in rates(self.q)])
        potential = sum((sp.sympify(b.potential_energy) for b in method.bodies), sp.S.Zero)
        forces = -self.qdot.jacobian(self.u).T * sp.Matrix([potential]).jacobian(self.q).T
        p = len(self.u) - len(km._udep)
        if len(km._udep):
            forces = forces[:p, :] + km._Ars.T * forces[p:, :]
        self.mass, self.forcing = km.mass_matrix, km.forcing + sp.Matrix([*forces, *[0] * (len(self.u) - p)])
        self.constraint, self.independent = (km._k_nh, km._f_nh), p
        self.names = [f"d{x.func.__name__}/dt" for x in self.u]
        self.exprs = [self.qdot, self.mass, self.forcing, *self.constraint]

    def draw(self, draw: Draw) -> SourceState | None:
        q = {x: draw.number(0.2, 1.2) for x in self.q}
        u = {x: draw.number(-1.0, 1.0) for x in self.u[: self.independent]}
        at = draw.point(self.exprs, {**q, **u})
        if len(self.u) > self.independent:
            k, f = (value(m, at) for m in self.constraint)
            dependent = _solve(k[:, self.independent :], -(k[:, : self.independent] @ [float(u[x]) for x in u] + f.ravel()))
            if dependent is None:
                return None
            at.update({x: sp.Float(float(v), DIGITS) for x, v in zip(self.u[self.independent :], dependent)})
        at.update({r: sp.Float(float(v), DIGITS) for r, v in zip(rates(self.q), value(self.qdot, at).ravel())})
        mass, forcing = value(self.mass, at), value(self.forcing, at).ravel()
        x = _solve(mass, forcing)
        return None if x is None else SourceState(at, x, _size(mass, forcing))


class LagrangeEquations:
    """The equations of a LagrangesMethod (formed on a copy): its mass_matrix_full and
    forcing_full, solved for q̈ and its multipliers."""

    label = "the LagrangesMethod's equations"

    def __init__(self, method: Any) -> None:
        lm = copy.copy(method)
        formed(self.label, lm.form_lagranges_equations)
        self.q, self.qdot, self.u = list(lm.q), rates(lm.q), list[sp.Expr]()
        n = len(self.q)
        self.mass, self.forcing = lm.mass_matrix_full[n:, n:], lm.forcing_full[n:, :]
        self.coneqs = sp.Matrix(lm.coneqs)
        self.names = [f"d²{x.func.__name__}/dt²" for x in self.q]
        self.exprs = [self.mass, self.forcing, self.coneqs]

    def draw(self, draw: Draw) -> SourceState | None:
        q = {x: draw.number(0.2, 1.2) for x in self.q}
        velocities = np.array([float(draw.number(-1.0, 1.0)) for _ in self.q])
        at = draw.point(self.exprs, {**q, **dict(zip(self.qdot, velocities))})
        if len(self.coneqs):
            # q̇ onto the constraints, which are affine in it: the least change that meets them.
            jac = value(self.coneqs.jacobian(self.qdot), at)
            residual = value(self.coneqs, at).ravel()
            velocities = velocities - np.linalg.lstsq(jac, residual, rcond=None)[0]
            at.update({r: sp.Float(float(v), DIGITS) for r, v in zip(self.qdot, velocities)})
        mass, forcing = value(self.mass, at), value(self.forcing, at).ravel()
        x = _solve(mass, forcing)
        return None if x is None else SourceState(at, x[: len(self.q)], _size(mass, forcing))


def check(source: Any, model: ModelEquations, parameters: Mapping[Any, float] | None, *, note: str = "") -> None:
    """ValueError naming ``system`` and the first differing acceleration where ``model`` does
    not give ``source``'s accelerations at STATES random states. The model's own coordinates
    (a contact's, added by the import) take random values and the rates its constraints give."""
    draw = Draw(parameters)
    extra = [i for i, x in enumerate(model.q) if x not in set(source.q)]
    compared = 0
    for _ in range(DRAWS):
        found = source.draw(draw)
        if found is None:
            continue
        at = found.state
        at.update({model.q[i]: draw.number(0.2, 1.2) for i in extra})
        at.update(draw.point(model.exprs, {}) | at)
        if not _meet_constraints(model, at, extra, source.label, note):
            continue
        mine = model.accelerations(at)
        if mine is None:
            continue
        ours, size = mine
        theirs = found.accelerations
        tol = RTOL * max(float(np.abs(ours).max(initial=0.0)), float(np.abs(theirs).max(initial=0.0)), size, found.size)
        for name, a, b in zip(source.names, theirs, ours):
            if not abs(a - b) <= tol:
                raise ValueError(
                    f"system: the model from_mechanics builds from it (L = T − V, its loads' generalized forces and its "
                    f"constraints' forces) does not give its equations of motion: at {_state(source, at)}, {name}: "
                    f"{source.label} give {a:.10g}, the model {b:.10g} (tolerance {tol:.1e}); varmech would integrate "
                    f"other dynamics{note}"
                )
        compared += 1
        if compared == STATES:
            return
    raise ValueError(
        f"system: at {DRAWS} random states {source.label} or the model's equations did not determine the "
        "accelerations (a singular mass matrix), so from_mechanics cannot check the model it builds against its "
        "source, and takes no model it cannot check"
    )


def _meet_constraints(model: ModelEquations, at: dict[sp.Expr, sp.Expr], extra: Sequence[int], label: str, note: str) -> bool:
    """Set the rates of the model's own coordinates from its constraints on q̇ (given the
    source's rates), and check that the source's velocities meet them; False where the rates
    are not determined, ValueError naming ``system`` where the constraints differ."""
    if not len(model.level):
        return True
    extra_rates = [model.qdot[i] for i in extra]
    at.update(dict.fromkeys(extra_rates, sp.Float(0, DIGITS)))
    residual = value(model.level, at).ravel()
    if extra:
        jac = value(model.level.jacobian(extra_rates), at)
        if np.linalg.matrix_rank(jac) < len(extra):
            return False
        solved = -np.linalg.lstsq(jac, residual, rcond=None)[0]
        at.update({r: sp.Float(float(v), DIGITS) for r, v in zip(extra_rates, solved)})
        residual = value(model.level, at).ravel()
    # |A q̇ + b| against the size of its terms, |A|∞|q̇|∞ + |b|∞.
    velocities = np.array([float(at[r]) for r in model.qdot])
    offset = model.level.xreplace(dict.fromkeys(model.qdot, 0))
    scale = float(np.abs(value(model.level.jacobian(model.qdot), at)).max() * np.abs(velocities).max() + np.abs(value(offset, at)).max())
    for i, r in enumerate(residual):
        if not abs(r) <= RTOL * scale:
            raise ValueError(
                f"system: the model from_mechanics builds from it does not hold its velocities: its constraint on q̇ "
                f"{model.level[i]} = 0 is {r:.10g} at a state that {label} allow{note}"
            )
    return True


def _state(source: Any, at: Mapping[sp.Expr, sp.Expr]) -> str:
    """The compared state, briefly: q, and u (or q̇)."""
    shown = [*source.q, *(source.u or rates(source.q))]
    return "(" + ", ".join(f"{_name(x)} = {float(at[x]):.4g}" for x in shown) + ")"


def _name(x: sp.Expr) -> str:
    return f"d{x.expr.func.__name__}/dt" if isinstance(x, sp.Derivative) else x.func.__name__
