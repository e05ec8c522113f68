"""Impacts with unilateral constraints φ(q) ≥ 0 (walls, floors, billiard tables): the
specification. The core resolves them in its step loop (``rust/core/src/integrators/jumps/``),
so a run with contacts composes with events, output files and their checkpoints, ``resume``,
continued runs (``integrate(traj, steps=)``) and ensembles.

The step that crosses a surface is split at the contact: the method's own partial step of size
αh from (qₙ, pₙ) to the contact configuration q̃ on φ = 0 (α located to round-off), the jump
p⁺ = p⁻ + λ∇φ(q̃), and the method's partial step of size (1 − α)h to the grid time tₙ₊₁. The
contact's ``law`` fixes λ:

- ``"variational"`` (the default; kick–drift methods, ``MethodInfo.splitting``, the implicit
  two-point rules ``midpoint`` and ``trapezoid`` and the Galerkin rules ``galerkin4`` and
  ``galerkin6``): the variational collision integrator of Fetecau, Marsden, Ortiz & West (2003).
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
``traj.events``. Where the method cannot hold a contact (not a Verlet composition, or a model with
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
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from . import surfaces as _surfaces
from ._core import ContactError
from ._util import floats, integer, number
from .events import Occurrences

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
        The impact law: the variational collision integrator (the discrete energy kept; for
        kick–drift methods, the two-point rules ``midpoint`` and ``trapezoid`` and the Galerkin
        rules ``galerkin4`` and ``galerkin6``, elastic contacts only), or the exact reflection of the momenta between the method's partial
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
    #: The impact law: ``"variational"``, the variational collision integrator (the discrete energy kept;
    #: kick–drift methods, the two-point rules ``midpoint`` and ``trapezoid``, the Galerkin rules), or
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
        return cls(surface, _surfaces.Gradient(surface), restitution, label, law)


#: A contact as the binding takes it: (name, restitution, law, kind, payload), the kind and
#: payload a native surface's (``Surface.native``) or ``("functions", (phi, gradient))``.
Spec = tuple[str, float, str, str, Any]


def specs(contacts: Sequence[Contact]) -> list[Spec]:
    """The binding's tuples of ``contacts``, each a :class:`Contact` (TypeError naming
    ``contacts[i]``); the core checks each against the model and the initial state."""
    out: list[Spec] = []
    for i, c in enumerate(contacts):
        if not isinstance(c, Contact):
            raise TypeError(f"contacts[{i}]: expected a varmech.Contact, got {type(c).__name__}")
        kind, payload = c.phi.native if isinstance(c.phi, _surfaces.Surface) else ("functions", (c.phi, c.gradient))
        out.append((c.name, float(c.restitution), c.law, kind, payload))
    return out


def occurrences(record: Any, contacts: Sequence[Contact | str], *, after: bool = False) -> tuple[Occurrences, ...]:
    """Each contact's impacts in the binding's record of a run (or its stepper's): time, contact
    configuration and the momenta just before (just after, ``after``)."""
    if not contacts:
        return ()
    index, t, q, before, p_after = record.impacts
    p = p_after if after else before
    return tuple(Occurrences(name(c), t[index == i], q[index == i], p[index == i]) for i, c in enumerate(contacts))


def switches(record: Any, contacts: Sequence[Contact | str]) -> tuple[Occurrences, ...]:
    """Each contact's closures in the binding's record of a run (or its stepper's), named
    ``"<name>.closed"`` (at the limit of its bounces' Zeno series, with the state of the impact
    that closed it), then each one's releases, ``"<name>.released"`` (at lift-off)."""
    if not contacts:
        return ()
    index, t, closed, q, p = record.switches
    names = occurrence_names(contacts)[len(contacts) :]
    rows = [(index == i) & (closed == flag) for flag in (True, False) for i in range(len(contacts))]
    return tuple(Occurrences(n, t[r], q[r], p[r]) for n, r in zip(names, rows))


def occurrence_names(contacts: Sequence[Contact | str]) -> list[str]:
    """The names of the contacts' occurrences in ``traj.events``: each contact's impacts
    (:func:`occurrences`), then each one's closures and each one's releases (:func:`switches`)."""
    names = [name(c) for c in contacts]
    return names + [f"{n}.closed" for n in names] + [f"{n}.released" for n in names]


def warn_grazing(count: int, stacklevel: int) -> None:
    """The RuntimeWarning of ``count`` grazing impacts (none: no warning), at the caller
    ``stacklevel`` frames up from here."""
    if count:
        warnings.warn(
            f"{count} grazing impact(s) had no discrete-energy solution near the reflection and took Newton's law",
            RuntimeWarning,
            stacklevel=stacklevel + 1,
        )


def name(contact: Contact | str) -> str:
    """A contact's name (a loaded file's contact given by Python functions is its name)."""
    return contact if isinstance(contact, str) else contact.name


def stored(contacts: Sequence[Contact | str]) -> str:
    """The contacts as a file stores them, JSON: each native one's name, restitution, law and
    surface (``Surface.native``), and null for one given by Python functions (no code is stored)."""
    rows = [
        [c.name, c.restitution, c.law, *c.phi.native] if isinstance(c, Contact) and isinstance(c.phi, _surfaces.Surface) else None
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
            name, restitution, law, kind, payload = row
            surface: _surfaces.Surface
            if kind == "crossing":
                k, value = payload
                surface = _surfaces.Wall(integer("k", k), number("value", value))
            else:
                ks, centre, axes, inside = payload
                surface = _surfaces.Ellipsoid(tuple(ks), tuple(centre), tuple(axes), bool(inside))
            out.append(Contact(surface, _surfaces.Gradient(surface), restitution, name, law))
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
