"""Impacts with unilateral constraints φ(q) ≥ 0 (walls, floors, billiard tables).

A run with ``contacts`` watches each φ as an event (g = φ(q), falling through 0, terminal). The
step that crosses a surface is split at the contact: the method's own partial step of size αh
from (qₙ, pₙ) to the contact configuration q̃ on φ = 0 (α found to round-off by the event
search), the jump p⁺ = p⁻ + λ∇φ(q̃), and the method's partial step of size (1 − α)h to the grid
time tₙ₊₁. The contact's ``law`` fixes λ:

- ``"variational"`` (the default; kick–drift methods, ``MethodInfo.splitting``): the variational
  collision integrator of Fetecau, Marsden, Ortiz & West (2003), :func:`collide`. The discrete
  energy E_d = −∂L_d/∂τ is the same on both sides of the impact, which makes the action of the
  two partial steps stationary in the contact point and the fraction, so **the step across an
  impact is symplectic** (measured defect ≤ 1e-9, round-off of the differences, for every
  kick–drift method). H itself moves by O(h²) at an impact and stays bounded over many.
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

Only the first contact crossed in a step is handled in that step, and a second crossing inside
the rest of the step, (1 − α)h, is not looked for: steps must be short against the time between
impacts.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from . import events as _events
from . import surfaces as _surfaces
from .impulses import Joined, Pieces, inverse_mass
from .methods import method_info
from .model import Model


@dataclass(frozen=True)
class Contact:
    """A unilateral constraint φ(q) ≥ 0 with its gradient ∇φ(q) and the coefficient of
    restitution ``restitution`` e ∈ [0, 1] (1: elastic).

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
    #: The impact law: ``"variational"``, the variational collision integrator (:func:`collide`;
    #: kick–drift methods), or ``"reflect"``, the exact reflection of the momenta between the
    #: method's partial steps (any method; symplectic across an impact only to the method's order).
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


def reflect(model: Model, contact: Contact, q: np.ndarray, p: np.ndarray, t: float) -> np.ndarray:
    """The momenta just after an impact on ``contact`` at (q, p): the normal velocity reversed and
    scaled by e, in the metric of the kinetic energy."""
    normal = np.asarray(contact.gradient(q.copy()), dtype=float).reshape(-1)
    minv = inverse_mass(model, q, t)
    v = np.asarray(_core.derivative(model._core, "velocity", np.array([t]), q[None, :], p[None, :])[0])
    return np.asarray(p - (1.0 + contact.restitution) * (normal @ v) / (normal @ minv @ normal) * normal)


class Splitting:
    """A kick–drift method's step of any size τ replayed from its fractions (``MethodInfo.splitting``),
    forward or undone, with its discrete energy: the step's discrete Lagrangian is

        L_d(q₀, q₁, τ) = Σᵢ bᵢτ T((qᵢ − qᵢ₋₁)/(bᵢτ)) − Σⱼ aⱼτ V(q⁽ʲ⁾),

    stationary in the intermediate positions (the drifts' ends, where the kicks act), so

        E_d = −∂L_d/∂τ = Σᵢ bᵢ T(pᵢ) + Σⱼ aⱼ V(q⁽ʲ⁾),

    with pᵢ the momenta of the i-th drift (for Verlet, T(p_½) + ½(V(q₀) + V(q₁)))."""

    def __init__(self, model: Model, kicks: list[float], drifts: list[float], t: float) -> None:
        self.model, self.kicks, self.drifts, self.t = model, kicks, drifts, t
        self.evaluations = 0

    def _call(self, what: str, q: np.ndarray, x: np.ndarray) -> np.ndarray:
        return np.asarray(_core.derivative(self.model._core, what, np.array([self.t]), q[None, :], x[None, :])[0])

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


def collide(
    flows: Splitting, normal: np.ndarray, q: np.ndarray, p: np.ndarray, before: float, after: float, restitution: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """The step through an impact at the contact configuration q on φ = 0, reached with momenta p
    by a step of ``before`` from the grid state, with ``after`` left to the next grid time: the
    momenta just after, p⁺ = p + λ∇φ, and the state at the grid time Ψ_after(q, p⁺).

    Elastic (e = 1): the variational collision integrator (Fetecau, Marsden, Ortiz & West 2003).
    The contact point and the fraction of the step make the action of the two partial steps
    stationary: the first partial step is the method's (so φ(q) = 0 fixes the fraction), and the
    jump and the second satisfy D₂L_d(q_k, q, τ₁) + D₁L_d(q, q_{k+1}, τ₂) = λ∇φ(q) and
    E_d(q_k, q, τ₁) = E_d(q, q_{k+1}, τ₂), solved for λ by secants from the exact reflection's
    λ (O(τ²) away). The discrete energy, not H, is continuous across the impact: that is what
    makes the step symplectic. Inelastic (e < 1): no symplectic structure is left to keep, and
    Newton's law applies at q: the normal velocity ∇φ·q̇ goes to −e times itself.

    The last value is False where the discrete energy equation has no root near the exact
    reflection (a grazing impact, |∇φ·q̇| of order τ): that impact takes Newton's law with e = 1."""
    zero = np.zeros_like(p)
    metric = flows._call("velocity", q, normal) - flows._call("velocity", q, zero)
    v = flows._call("velocity", q, p)
    exact = -(1.0 + restitution) * float(normal @ v) / float(normal @ metric)

    def state(lam: float) -> tuple[np.ndarray, np.ndarray, float]:
        return flows.forward(q, p + lam * normal, after)

    if restitution < 1.0:
        q1, p1, _ = state(exact)
        return p + exact * normal, q1, p1, True
    target = flows.undone(q, p, before)
    lam0, lam1 = exact, exact * (1.0 + 1e-6)
    f0 = state(lam0)[2] - target
    found = None
    for _ in range(40):
        q1, p1, e1 = state(lam1)
        f1 = e1 - target
        if f1 == 0.0 or abs(lam1 - lam0) <= 4.0 * np.finfo(float).eps * abs(lam1):
            found = (lam1, q1, p1)
            break
        if f1 == f0 or not np.isfinite(f1):
            break
        lam0, lam1, f0 = lam1, lam1 - f1 * (lam1 - lam0) / (f1 - f0), f1
    if found is None or not (0.5 * exact <= found[0] <= 1.5 * exact if exact > 0 else 1.5 * exact <= found[0] <= 0.5 * exact):
        q1, p1, _ = state(exact)
        return p + exact * normal, q1, p1, False
    lam, q1, p1 = found
    return p + lam * normal, q1, p1, True


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
    impact), and the impacts of each contact. A kick–drift method goes through each impact by
    :func:`collide`; the others reflect the momenta (:func:`reflect`) between their own partial
    steps."""
    split = method_info(method).splitting
    for i, c in enumerate(contacts):
        if isinstance(c, Contact) and c.law == "variational" and split is None:
            raise ValueError(
                f"contacts[{i}]: the variational collision integrator needs a kick–drift method, not {method!r};"
                " give the contact law='reflect' or use such a method (MethodInfo.splitting)"
            )
    specs = check(model, contacts, q0)
    grazing = 0
    hits: list[list[tuple[float, np.ndarray, np.ndarray]]] = [[] for _ in contacts]
    pieces = Pieces()
    q, p, t, done = q0, p0, t0, 0
    record = None
    while True:
        record = start(q, p, t, steps - done, None, specs)
        i = record.terminated_by
        if i is None:
            pieces.add(record)
            done += record.steps
            break
        # The step of the impact ends past the surface: its saved end is replaced.
        pieces.add(record, drop_last=True)
        index, te, qe, pe = record.events
        k = int(np.flatnonzero(index == i)[-1])
        t_hit, q_hit, p_hit = float(te[k]), np.asarray(qe[k]), np.asarray(pe[k])
        hits[i].append((t_hit, q_hit, p_hit))
        done += record.steps
        t_grid = t0 + done * dt
        if contacts[i].law == "variational":
            assert split is not None
            flows = Splitting(model, *split, t_hit)
            normal = np.asarray(contacts[i].gradient(q_hit.copy()), dtype=float).reshape(-1)
            before = t_hit - (t_grid - dt)
            p_after, q, p, ok = collide(flows, normal, q_hit, p_hit, before, dt - before, contacts[i].restitution)
            grazing += not ok
            pieces.nfev += flows.evaluations
        else:
            p_after = reflect(model, contacts[i], q_hit, p_hit, t_hit)
            stepper = _core.Stepper.from_checkpoint(model._core, record.checkpoint)
            stepper.reset(q_hit, p_after, t_hit)
            if t_grid > t_hit:
                stepper.dt = t_grid - t_hit
                stepper.step()
                pieces.nfev += stepper.force_evaluations
            q, p = np.asarray(stepper.q), np.asarray(stepper.p)
        pieces.row(t_hit, q_hit, p_hit)
        pieces.row(t_hit, q_hit, p_after)
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
    joined = pieces.joined(done, record.checkpoint)
    n = model.dim
    found = tuple(
        _events.Occurrences(
            c.name,
            np.array([h[0] for h in hits[j]]),
            np.array([h[1] for h in hits[j]]).reshape(-1, n),
            np.array([h[2] for h in hits[j]]).reshape(-1, n),
        )
        for j, c in enumerate(contacts)
    )
    return joined, found
