"""Impacts with unilateral constraints φ(q) ≥ 0 (walls, floors, billiard tables): the
specification. The core resolves them in its step loop (``rust/core/src/integrators/jumps/``),
so a run with contacts composes with events, output files and their checkpoints, ``resume``,
continued runs (``integrate(traj, steps=)``) and ensembles.

The step that crosses a surface is split at the contact: the method's own partial step of size
αh from (qₙ, pₙ) to the contact configuration q̃ on φ = 0 (α located to round-off), the jump
p⁺ = p⁻ + λ∇φ(q̃), and the method's partial step of size (1 − α)h to the grid time tₙ₊₁. The
contact's ``law`` fixes λ:

- ``"variational"`` (the default; the methods with ``"discrete_energy"`` in
  ``MethodInfo.features``: kick–drift methods, ``MethodInfo.splitting``, the implicit two-point
  rules ``midpoint`` and ``trapezoid`` and the Galerkin rules ``galerkin4`` and ``galerkin6``):
  the variational collision integrator of Fetecau, Marsden, Ortiz & West (2003).
  λ keeps the discrete energy E_d = −∂L_d/∂τ of the piece after the jump equal to that of the
  piece before, which makes the action of the two partial steps stationary in the contact point
  and the fraction, so **the step across an impact is symplectic** (measured defect ≤ 1e-9,
  round-off of the differences, for every kick–drift method, for midpoint and trapezoid on
  separable and on natural systems M(q), and for the Galerkin rules on a general Lagrangian).
  H itself moves by O(h²) at an impact and stays bounded over many. It needs a conservative, autonomous,
  unconstrained model (the energy balance is E_d's alone). Where E_d has no root near the
  reflection (a grazing impact, |∇φ·q̇| of order h) the impact takes Newton's law, with a
  RuntimeWarning counting such impacts.
- ``"reflect"`` (any method): the exact reflection in the metric of the kinetic energy,

      p⁺ = p⁻ − (1 + e) (∇φ·q̇⁻) / (∇φᵀM⁻¹∇φ) ∇φ,

  which conserves H at the impact (round-off over 10⁴ bounces of a ball, where Verlet is exact
  between them) but is symplectic across it only to the method's order (verlet's defect
  ‖ΨᵀJΨ − J‖ falls as h²: 8.4e-3, 1.9e-3, 4.3e-4 at h = 0.1, 0.05, 0.025). On a constrained
  model ∇φ is projected on the constraints (the constraints' own workless impulse).

Both keep the method's order away from grazing. For e < 1 there is no symplectic structure to
keep, and both apply Newton's law at q̃: the normal velocity ∇φ·q̇ goes to −e times itself. The
impacts are the contacts' occurrences in ``traj.events``, after the events' own (time, contact
configuration, momenta just before), and the saved states hold the state just before and just
after each impact (one time, two rows).

After a jump the rest of the step is checked against every contact: one crossed before its end
(a corner, or a ball's next bounce within the step) is located on that piece and taken in turn,
up to 64 impacts in one step. A contact closes where a body comes to rest on it (the impact whose
rebounds' Zeno series sums to less than a step, reported at the series' limit, or an arrival
without normal velocity), is held by RATTLE while it pushes, composed as the run's method
composes Verlet, and is released where its multiplier λ crosses 0 (lift-off); the closures
(``"<name>.closed"``) and releases (``"<name>.released"``) follow the impacts in
``traj.events``. A held contact with :class:`Friction` slides under the force μ_k N against its
slip and sticks where its slip stops and the force that holds it is within μ_s N (N = λ|∇φ|),
each switch located to round-off (``"<name>.stuck"``, ``"<name>.slipped"``); the work of the
sliding force is ``traj.work``. Where the method cannot hold a contact (not a Verlet composition, or a model with
forces or constraints of its own) a body that cannot leave a surface raises
:class:`ContactError` with the step, the time and the run up to that step. A piece is checked at its end only: a contact
entered and left again within one piece is missed, so steps must be short against the time a
body spends beyond a curved surface's chord.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal, TypeVar

import numpy as np
from numpy.typing import ArrayLike

from . import surfaces as _surfaces
from ._core import IMPACT_LAWS, ContactError
from ._util import floats, integer, number, with_sections
from ._warnings import VarmechWarning
from .events import Occurrences

if TYPE_CHECKING:
    from .model import Model

#: The public API; the rest serves :func:`varmech.integrate`.
__all__ = ["Contact", "ContactError", "Friction", "ImpactWarning"]

#: The kinds of a contact's switches, by the code the core reports them with.
SWITCHES = ("closed", "released", "stuck", "slipped")
#: The impact laws, by name: the core's (``_core.IMPACT_LAWS``), which the check reads.
LawName = Literal["variational", "reflect"]

# The parameters the native contacts' constructors (Contact.wall, Contact.ellipsoid) share,
# which Contact and Friction document, put in for their placeholder (as varmech.events does its
# events' sections).
_NATIVE_SECTIONS = {
    "{law and friction}": """law : {"variational", "reflect"}, default "variational"
            The impact law (see :class:`Contact`).
        friction : Friction, optional
            Coulomb friction while the contact is held (see :class:`Friction`).""",
}

_F = TypeVar("_F", bound=Callable[..., Any])


def _native_documented(constructor: _F) -> _F:
    """``constructor`` with the shared sections put into its docstring for their placeholders."""
    return with_sections(constructor, _NATIVE_SECTIONS)


@dataclass(frozen=True)
class Friction:
    """Coulomb friction on a held contact: the force μ_k N against the slip of the contact point
    while it slides, and none needed beyond μ_s N while it sticks (N = λ|∇φ|, the normal force of
    the contact's multiplier: φ written as a distance makes N the force itself).

    The slip is s = J q̇, the velocity of the contact point along the surface. For a particle's
    own coordinates (n = 2 or 3) J is the tangent plane of ∇φ and need not be given; a body that
    turns gives its rows (``slip``), constant, or as a function J(q) where they turn with the
    body: a velocity constraint J(q)q̇ = 0 then holds while the contact sticks, and gives way to
    sliding where it needs more than μ_s N (a wheel rolling on its heading φ, slip
    J = [[1, 0, −r cos φ], [0, 1, −r sin φ]] in (x, y, θ), skids). A sliding contact sticks where its slip comes to rest and the
    force that holds it there is within μ_s N (a block stopping on a slope, a ball that starts to
    roll), and a stuck one slips where that force reaches μ_s N; both are located to round-off
    on the held steps, and reported as ``"<name>.stuck"`` and ``"<name>.slipped"`` in
    ``traj.events``. The work of the sliding force is ``traj.work`` (the discrete
    Lagrange–d'Alembert work ½(F₀ + F₁)·(q₁ − q₀) a step), which
    :func:`varmech.check_conservation` balances against the energy.

    Friction acts on held contacts, so it needs a method that holds one (verlet and its
    compositions, ``"held_step"`` in ``MethodInfo.features``) and a model without forces or
    constraints of its own.

    Attributes
    ----------
    mu_s : float
        The static coefficient μ_s ≥ μ_k.
    mu_k : float, optional
        The kinetic coefficient μ_k ≥ 0 (default μ_s).
    slip : array_like, shape (k, n), or callable, optional
        The slip's rows J: s = J q̇. Constant rows, or a function ``slip(q)`` returning them
        (k, n); default: a particle's tangent plane (n = 2 or 3).
    slip_count : int, optional
        k, the number of rows a ``slip`` function returns (required with one).

    Raises
    ------
    ValueError
        A coefficient negative or not finite, ``mu_s`` < ``mu_k``, ``slip`` not a
        non-empty finite matrix or a function, or ``slip_count`` not a positive integer given
        with a function (and only with one).

    Examples
    --------
    A block at rest on a slope of 30° stays for μ_s ≥ tan 30° and slides down at
    g(sin α − μ_k cos α) otherwise.

    >>> import numpy as np, varmech
    >>> g, a = 9.81, np.radians(30)
    >>> block = varmech.MechanicalSystem(2, lambda q: g * q[1], lambda q: np.array([0.0, g]))
    >>> def slope(mu):
    ...     plane = varmech.Contact(lambda q: q[1] * np.cos(a) - q[0] * np.sin(a),
    ...                             lambda q: np.array([-np.sin(a), np.cos(a)]), name="slope",
    ...                             restitution=0.0, law="reflect", friction=varmech.Friction(mu, 0.8 * mu))
    ...     return varmech.integrate(block, [0.0, 0.0], [0.0, 0.0], dt=0.01, steps=100, contacts=[plane])
    >>> bool(np.all(slope(0.6).q == 0.0))
    True
    >>> down = slope(0.3).q[-1] @ [-np.cos(a), -np.sin(a)]
    >>> bool(abs(down - 0.5 * g * (np.sin(a) - 0.24 * np.cos(a))) < 1e-12)
    True
    """

    mu_s: float
    mu_k: float | None = None
    slip: Any = None
    slip_count: int | None = None

    def __post_init__(self) -> None:
        mu_s = number("mu_s", self.mu_s)
        mu_k = mu_s if self.mu_k is None else number("mu_k", self.mu_k)
        if not (np.isfinite(mu_k) and mu_k >= 0.0):
            raise ValueError(f"mu_k: must be a finite number ≥ 0, got {self.mu_k!r}")
        if not (np.isfinite(mu_s) and mu_s >= mu_k):
            raise ValueError(f"mu_s: must be finite and at least mu_k = {mu_k:g} (static friction holds what sliding does), got {self.mu_s!r}")
        object.__setattr__(self, "mu_s", mu_s)
        object.__setattr__(self, "mu_k", mu_k)
        if callable(self.slip):
            if self.slip_count is None:
                raise ValueError("slip_count: required with a slip function, the number k of the rows (k, n) it returns")
            count = integer("slip_count", self.slip_count)
            if count < 1:
                raise ValueError(f"slip_count: must be at least 1, got {self.slip_count!r}")
            object.__setattr__(self, "slip_count", count)
        elif self.slip_count is not None:
            raise ValueError("slip_count: only with a slip function (constant rows count themselves)")
        elif self.slip is not None:
            rows = np.array(floats("slip", self.slip), dtype=float)
            if rows.ndim == 1:
                rows = rows[None, :]
            if rows.ndim != 2 or rows.size == 0 or not np.all(np.isfinite(rows)):
                raise ValueError(f"slip: must be a finite (k, n) matrix, the rows J of the contact point's slip s = J q̇, got {rows.tolist()}")
            object.__setattr__(self, "slip", tuple(tuple(float(x) for x in row) for row in rows))

    def spec(self) -> tuple[float, float, tuple[int, list[float] | Callable[[np.ndarray], ArrayLike]] | None]:
        """The friction as the binding takes it (and a file stores it).

        Returns
        -------
        tuple
            (μ_s, μ_k, slip): slip None for a particle's tangent plane, (k, the k × n rows
            J row by row), or (k, the function J(q)).

        Examples
        --------
        >>> Friction(0.5, 0.4).spec()
        (0.5, 0.4, None)
        >>> Friction(0.2, slip=[[1.0, 0.0, -0.1]]).spec()
        (0.2, 0.2, (1, [1.0, 0.0, -0.1]))
        """
        slip: tuple[int, list[float] | Callable[[np.ndarray], ArrayLike]] | None
        if callable(self.slip):
            slip = (int(self.slip_count or 0), self.slip)
        else:
            slip = None if self.slip is None else (len(self.slip), [x for row in self.slip for x in row])
        return (float(self.mu_s), float(self.mu_k or 0.0), slip)


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
        The impact law: the variational collision integrator (the discrete energy kept; for
        kick–drift methods, the two-point rules ``midpoint`` and ``trapezoid`` and the Galerkin
        rules ``galerkin4`` and ``galerkin6``, elastic contacts only), or the exact reflection of the momenta between the method's partial
        steps (any method; symplectic across an impact only to the method's order).
    friction : Friction, optional
        Coulomb friction while the contact is held (see :class:`Friction`).
    native : bool
        Whether the core evaluates the contact without Python (read-only).

    Raises
    ------
    ValueError
        ``restitution`` not in [0, 1], or an unknown ``law``.
    TypeError
        ``friction`` not a :class:`Friction`.

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
    #: The impact law: ``"variational"``, the variational collision integrator (the discrete energy kept;
    #: kick–drift methods, the two-point rules ``midpoint`` and ``trapezoid``, the Galerkin rules), or
    #: ``"reflect"``, the exact reflection of the momenta between the method's partial steps (any
    #: method; symplectic across an impact only to the method's order).
    law: LawName = "variational"
    #: Coulomb friction while the contact is held, if any.
    friction: Friction | None = None

    def __post_init__(self) -> None:
        if not (isinstance(self.restitution, (int, float)) and 0.0 <= float(self.restitution) <= 1.0):
            raise ValueError(f"restitution: must lie in [0, 1], got {self.restitution!r}")
        if self.law not in IMPACT_LAWS:
            raise ValueError(f"law: {' or '.join(map(repr, IMPACT_LAWS))}, got {self.law!r}")
        if self.friction is not None and not isinstance(self.friction, Friction):
            raise TypeError(f"friction: expected a varmech.Friction, got {type(self.friction).__name__}")

    @property
    def native(self) -> bool:
        """Whether the core evaluates the contact without Python: a native surface
        (:meth:`wall`, :meth:`ellipsoid`) and no slip function; such a contact runs in the
        parallel ensemble and a file stores it.

        Returns
        -------
        bool

        Examples
        --------
        >>> import varmech
        >>> varmech.Contact.wall(0).native, varmech.Contact(lambda q: q[0], lambda q: [1.0]).native
        (True, False)
        """
        return isinstance(self.phi, _surfaces.Surface) and (self.friction is None or not callable(self.friction.slip))

    @classmethod
    @_native_documented
    def wall(
        cls,
        k: int,
        value: float = 0.0,
        *,
        restitution: float = 1.0,
        name: str | None = None,
        law: LawName = "variational",
        friction: Friction | None = None,
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
        {law and friction}

        Returns
        -------
        Contact
            The wall, watched natively.

        Raises
        ------
        ValueError
            ``k`` not an integer ≥ 0, ``value`` not a number, ``restitution`` not in [0, 1],
            or an unknown ``law``.

        Examples
        --------
        >>> import numpy as np, varmech
        >>> ball = varmech.MechanicalSystem(1, lambda q: 9.81 * q[0], lambda q: np.array([9.81]))
        >>> traj = varmech.integrate(ball, [1.0], [0.0], dt=1e-3, steps=3000, contacts=[varmech.Contact.wall(0)])
        >>> len(traj.events[0])
        3
        """

        surface = _surfaces.Wall(integer("k", k), number("value", value))
        label = name if name is not None else f"q[{k}] ≥ {value:g}"
        return cls(surface, _surfaces.Gradient(surface), restitution, label, law, friction)

    @classmethod
    @_native_documented
    def ellipsoid(
        cls,
        semi_axes: ArrayLike,
        coordinates: ArrayLike | None = None,
        centre: ArrayLike | None = None,
        *,
        inside: bool = True,
        restitution: float = 1.0,
        name: str | None = None,
        law: LawName = "variational",
        friction: Friction | None = None,
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
        {law and friction}

        Returns
        -------
        Contact
            The ellipsoid, watched natively (:class:`varmech.surfaces.Ellipsoid`).

        Raises
        ------
        ValueError
            ``semi_axes``, ``coordinates`` and ``centre`` of different lengths, semi-axes not
            numbers, finite and positive, a centre not finite numbers, a coordinate not an integer
            ≥ 0, ``restitution``
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
        axes = tuple(float(a) for a in np.atleast_1d(floats("semi_axes", semi_axes)))
        ks = tuple(range(len(axes))) if coordinates is None else tuple(integer("coordinates", k) for k in np.atleast_1d(coordinates).tolist())
        c = (0.0,) * len(ks) if centre is None else tuple(float(x) for x in np.atleast_1d(floats("centre", centre)))
        surface = _surfaces.Ellipsoid(ks, c, axes, bool(inside))
        label = name if name is not None else ("ellipsoid" if inside else "outside an ellipsoid")
        return cls(surface, _surfaces.Gradient(surface), restitution, label, law, friction)


#: A contact as the binding takes it: (name, restitution, law, kind, payload, friction), the kind
#: and payload a native surface's (``Surface.native``) or ``("functions", (phi, gradient))``, the
#: friction ``Friction.spec()`` or None.
Spec = tuple[str, float, str, str, Any, Any]


def specs(contacts: Sequence[Contact]) -> list[Spec]:
    """The binding's tuples of ``contacts``, each a :class:`Contact` (TypeError naming
    ``contacts[i]``); the core checks each against the model and the initial state."""
    out: list[Spec] = []
    for i, c in enumerate(contacts):
        if not isinstance(c, Contact):
            raise TypeError(f"contacts[{i}]: expected a varmech.Contact, got {type(c).__name__}")
        kind, payload = c.phi.native if isinstance(c.phi, _surfaces.Surface) else ("functions", (c.phi, c.gradient))
        friction = None if c.friction is None else c.friction.spec()
        out.append((c.name, float(c.restitution), c.law, kind, payload, friction))
    return out


def occurrences(record: Any, contacts: Sequence[Contact | str], *, after: bool = False) -> tuple[Occurrences, ...]:
    """Each contact's impacts in the binding's record of a run (or its stepper's): time, contact
    configuration and the momenta just before (just after, ``after``)."""
    if not contacts:
        return ()
    index, t, q, before, p_after = record.impacts
    p = p_after if after else before
    if len(contacts) == 1:
        # Every impact is the one contact's: no mask (an ensemble makes these for every member).
        return (Occurrences(name(contacts[0]), t, q, p),)
    return tuple(Occurrences(name(c), t[index == i], q[index == i], p[index == i]) for i, c in enumerate(contacts))


def switches(record: Any, contacts: Sequence[Contact | str]) -> tuple[Occurrences, ...]:
    """Each contact's switches in the binding's record of a run (or its stepper's), kind by kind
    (:data:`SWITCHES`): its closures, ``"<name>.closed"`` (at the limit of its bounces' Zeno
    series, with the state of the impact that closed it), its releases, ``"<name>.released"`` (at
    lift-off), and its friction's, ``"<name>.stuck"`` and ``"<name>.slipped"``."""
    if not contacts:
        return ()
    index, t, kind, q, p = record.switches
    names = occurrence_names(contacts)[len(contacts) :]
    if len(t) == 0:
        return tuple(Occurrences(n, t, q, p) for n in names)
    rows = [(index == i) & (kind == code) for code in range(len(SWITCHES)) for i in range(len(contacts))]
    return tuple(Occurrences(n, t[r], q[r], p[r]) for n, r in zip(names, rows))


def occurrence_names(contacts: Sequence[Contact | str]) -> list[str]:
    """The names of the contacts' occurrences in ``traj.events``: each contact's impacts
    (:func:`occurrences`), then their switches kind by kind (:func:`switches`)."""
    names = [name(c) for c in contacts]
    return names + [f"{n}.{kind}" for kind in SWITCHES for n in names]


def exchanges(model: Model, contacts: Sequence[Contact | str], impulses: Sequence[object] = ()) -> bool:
    """Whether anything can put energy into a run of ``model`` or take it out, so that the run
    records the energy put in, W (``traj.work``), and :func:`varmech.check_conservation` judges
    the balance E − W: the model's forces, an L that depends on t, a contact with friction or
    with restitution below 1 (each law's own loss; an elastic contact puts in none), or an
    impulse. The core counts W by the same rule (``Watch::exchanges``); a contact of Python
    functions loaded from a file as its name counts, its coefficients unknown."""
    touching = any(not isinstance(c, Contact) or c.friction is not None or c.restitution < 1 for c in contacts)
    return model.forced or model.time_dependent or touching or len(impulses) > 0


def acting(contact: Contact, q: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """The directions along which ``contact`` pushes at each configuration of ``q`` (N, n): its
    normal ∇φ, and with friction its slip rows J (a particle's tangent plane as the projector
    onto it), each as (what, rows of shape (N, k, n)). A momentum p·ξ whose ξ has a component
    along them is changed by the contact: its symmetry is broken there."""
    q = np.asarray(q, dtype=float)
    surface = contact.phi
    if isinstance(surface, _surfaces.Wall):
        normals = np.zeros_like(q)
        normals[:, surface.k] = 1.0
    elif isinstance(surface, _surfaces.Ellipsoid):
        normals = np.zeros_like(q)
        sign = -2.0 if surface.inside else 2.0
        for k, c, a in zip(surface.coordinates, surface.centre, surface.semi_axes):
            normals[:, k] += sign * (q[:, k] - c) / (a * a)
    else:
        normals = np.array([np.asarray(contact.gradient(x.copy()), dtype=float) for x in q]).reshape(q.shape)
    found = [(f"contact {contact.name!r} (its normal ∇φ·ξ ≠ 0)", normals[:, None, :])]
    friction = contact.friction
    if friction is None:
        return found
    what = f"the friction of contact {contact.name!r} (its slip rows J·ξ ≠ 0)"
    if friction.slip is None:
        # The tangent plane: J·ξ ≠ 0 exactly where ξ leaves the normal's line.
        size = np.sum(normals**2, axis=1)[:, None, None]
        outer = normals[:, :, None] * normals[:, None, :]
        projector = np.eye(q.shape[1])[None] - np.divide(outer, size, out=np.zeros_like(outer), where=size > 0)
        found.append((what, projector))
    elif callable(friction.slip):
        found.append((what, np.array([np.reshape(np.asarray(friction.slip(x.copy()), dtype=float), (-1, q.shape[1])) for x in q])))
    else:
        found.append((what, np.broadcast_to(np.asarray(friction.slip, dtype=float), (len(q), *np.shape(friction.slip)))))
    return found


class ImpactWarning(VarmechWarning, RuntimeWarning):
    """Grazing impacts whose discrete-energy equation had no solution near the reflection, and
    which took Newton's law of restitution instead (a :class:`RuntimeWarning` too, as it was).

    :func:`varmech.integrate` issues it once a run, with the count, where a contact's
    ``law="variational"`` met such impacts; the run goes on.

    Examples
    --------
    >>> import warnings, varmech
    >>> issubclass(varmech.ImpactWarning, (varmech.VarmechWarning, RuntimeWarning))
    True
    >>> with warnings.catch_warnings():   # one's grazing impacts, expected
    ...     warnings.simplefilter("ignore", varmech.ImpactWarning)
    """


def warn_grazing(count: int, stacklevel: int) -> None:
    """The :class:`ImpactWarning` of ``count`` grazing impacts (none: no warning), at the caller
    ``stacklevel`` frames up from here."""
    if count:
        warnings.warn(
            f"{count} grazing impact(s) had no discrete-energy solution near the reflection and took Newton's law",
            ImpactWarning,
            stacklevel=stacklevel + 1,
        )


def name(contact: Contact | str) -> str:
    """A contact's name (a loaded file's contact given by Python functions is its name)."""
    return contact if isinstance(contact, str) else contact.name


def stored(contacts: Sequence[Contact | str]) -> str:
    """The contacts as a file stores them, JSON: each native one's name, restitution, law,
    surface (``Surface.native``) and friction (``Friction.spec()`` or null), and null for one given
    by Python functions (no code is stored)."""
    rows = [
        [c.name, c.restitution, c.law, *c.phi.native, None if c.friction is None else c.friction.spec()]
        if isinstance(c, Contact) and c.native and isinstance(c.phi, _surfaces.Surface)
        else None
        for c in contacts
    ]
    return json.dumps(rows)


def restored(text: str, names: Sequence[str]) -> tuple[Contact | str, ...]:
    """The contacts a file stored (:func:`stored`), those given by Python functions as their
    ``names``; ValueError naming ``path`` for a record that is not one."""
    try:
        rows = json.loads(text)
        out: list[Contact | str] = []
        for row, label in zip(rows, names, strict=True):
            if row is None:
                out.append(str(label))
                continue
            name, restitution, law, kind, payload, *rest = row
            friction = None
            if rest and rest[0] is not None:
                mu_s, mu_k, slip = rest[0]
                friction = Friction(mu_s, mu_k, None if slip is None else np.reshape(slip[1], (slip[0], -1)))
            surface: _surfaces.Surface
            if kind == "crossing":
                k, value = payload
                surface = _surfaces.Wall(integer("k", k), number("value", value))
            else:
                ks, centre, axes, inside = payload
                surface = _surfaces.Ellipsoid(tuple(ks), tuple(centre), tuple(axes), bool(inside))
            out.append(Contact(surface, _surfaces.Gradient(surface), restitution, name, law, friction))
        return tuple(out)
    except (ValueError, TypeError) as e:
        raise ValueError(f"path: its contacts are not a stored contact list ({e})") from None


def going_on(stored: Sequence[Contact | str], given: Sequence[Contact] | None = None) -> tuple[Contact, ...]:
    """The contacts a continued run goes on with: its own, or ``given`` in their place (the same
    names, in the same order); a ValueError naming ``contacts`` for one of Python functions
    loaded from a file as its name and not given again."""
    if given is None:
        unknown = [c for c in stored if isinstance(c, str)]
        if unknown:
            raise ValueError(
                f"contacts: the run's contacts {', '.join(map(repr, unknown))} were given by Python functions, which its"
                " file does not store; pass them again: varmech.resume(path, contacts=[...])"
            )
        return tuple(c for c in stored if isinstance(c, Contact))
    specs(given)
    if [name(c) for c in given] != [name(c) for c in stored]:
        raise ValueError(f"contacts: the run has the contacts {[name(c) for c in stored]}, not {[name(c) for c in given]}")
    return tuple(given)
