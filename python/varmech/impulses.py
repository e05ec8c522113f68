"""Impulsive forces and sudden constraints (Byerly 1916, ch. III): the state just after a blow,
and just after constraints engage.

A blow changes the generalized momenta at once and the positions not at all (Byerly, Arts.
26–28):

    Δ(∂L/∂q̇ᵣ) = P_r,   P_r = I · ∂x/∂qᵣ,

P_r the *component of impulse* on qᵣ of an impulse I applied at the point x(q). For
L = ½q̇ᵀM(q)q̇ + … this is M Δq̇ = Jᵀ I, J = ∂x/∂q. :func:`impulse_response` gives the momenta
and velocities after an :class:`Impulse` and the change of kinetic energy, which answers
Byerly's "find the initial motion" problems.

Constraints A(q)q̇ = 0 that engage suddenly (a body set down, a rolling contact that grips;
holonomic g(q) = 0 with A = ∂g/∂q, or velocity constraints given as A(q)) act by an impulse
Aᵀλ: Lagrange's impulsive equations Δp = Aᵀλ with A q̇⁺ = 0, whose solution is the M-orthogonal
projection of the velocity (the one :func:`varmech.project` uses). :func:`engage` gives the
state after, and the kinetic energy lost, which equals Carnot's ½Δq̇ᵀMΔq̇ for any such
perfectly inelastic engagement.

The metric M⁻¹ is the model's inverse Legendre transform: q̇(q, p) = M⁻¹(p − a(q)) for a
Lagrangian quadratic in q̇ (kinetic energy, gyroscopic terms); its columns are differences
q̇(q, eᵢ) − q̇(q, 0), exact for such Lagrangians.

This module declares; the core computes (``varmech::integrators::impulsive``, and the blows of
a run's impulses, ``jumps/schedule.rs``), with the same components of impulse in both.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from ._util import floats, vector
from ._warnings import DerivativeWarning
from .model import Model

#: The public API; the rest serves :func:`varmech.integrate`.
__all__ = ["Engagement", "Impulse", "ImpulseResponse", "engage", "impulse_response"]


@dataclass(frozen=True)
class Impulse:
    """A blow: the components of impulse P_r = I · ∂x/∂qᵣ it gives each generalized coordinate.

    Give either the components P themselves (``generalized``), or an impulse vector
    ``impulse`` applied at the point ``point(q)``, with P = (∂x/∂q)ᵀ I.

    Attributes
    ----------
    generalized : array_like or callable, optional
        P as an array (n,), or a function of q returning one.
    point : callable, optional
        x(q), the point struck, an array (d,).
    impulse : array_like, optional
        The impulse vector I (d,) applied at ``point``.
    jacobian : callable, optional
        ∂x/∂q(q), the (d, n) matrix; default central differences, with a warning.
    t : float, default 0.0
        When it acts (for the runs that take impulses, ``integrate(..., impulses=[...])``).

    See Also
    --------
    impulse_response : The state just after the blow.

    References
    ----------
    .. [1] W. E. Byerly, *An Introduction to the Use of Generalized Coordinates in Mechanics
       and Physics*, Ginn (1916), chapter III.

    Examples
    --------
    >>> import numpy as np
    >>> end = Impulse(point=lambda q: q[:2] + np.array([np.cos(q[2]), np.sin(q[2])]),
    ...               jacobian=lambda q: np.array([[1.0, 0.0, -np.sin(q[2])], [0.0, 1.0, np.cos(q[2])]]),
    ...               impulse=[0.0, 1.0])
    >>> end.components(np.zeros(3)).tolist()   # a rod's end struck across it: P = (0, 1, 1)
    [0.0, 1.0, 1.0]
    """

    generalized: ArrayLike | Callable[[np.ndarray], ArrayLike] | None = None
    point: Callable[[np.ndarray], ArrayLike] | None = None
    impulse: ArrayLike | None = None
    jacobian: Callable[[np.ndarray], ArrayLike] | None = None
    t: float = 0.0

    def components(self, q: np.ndarray) -> np.ndarray:
        """The components of impulse P_r = I · ∂x/∂qᵣ at the configuration q.

        Parameters
        ----------
        q : numpy.ndarray
            The configuration, shape (n,).

        Returns
        -------
        numpy.ndarray
            P, shape (n,).

        Raises
        ------
        ValueError
            Not exactly one of ``generalized`` and ``point``; a ``point`` without ``impulse``;
            ``generalized`` not n finite numbers; ``point`` not returning d numbers for an
            impulse of d; or ``jacobian`` not returning shape (d, n).

        Examples
        --------
        Components given as a function of q, evaluated where the blow strikes:

        >>> import numpy as np
        >>> Impulse(generalized=lambda q: [np.cos(q[1]), 0.0]).components(np.array([0.0, np.pi])).tolist()
        [-1.0, 0.0]
        """
        kind, payload = self._spec()
        return _core.impulse_components(kind, payload, np.ascontiguousarray(q, dtype=float))

    def _spec(self) -> tuple[str, Any]:
        """The binding's kind and payload of this blow, checked (a ValueError for a malformed
        one; the core checks the number of components); a point without its Jacobian warns
        that central differences are used."""
        if (self.generalized is None) == (self.point is None):
            raise ValueError("impulse: give exactly one of generalized= and point= (with impulse=)")
        if self.generalized is not None:
            if callable(self.generalized):
                return "function", self.generalized
            return "generalized", floats("generalized", self.generalized).reshape(-1).tolist()
        if self.impulse is None:
            raise ValueError("impulse: a point struck needs the impulse vector, impulse=")
        if self.jacobian is None:
            warnings.warn("impulse: no jacobian of the point given; central differences are used", DerivativeWarning, stacklevel=4)
        blow = np.asarray(self.impulse, dtype=float).reshape(-1).tolist()
        return "point", (self.point, self.jacobian, blow)


@dataclass(frozen=True)
class ImpulseResponse:
    """The state just after a blow, and the change of kinetic energy.

    The record :func:`impulse_response` returns.

    Attributes
    ----------
    p : numpy.ndarray
        The momenta just after, p⁺ = p⁻ + P, shape (n,).
    v : numpy.ndarray
        The velocities just after, q̇(q, p⁺), shape (n,).
    kinetic_change : float
        T⁺ − T⁻ (the energy the blow gives; negative if it takes some).
    p_before : numpy.ndarray
        The momenta just before, shape (n,).
    v_before : numpy.ndarray
        The velocities just before, shape (n,).

    Examples
    --------
    A free particle of unit mass at rest, struck by a unit impulse along x:

    >>> import numpy as np, varmech
    >>> free = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2))
    >>> after = varmech.impulse_response(free, [0.0, 0.0], [0.0, 0.0], varmech.Impulse(generalized=[1.0, 0.0]))
    >>> after.v.tolist(), after.v_before.tolist(), after.kinetic_change
    ([1.0, 0.0], [0.0, 0.0], 0.5)
    """

    p: np.ndarray
    v: np.ndarray
    kinetic_change: float
    p_before: np.ndarray
    v_before: np.ndarray


@dataclass(frozen=True)
class Engagement:
    """The state just after constraints engage, and the kinetic energy lost.

    The record :func:`engage` returns.

    Attributes
    ----------
    p : numpy.ndarray
        The momenta just after, p⁺ = p⁻ + Aᵀλ, shape (n,).
    v : numpy.ndarray
        The velocities just after, with A q̇⁺ = 0, shape (n,).
    multipliers : numpy.ndarray
        λ, the multipliers of the impulse Aᵀλ, shape (m,).
    energy_lost : float
        T⁻ − T⁺.
    carnot : float
        Carnot's ½Δq̇ᵀMΔq̇, which ``energy_lost`` equals for a perfectly inelastic engagement.

    Examples
    --------
    >>> import numpy as np, varmech
    >>> free = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2))
    >>> after = varmech.engage(free, [0.0, 0.0], [1.0, 1.0], velocity_constraints=lambda q: [[0.0, 1.0]])
    >>> after.p.tolist(), after.multipliers.tolist(), after.energy_lost
    ([1.0, 0.0], [-1.0], 0.5)
    """

    p: np.ndarray
    v: np.ndarray
    multipliers: np.ndarray
    energy_lost: float
    carnot: float


def _state(model: Model, q: ArrayLike, p: ArrayLike | None, v: ArrayLike | None, t: float) -> tuple[np.ndarray, np.ndarray]:
    n = model.dim
    qq = vector("q", q, n)
    if (p is None) == (v is None):
        raise ValueError("p, v: give exactly one of the momenta p and the velocities v")
    if p is not None:
        return qq, vector("p", p, n)
    assert v is not None
    return qq, model.momentum(qq, vector("v", v, n), t)


def inverse_mass(model: Model, q: ArrayLike, t: float = 0.0) -> np.ndarray:
    """M(q)⁻¹, the metric of the inverse Legendre transform q̇ = M⁻¹(p − a(q)): columns
    q̇(q, eᵢ) − q̇(q, 0), exact for a Lagrangian quadratic in q̇.

    Parameters
    ----------
    model : Model
        A varmech model.
    q : array_like
        The configuration, shape (n,).
    t : float, default 0.0
        The time.

    Returns
    -------
    numpy.ndarray
        M(q)⁻¹, shape (n, n).

    Raises
    ------
    ValueError
        ``q`` not n finite numbers.

    Examples
    --------
    >>> import numpy as np, varmech
    >>> from varmech.impulses import inverse_mass
    >>> rod = varmech.MechanicalSystem(3, lambda q: 0.0, lambda q: np.zeros(3), mass=[1.0, 1.0, 1.0 / 3.0])
    >>> np.diag(inverse_mass(rod, np.zeros(3))).round(12)
    array([1., 1., 3.])
    """
    return _core.inverse_mass(model._core, vector("q", q, model.dim), float(t))


def impulse_response(
    model: Model,
    q: ArrayLike,
    p: ArrayLike | None = None,
    impulse: Impulse | None = None,
    *,
    v: ArrayLike | None = None,
    t: float = 0.0,
) -> ImpulseResponse:
    """The state just after ``impulse`` strikes ``model`` at (q, p) (or the velocities v):
    p⁺ = p + P(q), q̇⁺ = q̇(q, p⁺), and the change of kinetic energy.

    The positions do not change during a blow; the momenta jump by the components of impulse,
    Δ(∂L/∂q̇ᵣ) = P_r (Byerly, Arts. 26–28 [1]_).

    Parameters
    ----------
    model : Model
        A varmech model.
    q : array_like
        The configuration, shape (n,).
    p : array_like, optional
        The momenta just before (give ``p`` or ``v``).
    impulse : Impulse
        The blow.
    v : array_like, optional
        The velocities just before, instead of ``p``.
    t : float, default 0.0
        The time (for a time-dependent Lagrangian).

    Returns
    -------
    ImpulseResponse
        The momenta and velocities after and before, and the change of kinetic energy.

    Raises
    ------
    TypeError
        ``impulse`` is not an :class:`Impulse`.
    ValueError
        Not exactly one of ``p`` and ``v``; ``q``, ``p`` or ``v`` not n finite numbers; or the
        impulse malformed (see :meth:`Impulse.components`).

    See Also
    --------
    engage : Constraints that engage suddenly.

    References
    ----------
    .. [1] W. E. Byerly, *An Introduction to the Use of Generalized Coordinates in Mechanics
       and Physics*, Ginn (1916), chapter III.

    Examples
    --------
    A uniform rod of mass 1 and length 2 (k² = 1/3) on a smooth table, struck across one end by a
    unit impulse: its centre moves off at 1, it turns at ω = 3P/(ma) = 3 (Byerly, Art. 27).

    >>> import numpy as np, varmech
    >>> rod = varmech.MechanicalSystem(3, lambda q: 0.0, lambda q: np.zeros(3), mass=[1.0, 1.0, 1.0 / 3.0])
    >>> end = varmech.Impulse(point=lambda q: q[:2] + np.array([np.cos(q[2]), np.sin(q[2])]),
    ...                       jacobian=lambda q: np.array([[1.0, 0.0, -np.sin(q[2])], [0.0, 1.0, np.cos(q[2])]]),
    ...                       impulse=[0.0, 1.0])
    >>> after = varmech.impulse_response(rod, np.zeros(3), np.zeros(3), end)
    >>> after.v.round(12).tolist(), round(after.kinetic_change, 12)
    ([0.0, 1.0, 3.0], 2.0)
    """
    if not isinstance(impulse, Impulse):
        raise TypeError(f"impulse: expected a varmech.Impulse, got {type(impulse).__name__}")
    qq, before = _state(model, q, p, v, t)
    after, v_after, v_before, change = _core.impulse_response(model._core, float(t), qq, before, *impulse._spec())
    return ImpulseResponse(after, v_after, change, before, v_before)


def engage(
    model: Model,
    q: ArrayLike,
    p: ArrayLike | None = None,
    *,
    v: ArrayLike | None = None,
    constraints: Callable[[np.ndarray], ArrayLike] | None = None,
    jacobian: Callable[[np.ndarray], ArrayLike] | None = None,
    velocity_constraints: Callable[[np.ndarray], ArrayLike] | None = None,
    t: float = 0.0,
) -> Engagement:
    """The state just after constraints engage impulsively at (q, p): holonomic g(q) = 0
    (``constraints``, with ``jacobian`` ∂g/∂q or central differences), or velocity constraints
    A(q)q̇ = 0 (``velocity_constraints`` giving A, for rolling), by Lagrange's impulsive equations
    Δp = Aᵀλ, A q̇⁺ = 0: λ = −(A M⁻¹ Aᵀ)⁻¹ A q̇⁻. Reports the kinetic energy lost and Carnot's
    ½Δq̇ᵀMΔq̇.

    Parameters
    ----------
    model : Model
        A varmech model whose Lagrangian is quadratic in q̇ (M⁻¹ from its inverse Legendre
        transform).
    q : array_like
        The configuration, shape (n,).
    p : array_like, optional
        The momenta just before (give ``p`` or ``v``).
    v : array_like, optional
        The velocities just before, instead of ``p``.
    constraints : callable, optional
        g(q) → (m,), holonomic constraints g(q) = 0 (give this or ``velocity_constraints``).
    jacobian : callable, optional
        ∂g/∂q(q) → (m, n); default central differences of ``constraints``, with a warning.
    velocity_constraints : callable, optional
        A(q) → (m, n), velocity constraints A(q)q̇ = 0.
    t : float, default 0.0
        The time (for a time-dependent Lagrangian).

    Returns
    -------
    Engagement
        The momenta and velocities after, λ, the kinetic energy lost and Carnot's term.

    Raises
    ------
    ValueError
        Not exactly one of ``p`` and ``v``, or of ``constraints`` and ``velocity_constraints``;
        ``q``, ``p`` or ``v`` not n finite numbers; A not a matrix with n columns; or dependent
        constraints (A M⁻¹ Aᵀ singular).

    See Also
    --------
    varmech.project : The same M-orthogonal projection of the momenta.
    impulse_response : A blow.

    References
    ----------
    .. [1] W. E. Byerly, *An Introduction to the Use of Generalized Coordinates in Mechanics
       and Physics*, Ginn (1916), chapter III.

    Examples
    --------
    A particle moving at (1, 1) meets the constraint y = 0 (a smooth floor that grips): the normal
    velocity is lost, and with it ½ of kinetic energy, Carnot's ½·1².

    >>> import numpy as np, varmech
    >>> free = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2))
    >>> after = varmech.engage(free, [0.0, 0.0], [1.0, 1.0], constraints=lambda q: [q[1]], jacobian=lambda q: [[0.0, 1.0]])
    >>> after.v.tolist(), after.energy_lost, after.carnot
    ([1.0, 0.0], 0.5, 0.5)
    """
    qq, before = _state(model, q, p, v, t)
    n = model.dim
    if (constraints is None) == (velocity_constraints is None):
        raise ValueError("constraints, velocity_constraints: give exactly one")
    if velocity_constraints is not None:
        a = np.atleast_2d(np.asarray(velocity_constraints(qq.copy()), dtype=float))
        name = "velocity_constraints"
    else:
        assert constraints is not None
        if jacobian is not None:
            a = np.atleast_2d(np.asarray(jacobian(qq.copy()), dtype=float))
        else:
            warnings.warn("engage: no jacobian of the constraints given; central differences are used", DerivativeWarning, stacklevel=2)
            a = _core.central_differences(constraints, qq, "constraints")
        name = "jacobian"
    if a.ndim != 2 or a.shape[1] != n:
        raise ValueError(f"{name}: expected a matrix with {n} columns, got shape {a.shape}")
    after, v_after, multipliers, lost, carnot = _core.engage(model._core, float(t), qq, before, np.ascontiguousarray(a), name)
    return Engagement(after, v_after, multipliers, lost, carnot)


Spec = tuple[float, str, Any]


def specs(impulses: Sequence[Impulse], t0: float, t_end: float) -> list[Spec]:
    """The binding's tuples of ``impulses``, each an :class:`Impulse` (TypeError naming
    ``impulses[i]``) at a time in the run's span [t0, t_end] (ValueError naming ``impulses``); the
    core checks each against the model."""
    out: list[Spec] = []
    for i, imp in enumerate(impulses):
        if not isinstance(imp, Impulse):
            raise TypeError(f"impulses[{i}]: expected a varmech.Impulse, got {type(imp).__name__}")
        if not (np.isfinite(imp.t) and min(t0, t_end) <= imp.t <= max(t0, t_end)):
            raise ValueError(f"impulses: a time {imp.t} outside the run's span [{t0}, {t_end}]")
        out.append((float(imp.t), *imp._spec()))
    return out


def stored(impulses: Sequence[Impulse | float]) -> str:
    """The impulses as a file stores them, JSON: each one's time and its components given as
    numbers, or null for one given by Python functions (no code is stored)."""
    rows = []
    for imp in impulses:
        native = isinstance(imp, Impulse) and imp.generalized is not None and not callable(imp.generalized)
        components = np.asarray(imp.generalized, dtype=float).reshape(-1).tolist() if native else None  # type: ignore[union-attr]
        rows.append([float(imp if isinstance(imp, float) else imp.t), components])
    return json.dumps(rows)


def restored(text: str) -> tuple[Impulse | float, ...]:
    """The impulses a file stored (:func:`stored`), those given by Python functions as their
    times; ValueError naming ``path`` for a record that is not one."""
    try:
        return tuple(float(t) if p is None else Impulse(generalized=[float(x) for x in p], t=float(t)) for t, p in json.loads(text))
    except (ValueError, TypeError) as e:
        raise ValueError(f"path: its impulses are not a stored impulse list ({e})") from None


def going_on(
    stored: Sequence[Impulse | float], given: Sequence[Impulse] | None, t: float
) -> tuple[tuple[Impulse, ...], list[Spec]]:
    """The impulses a run continued from time ``t`` goes on with, and their binding's tuples:
    its own, or ``given`` in their place (the same times); a ValueError naming ``impulses`` for
    one still to come that was given by Python functions, loaded from a file as its time, and
    not given again."""
    if given is None:
        unknown = [imp for imp in stored if isinstance(imp, float) and imp > t]
        if unknown:
            raise ValueError(
                f"impulses: the run's impulses at t = {', '.join(map(str, unknown))} were given by Python functions, which"
                " its file does not store; pass them again: varmech.resume(path, impulses=[...])"
            )
        own = tuple(imp for imp in stored if isinstance(imp, Impulse))
        return own, specs(own, -np.inf, np.inf)
    tuples = specs(given, -np.inf, np.inf)
    times = sorted(imp if isinstance(imp, float) else imp.t for imp in stored)
    if sorted(imp.t for imp in given) != times:
        raise ValueError(f"impulses: the run has impulses at t = {times}, not at {sorted(imp.t for imp in given)}")
    return tuple(given), tuples
