"""Variable mass: a body whose mass m(q, t) changes as matter leaves it or joins it at a velocity
u, and the reactive generalized force of Meshchersky's equation d(mv)/dt = F + ṁu."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import sympy as sp

from ._inputs import Variables, expressions
from ._lower import check_compilable

__all__ = ["MassFlow"]


@dataclass(frozen=True)
class MassFlow:
    """A body of variable mass: its mass, where it is, and the velocity of the matter it ejects
    or accretes (Meshchersky; the source's "reactive forces produced by ejected burnt fuel").

    The body is a point, or a body moving as one, at r(q) with velocity v = J q̇, J = ∂r/∂q, and
    its kinetic energy ½m|v|² is in L. Matter leaves it (ṁ < 0: a rocket's exhaust) or joins it
    (ṁ > 0: a snowplough's snow, a chain's links picked up from a heap) with the absolute
    velocity u, so that its momentum obeys d(mv)/dt = F + ṁu. In L's coordinates that is the
    generalized force

    Q_r = ṁ Jᵀu − ½|J q̇|² ∂m/∂q,   ṁ = ∂m/∂t + (∂m/∂q)·q̇,

    which the model adds to its forces: the second term takes back the part of ∂L/∂q that
    differentiates the mass in ½m|v|² (no force: matter changes hands, it is not pushed).

    Attributes
    ----------
    mass
        m(q, t): a SymPy expression of the coordinates and t (a rocket's m₀ − kt, a chain's ρx);
        it must stay positive during a run, which stops with a :class:`~varmech.VarmechError`
        at the step where it does not.
    velocity
        u, the absolute velocity of the matter ejected or accreted, one component per
        component of ``at`` (a scalar for one): an expression of q, q̇ and t (a rocket's
        exhaust ẋ − c for an exhaust speed c relative to the rocket; 0 for matter at rest).
    at
        The body's position r(q), a list of expressions of the coordinates (default: the
        coordinates themselves, J = I).

    Examples
    --------
    A rocket rising in uniform gravity, burning k = 0.4 of its mass m₀ = 10 a unit of time with
    an exhaust speed c = 400 relative to it:

    >>> import sympy as sp
    >>> import varmech
    >>> x, w, t = sp.symbols("x w t")
    >>> m = 10 - 0.4 * t
    >>> rocket = varmech.symbolic.lagrangian(m * w**2 / 2 - m * 9.81 * x, [x], [w], t=t,
    ...                                      mass_flow=varmech.symbolic.MassFlow(m, w - 400))
    >>> traj = varmech.integrate(rocket, [0.0], v0=[0.0], dt=0.01, t_end=10.0)
    >>> round(float(traj.v[-1, 0]), 2)   # Tsiolkovsky: c ln(m₀/m) − gt = 400 ln(10/6) − 98.1
    106.23
    """

    mass: Any
    velocity: Any
    at: Any = None


def reactive_force(flows: Any, variables: Variables) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """The reactive generalized force Σ Q_r of ``flows`` (a :class:`MassFlow` or a list of
    them) and their masses, in the plain symbols; TypeError or ValueError naming the argument
    ``mass_flow`` and the part of it at fault."""
    if isinstance(flows, MassFlow):
        flows = [flows]
    if not isinstance(flows, Sequence) or not flows or not all(isinstance(f, MassFlow) for f in flows):
        raise TypeError(f"mass_flow: expected a varmech.symbolic.MassFlow or a list of them, got {flows!r}")
    q, v, t = list(variables.q), list(variables.v), variables.t
    total = [sp.S.Zero] * len(q)
    masses = []
    for i, flow in enumerate(flows):
        name = f"mass_flow[{i}]"
        m = variables.plain(flow.mass, f"{name}.mass")
        r = list(q) if flow.at is None else expressions(flow.at, f"{name}.at", variables)
        u = expressions(flow.velocity, f"{name}.velocity", variables)
        for what, x in [("mass", m), *((f"at[{a}]", x) for a, x in enumerate(r)), *((f"velocity[{a}]", x) for a, x in enumerate(u))]:
            check_compilable(x, f"{name}.{what}")
        if m.has(*v):
            raise ValueError(f"{name}.mass: must depend on the coordinates and t alone, got {m}")
        if any(x.has(*v, t) for x in r):
            raise ValueError(f"{name}.at: must depend on the coordinates alone (a point r(q)), got {r}")
        if len(u) != len(r):
            raise ValueError(
                f"{name}.velocity: needs one component per component of the body's position ({len(r)}), got {len(u)}: {u}"
            )
        jacobian = sp.Matrix(r).jacobian(q)
        speed2 = sum(((jacobian * sp.Matrix(v))[a] ** 2 for a in range(len(r))), sp.S.Zero)
        rate = sp.diff(m, t) + sum((sp.diff(m, s) * w for s, w in zip(q, v)), sp.S.Zero)
        pushed = jacobian.T * sp.Matrix(u)
        total = [f + rate * pushed[j] - speed2 * sp.diff(m, q[j]) / 2 for j, f in enumerate(total)]
        masses.append(m)
    return total, masses
