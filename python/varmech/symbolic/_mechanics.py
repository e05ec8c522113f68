"""Models of ``sympy.physics.mechanics``: a ``LagrangesMethod``, a ``KanesMethod`` or a
``System`` read as what :func:`~varmech.symbolic.lagrangian` takes, L(q, q̇, t), the generalized
forces of the loads, and the holonomic and velocity constraints."""

from __future__ import annotations

import random
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import sympy as sp
from sympy.physics import mechanics as me

from . import _contact
from ._constructors import lagrangian
from ._mechanics_check import KaneEquations, LagrangeEquations, ModelEquations, check, formed
from ._mechanics_check import rates as _rates
from ._model import SymbolicModel

__all__ = ["from_mechanics"]


@dataclass
class _Parts:
    """What a mechanics object says, in its own dynamicsymbols: L, the coordinates, the
    generalized forces and the constraints (g(q) = 0; A(q)q̇ + b(q) = 0)."""

    L: sp.Expr
    q: list[sp.Expr]
    force: list[sp.Expr] | None = None
    holonomic: list[sp.Expr] = field(default_factory=list)
    velocity: list[sp.Expr] = field(default_factory=list)
    #: The speeds u in q̇ (Kane's, a System's); what the check compares is their rates u̇.
    speeds: dict[sp.Expr, sp.Expr] = field(default_factory=dict)
    #: Why the source's equations may not be those of L (for the check's message).
    note: str = ""


def from_mechanics(
    system: Any,
    *,
    parameters: Mapping[Any, float] | None = None,
    jit: bool = True,
    name: str | None = None,
    progress: bool | None = None,
) -> SymbolicModel:
    """The compiled model of a ``sympy.physics.mechanics`` system: the same model as
    :func:`lagrangian` builds from its L, forces and constraints.

    - A ``LagrangesMethod``: its Lagrangian and coordinates, its holonomic and nonholonomic
      constraint equations, and the generalized forces of its loads in its inertial frame.
    - A ``KanesMethod`` whose equations come from a Lagrangian: L = T − V of its bodies (their
      ``potential_energy``), the speeds u written in the coordinates' rates q̇ by its kinematic
      differential equations; its loads, configuration constraints and velocity constraints (less
      those that are the configuration constraints' derivatives: varmech holds g(q) = 0 itself).
    - A ``System``: its bodies, loads (with its actuators'), holonomic and nonholonomic
      constraints, the same way; a load constant in its frame acting at a point (uniform
      gravity, ``apply_uniform_gravity``) becomes the potential −F·r of that point from the
      system's fixed point, so that the model is conservative as the physics is.

    Each load (a force at a point, a torque on a frame) becomes the generalized force
    Qᵢ = F·∂v/∂q̇ᵢ (T·∂ω/∂q̇ᵢ for a torque), and the model tracks its work.

    Kinematics that embed a rolling contact, as SymPy's rolling disc does (a point C with
    ``C.set_vel(N, 0)`` and no position in N, the body's centre moving at ω × r by
    ``v2pt_theory(C, N, body)``), would put the rolling into T, which is other dynamics: the
    model gives C its coordinates along N's axes that the rolling moves it along (``C_x``,
    ``C_y``, after the system's own), takes T of the bodies' velocities from them, and holds the
    rolling (the body's point at C at rest) as velocity constraints.

    The model is checked against the source's own equations before it is compiled: at three
    random states (a fixed seed), the accelerations of its Euler–Lagrange equations (with the
    loads' generalized forces and the constraints' forces, solved for q̈ and the multipliers)
    against those of Kane's fr + fr* (the speeds' rates u̇, through the kinematic differential
    equations; with −∂V/∂q of the bodies' ``potential_energy``, which ``KanesMethod`` leaves out
    and varmech takes) or of the ``LagrangesMethod``'s equations (q̈), to 1e-8 of their size.

    Parameters
    ----------
    system : LagrangesMethod, KanesMethod or System
        The model built with ``sympy.physics.mechanics``; its equations need not have been
        formed.
    parameters : mapping of Symbol to float, optional
        The values of its other symbols (masses, lengths, g), as for :func:`lagrangian`.
    jit : bool, default True
        Compile to machine code, as for :func:`lagrangian`.
    name : str, optional
        The model's name (default: the kind of system it came from).
    progress : bool, optional
        A progress bar of the derivation, as for :func:`lagrangian`.

    Returns
    -------
    SymbolicModel
        The compiled model, its coordinates named as the system's (``q1`` for ``q1(t)``).

    Raises
    ------
    TypeError
        ``system`` is none of the three.
    ValueError
        Naming ``system``, with the reason, for what varmech cannot take: a body whose mass or
        inertia changes with t (a variable mass needs its reactive force:
        :class:`MassFlow`), a load of the accelerations, kinematic differential equations that
        do not give u from q̇, a velocity constraint that is not affine in q̇, auxiliary speeds,
        loads without an inertial frame; a model that does not give the source's equations (the
        first differing acceleration, its two values, and where the kinematics embed a
        constraint that is not a rolling contact, how to state it); a source whose equations
        cannot be formed or do not determine the accelerations (no model is taken unchecked);
        and what :func:`lagrangian` refuses.

    See Also
    --------
    lagrangian : The model of an L written directly.

    Examples
    --------
    A pendulum, as sympy.physics.mechanics builds it:

    >>> import sympy as sp
    >>> from sympy.physics import mechanics as me
    >>> import varmech
    >>> theta = me.dynamicsymbols("theta")
    >>> m, l, g = sp.symbols("m l g", positive=True)
    >>> N = me.ReferenceFrame("N")
    >>> O = me.Point("O")
    >>> O.set_vel(N, 0)
    >>> P = O.locatenew("P", l * (sp.sin(theta) * N.x - sp.cos(theta) * N.y))
    >>> P.set_vel(N, P.pos_from(O).dt(N))
    >>> bob = me.Particle("bob", P, m)
    >>> bob.potential_energy = m * g * P.pos_from(O).dot(N.y)
    >>> method = me.LagrangesMethod(me.Lagrangian(N, bob), [theta])
    >>> model = varmech.symbolic.from_mechanics(method, parameters={m: 1.0, l: 1.0, g: 1.0})
    >>> model.coordinates, model.kind_name
    (('theta',), 'separable')
    >>> traj = varmech.integrate(model, [0.5], v0=[0.0], dt=0.01, t_end=10.0)
    >>> varmech.check_conservation(traj).verdict
    'bounded'
    """
    if isinstance(system, me.LagrangesMethod):
        parts, kind = _lagranges(system), "LagrangesMethod"
        source: Any = LagrangeEquations(system)
        outputs = [x.diff(me.dynamicsymbols._t, 2) for x in parts.q]
    elif isinstance(system, (me.KanesMethod, getattr(me, "System", ()))):
        kanes = isinstance(system, me.KanesMethod)
        source = KaneEquations(system if kanes else formed("its KanesMethod", lambda: _kanes_method(system)))
        parts, kind = (_kanes(system), "KanesMethod") if kanes else (_system(system), "System")
        outputs = [parts.speeds[u].diff(me.dynamicsymbols._t) for u in source.u]
    else:
        raise TypeError(
            "system: expected a LagrangesMethod, KanesMethod or System of sympy.physics.mechanics, "
            f"got {type(system).__name__}"
        )
    model = ModelEquations(parts.L, parts.q, parts.force, parts.holonomic, parts.velocity, outputs)
    check(source, model, parameters, note=parts.note)
    return lagrangian(
        parts.L, parts.q, t=me.dynamicsymbols._t, parameters=parameters, force=parts.force,
        constraints=parts.holonomic or None, velocity_constraints=parts.velocity or None, jit=jit,
        name=name or f"sympy.physics.mechanics {kind}", progress=progress,
    )  # fmt: skip


def _lagranges(method: Any) -> _Parts:
    """A LagrangesMethod: its own L, constraints (the nonholonomic ones already in q̇) and loads."""
    q = list(method.q)
    holonomic = list(method._hol_coneqs)
    velocity = list(method.coneqs[len(holonomic) :])
    qdot = _rates(q)
    force = _generalized_forces(method.loads, method.inertial, qdot, {})
    return _Parts(sp.sympify(method._L[0]), q, force, holonomic, _affine(velocity, qdot, {}))


def _kanes(method: Any) -> _Parts:
    """A KanesMethod: L = T − V of its bodies and its loads, in q̇ by its kinematic equations."""
    if len(method._uaux):
        raise ValueError("system: auxiliary speeds (u_auxiliary, for reaction forces) are not taken; build it without them")
    q, u = list(method.q), list(method.u)
    qdot = _rates(q)
    speeds = _speeds(list(method._k_kqdot * sp.Matrix(qdot) + method._k_ku * sp.Matrix(u) + method._f_k), u)
    holonomic = list(method._f_h)
    velocity = list(method._k_nh * sp.Matrix(u) + method._f_nh) if len(method._k_nh) else []
    velocity = _independent(_affine(velocity, qdot, speeds), holonomic, q, qdot)
    L = _lagrangian(method.bodies, method._inertial, q, speeds)
    force = _generalized_forces(method.loads, method._inertial, qdot, speeds)
    parts = _Parts(L, q, force, holonomic, velocity, speeds)
    return _rolling(parts, method.bodies, method.loads, method._inertial, sp.S.Zero)


def _system(system: Any) -> _Parts:
    """A System: as a KanesMethod, its uniform loads as potentials from its fixed point."""
    if len(system.u_aux):
        raise ValueError("system: auxiliary speeds (u_aux, for reaction forces) are not taken; build it without them")
    q, u = list(system.q), list(system.u)
    qdot = _rates(q)
    speeds = _speeds(list(system.kdes), u)
    velocity = _affine(list(system.nonholonomic_constraints), qdot, speeds)
    loads = _system_loads(system)
    potential, loads = _uniform_potential(loads, system.frame, system.fixed_point)
    L = _lagrangian(system.bodies, system.frame, q, speeds) - potential
    force = _generalized_forces(loads, system.frame, qdot, speeds)
    parts = _Parts(L, q, force, list(system.holonomic_constraints), velocity, speeds)
    return _rolling(parts, system.bodies, loads, system.frame, potential)


def _system_loads(system: Any) -> list[Any]:
    """A System's loads and its actuators'."""
    return [*system.loads, *(load for actuator in system.actuators for load in actuator.to_loads())]


def _kanes_method(system: Any) -> Any:
    """The KanesMethod of a System, as its ``form_eoms`` builds it (the System untouched)."""
    loads = _system_loads(system)
    return me.KanesMethod(
        system.frame, q_ind=system.q_ind, u_ind=system.u_ind, kd_eqs=system.kdes, q_dependent=system.q_dep,
        u_dependent=system.u_dep, configuration_constraints=system.holonomic_constraints,
        velocity_constraints=system.velocity_constraints, forcelist=loads or None, bodies=system.bodies,
    )  # fmt: skip


def _rolling(parts: _Parts, bodies: Sequence[Any], loads: Sequence[Any] | None, frame: Any, potential: sp.Expr) -> _Parts:
    """``parts``, or where the bodies' kinematics embed a rolling contact, the constrained system:
    the contact's coordinates, T of the bodies' velocities from them, the loads' generalized
    forces in them, and the rolling's velocity constraints (``potential``: the loads taken as
    one). Where they embed a constraint of another kind, ``parts`` with a note for the check."""
    contact, note = _contact.find(bodies, frame, parts.q, parts.speeds)
    if contact is None:
        return replace(parts, note=note)
    q = [*parts.q, *contact.coordinates]
    qdot = _rates(q)
    velocity = _contact.velocity(contact, frame)
    L = _lagrangian(bodies, frame, q, parts.speeds, velocity) - potential
    force = _generalized_forces(loads or [], frame, qdot, parts.speeds, velocity)
    rolling = [x - w for x, w in zip(_rates(contact.coordinates), contact.rates)]
    note = (
        f" (its kinematics embed the rolling of body {contact.body.name} on {contact.point.name}, whose velocity is set to "
        f"zero: from_mechanics gave {contact.point.name} the coordinates {', '.join(x.func.__name__ for x in contact.coordinates)} "
        "and the rolling as velocity constraints)"
    )
    return _Parts(L, q, force, parts.holonomic, [*parts.velocity, *rolling], parts.speeds, note)


def _speeds(kinematics: Sequence[sp.Expr], u: Sequence[sp.Expr]) -> dict[sp.Expr, sp.Expr]:
    """The speeds u in the coordinates' rates q̇, from kinematic differential equations linear
    in both (f(q, q̇, u) = 0); ValueError naming ``system`` where they do not determine u."""
    if not u:
        return {}
    equations = sp.Matrix(kinematics)
    coefficients = equations.jacobian(list(u))
    if coefficients.shape[0] != coefficients.shape[1] or sp.simplify(coefficients.det()) == 0:
        raise ValueError(
            "system: its kinematic differential equations do not determine the speeds u from the rates q̇ "
            "(their coefficients of u are not an invertible matrix); varmech integrates L(q, q̇, t)"
        )
    rest = equations.xreplace(dict.fromkeys(u, 0))
    solved = coefficients.LUsolve(-rest)
    return {speed: sp.cancel(value) for speed, value in zip(u, solved)}


def _lagrangian(
    bodies: Sequence[Any], frame: Any, coordinates: Sequence[sp.Expr], speeds: Mapping[sp.Expr, sp.Expr],
    velocity: Callable[[Any], Any] | None = None,
) -> sp.Expr:
    """T − V of ``bodies`` in ``frame`` (their ``potential_energy``), written in q̇, their centres'
    velocities given by ``velocity`` if given (else their own); ValueError naming ``system`` for
    a body varmech cannot take."""
    if frame is None:
        raise ValueError("system: it has no inertial frame, in which the bodies' kinetic energy is taken")
    t = me.dynamicsymbols._t
    total = sp.S.Zero
    for body in bodies:
        if not isinstance(body, (me.Particle, me.RigidBody)):
            raise ValueError(f"system: {body!r} is a {type(body).__name__}, not a Particle or a RigidBody")
        # A mass of t or of the state changes; an inertia may hold the coordinates (written in
        # another frame than the body's), not t or the speeds.
        changing = [body.mass] if sp.sympify(body.mass).has(t) else []
        if isinstance(body, me.RigidBody):
            still = dict.fromkeys(coordinates, sp.S.Zero)
            changing += [x for x in body.central_inertia.to_matrix(body.frame) if sp.sympify(x).xreplace(still).has(t)][:1]
        if changing:
            raise ValueError(
                f"system: body {body.name}'s mass or inertia changes with t ({changing[0]}); a body whose mass changes "
                "needs the reactive force of the matter it gains or loses: give it as varmech.symbolic.lagrangian(..., "
                "mass_flow=varmech.symbolic.MassFlow(...))"
            )
        if velocity is None:
            total += body.kinetic_energy(frame)
        else:
            v, omega = velocity(body.masscenter), body.frame.ang_vel_in(frame) if isinstance(body, me.RigidBody) else me.Vector(0)
            total += body.mass * v.dot(v) / 2 + (omega.dot(body.central_inertia.dot(omega)) / 2 if omega != 0 else 0)
        total -= sp.sympify(body.potential_energy)
    return total.xreplace(speeds)


def _uniform_potential(loads: Sequence[Any], frame: Any, origin: Any) -> tuple[sp.Expr, list[Any]]:
    """The potential −F·r of each force constant in ``frame`` at a point r from ``origin``, and
    the loads left."""
    potential, left = sp.S.Zero, []
    for load in loads:
        where, vector = load[0], load[1]
        components = [sp.sympify(c) for c in vector.to_matrix(frame)] if isinstance(where, me.Point) else []
        if components and not any(me.find_dynamicsymbols(c) or c.has(me.dynamicsymbols._t) for c in components):
            try:
                potential -= vector.dot(where.pos_from(origin))
                continue
            except ValueError:
                pass  # no position from the origin (a contact's body): its force is a load
        left.append(load)
    return potential, left


def _generalized_forces(
    loads: Sequence[Any], frame: Any, qdot: Sequence[sp.Expr], speeds: Mapping[sp.Expr, sp.Expr],
    velocity: Callable[[Any], Any] | None = None,
) -> list[sp.Expr] | None:
    """Qᵢ = Σ F·∂v/∂q̇ᵢ (+ T·∂ω/∂q̇ᵢ) of ``loads`` in ``frame``, v and ω in q̇ (a point's v given by
    ``velocity`` if given); None without loads."""
    if not loads:
        return None
    if frame is None:
        raise ValueError("system: it has loads but no inertial frame, in which their generalized forces are taken")
    t = me.dynamicsymbols._t
    accelerations = {x.diff(t) for x in qdot} | {s.diff(t) for s in speeds}
    force = [sp.S.Zero] * len(qdot)
    for load in loads:
        where, vector = load[0], load[1]
        held = me.find_dynamicsymbols(vector, reference_frame=frame) if vector != 0 else set()
        if held & accelerations:
            raise ValueError(
                f"system: the load on {where} depends on the accelerations; a force linear in them is added mass "
                "(varmech.symbolic.lagrangian(..., added_mass=A))"
            )
        if isinstance(where, me.Point):
            rate_of = where.vel(frame) if velocity is None else velocity(where)
        else:
            rate_of = where.ang_vel_in(frame)
        rate_of = rate_of.xreplace(speeds) if speeds else rate_of
        for i, rate in enumerate(qdot):
            force[i] += vector.dot(rate_of.diff(rate, frame)).xreplace(speeds)
    return force


def _affine(constraints: Sequence[sp.Expr], qdot: Sequence[sp.Expr], speeds: Mapping[sp.Expr, sp.Expr]) -> list[sp.Expr]:
    """Velocity constraints written in q̇ (the speeds replaced by ``speeds``), each affine in q̇ as
    varmech takes them (A(q)q̇ + b(q) = 0); ValueError naming ``system`` otherwise."""
    written = [sp.sympify(c).xreplace(speeds) for c in constraints]
    for c in written:
        if any(sp.diff(c, a, b) != 0 for a in qdot for b in qdot):
            raise ValueError(f"system: the velocity constraint {c} = 0 is not affine in the rates q̇ (A(q)q̇ + b(q) = 0)")
    return written


def _independent(velocity: list[sp.Expr], holonomic: Sequence[sp.Expr], q: Sequence[sp.Expr], qdot: Sequence[sp.Expr]) -> list[sp.Expr]:
    """The velocity constraints that are not the holonomic constraints' derivatives: those whose
    rows of ∂/∂q̇ add to the rank of [∂g/∂q; rows kept], at a point of random values (generic
    with probability 1)."""
    if not holonomic or not velocity:
        return velocity
    free = set().union(*(sp.sympify(c).free_symbols for c in [*velocity, *holonomic])) - {me.dynamicsymbols._t}
    state = [*q, *free]
    rng = random.Random(0)
    at = {s: sp.Float(rng.uniform(0.3, 1.7)) for s in state}
    zero = lambda x: abs(x) < 1e-9  # noqa: E731 - round-off of the random point's arithmetic
    rows = sp.Matrix(list(holonomic)).jacobian(list(q)).xreplace(at)
    rank = rows.rank(iszerofunc=zero)
    kept: list[sp.Expr] = []
    for c in velocity:
        stacked = rows.col_join(sp.Matrix([c]).jacobian(list(qdot)).xreplace(at))
        if stacked.rank(iszerofunc=zero) > rank:
            rows, rank, kept = stacked, rank + 1, [*kept, c]
    return kept
