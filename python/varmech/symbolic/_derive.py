"""Derivation: from a Lagrangian L(q, q̇, t) to the functions the core evaluates.

For a general Lagrangian these are L, its gradients (∂L/∂q, ∂L/∂q̇) and its Hessians
(∂²L/∂q², ∂²L/∂q∂q̇, ∂²L/∂q̇²); for a separable one, L = ½q̇ᵀMq̇ − V(q) with M constant, the
potential V, its gradient ∇V and M. Forces Q(q, q̇, t) (with Rayleigh's −∂R/∂q̇) and holonomic
constraints g(q) with their Jacobian G = ∂g/∂q come with either kind. Cyclic coordinates,
∂L/∂qᵢ ≡ 0, are found exactly.
"""

from __future__ import annotations

import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import sympy as sp


@dataclass(frozen=True)
class Derivation:
    """What the core needs of a model: its kind (``"lagrangian"`` or ``"separable"``), the
    expressions of each function by name (outputs row-major), the cyclic coordinates,
    whether L depends on t, and whether a t it held cancelled (a moving frame: its energy
    function is a Jacobi integral)."""

    kind: str
    functions: dict[str, tuple[sp.Expr, ...]]
    cyclic: tuple[int, ...]
    time_dependent: bool
    moving_frame: bool = False


def vanishes(expr: sp.Expr) -> bool:
    """Whether ``expr`` is identically 0: decided by ``sympy.simplify``, after a numerical
    probe at two random points has found no value away from 0 (which settles the common case,
    a nonzero expression, without simplifying); floats taken as the decimals they are written
    as, so that 0.49·36·(sin² + cos²) − 17.64 cancels as 49/100·36 − 1764/100 does."""
    if expr == 0:
        return True
    rng = random.Random(14)
    for _ in range(2):
        point = {s: rng.uniform(0.3, 0.9) for s in expr.free_symbols}
        try:
            value = complex(expr.evalf(subs=point))
        except (TypeError, ValueError):
            break
        if abs(value) > 1e-9:
            return False
    if sp.simplify(expr) == 0:
        return True
    return expr.has(sp.Float) and sp.simplify(sp.nsimplify(expr, rational=True)) == 0


def _free_of(expr: sp.Expr, symbols: Sequence[sp.Symbol] | set[sp.Symbol]) -> bool:
    """Whether ``expr`` does not depend on any of ``symbols`` (∂expr/∂s ≡ 0 for each)."""
    # Over the symbols expr holds (none, for the zeros of a large Hessian), not over ``symbols``.
    return all(vanishes(sp.diff(expr, s)) for s in expr.free_symbols if s in symbols)


def gradient(expr: sp.Expr, symbols: Sequence[sp.Symbol]) -> list[sp.Expr]:
    """[∂expr/∂s for s in symbols], each term of a sum differentiated only by the symbols it
    holds: the same expressions as ``sp.diff`` one symbol at a time, which walks every term of
    the sum for each symbol (n² work for a chain of n coordinates, where this is n)."""
    holding: dict[sp.Symbol, list[sp.Expr]] = {s: [] for s in symbols}
    for term in sp.Add.make_args(expr):
        for s in term.free_symbols:
            if s in holding:
                holding[s].append(term)
    return [sp.Add(*(sp.diff(term, s) for term in holding[s])) if holding[s] else sp.S.Zero for s in symbols]


def derive(
    L: sp.Expr,
    q: Sequence[sp.Symbol],
    v: Sequence[sp.Symbol],
    t: sp.Symbol,
    *,
    force: Sequence[sp.Expr] | None = None,
    rayleigh: sp.Expr | None = None,
    constraints: Sequence[sp.Expr] | None = None,
    velocity_constraints: Sequence[sp.Expr] | None = None,
    tick: Callable[[int], object] | None = None,
) -> Derivation:
    """The functions of L(q, q̇, t) for the core, with the generalized force
    Q = ``force`` − ∂R/∂q̇ (R the Rayleigh function ``rayleigh``), the constraints g(q) = 0
    and the velocity constraints A(q)q̇ = 0 (see :func:`velocity_constraint_functions`).
    ``tick(k)`` is called as each k rows of derivatives are done, 3n + 2 in all (a progress bar).

    ``L`` is a scalar expression, ``force`` has n components, and ``constraints`` m < n
    components free of q̇ and t (see :func:`constraint_functions`).

    Examples
    --------
    >>> import sympy as sp
    >>> r, th, vr, vth, t = sp.symbols("r theta v_r v_theta t")
    >>> kepler = derive(sp.Rational(1, 2) * (vr**2 + r**2 * vth**2) + 1 / r, [r, th], [vr, vth], t)
    >>> kepler.kind, kepler.cyclic
    ('lagrangian', (1,))
    >>> kepler.functions["gradients"]
    (r*v_theta**2 - 1/r**2, 0, v_r, r**2*v_theta)
    """
    # Derived over real symbols (the state and the parameters are real), so that |x|' = sign x
    # rather than an expression in re(x) and im(x); the results are in the caller's symbols.
    given = [L, *(force or ()), *(() if rayleigh is None else (rayleigh,)), *(constraints or ()), *(velocity_constraints or ())]
    symbols = {s for e in given for s in e.free_symbols} | {*q, *v, t}
    real = {s: _real_twin(s, symbols) for s in symbols if not s.is_real}
    derivation = _derive(
        L.xreplace(real),
        [real.get(s, s) for s in q],
        [real.get(s, s) for s in v],
        real.get(t, t),
        force=None if force is None else [e.xreplace(real) for e in force],
        rayleigh=None if rayleigh is None else rayleigh.xreplace(real),
        constraints=None if constraints is None else [e.xreplace(real) for e in constraints],
        velocity_constraints=None if velocity_constraints is None else [e.xreplace(real) for e in velocity_constraints],
        tick=tick or (lambda k: None),
    )
    back = {r: s for s, r in real.items()}
    # An atom is its own twin's or itself: xreplace would rebuild each of a Hessian's n² zeros.
    functions = {
        name: tuple(back.get(e, e) if e.is_Atom else e.xreplace(back) for e in exprs) for name, exprs in derivation.functions.items()
    }
    return replace(derivation, functions=functions)


def _real_twin(s: sp.Symbol, taken: set[sp.Symbol]) -> sp.Symbol:
    """A real symbol of the same name (printed alike in messages), or a real Dummy when the
    expressions already hold that one."""
    twin = sp.Symbol(s.name, real=True)
    return twin if twin not in taken else sp.Dummy(s.name, real=True)


def _derive(
    L: sp.Expr,
    q: Sequence[sp.Symbol],
    v: Sequence[sp.Symbol],
    t: sp.Symbol,
    *,
    force: Sequence[sp.Expr] | None,
    rayleigh: sp.Expr | None,
    constraints: Sequence[sp.Expr] | None,
    velocity_constraints: Sequence[sp.Expr] | None,
    tick: Callable[[int], object],
) -> Derivation:
    """:func:`derive` over real symbols."""
    n = len(q)
    time_dependent = not _free_of(L, [t])
    moving_frame = not time_dependent and t in L.free_symbols
    if moving_frame:
        # t cancels (a bead on a spinning hoop written in inertial coordinates: sin² + cos²):
        # L is the same at every t, so at t = 0, and every function derived from it is free of t.
        L = L.xreplace({t: sp.Integer(0)})
    dl_dq = gradient(L, q)
    dl_dv = gradient(L, v)
    tick(2)
    hessians = []
    for rows, symbols in ((dl_dq, q), (dl_dq, v), (dl_dv, v)):
        for d in rows:
            hessians.append(gradient(d, symbols))
            tick(1)
    generalized = _generalized_force(force, rayleigh, v, n)
    functions: dict[str, tuple[sp.Expr, ...]] = {}
    mass = None if generalized is not None or time_dependent else _constant_mass(dl_dv, hessians[n:], q, v, t)
    if mass is None:
        functions["lagrangian"] = (L,)
        functions["gradients"] = tuple(dl_dq + dl_dv)
        functions["hessians"] = tuple(entry for row in hessians for entry in row)
        if generalized is not None:
            functions["force"] = generalized
        if time_dependent:
            # The energy E = p·q̇ − L changes by −∂L/∂t, which the run tracks: also the
            # gradients' last output, their common subexpressions shared, so that a step keeps
            # it from its last evaluation of them.
            dl_dt = sp.diff(L, t)
            functions["dl_dt"] = (dl_dt,)
            functions["gradients"] += (dl_dt,)
    else:
        potential = -L.xreplace(dict.fromkeys(v, sp.Integer(0)))
        functions["potential"] = (potential,)
        functions["gradient"] = tuple(gradient(potential, q))
        functions["mass"] = mass
    if constraints is not None:
        functions.update(constraint_functions(constraints, q, v, t))
    if velocity_constraints is not None:
        functions.update(velocity_constraint_functions(velocity_constraints, q, v, t))
    cyclic = tuple(
        i for i, s in enumerate(q) if _cyclic(i, s, dl_dq[i], generalized, constraints)
        # The coordinates a velocity constraint moves take its force Aᵀλ: their momenta change.
        and all(_free_of(c, [v[i]]) for c in velocity_constraints or ())
    )
    return Derivation("lagrangian" if mass is None else "separable", functions, cyclic, time_dependent, moving_frame)


def _generalized_force(
    force: Sequence[sp.Expr] | None, rayleigh: sp.Expr | None, v: Sequence[sp.Symbol], n: int
) -> tuple[sp.Expr, ...] | None:
    """Q = ``force`` − ∂R/∂q̇, or None for a model without forces."""
    if force is None and rayleigh is None:
        return None
    q_force = list(force) if force is not None else [sp.Integer(0)] * n
    if rayleigh is not None:
        q_force = [f - sp.diff(rayleigh, s) for f, s in zip(q_force, v)]
    return tuple(q_force)


def _constant_mass(
    dl_dv: Sequence[sp.Expr],
    mixed_and_vv: Sequence[Sequence[sp.Expr]],
    q: Sequence[sp.Symbol],
    v: Sequence[sp.Symbol],
    t: sp.Symbol,
) -> tuple[sp.Expr, ...] | None:
    """M in its smallest form (one entry for m·I, n for a diagonal, n² row-major) when
    L = ½q̇ᵀMq̇ − V(q) with M constant, else None: ∂²L/∂q̇² is free of q, q̇ and t,
    ∂²L/∂q∂q̇ ≡ 0, and ∂L/∂q̇ vanishes at q̇ = 0 (no term linear in q̇)."""
    n = len(q)
    mixed, vv = mixed_and_vv[:n], mixed_and_vv[n:]
    state = {*q, *v, t}
    if not all(_free_of(entry, state) for row in vv for entry in row):
        return None
    if not all(vanishes(entry) for row in mixed for entry in row):
        return None
    at_rest = dict.fromkeys(v, sp.Integer(0))
    if not all(vanishes(d.xreplace(at_rest)) for d in dl_dv):
        return None
    # Free of the state, but perhaps only after simplification (sin²q + cos²q).
    m = [[entry if not entry.free_symbols & state else sp.simplify(entry) for entry in row] for row in vv]
    if not all(vanishes(m[i][j]) for i in range(n) for j in range(n) if i != j):
        return tuple(entry for row in m for entry in row)
    diagonal = tuple(m[i][i] for i in range(n))
    if all(vanishes(d - diagonal[0]) for d in diagonal[1:]):
        return diagonal[:1]
    return diagonal


def constraint_functions(
    constraints: Sequence[sp.Expr], q: Sequence[sp.Symbol], v: Sequence[sp.Symbol], t: sp.Symbol
) -> dict[str, tuple[sp.Expr, ...]]:
    """g(q) and G = ∂g/∂q (m·n, row-major) of m holonomic constraints g(q) = 0, 0 < m < n.

    ValueError names the constraints when there are none or too many, and a constraint that
    depends on the velocities or on t (only g(q) = 0 is holonomic and scleronomic)."""
    n, m = len(q), len(constraints)
    if not 0 < m < n:
        raise ValueError(
            f"constraints: need between 1 and {n - 1} constraints g(q) = 0 on {n} coordinates "
            f"(each removes a degree of freedom), got {m}: {list(constraints)}"
        )
    for g in constraints:
        moving = [s for s in [*v, t] if not _free_of(g, [s])]
        if moving:
            raise ValueError(
                f"constraints: {g} depends on {', '.join(map(str, moving))}; only holonomic constraints g(q) = 0 "
                "(functions of the coordinates alone) are supported"
            )
    jacobian = tuple(sp.diff(g, s) for g in constraints for s in q)
    return {"constraints": tuple(constraints), "constraint_jacobian": jacobian}


def velocity_constraint_functions(
    constraints: Sequence[sp.Expr], q: Sequence[sp.Symbol], v: Sequence[sp.Symbol], t: sp.Symbol
) -> dict[str, tuple[sp.Expr, ...]]:
    """A(q) (m·n, row-major) of m velocity constraints A(q)q̇ = 0, 0 < m < n, given as
    expressions linear in q̇ (A = ∂c/∂q̇), and its derivatives ∂A/∂qᵢ (n blocks of m·n) for
    Newton's exact Jacobian.

    ValueError names the constraint that is not linear in q̇, has a part free of q̇ (A q̇ + b
    with b ≠ 0), or depends on t, and the constraints when there are none or too many.

    Examples
    --------
    >>> import sympy as sp
    >>> x, y, th, vx, vy, vth, t = sp.symbols("x y theta v_x v_y v_theta t")
    >>> blade = -sp.sin(th) * vx + sp.cos(th) * vy - vth   # the Chaplygin sleigh
    >>> velocity_constraint_functions([blade], [x, y, th], [vx, vy, vth], t)["velocity_constraints"]
    (-sin(theta), cos(theta), -1)
    """
    n, m = len(q), len(constraints)
    if not 0 < m < n:
        raise ValueError(
            f"velocity_constraints: need between 1 and {n - 1} constraints A(q)q̇ = 0 on {n} coordinates, "
            f"got {m}: {list(constraints)}"
        )
    rows = []
    for k, c in enumerate(constraints):
        what = f"velocity_constraints[{k}]"
        if not _free_of(c, [t]):
            raise ValueError(f"{what}: {c} depends on {t}; only constraints A(q)q̇ = 0 free of t are supported")
        row = [sp.diff(c, s) for s in v]
        bent = [s for s in v if any(not _free_of(a, [s]) for a in row)]
        if bent:
            raise ValueError(
                f"{what}: {c} is not linear in the velocities (its coefficients depend on {', '.join(map(str, bent))}); "
                "Lagrange–d'Alembert needs constraints A(q)q̇ = 0"
            )
        rest = c - sum(a * s for a, s in zip(row, v))
        if not vanishes(rest):
            raise ValueError(
                f"{what}: {c} has a part free of the velocities ({sp.simplify(rest)}); only A(q)q̇ = 0 is supported"
            )
        rows.append(row)
    matrix = tuple(a for row in rows for a in row)
    derivative = tuple(sp.diff(a, s) for s in q for a in matrix)
    return {"velocity_constraints": matrix, "velocity_constraint_derivative": derivative}


def _cyclic(
    i: int, s: sp.Symbol, dl_dqi: sp.Expr, force: Sequence[sp.Expr] | None, constraints: Sequence[sp.Expr] | None
) -> bool:
    """Whether coordinate i is cyclic with a conserved momentum pᵢ: ∂L/∂qᵢ ≡ 0, no force
    depends on qᵢ nor acts on it (Qᵢ ≡ 0), and no constraint depends on qᵢ."""
    others = [*(force or ()), *(constraints or ())]
    return vanishes(dl_dqi) and all(_free_of(e, [s]) for e in others) and (force is None or vanishes(force[i]))
