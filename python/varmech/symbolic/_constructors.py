"""The constructors of symbolic models, :func:`lagrangian`, :func:`mechanical` and :func:`routh`
(re-exported by :mod:`varmech.symbolic`, whose examples build their models with them)."""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import Any

import sympy as sp

from .._progress import progress_bar
from ..model import Cyclic, Symmetry
from ._delays import Delayed, delayed_forces, delayed_tape, history_functions, history_tape
from ._derive import derive, vanishes
from ._inputs import Variables, check_symbols, expressions, parameters, variables
from ._lower import check_compilable, lower
from ._mass_flow import MassFlow, reactive_force
from ._model import Spec, Symbolic, SymbolicModel
from ._routh import routhian

__all__ = ["MAX_COORDINATES", "lagrangian", "mechanical", "routh"]


#: The most coordinates a symbolic model is compiled with: a chain's build grows linearly, about
#: 0.1 s a coordinate under load (SymPy's derivatives, term by term), minutes at this size.
MAX_COORDINATES = 2000


def lagrangian(
    L: Any,
    q: Any,
    v: Any = None,
    *,
    t: Any = None,
    parameters: Mapping[Any, float] | None = None,
    constraints: Any = None,
    velocity_constraints: Any = None,
    force: Any = None,
    rayleigh: Any = None,
    added_mass: Any = None,
    mass_flow: MassFlow | Sequence[MassFlow] | None = None,
    delayed: Delayed | Sequence[Delayed] | None = None,
    history: Any = None,
    symmetries: Sequence[Symmetry] = (),
    jit: bool = True,
    name: str = "symbolic lagrangian",
    progress: bool | None = None,
) -> SymbolicModel:
    """A compiled model of the Lagrangian ``L``.

    Parameters
    ----------
    L
        L(q, q̇, t), a scalar SymPy expression.
    q
        The coordinates: SymPy symbols, or ``sympy.physics.mechanics.dynamicsymbols`` (then
        ``L`` may hold q.diff(t), and ``v`` may be omitted: fresh symbols ``<name>_dot`` stand
        for the velocities).
    v
        The velocity symbols q̇, one per coordinate.
    t
        The time symbol, if ``L``, the force or the Rayleigh function depend on t (default: the
        dynamicsymbols' time, else none).
    parameters
        ``{symbol or name: default value}``: the symbols that are neither coordinates,
        velocities nor t, in the order of the parameter vector. Change them per run with
        :meth:`SymbolicModel.with_parameters` or ``integrate(..., parameters={...})``.
    constraints
        Holonomic constraints g(q) = 0: a list of m < n expressions of q alone; their Jacobian
        G = ∂g/∂q is derived.
    velocity_constraints
        Nonholonomic constraints A(q)q̇ = 0 (rolling without slipping, a skate's blade): a list
        of m < n expressions linear in the velocities; A = ∂c/∂q̇ and its derivatives ∂A/∂q are
        derived, and the model takes the discrete Lagrange–d'Alembert integrator. A coordinate
        they move (its column of A not ≡ 0) is not cyclic: the constraint force acts on it. With
        ``constraints`` too (fewer than n of both), each step also holds g(q) = 0.
    force
        A generalized force Q(q, q̇, t), one expression per coordinate (friction, driving).
    rayleigh
        A Rayleigh dissipation function R(q, q̇), which adds the force −∂R/∂q̇.
    added_mass
        A force of the acceleration, −A(q)q̈ (the fluid a body drags along: a pendulum in water,
        the Kirchhoff–Thomson added mass), given by A: a symmetric n×n matrix (SymPy or nested
        lists) of q, or a scalar a for A = a·I. It is folded into the metric, L + ½q̇ᵀA(q)q̇,
        so that the variational step integrates it as the source states it; where A depends on
        q, the force Ȧq̇ − ½q̇ᵀ(∂A/∂q)q̇ that the fold adds is taken back (the model is then
        forced). A not symmetric is refused: its antisymmetric part is no mass, and would need
        q̈ in a force.
    mass_flow
        Variable mass: a :class:`MassFlow` (or a list of them) for each body whose mass changes
        by matter ejected or accreted (a rocket, a falling chain, a snowplough). Its reactive
        force (Meshchersky) is added to the model's forces; the run stops with a
        :class:`~varmech.VarmechError` at a step where a mass is not positive.
    delayed
        Delayed forces: a :class:`Delayed` (or a list of them), each a force of the state now
        and of the state τ ago (its position, velocity and acceleration), read from the run's
        own history (``midpoint`` and ``trapezoid``, at a step no longer than τ, or τ/1.5 where
        the term reads the acceleration). Not with ``constraints`` or ``velocity_constraints``.
    history
        The state before the run for the delayed forces: q(t) for t ≤ t₀, one expression of t
        (and the parameters) per coordinate, q̇ and q̈ its derivatives. Then every delayed term acts
        from the start, reading the history where its past is before the run's first step;
        without it, a term acts only once its past exists.
    symmetries
        Declared symmetries (:class:`~varmech.Translation`, :class:`~varmech.Rotation`,
        :class:`~varmech.Cyclic`); each cyclic coordinate found is added as a
        :class:`~varmech.Cyclic`.
    jit
        Compile the tapes to machine code (the interpreter runs them otherwise).
    name
        A label for reports.
    progress
        A progress bar (tqdm, on stderr) once the build has taken a second: the rows of
        derivatives (3n + 2), then the functions lowered. ``None`` (default): only when stderr
        is a terminal. The build grows with the terms of L and of its derivatives (see the
        user guide's "Compile time"); Ctrl-C stops it.

    Returns
    -------
    SymbolicModel
        The compiled model: its kind (``kind_name``, ``kind``), expressions, parameters and
        cyclic coordinates; it integrates like any model, with no Python call per step.

    Raises
    ------
    TypeError
        ``L`` is not a scalar expression (a Matrix, a list), or ``q``, ``v`` are not symbols.
    ValueError
        An expression that cannot be compiled (an unsupported function such as an undefined
        ``sympy.Function('f')``, or a symbol that is neither a coordinate, a velocity, t nor a
        parameter), naming it and why; more than :data:`MAX_COORDINATES` coordinates, naming
        ``q``; constraints of the wrong number or depending on q̇ or t;
        velocity constraints not linear in q̇, with a part free of q̇, depending on t, or with
        ``constraints`` n or more together, naming them; a force with the wrong number of
        components; an ``added_mass`` of the wrong shape, not symmetric or depending on q̇ or t;
        a ``mass_flow`` whose mass depends on q̇, whose point depends on q̇ or t, or whose
        velocity has another number of components than its point; a ``delayed`` term whose τ
        is not positive, whose past symbols are not one new symbol per coordinate, or with
        constraints; a ``history`` without ``delayed``, of the wrong length or depending on the
        state; an L whose kinetic energy is not positive definite in the velocities (a constant
        ∂²L/∂q̇² that is singular or indefinite), naming ``L``.

    Examples
    --------
    >>> import sympy as sp
    >>> import varmech.symbolic
    >>> th, om, g = sp.symbols("theta omega g")
    >>> model = varmech.symbolic.lagrangian(om**2 / 2 + g * sp.cos(th), [th], [om],
    ...                                     parameters={g: 9.81})  # doctest: +SKIP
    >>> model.kind_name, model.parameters  # doctest: +SKIP
    ('separable', {'g': 9.81})
    """
    started = time.perf_counter()
    variables_ = _sized(variables(q, v, t))
    try:
        return _build(
            variables_, variables_.plain(L, "L"), parameters, constraints, force, rayleigh, symmetries, jit, name, started,
            velocity_constraints=velocity_constraints, progress=progress, added_mass=added_mass,
            mass_flow=mass_flow, delayed=delayed, history=history,
        )
    except ValueError as e:
        # Here the mass matrix is derived from L's kinetic terms, not an argument the user passed.
        if not str(e).startswith("mass:"):
            raise
        raise ValueError(
            f"L: ∂²L/∂q̇², the constant mass matrix derived from L,{str(e)[len('mass:'):]}: its kinetic energy must "
            "be positive definite in the velocities. A singular one leaves q̈ undetermined (L is not regular); a "
            "negative one is that of −L, which has the same motion. Check the signs of the kinetic terms and that "
            "every velocity enters them"
        ) from None


def mechanical(
    V: Any,
    q: Any,
    mass: Any,
    *,
    v: Any = None,
    t: Any = None,
    parameters: Mapping[Any, float] | None = None,
    constraints: Any = None,
    velocity_constraints: Any = None,
    force: Any = None,
    rayleigh: Any = None,
    added_mass: Any = None,
    mass_flow: MassFlow | Sequence[MassFlow] | None = None,
    delayed: Delayed | Sequence[Delayed] | None = None,
    history: Any = None,
    symmetries: Sequence[Symmetry] = (),
    jit: bool = True,
    name: str = "symbolic mechanical system",
    progress: bool | None = None,
) -> SymbolicModel:
    """A compiled model of the mechanical system L = ½q̇ᵀM(q)q̇ − V(q, t).

    ``mass`` is M: a symmetric n×n SymPy Matrix or nested list, or a scalar m for M = m·I; it
    may depend on q (then the model is a general Lagrangian, for the implicit methods). With M
    constant, the model is separable and every method applies.

    Parameters
    ----------
    V
        The potential V(q, t), a scalar SymPy expression.
    q
        The coordinates, as for :func:`lagrangian`.
    mass
        M: a symmetric n×n matrix (SymPy or nested lists) or a scalar m for M = m·I.
    v
        The velocity symbols; may be omitted (V and M hold no velocities: fresh symbols
        ``<q>_dot`` stand for them, as in ``expressions``).
    t, parameters, constraints, velocity_constraints, force, rayleigh, added_mass, mass_flow, delayed, history, symmetries, jit, name, progress
        As for :func:`lagrangian`.

    Returns
    -------
    SymbolicModel
        The compiled model: its kind (``kind_name``, ``kind``), expressions, parameters and
        cyclic coordinates; it integrates like any model, with no Python call per step.

    Raises
    ------
    ValueError
        ``mass`` of the wrong shape or not symmetric, naming it; and what :func:`lagrangian`
        refuses.
    TypeError
        ``q`` or ``v`` not symbols.

    Examples
    --------
    >>> import sympy as sp
    >>> import varmech.symbolic
    >>> x, y = sp.symbols("x y")
    >>> kepler = varmech.symbolic.mechanical(-1 / sp.sqrt(x**2 + y**2), [x, y], 1)
    >>> kepler.kind_name, kepler.expressions["mass"]
    ('separable', (1,))
    """
    started = time.perf_counter()
    variables_ = _sized(variables(q, v, t, fresh_velocities=True))
    m = _mass_matrix(mass, variables_, "mass")
    potential = variables_.plain(V, "V")
    check_compilable(potential, "V")
    velocity = sp.Matrix(variables_.v)
    L = (velocity.T * m * velocity)[0, 0] / 2 - potential
    return _build(
        variables_, L, parameters, constraints, force, rayleigh, symmetries, jit, name, started,
        velocity_constraints=velocity_constraints, progress=progress, added_mass=added_mass,
        mass_flow=mass_flow, delayed=delayed, history=history,
    )


def routh(model: SymbolicModel, cyclic: Sequence[int], momenta: Any) -> SymbolicModel:
    """The Routhian of ``model`` in closed form: a symbolic model on the coordinates that
    remain when the cyclic coordinates ``cyclic`` are ignored at their conserved momenta
    μ = ∂L/∂ċ.

    With the sign convention of :func:`varmech.routh` (Marsden, Ratiu & Scheurle),

        R(x, ẋ, t; μ) = L − μ·ċ,   ċ solving ∂L/∂ċ = μ,

    R acts as a Lagrangian: x(t) solves its Euler–Lagrange equations exactly when (x, c)(t)
    solves those of L with p_c = μ. Where ∂L/∂ċ = b + Aċ is linear in ċ (A and b free of ċ,
    A invertible) ċ = A⁻¹(μ − b) is solved symbolically and R simplified. The momenta are
    parameters named ``mu_<coordinate>`` with the values ``momenta`` as defaults, so they
    change per run by :meth:`SymbolicModel.with_parameters` without rebuilding; the model's
    own parameters are kept.

    Parameters
    ----------
    model
        A :class:`SymbolicModel`, unforced and unconstrained.
    cyclic
        The indices of the coordinates to ignore; each must be cyclic (``model.cyclic``).
    momenta
        Their momenta μ, in the order of ``cyclic``.

    Returns
    -------
    SymbolicModel
        The reduced model on the remaining coordinates, with the momenta as parameters
        ``mu_<coordinate>``.

    Raises
    ------
    ValueError
        A coordinate that is not cyclic or an index out of range, naming it; ∂L/∂ċ not linear
        in ċ or with a singular ∂²L/∂ċ², naming the expression; a forced or constrained model;
        ``momenta`` of the wrong length or not finite.
    TypeError
        ``model`` is not a :class:`SymbolicModel`.

    Examples
    --------
    The heavy top with its precession φ and spin ψ ignored:

    >>> import varmech.symbolic
    >>> from varmech.symbolic import examples
    >>> top = examples.heavy_top()
    >>> reduced = varmech.symbolic.routh(top, [1, 2], [2.0, 2.5])
    >>> reduced.q, reduced.parameters
    ((theta,), {'I1': 1.0, 'I3': 0.5, 'Mgl': 1.0, 'mu_phi': 2.0, 'mu_psi': 2.5})
    """
    started = time.perf_counter()
    reduced = routhian(model, cyclic, momenta)
    variables_ = variables(list(reduced.q), list(reduced.v), model.t)
    name = f"{model.name}, Routhian (ignoring {', '.join(str(model.q[i]) for i in cyclic)})"
    return _build(variables_, reduced.R, reduced.parameters, None, None, None, (), model._spec.jit, name, started)


def _sized(variables: Variables) -> Variables:
    """``variables``, if there are at most :data:`MAX_COORDINATES` coordinates: ValueError naming
    ``q`` otherwise, before anything is derived."""
    n = len(variables.q)
    if n > MAX_COORDINATES:
        raise ValueError(
            f"q: {n} coordinates; symbolic models are compiled up to {MAX_COORDINATES} (SymPy derives each term of L"
            " and of its derivatives, about 0.1 s per coordinate of a chain and more for a denser L, and a general"
            " L compiles three dense n×n Hessians); give a native or closure model (varmech.MechanicalSystem)"
        )
    return variables


def _mass_matrix(mass: Any, variables: Variables, name: str) -> sp.Matrix:
    """A mass matrix (the argument ``name``) as an n×n SymPy Matrix in the plain symbols;
    ValueError naming ``name`` unless it is a scalar or a symmetric n×n matrix."""
    n = len(variables.q)
    if not isinstance(mass, (sp.MatrixBase, list, tuple)):
        scalar = variables.plain(mass, name)
        check_compilable(scalar, name)
        return scalar * sp.eye(n)
    m = sp.Matrix(mass)
    if m.shape != (n, n):
        raise ValueError(f"{name}: must be a scalar or a {n}×{n} matrix, got shape {m.shape}")
    m = m.applyfunc(lambda x: variables.plain(x, name))
    for x in m:
        check_compilable(x, name)
    if not all(vanishes(m[i, j] - m[j, i]) for i in range(n) for j in range(i)):
        raise ValueError(f"{name}: must be symmetric, got {m.tolist()}")
    return m


def _added_mass(added_mass: Any, variables: Variables) -> tuple[sp.Expr, list[sp.Expr] | None]:
    """The force −A(q)q̈ folded into the metric: the term ½q̇ᵀAq̇ of L, and the force the fold
    adds and the model takes back where A depends on q, Ȧq̇ − ½q̇ᵀ(∂A/∂q)q̇ (None for a constant
    A). ValueError naming ``added_mass`` for a malformed or non-symmetric A, or one that
    depends on q̇ or t."""
    try:
        a = _mass_matrix(added_mass, variables, "added_mass")
    except ValueError as e:
        if "symmetric" in str(e):
            raise ValueError(
                f"{e}: only its symmetric part is a mass (a metric the variational step folds it into); an "
                "antisymmetric part would leave q̈ in the force"
            ) from None
        raise
    q, v = list(variables.q), list(variables.v)
    held = {s for x in a for s in x.free_symbols}
    if any(s in held for s in v) or variables.t in held:
        raise ValueError("added_mass: must depend on the positions q alone (the fold into the metric needs it)")
    velocity = sp.Matrix(v)
    term = (velocity.T * a * velocity)[0, 0] / 2
    if not any(s in held for s in q):
        return term, None
    n = len(q)
    force = [
        sp.Add(
            *(sp.diff(a[i, j], q[k]) * v[k] * v[j] for j in range(n) for k in range(n)),
            *(-sp.diff(a[j, k], q[i]) * v[j] * v[k] / 2 for j in range(n) for k in range(n)),
        )
        for i in range(n)
    ]
    return term, force


def _build(
    variables: Variables,
    L: sp.Expr,
    given_parameters: Mapping[Any, float] | None,
    constraints: Any,
    force: Any,
    rayleigh: Any,
    symmetries: Sequence[Symmetry],
    jit: bool,
    name: str,
    started: float,
    *,
    velocity_constraints: Any = None,
    progress: bool | None = None,
    added_mass: Any = None,
    mass_flow: Any = None,
    delayed: Any = None,
    history: Any = None,
) -> SymbolicModel:
    """Checks, derives, lowers and compiles: the common path of :func:`lagrangian` and
    :func:`mechanical`."""
    n = len(variables.q)
    forces = expressions(force, "force", variables) if force is not None else None
    if forces is not None and len(forces) != n:
        raise ValueError(f"force: must have one component per coordinate ({n}), got {len(forces)}: {forces}")
    if added_mass is not None:
        term, taken_back = _added_mass(added_mass, variables)
        L = L + term
        if taken_back is not None:
            forces = [a + b for a, b in zip(forces or [sp.S.Zero] * n, taken_back)]
    masses: list[sp.Expr] = []
    if mass_flow is not None:
        reactive, masses = reactive_force(mass_flow, variables)
        forces = [a + b for a, b in zip(forces or [sp.S.Zero] * n, reactive)]
    delays: tuple[float, ...] = ()
    if delayed is not None:
        if constraints is not None or velocity_constraints is not None:
            raise ValueError("delayed: delayed forces are not taken with constraints or velocity_constraints yet")
        delays, delayed_exprs, pasts = delayed_forces(delayed, variables)
        # The delayed forces act beside Q: the model is forced, its work tracked.
        forces = forces or [sp.S.Zero] * n
    if history is not None and delayed is None:
        raise ValueError("history: the state before the run, which only delayed forces read; give delayed= with it")
    past_state = history_functions(history, variables) if history is not None else []
    dissipation = variables.plain(rayleigh, "rayleigh") if rayleigh is not None else None
    holonomic = expressions(constraints, "constraints", variables) if constraints is not None else None
    nonholonomic = None
    if velocity_constraints is not None:
        nonholonomic = expressions(velocity_constraints, "velocity_constraints", variables)
    parts = [("L", L)] + [(f"force[{i}]", x) for i, x in enumerate(forces or [])]
    parts += [("rayleigh", dissipation)] if dissipation is not None else []
    parts += [(f"constraints[{i}]", x) for i, x in enumerate(holonomic or [])]
    parts += [(f"velocity_constraints[{i}]", x) for i, x in enumerate(nonholonomic or [])]
    parts += [(f"mass_flow[{i}].mass", x) for i, x in enumerate(masses)]
    if delays:
        # The past symbols are inputs of the delayed forces' tape, not parameters.
        past = dict.fromkeys([s for symbols in pasts for s in symbols], sp.S.Zero)
        parts += [(f"delayed[{i // n}].force[{i % n}]", x.xreplace(past)) for i, x in enumerate(delayed_exprs)]
    parts += [(f"history[{i}]", x) for i, x in enumerate(past_state[:n])]
    params = parameters(given_parameters, {s for _, x in parts for s in x.free_symbols}, variables)
    for what, x in parts:
        check_compilable(x, what)
        check_symbols(x, what, variables, params.index)
    # Derivation, then lowering, row by row and function by function: a bar after a second.
    bar = progress_bar(total=3 * n + 2, unit="row", desc=f"{name}: deriving", enabled=progress)
    try:
        derivation = derive(
            L, variables.q, variables.v, variables.t, force=forces, rayleigh=dissipation, constraints=holonomic,
            velocity_constraints=nonholonomic, tick=bar.update,
        )
        functions = {**derivation.functions, **({"masses": tuple(masses)} if masses else {})}
        bar.set_description(f"{name}: lowering", refresh=False)
        bar.reset(total=len(functions))
        tapes = {}
        for fn, exprs in functions.items():
            tapes[fn] = lower(exprs, variables.slots, params.index)
            bar.update()
        if delays:
            # Q first, then the delayed terms: the step evaluates all of them in one call.
            now = list(functions["force"])
            tapes["delayed_force"] = delayed_tape(now + delayed_exprs, pasts, variables, params.index)
            functions["delayed_force"] = (*now, *delayed_exprs)
        if past_state:
            tapes["history"] = history_tape(past_state, variables, params.index)
            functions["history"] = tuple(past_state)
        bar.set_description(f"{name}: compiling")
        declared = tuple(symmetries)
        found = tuple(Cyclic(i) for i in derivation.cyclic if Cyclic(i) not in declared)
        spec = Spec(
            kind=derivation.kind,
            dim=n,
            functions=tapes,
            parameter_names=params.names,
            parameters=params.values,
            constraints=len(derivation.functions.get("constraints", ())),
            velocity_constraints=len(nonholonomic or ()),
            time_dependent=derivation.time_dependent,
            forced="force" in functions,
            symmetries=declared + found,
            jit=bool(jit),
            delays=delays,
            energy_name="Jacobi integral" if derivation.moving_frame else "energy",
        )
        symbolic = Symbolic(variables.q, variables.v, variables.t, L, functions, derivation.cyclic, name)
        return SymbolicModel(spec, symbolic, started=started)
    finally:
        bar.close()
