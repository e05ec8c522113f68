"""Impacts with unilateral constraints φ(q) ≥ 0 (walls, floors, billiard tables).

A run with ``contacts`` watches each φ as an event (g = φ(q), falling through 0, terminal). The
step that crosses a surface is split at the contact: the method's own partial step of size αh
from (qₙ, pₙ) to the contact configuration q̃ on φ = 0 (α found to round-off by the event
search), the jump p⁺ = p⁻ + λ∇φ(q̃), and the method's partial step of size (1 − α)h to the grid
time tₙ₊₁. The contact's ``law`` fixes λ:

- ``"variational"`` (the default; kick–drift methods, ``MethodInfo.splitting``, and the implicit
  two-point rules ``midpoint`` and ``trapezoid``): the variational collision integrator of
  Fetecau, Marsden, Ortiz & West (2003), :func:`variational_jump`. The discrete energy E_d = −∂L_d/∂τ is
  the same on both sides of the impact, which makes the action of the two partial steps
  stationary in the contact point and the fraction, so **the step across an impact is
  symplectic** (measured defect ≤ 1e-9, round-off of the differences, for every kick–drift
  method, and for midpoint and trapezoid on separable and on natural systems M(q)). H itself
  moves by O(h²) at an impact and stays bounded over many. The two-point rules replay the
  core's own partial steps (:class:`TwoPoint`) from the start of the crossing step, which each
  located crossing carries; they need a conservative, autonomous, unconstrained model (the
  energy balance is E_d's alone). Their E_d takes the velocities from the momenta, so an impact
  at a fraction α = 1e-9 or 1 − 1e-9 of a step keeps H's jump to round-off (position differences
  would lose all but τ|v|/|q| of the digits).
- ``"reflect"`` (any method): the exact reflection in the metric of the kinetic energy,

      p⁺ = p⁻ − (1 + e) (∇φ·q̇⁻) / (∇φᵀM⁻¹∇φ) ∇φ,

  which conserves H at the impact (round-off over 10⁴ bounces of a ball, where Verlet is exact
  between them) but is symplectic across it only to the method's order (verlet's defect
  ‖ΨᵀJΨ − J‖ falls as h²: 8.4e-3, 1.9e-3, 4.3e-4 at h = 0.1, 0.05, 0.025).

Both keep the method's order away from grazing. For e < 1 there is no symplectic structure to
keep, and both apply Newton's law at q̃: the normal velocity ∇φ·q̇ goes to −e times itself (the
variational law's elastic limit differs from it by O(h²)). The impacts are the contacts'
occurrences in ``traj.events`` (time, contact configuration, momenta just before), and the saved
states hold the state just before and just after each impact (one time, two rows).

After a jump the rest of the step is checked against every contact: one crossed before its end
(a corner, or a ball's next bounce within the step) is located on that piece (:func:`crossing`)
and taken in turn (:func:`through`), up to :data:`MAX_IMPACTS` in one step. Under the variational
law each jump keeps E_d equal across it, piece by piece, so the step stays symplectic. A body
that cannot leave a surface (a resting contact: e = 0 under a force pressing it on, or a ball
whose bounces accumulate) raises :class:`ContactError` with the step, the time and the run up to
that step. A piece is checked at its end only: a contact entered and left again within one piece
is missed, so steps must be short against the time a body spends beyond a curved surface's
chord.
"""

from __future__ import annotations

import warnings
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from . import events as _events
from . import surfaces as _surfaces
from .impulses import Joined, Pieces, _velocity
from .methods import method_info
from .model import Model
from .trajectory import take_partial

#: The public API; the rest serves :func:`varmech.integrate`.
__all__ = ["Contact", "ContactError"]


@dataclass(frozen=True)
class Contact:
    """A unilateral constraint φ(q) ≥ 0 with its gradient ∇φ(q) and the coefficient of
    restitution ``restitution`` e ∈ [0, 1] (1: elastic).

    :func:`varmech.integrate` (``contacts=``) splits each step that crosses φ = 0 at the
    contact configuration and applies the impact there: p⁺ = p⁻ + λ∇φ(q), with λ such that the
    normal velocity ∇φ·q̇ goes to −e times itself (the exact reflection), or, for elastic
    contacts under ``law="variational"``, such that the discrete energy is continuous (the
    variational collision integrator of Fetecau, Marsden, Ortiz & West [1]_).

    Attributes
    ----------
    phi : callable
        φ(q) -> float, positive on the allowed side.
    gradient : callable
        ∇φ(q) -> array_like, shape (n,).
    restitution : float, default 1.0
        The coefficient of restitution e ∈ [0, 1].
    name : str, default "contact"
        The contact's name (its events' name in ``traj.events``).
    law : {"variational", "reflect"}, default "variational"
        The impact law: the variational collision integrator (:func:`variational_jump`; for
        kick–drift methods and the two-point rules ``midpoint`` and ``trapezoid``, elastic
        contacts only), or the exact reflection of the momenta between the method's partial
        steps (any method; symplectic across an impact only to the method's order).

    Raises
    ------
    ValueError
        ``restitution`` not in [0, 1], or an unknown ``law``.

    See Also
    --------
    varmech.surfaces : the native surfaces of :meth:`wall` and :meth:`ellipsoid`.
    ContactError : an impact that cannot be resolved.

    References
    ----------
    .. [1] R. C. Fetecau, J. E. Marsden, M. Ortiz and M. West, "Nonsmooth Lagrangian mechanics
       and variational collision integrators", *SIAM J. Appl. Dyn. Syst.* 2 (2003) 381–416.

    Examples
    --------
    >>> import numpy as np, varmech
    >>> ball = varmech.MechanicalSystem(1, lambda q: 9.81 * q[0], lambda q: np.array([9.81]))
    >>> floor = varmech.Contact(lambda q: q[0], lambda q: [1.0], name="floor")
    >>> traj = varmech.integrate(ball, [1.0], [0.0], dt=1e-3, steps=3000, contacts=[floor])
    >>> first = traj.events[0].t[0]        # √(2h₀/g)
    >>> bool(abs(first - np.sqrt(2 / 9.81)) < 1e-12), len(traj.events[0])
    (True, 3)
    """

    phi: Callable[[np.ndarray], float]
    gradient: Callable[[np.ndarray], ArrayLike]
    restitution: float = 1.0
    name: str = "contact"
    #: The impact law: ``"variational"``, the variational collision integrator (:func:`variational_jump`;
    #: kick–drift methods and the two-point rules ``midpoint`` and ``trapezoid``), or
    #: ``"reflect"``, the exact reflection of the momenta between the method's partial steps (any
    #: method; symplectic across an impact only to the method's order).
    law: Literal["variational", "reflect"] = "variational"

    def __post_init__(self) -> None:
        if not (isinstance(self.restitution, (int, float)) and 0.0 <= float(self.restitution) <= 1.0):
            raise ValueError(f"restitution: must lie in [0, 1], got {self.restitution!r}")
        if self.law not in ("variational", "reflect"):
            raise ValueError(f"law: 'variational' or 'reflect', got {self.law!r}")

    @classmethod
    def wall(
        cls,
        k: int,
        value: float = 0.0,
        *,
        restitution: float = 1.0,
        name: str | None = None,
        law: Literal["variational", "reflect"] = "variational",
    ) -> Contact:
        """The wall q_k ≥ ``value`` (a floor, a side of a box): φ = q_k − value, watched in the
        core (the native ``crossing`` event), with no Python call per step; φ and ∇φ are
        :class:`varmech.surfaces.Wall` (they pickle and compare by k and the value).

        Parameters
        ----------
        k : int
            The coordinate bounded.
        value : float, default 0.0
            The wall's position.
        restitution : float, default 1.0
            The coefficient of restitution e ∈ [0, 1].
        name : str, optional
            The contact's name (default ``"q[k] ≥ value"``).
        law : {"variational", "reflect"}, default "variational"
            The impact law (see :class:`Contact`).

        Returns
        -------
        Contact
            The wall, watched natively.

        Raises
        ------
        ValueError
            ``restitution`` not in [0, 1], or an unknown ``law``.

        Examples
        --------
        >>> import numpy as np, varmech
        >>> ball = varmech.MechanicalSystem(1, lambda q: 9.81 * q[0], lambda q: np.array([9.81]))
        >>> traj = varmech.integrate(ball, [1.0], [0.0], dt=1e-3, steps=3000, contacts=[varmech.Contact.wall(0)])
        >>> len(traj.events[0])
        3
        """

        surface = _surfaces.Wall(int(k), float(value))
        label = name if name is not None else f"q[{k}] ≥ {value:g}"
        return cls(surface, _surfaces.Gradient(surface), restitution, label, law)

    @classmethod
    def ellipsoid(
        cls,
        semi_axes: ArrayLike,
        coordinates: ArrayLike | None = None,
        centre: ArrayLike | None = None,
        *,
        inside: bool = True,
        restitution: float = 1.0,
        name: str | None = None,
        law: Literal["variational", "reflect"] = "variational",
    ) -> Contact:
        """The ellipsoid Σᵢ ((q_{kᵢ} − cᵢ)/aᵢ)² ≤ 1 in the ``coordinates`` kᵢ (default the first
        len(semi_axes)) about the ``centre`` c (default the origin), with ``semi_axes`` a:

            φ(q) = 1 − Σᵢ ((q_{kᵢ} − cᵢ)/aᵢ)²  (``inside``: a billiard table or a bowl),

        or −φ (``inside=False``: an obstacle the state stays out of). Watched in the core (the
        native ``ellipsoid`` event), with no Python call per step; an ellipse is two semi-axes,
        a circle or sphere equal ones.

        Parameters
        ----------
        semi_axes : array_like, shape (m,)
            The semi-axes aᵢ, finite and positive.
        coordinates : array_like of int, shape (m,), optional
            The coordinates kᵢ (default 0, …, m − 1).
        centre : array_like, shape (m,), optional
            The centre c (default the origin).
        inside : bool, default True
            Keep the state inside (a table) or, if False, outside (an obstacle).
        restitution : float, default 1.0
            The coefficient of restitution e ∈ [0, 1].
        name : str, optional
            The contact's name (default ``"ellipsoid"`` or ``"outside an ellipsoid"``).
        law : {"variational", "reflect"}, default "variational"
            The impact law (see :class:`Contact`).

        Returns
        -------
        Contact
            The ellipsoid, watched natively (:class:`varmech.surfaces.Ellipsoid`).

        Raises
        ------
        ValueError
            ``semi_axes``, ``coordinates`` and ``centre`` of different lengths, semi-axes not
            finite and positive, a centre not finite, a negative coordinate, ``restitution``
            not in [0, 1], or an unknown ``law``.

        Examples
        --------
        The elliptic billiard x²/4 + y² ≤ 1: a free particle stays inside.

        >>> import numpy as np, varmech
        >>> free = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2))
        >>> table = varmech.Contact.ellipsoid([2.0, 1.0], name="table")
        >>> traj = varmech.integrate(free, [0.3, 0.1], [0.6, 0.8], dt=0.1, steps=1000, contacts=[table])
        >>> len(traj.events[0]) > 20, min(table.phi(q) for q in traj.q) > -1e-12
        (True, True)
        """
        axes = tuple(float(a) for a in np.atleast_1d(np.asarray(semi_axes, dtype=float)))
        ks = tuple(range(len(axes))) if coordinates is None else tuple(int(k) for k in np.atleast_1d(coordinates))
        c = (0.0,) * len(ks) if centre is None else tuple(float(x) for x in np.atleast_1d(np.asarray(centre, dtype=float)))
        surface = _surfaces.Ellipsoid(ks, c, axes, bool(inside))
        label = name if name is not None else ("ellipsoid" if inside else "outside an ellipsoid")
        return cls(surface, _surfaces.Gradient(surface), restitution, label, law)


def exact_jump(model: Model, t: float, normal: np.ndarray, q: np.ndarray, p: np.ndarray, restitution: float) -> float:
    """λ of the exact reflection p⁺ = p + λ∇φ in the metric of the kinetic energy:
    λ = −(1 + e)(∇φ·q̇)/(∇φᵀM⁻¹∇φ), so the normal velocity goes to −e times itself."""
    metric = _velocity(model, q, normal, t) - _velocity(model, q, np.zeros_like(p), t)
    return -(1.0 + restitution) * float(normal @ _velocity(model, q, p, t)) / float(normal @ metric)


def reflect(model: Model, contact: Contact, q: np.ndarray, p: np.ndarray, t: float) -> np.ndarray:
    """The momenta just after an impact on ``contact`` at (q, p): the normal velocity reversed and
    scaled by e, in the metric of the kinetic energy (:func:`exact_jump`), along the constraints of
    a constrained model (:func:`_normal`)."""
    normal = _normal(model, contact, q, p)
    return np.asarray(p + exact_jump(model, t, normal, q, p, contact.restitution) * normal)


class Flow(ABC):
    """A method's step of any size τ from a state, replayed at time t for an impact, with the
    discrete energy E_d = −∂L_d/∂τ of the step (``forward``) and the force evaluations made."""

    def __init__(self, model: Model, t: float) -> None:
        self.model, self.t = model, t
        self.evaluations = 0

    def _calls(self, what: str, q: np.ndarray, x: np.ndarray) -> np.ndarray:
        """``_core.derivative`` ``what`` at the states (q, x), rows, at time t."""
        return np.asarray(_core.derivative(self.model._core, what, np.full(len(q), self.t), q, x))

    def _call(self, what: str, q: np.ndarray, x: np.ndarray) -> np.ndarray:
        return self._calls(what, q[None, :], x[None, :])[0]

    @abstractmethod
    def forward(self, q: np.ndarray, p: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray, float]:
        """Ψ_τ(q, p) and E_d of that step."""


class Splitting(Flow):
    """A kick–drift method's step of any size τ replayed from its fractions (``MethodInfo.splitting``),
    forward or undone, with its discrete energy: the step's discrete Lagrangian is

        L_d(q₀, q₁, τ) = Σᵢ bᵢτ T((qᵢ − qᵢ₋₁)/(bᵢτ)) − Σⱼ aⱼτ V(q⁽ʲ⁾),

    stationary in the intermediate positions (the drifts' ends, where the kicks act), so

        E_d = −∂L_d/∂τ = Σᵢ bᵢ T(pᵢ) + Σⱼ aⱼ V(q⁽ʲ⁾),

    with pᵢ the momenta of the i-th drift (for Verlet, T(p_½) + ½(V(q₀) + V(q₁)))."""

    def __init__(self, model: Model, kicks: list[float], drifts: list[float], t: float) -> None:
        super().__init__(model, t)
        self.kicks, self.drifts = kicks, drifts

    def _force(self, q: np.ndarray) -> np.ndarray:
        self.evaluations += 1
        return self._call("dl_dq", q, np.zeros_like(q))

    def _energy(self, kinetic: float, points: list[tuple[float, np.ndarray]]) -> float:
        if not points:
            return kinetic
        qs = np.array([q for _, q in points])
        v = np.asarray(_core.energy_terms(self.model._core, np.full(len(qs), self.t), qs, np.zeros_like(qs))[2])
        return kinetic + float(sum(a * vj for (a, _), vj in zip(points, v)))

    def forward(self, q: np.ndarray, p: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray, float]:
        """Ψ_τ(q, p) and E_d of that step."""
        a, b = self.kicks, self.drifts
        points: list[tuple[float, np.ndarray]] = []
        kinetic = 0.0
        if a[0] != 0.0:
            points.append((a[0], q))
            p = p + a[0] * tau * self._force(q)
        for bi, ai in zip(b, a[1:]):
            v = self._call("velocity", q, p)
            kinetic += bi * 0.5 * float(p @ v)
            q = q + bi * tau * v
            if ai != 0.0:
                points.append((ai, q))
                p = p + ai * tau * self._force(q)
        return q, p, self._energy(kinetic, points)

    def undone(self, q: np.ndarray, p: np.ndarray, tau: float) -> float:
        """E_d of the step Ψ_τ that ends at (q, p), undone from its end."""
        a, b = self.kicks, self.drifts
        points: list[tuple[float, np.ndarray]] = []
        kinetic = 0.0
        for bi, ai in zip(reversed(b), reversed(a[1:])):
            if ai != 0.0:
                points.append((ai, q))
                p = p - ai * tau * self._force(q)
            v = self._call("velocity", q, p)
            kinetic += bi * 0.5 * float(p @ v)
            q = q - bi * tau * v
        if a[0] != 0.0:
            points.append((a[0], q))
        return self._energy(kinetic, points)


#: The implicit two-point rules whose impacts the variational collision integrator takes (:class:`TwoPoint`).
TWO_POINT = ("midpoint", "trapezoid")


class CoreStep(Flow):
    """Any method's step of size τ, the core's own: its :class:`varmech._core.Stepper` from a run's
    checkpoint (``law="reflect"``). It has no discrete energy here (NaN)."""

    def __init__(self, model: Model, checkpoint: bytes, t: float) -> None:
        super().__init__(model, t)
        self.stepper = _core.Stepper.from_checkpoint(model._core, checkpoint)

    def forward(self, q: np.ndarray, p: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray, float]:
        """Ψ_τ(q, p), the core's step, and E_d of that step (of H(q, p) for τ = 0)."""
        q1, p1 = q, p
        if tau > 0.0:
            s = self.stepper
            counted = s.force_evaluations
            s.reset(q, p, self.t)
            s.dt = tau
            s.step()
            self.evaluations += s.force_evaluations - counted
            q1, p1 = np.asarray(s.q), np.asarray(s.p)
        return q1, p1, self.energy(q, p, q1, p1, tau)

    def energy(self, q0: np.ndarray, p0: np.ndarray, q1: np.ndarray, p1: np.ndarray, tau: float) -> float:
        """E_d of the step of size τ from (q0, p0) to (q1, p1): none for a method in general."""
        return float("nan")


class TwoPoint(CoreStep):
    """An implicit two-point rule's step of any size τ (``midpoint``, ``trapezoid``), the core's
    own (its :class:`varmech._core.Stepper` from a run's checkpoint), with its discrete energy
    E_d = −∂L_d/∂τ at fixed ends, for an autonomous L. With v = (q₁ − q₀)/τ and the energy
    function E(q, v) = v·∂L/∂q̇ − L:

    - midpoint, L_d = τL(q̄, v) at q̄ = (q₀ + q₁)/2: E_d = E(q̄, v). Its momenta
      p₀,₁ = ∂L/∂q̇ ∓ (τ/2)∂L/∂q (at q̄, v) have the half-sum p̄ = ∂L/∂q̇(q̄, v), so
      E_d = H(q̄, p̄), the Hamiltonian at the mean of the two states;
    - trapezoid, L_d = (τ/2)[L(q₀, v) + L(q₁, v)]: E_d = ½[E(q₀, v) + E(q₁, v)], with v solved
      from the half-sum of its momenta, ½[∂L/∂q̇(q₀, v) + ∂L/∂q̇(q₁, v)] = p̄ + (τ/4)[∂L/∂q(q₀, v)
      − ∂L/∂q(q₁, v)] (by the inverse Legendre map at q̄, iterated: a contraction by O(τ‖q₁ − q₀‖)
      and O(‖q₁ − q₀‖²); one pass for a constant mass).

    v comes from the momenta, not from (q₁ − q₀)/τ: the core steps δq = τv itself, and a
    difference of the saved positions keeps only a fraction τ‖v‖/‖q‖ of the digits of v, none as
    τ → 0 (an impact at a fraction α or 1 − α of the step near 0).

    Examples
    --------
    The ball's midpoint step is exact on its parabola, and E_d = H − g²τ²/8:

    >>> import numpy as np, varmech
    >>> ball = varmech.MechanicalSystem(1, lambda q: 9.81 * q[0], lambda q: np.array([9.81]))
    >>> stepper = varmech._core.Stepper(ball._core, np.array([1.0]), np.array([0.0]), dt=0.1, method="midpoint")
    >>> flow = TwoPoint(ball, stepper.checkpoint(), 0.0)
    >>> q1, p1, energy = flow.forward(np.array([1.0]), np.array([0.0]), 0.1)
    >>> bool(abs(energy - (9.81 - 9.81**2 * 0.1**2 / 8)) < 1e-14)
    True
    """

    def __init__(self, model: Model, checkpoint: bytes, t: float) -> None:
        super().__init__(model, checkpoint, t)
        self.rule = self.stepper.method
        if self.rule not in TWO_POINT:
            raise ValueError(f"method: the two-point rules are {TWO_POINT}, not {self.rule!r}")

    def energy(self, q0: np.ndarray, p0: np.ndarray, q1: np.ndarray, p1: np.ndarray, tau: float) -> float:
        """E_d of the rule's step of size τ from (q0, p0) to (q1, p1)."""
        mean, p = 0.5 * (q0 + q1), 0.5 * (p0 + p1)
        if self.rule == "midpoint":
            return float(self._hamiltonian(mean[None, :], p[None, :])[0])
        ends = np.stack([q0, q1])
        v, step = self._call("velocity", mean, p), np.inf
        for _ in range(50):
            both = np.stack([v, v])
            momenta = self._calls("momentum", ends, both)
            forces = self._calls("dl_dq", ends, both)
            self.evaluations += 2
            shift = 0.25 * tau * (forces[0] - forces[1]) + self._call("momentum", mean, v) - momenta.mean(axis=0)
            new = self._call("velocity", mean, p + shift)
            last, step = step, float(np.max(np.abs(new - v)))
            v = new
            # Converged to round-off: no change, or no more progress.
            if step == 0.0 or step >= last:
                break
        both = np.stack([v, v])
        return float(self._hamiltonian(ends, self._calls("momentum", ends, both)).mean())

    def _hamiltonian(self, q: np.ndarray, p: np.ndarray) -> np.ndarray:
        """E = p·q̇ − L at each state (q, p)."""
        return np.asarray(_core.energy_terms(self.model._core, np.full(len(q), self.t), q, p)[0])


class ContactError(_core.VarmechError):
    """An impact could not be resolved: a non-finite state through it, a body that crosses the
    surface again at once after leaving it (a resting or grazing contact), or more than
    :data:`MAX_IMPACTS` impacts in one step (an accumulation of impacts, as of a ball coming to
    rest).

    Impacts model collisions, not resting contact: a ball with e < 1 bounces ever lower and
    faster, and its impacts accumulate at a finite time; stop the run before it (a terminal
    event) or model the resting phase as a constraint.

    Attributes
    ----------
    step : int
        The step in which the impact failed (1 for the first).
    time : float
        The time tₙ at the start of that step.
    partial : Trajectory
        The run up to the last good step (``status`` -1), with the impacts resolved so far in
        its ``events``.

    See Also
    --------
    Contact : the surfaces and their coefficients of restitution.

    Examples
    --------
    A ball with e = 0.5 comes to rest on the floor at t = (1 + 2e/(1 − e))√(2h₀/g) ≈ 1.35:

    >>> import varmech
    >>> try:
    ...     varmech.integrate(varmech.scenes.bouncing_ball(restitution=0.5), dt=0.01, t_end=2.0)
    ... except varmech.ContactError as err:
    ...     print(err.step, round(err.time, 2), len(err.partial.events[0]), err.partial.status)
    136 1.35 8 -1
    """

    step: int
    time: float
    partial: Any


#: Impacts resolved in one step at most.
MAX_IMPACTS = 64

#: A piece of a step after a jump: (the state where it ends, its discrete energy, its length,
#: and the contact crossed where it ends, or None at the end of the step).
Piece = tuple[np.ndarray, np.ndarray, float, float, int | None]




def variational_jump(piece: Callable[[float], Piece], exact: float, target: float, scale: float) -> tuple[float, bool]:
    """λ of the variational collision integrator (Fetecau, Marsden, Ortiz & West 2003): the
    discrete energy of the piece after the jump, ``piece(λ)``, equal to ``target``, that of the
    piece before. The contact point and the fraction of the step then make the action of the two
    pieces stationary, D₂L_d(q_k, q̃, τ₁) + D₁L_d(q̃, q_{k+1}, τ₂) = λ∇φ(q̃) and E_d(q_k, q̃, τ₁) =
    E_d(q̃, q_{k+1}, τ₂), so the step across the impact is symplectic. Solved by secants from the
    exact reflection's λ, O(τ²) away; False (and ``exact``) where there is no root near it (a
    grazing impact, |∇φ·q̇| of order τ). ``scale`` sizes the energies' round-off."""
    # An implicit rule's E_d(λ), from a Newton solve, can stall a few ulps from the root, where
    # the secant sees no slope.
    eps = np.finfo(float).eps
    noise = 16.0 * eps * (abs(target) + abs(scale))
    lam0, lam1 = exact, exact * (1.0 + 1e-6)
    f0 = piece(lam0)[2] - target
    for _ in range(40):
        f1 = piece(lam1)[2] - target
        if f1 == 0.0 or abs(lam1 - lam0) <= 4.0 * eps * abs(lam1) or (f1 == f0 and abs(f1) <= noise):
            near = 0.5 * exact <= lam1 <= 1.5 * exact if exact > 0 else 1.5 * exact <= lam1 <= 0.5 * exact
            return (lam1, True) if near else (exact, False)
        if f1 == f0 or not np.isfinite(f1):
            break
        lam0, lam1, f0 = lam1, lam1 - f1 * (lam1 - lam0) / (f1 - f0), f1
    return exact, False


def crossing(g: Callable[[float], float], tau: float, leaving: bool) -> float:
    """The first s in (0, τ] where g(s) = φ(q(s)) falls through 0, given g(τ) < 0 (``leaving``:
    the piece starts on that surface, g(0) = 0, and moves in): bracketed by samples (refined
    towards 0 for a piece leaving the surface), then regula falsi (Illinois) to round-off."""
    lo, g_lo, hi = 0.0, (0.0 if leaving else g(0.0)), tau
    for _ in range(4):
        xs = lo + (hi - lo) * np.arange(1, 9) / 8
        values = [g(x) for x in xs]
        k = next(k for k, v in enumerate(values) if v < 0.0)
        if k > 0:
            lo, g_lo = xs[k - 1], values[k - 1]
        if k > 0 or not leaving:
            hi, g_hi = xs[k], values[k]
            break
        hi = xs[0]
    else:
        raise ContactError(
            "a body leaving a surface crosses it again at once (a resting or grazing contact, such as e = 0 under"
            " a force pressing on it), which impacts cannot resolve"
        )
    side = 0
    for _ in range(200):
        if hi - lo <= 4.0 * np.finfo(float).eps * tau:
            break
        x = (lo * g_hi - hi * g_lo) / (g_hi - g_lo)
        if not lo < x < hi:
            break
        gx = g(x)
        if gx == 0.0:
            return float(x)
        if gx > 0.0:
            lo, g_lo = x, gx
            g_hi, side = (0.5 * g_hi if side == -1 else g_hi), -1
        else:
            hi, g_hi = x, gx
            g_lo, side = (0.5 * g_lo if side == 1 else g_lo), 1
    return float(lo if abs(g_lo) <= abs(g_hi) else hi)


def through(
    flows: Flow, contacts: list[Contact], i: int, t: float, q: np.ndarray, p: np.ndarray, tau: float, first: Callable[[], float]
) -> tuple[np.ndarray, np.ndarray, list[tuple[int, float, np.ndarray, np.ndarray, np.ndarray]], int]:
    """The rest τ of a step from an impact on ``contacts[i]`` at (t, q, p), whose first piece had
    the discrete energy ``first()``: each jump, then the piece to the next contact crossed within
    the step (several contacts in one step, a corner), to the step's end. Returns the end state,
    the impacts (contact, time, configuration, momenta before and after) and how many took
    Newton's law for want of a discrete-energy root (grazing)."""
    impacts: list[tuple[int, float, np.ndarray, np.ndarray, np.ndarray]] = []
    grazing = 0
    while True:
        contact = contacts[i]
        normal = _normal(flows.model, contact, q, p)
        lam = exact_jump(flows.model, t, normal, q, p, contact.restitution)

        def piece(lam: float, q: np.ndarray = q, p: np.ndarray = p, normal: np.ndarray = normal, i: int = i, tau: float = tau) -> Piece:
            return _piece(flows, contacts, i, q, p + lam * normal, tau)

        if contact.law == "variational" and contact.restitution == 1.0:
            lam, ok = variational_jump(piece, lam, first(), float(p @ _velocity(flows.model, q, p, t)))
            grazing += not ok
        q1, p1, energy, s, j = piece(lam)
        impacts.append((i, t, q, p, p + lam * normal))
        if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(p1))):
            raise ContactError(f"a non-finite state after the impact on {contact.name!r} at t = {t}")
        if j is None:
            return q1, p1, impacts, grazing
        if len(impacts) == MAX_IMPACTS:
            raise ContactError(
                f"more than {MAX_IMPACTS} impacts in the step of the impact at t = {t} (an accumulation of"
                " impacts, as of a body coming to rest on a surface); shorten the step or stop the run before"
            )
        i, t, q, p, tau = j, t + s, q1, p1, tau - s
        first = partial(float, energy)


def _normal(model: Model, contact: Contact, q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The direction of an impact's jump: ∇φ(q), or on a constrained model the part of it the
    constraints let act. The surface's impulse comes with the constraints' own workless impulse
    Gᵀμ that keeps the momenta on them (GM⁻¹p⁺ = 0), which adds up to λ∇φ projected
    M-orthogonally (:func:`varmech.project`'s projection, whose affine part cancels here)."""
    normal = np.asarray(contact.gradient(q.copy()), dtype=float).reshape(-1)
    if model.constraints or model.velocity_constraints:
        normal = _core.project(model._core, q, p + normal)[1] - _core.project(model._core, q, p)[1]
    return np.asarray(normal)


def _piece(flows: Flow, contacts: list[Contact], i: int, q: np.ndarray, p: np.ndarray, tau: float) -> Piece:
    """The piece of a step from (q, p) just after a jump on ``contacts[i]``: to the end τ, or to the
    first contact crossed before it."""
    q1, p1, energy = flows.forward(q, p, tau)
    below = [j for j, c in enumerate(contacts) if c.phi(q1.copy()) < 0.0]
    if not below:
        return q1, p1, energy, tau, None

    def surface(c: Contact) -> Callable[[float], float]:
        """φ along the piece, s ↦ φ(q(s))."""
        return lambda s: float(c.phi(flows.forward(q, p, s)[0]))

    s, j = min((crossing(surface(contacts[j]), tau, j == i), j) for j in below)
    q1, p1, energy = flows.forward(q, p, s)
    return q1, p1, energy, s, j


def check(model: Model, contacts: list[Contact], q0: np.ndarray) -> list[Any]:
    """The contacts checked against the initial state (ValueError naming ``q0`` outside φ ≥ 0),
    as the spec tuples of their terminal events."""
    watched = []
    for i, c in enumerate(contacts):
        if not isinstance(c, Contact):
            raise TypeError(f"contacts[{i}]: expected a varmech.Contact, got {type(c).__name__}")
        if isinstance(c.phi, _surfaces.Surface) and max(c.phi.coordinates) >= len(q0):
            raise ValueError(f"contacts[{i}]: coordinates {c.phi.coordinates} not all in 0 … {len(q0) - 1}")
        value = float(c.phi(q0.copy()))
        if not value >= 0.0:
            raise ValueError(f"q0: outside the contact {c.name!r}: φ(q0) = {value} < 0")
        if isinstance(c.phi, _surfaces.Surface):
            watched.append(_events.Event(None, -1, 1, name=c.name, native=c.phi.native))
        else:
            watched.append(_events.Event(_surface(c), direction=-1, terminal=1, name=c.name))
    return _events.specs(watched, model.dim)[1]


def _surface(contact: Contact) -> Callable[[float, np.ndarray, np.ndarray], float]:
    """g(t, q, p) = φ(q), the event of a contact."""

    def g(t: float, q: np.ndarray, p: np.ndarray) -> float:
        return float(contact.phi(q))

    return g


Start = Callable[..., Any]


def run(
    start: Start,
    model: Model,
    method: str,
    q0: np.ndarray,
    p0: np.ndarray,
    t0: float,
    dt: float,
    steps: int,
    contacts: list[Contact],
) -> tuple[Joined, tuple[_events.Occurrences, ...]]:
    """A run of ``steps`` steps of ``dt`` of ``method`` from (t0, q0, p0) through the impacts on
    ``contacts`` (``start(q, p, t0, steps, progress, events)`` runs a piece up to the first
    impact), and the impacts of each contact. Under the variational law a kick–drift method
    (:class:`Splitting`) or a two-point rule (:class:`TwoPoint`) goes through each impact by
    :func:`through` with :func:`variational_jump`; under ``"reflect"`` the momenta jump by
    :func:`exact_jump` between the method's own partial steps (:class:`CoreStep`)."""
    split = method_info(method).splitting
    for i, c in enumerate(contacts):
        if not (isinstance(c, Contact) and c.law == "variational"):
            continue
        if split is None and method not in TWO_POINT:
            raise ValueError(
                f"contacts[{i}]: the variational collision integrator needs a kick–drift method (MethodInfo.splitting)"
                f" or a two-point rule {TWO_POINT}, not {method!r}; give the contact law='reflect' or use such a method"
            )
        if model.forced or model.time_dependent or model.constraints:
            raise ValueError(
                f"contacts[{i}]: the variational collision integrator keeps the discrete energy, which needs a"
                " conservative, autonomous, unconstrained model; give the contact law='reflect'"
            )
    specs = check(model, contacts, q0)
    grazing = 0
    hits: list[list[tuple[float, np.ndarray, np.ndarray]]] = [[] for _ in contacts]
    pieces = Pieces()

    def occurrences() -> tuple[_events.Occurrences, ...]:
        """The impacts so far, as each contact's occurrences."""
        n = model.dim
        return tuple(
            _events.Occurrences(
                c.name,
                np.array([h[0] for h in hits[j]]),
                np.array([h[1] for h in hits[j]]).reshape(-1, n),
                np.array([h[2] for h in hits[j]]).reshape(-1, n),
            )
            for j, c in enumerate(contacts)
        )

    q, p, t, done = q0, p0, t0, 0
    record = None
    while True:
        try:
            record = start(q, p, t, steps - done, None, specs)
        except BaseException as err:
            # The run so far is the error's partial trajectory, with the piece's own.
            piece = take_partial(err)
            if piece is not None:
                pieces.add(piece)
                err._varmech_joined = (pieces.joined(done + piece.steps, piece.checkpoint), occurrences())  # type: ignore[attr-defined]
            raise
        i = record.terminated_by
        if i is None:
            pieces.add(record)
            done += record.steps
            break
        # The step of the impact ends past the surface: its saved end is replaced.
        pieces.add(record, drop_last=True)
        index, te, qe, pe, q_start, p_start = record.events
        k = int(np.flatnonzero(index == i)[-1])
        t_hit, q_hit, p_hit = float(te[k]), np.asarray(qe[k]), np.asarray(pe[k])
        done += record.steps
        t_grid = t0 + done * dt
        before = t_hit - (t_grid - dt)
        # The first partial step's E_d: a splitting's undone from its end, a two-point rule's from
        # both ends (the crossing carries the state its step started from).
        flows: Flow
        first: Callable[[], float]
        if contacts[i].law == "reflect":
            flows = CoreStep(model, record.checkpoint, t_hit)
            first = partial(float, "nan")
        elif split is not None:
            flows = Splitting(model, *split, t_hit)
            first = partial(flows.undone, q_hit, p_hit, before)
        else:
            flows = TwoPoint(model, record.checkpoint, t_hit)
            first = partial(flows.energy, np.asarray(q_start[k]), np.asarray(p_start[k]), q_hit, p_hit, before)
        try:
            q, p, impacts, grazed = through(flows, contacts, i, t_hit, q_hit, p_hit, dt - before, first)
        except ContactError as err:
            # The run up to the step of the impact, ending with that step's start tₙ, the error's time.
            err.step, err.time = done, t_grid - dt
            stepper = _core.Stepper.from_checkpoint(model._core, record.checkpoint)
            stepper.reset(np.asarray(q_start[k]), np.asarray(p_start[k]), t_grid - dt)
            err._varmech_joined = (pieces.joined(done - 1, stepper.checkpoint()), occurrences())  # type: ignore[attr-defined]
            raise
        grazing += grazed
        pieces.nfev += flows.evaluations
        for j, t_j, q_j, before_j, after_j in impacts:
            hits[j].append((t_j, q_j, before_j))
            pieces.row(t_j, q_j, before_j)
            pieces.row(t_j, q_j, after_j)
        t = t_grid
        pieces.row(t, q, p)
        if done >= steps:
            break
    assert record is not None
    if grazing:
        warnings.warn(
            f"{grazing} grazing impact(s) had no discrete-energy solution near the reflection and took Newton's law",
            RuntimeWarning,
            stacklevel=3,
        )
    return pieces.joined(done, record.checkpoint), occurrences()
