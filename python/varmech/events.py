"""Events: functions of the state whose zero crossings a run locates, and may stop at.

``varmech.integrate(..., events=[...])`` follows :func:`scipy.integrate.solve_ivp`: each event is
a function g(t, q, p) with a ``direction`` (+1: only crossings where g increases, −1: where it
decreases, 0: both) and ``terminal`` (True: stop at the first occurrence; an integer k: at the
k-th; False: never). A plain function with those attributes is an event, as in scipy; so is an
:class:`Event`, which also says whether the function takes the momenta p or the velocities
q̇ = v (``variables="v"``, g(t, q, v)). The built-in events, :func:`crossing`,
:func:`energy_error`, :func:`escape` and :func:`encounter`, are evaluated in the Rust core with
no Python call per step (and without the GIL for native models); a Python function is called
once per step, and a few times more per crossing.

How a crossing is located
-------------------------
After every step zₙ → zₙ₊₁ (the steps are taken one at a time when events are given) each g is
evaluated; a crossing is g(zₙ) ≠ 0 with g(zₙ₊₁) of the other sign or 0. It is located on the
method's own map: τ* ∈ (0, h] with g(Φ_τ*(zₙ)) = 0 to round-off, Φ_τ one step of size τ of the
same method from zₙ, found by the Illinois method on the bracket [0, h] (a handful of partial
steps). The located state is therefore a state of the integrator, with the method's own error
(order p), not an interpolant's; its time is off the exact crossing time by O(hᵖ).

A terminal event stops the run at the end of the step in which its last counted crossing
occurred: the trajectory's last state is a state of the step grid (a continuation from it is the
same as one longer run), the located crossing is in ``traj.events``, ``traj.status`` is 1 and
``traj.message`` names the event.

Examples
--------
The harmonic oscillator q = sin t falls through q = 0 at t = π and 3π:

>>> import numpy as np
>>> import varmech
>>> from varmech.events import crossing
>>> traj = varmech.integrate(varmech.scenes.harmonic_oscillator(), dt=0.01, t_end=10.0,
...                          events=[crossing(0, 0.0, direction=-1)])
>>> np.round(traj.events[0].t / np.pi, 4)
array([1., 3.])
>>> bool(abs(traj.events[0].q[:, 0]).max() < 1e-15)
True
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, TypeVar

import numpy as np

from . import _core
from ._util import finite, integer, number, positive, positive_int, with_sections

#: An event function g(t, q, p) (or g(t, q, v), see :class:`Event`).
EventFunction = Callable[[float, np.ndarray, np.ndarray], float]

_F = TypeVar("_F", bound=Callable[..., Any])

# The docstring sections the built-in events share, put in for their placeholders by
# :func:`_documented` (as varmech.charts does its charts').
_SECTIONS = {
    "{terminal}": """terminal
        Stop the run at the end of the step of the first crossing (True), of the k-th (an
        integer k), or never (False).""",
    "{returns}": """Returns
    -------
    Event
        The event, for ``integrate(..., events=[...])``: its crossings are located by a partial
        step of the method and kept in ``traj.events``.""",
    # escape's and encounter's, both checked by _distance.
    "{distance raises}": """Raises
    ------
    ValueError
        ``radius`` not finite and positive, or ``groups`` not lists of indices of one length,
        naming it.""",
}


def _documented(event: _F) -> _F:
    """``event`` with the shared sections put into its docstring for their placeholders."""
    return with_sections(event, _SECTIONS)


@dataclass(frozen=True)
class Event:
    """An event: the function g and how its crossings are watched.

    A crossing is a sign change of g(t, q, p) over a step; :func:`varmech.integrate` locates it
    by a partial step of the method (see the module's documentation) and records it in the
    trajectory's ``events``.

    Attributes
    ----------
    function : callable or None
        g(t, q, p) → float, or g(t, q, v) with ``variables="v"`` (v = q̇, the velocities).
        None for the built-in events, which carry a ``native`` spec instead.
    direction : int, default 0
        +1: count only crossings where g increases (− to +); −1: where it decreases; 0: both.
    terminal : bool or int, default False
        True: the run stops after the step of the first crossing; an integer k ≥ 1: of the k-th;
        False: never.
    variables : {"p", "v"}, default "p"
        ``"p"``: g takes the momenta; ``"v"``: the velocities.
    name : str, default ""
        Shown in messages (empty: the function's ``__name__``).
    native : (str, object) or None, default None
        A built-in event's spec for the core, (kind, payload), as :func:`crossing` and the other
        built-in events set it; None for a Python function.

    See Also
    --------
    crossing : The built-in event q_k = value, evaluated natively.
    Occurrences : The located crossings of an event.

    Examples
    --------
    The pendulum H = p²/2 − cos q from (0, 1) swings up to q̇ = 0 at its turning point
    q = arccos(1/2) = π/3:

    >>> import numpy as np
    >>> import varmech
    >>> from varmech.events import Event
    >>> turn = Event(lambda t, q, v: v[0], direction=-1, terminal=True, variables="v", name="turn")
    >>> traj = varmech.integrate(varmech.scenes.pendulum(), dt=0.01, t_end=10.0, events=[turn])
    >>> traj.status, traj.message
    (1, 'A termination event occurred: turn (occurrence 1) at t = 1.68575.')
    >>> round(float(traj.events[0].q[0, 0] / np.pi), 4)
    0.3333
    """

    function: EventFunction | None
    direction: int = 0
    terminal: bool | int = False
    variables: Literal["p", "v"] = "p"
    name: str = ""
    #: The built-in event's spec for the core: (kind, payload).
    native: tuple[str, Any] | None = field(default=None, repr=False)


@dataclass(frozen=True)
class Occurrences:
    """The located crossings of one event, in order of time.

    Each crossing is a state of the integrator (a partial step of the method); ``len()`` is
    their number. ``trajectory.events[i]`` holds those of the i-th event.

    Attributes
    ----------
    name : str
        The event's name.
    t : numpy.ndarray
        The crossing times, shape (k,).
    q : numpy.ndarray
        The positions at the crossings, shape (k, n).
    p : numpy.ndarray
        The momenta at the crossings, shape (k, n).

    Examples
    --------
    The harmonic oscillator q = sin t crosses q = 0 downward at t = π and 3π:

    >>> import numpy as np
    >>> import varmech
    >>> from varmech.events import crossing
    >>> traj = varmech.integrate(varmech.scenes.harmonic_oscillator(), dt=0.01, t_end=10.0,
    ...                          method="kahan_li6", events=[crossing(0, direction=-1)])
    >>> found = traj.events[0]
    >>> len(found), (found.t / np.pi).round(6)
    (2, array([1., 3.]))
    """

    name: str
    t: np.ndarray
    q: np.ndarray
    p: np.ndarray

    def __len__(self) -> int:
        return len(self.t)

    def __eq__(self, other: object) -> bool:
        """Equal names and arrays (the generated comparison would ask arrays for one truth value)."""
        if not isinstance(other, Occurrences):
            return NotImplemented
        pairs = ((self.t, other.t), (self.q, other.q), (self.p, other.p))
        return self.name == other.name and all(np.array_equal(a, b) for a, b in pairs)


@_documented
def crossing(k: int, value: float = 0.0, *, direction: int = 0, terminal: bool | int = False) -> Event:
    """The coordinate q_k crossing ``value``: g = q_k − value (evaluated natively).

    Parameters
    ----------
    k
        The coordinate's index.
    value
        The level it crosses.
    direction
        +1: only upward crossings (g from − to +); −1: only downward; 0: both.
    {terminal}

    {returns}

    Raises
    ------
    ValueError
        ``k`` not a non-negative integer, or ``value`` not finite, naming it (an index beyond
        the model's coordinates is refused by ``integrate``, naming ``events``).

    Examples
    --------
    >>> import varmech
    >>> traj = varmech.integrate(varmech.scenes.harmonic_oscillator(), dt=0.01, t_end=10.0,
    ...                          events=[crossing(0, 0.5, direction=+1)])
    >>> len(traj.events[0])   # sin t rises through 1/2 at π/6 and 2π + π/6
    2
    """
    k = integer("k", k)
    value = finite("value", value)
    return Event(None, direction, terminal, name=f"q[{k}] = {value:g}", native=("crossing", (k, value)))


@_documented
def energy_error(bound: float, *, terminal: bool | int = True) -> Event:
    """The energy error growing beyond ``bound``: g = |E(q, p) − E₀| − bound, E₀ the energy at
    the start, crossing upward (evaluated natively). Terminal by default: a run that stops when
    its energy is off by more than it can accept.

    Parameters
    ----------
    bound
        The largest acceptable |E − E₀|, absolute.
    {terminal}

    {returns}

    Raises
    ------
    ValueError
        ``bound`` not finite and positive, naming it.

    Examples
    --------
    Explicit Euler multiplies the oscillator's energy ½ by 1 + h² a step: it passes ½ + 0.01
    during step 199, log(1.02)/log(1.0001) = 198.03:

    >>> import varmech
    >>> traj = varmech.integrate(varmech.scenes.harmonic_oscillator(), dt=0.01, t_end=100.0,
    ...                          method="explicit_euler", max_energy_error=None, events=[energy_error(0.01)])
    >>> traj.status, round(float(traj.t[-1]), 2)
    (1, 1.99)
    """
    bound = positive("bound", bound)
    return Event(None, +1, terminal, name=f"|E - E0| > {bound:g}", native=("energy_error", bound))


@_documented
def multiplier(k: int = 0, *, direction: int = 0, terminal: bool | int = False) -> Event:
    """The multiplier λ_k of the model's constraints crossing 0: g = λ_k (evaluated natively, in
    the core). λ is :meth:`Trajectory.reactions`'s, with Lagrange's sign (the constraints'
    force is Cᵀλ), so this is where a held contact's force or a string's tension vanishes: the
    instant a body on a surface would leave it (lift-off), or a string go slack. Located by a
    partial step of the method, like every event, so to the method's order.

    Parameters
    ----------
    k
        The row of λ (holonomic constraints first, then velocity constraints).
    direction
        +1: only crossings upward; −1: only downward; 0: both.
    {terminal}

    Returns
    -------
    Event
        The event, for ``integrate(..., events=[...])``; the model must have a row k.

    Raises
    ------
    ValueError
        ``k`` not an integer ≥ 0; at ``integrate``, ``direction`` not a number or a model
        without row k (naming ``events``).

    Examples
    --------
    A particle sliding from rest at the top of a smooth sphere of radius 1 (x, z), held on it
    by ½(x² + z² − 1) = 0: the sphere pushes, λ > 0, until z = 2/3 (cos θ = 2/3), where it
    would leave it:

    >>> import numpy as np, varmech
    >>> sphere = varmech.MechanicalSystem(2, lambda q: q[1], lambda q: np.array([0.0, 1.0]),
    ...     constraints=lambda q: np.array([0.5 * (q @ q - 1)]), constraint_jacobian=lambda q: q[None, :].copy(),
    ...     constraint_count=1)
    >>> q0 = [np.sin(1e-3), np.cos(1e-3)]
    >>> traj = varmech.integrate(sphere, q0, v0=[0.0, 0.0], dt=1e-3, t_end=20.0, method="rattle4",
    ...                          events=[varmech.events.multiplier(0, direction=-1, terminal=True)])
    >>> z = traj.events[0].q[0, 1]
    >>> round(float(z), 6), round(2 / 3 * float(np.cos(1e-3)), 6)
    (0.666666, 0.666666)
    """
    k = integer("k", k)
    return Event(None, direction, terminal, name=f"lambda[{k}] = 0", native=("multiplier", k))


@_documented
def escape(radius: float, *, groups: Sequence[Sequence[int]] | None = None, dim: int = 3, terminal: bool | int = True) -> Event:
    """A group of coordinates (a body's position) leaving the ball of ``radius`` about the
    origin: g = maxⱼ |x_j|² − radius², crossing upward (evaluated natively). Terminal by default.

    Parameters
    ----------
    radius
        The ball's radius.
    groups
        The coordinate indices of each position x_j; default: consecutive blocks of ``dim``
        (the bodies of an N-body scene, 3 coordinates each; ``dim=2`` for the planar Kepler
        problem).
    dim
        The size of each block when ``groups`` is not given.
    {terminal}

    {returns}

    {distance raises}

    Examples
    --------
    A hyperbolic Kepler orbit (E > 0) leaves r = 10:

    >>> import numpy as np
    >>> import varmech
    >>> kepler = varmech.scenes.kepler()
    >>> traj = varmech.integrate(kepler.model, [1.0, 0.0], [0.0, 1.6], dt=0.01, t_end=100.0,
    ...                          events=[escape(10.0, dim=2)])
    >>> traj.status, bool(abs(np.hypot(*traj.events[0].q[0]) - 10.0) < 1e-12)
    (1, True)
    """
    return _distance("escape", radius, groups, dim, +1, terminal)


@_documented
def encounter(radius: float, *, groups: Sequence[Sequence[int]] | None = None, dim: int = 3, terminal: bool | int = True) -> Event:
    """Two groups of coordinates (bodies' positions) coming closer than ``radius``:
    g = min_{i<j} |x_i − x_j|² − radius², crossing downward; with a single group, its distance
    to the origin (evaluated natively). Terminal by default.

    Parameters
    ----------
    radius
        The distance below which the groups have met.
    groups, dim
        The positions, as for :func:`escape`.
    {terminal}

    {returns}

    {distance raises}

    Examples
    --------
    The Kepler orbit of eccentricity 0.6 (from pericentre r = 0.4) comes back within r = 0.5
    once a period, 2π:

    >>> import varmech
    >>> traj = varmech.integrate(varmech.scenes.kepler(), dt=0.001, t_end=10.0,
    ...                          events=[encounter(0.5, dim=2, terminal=False)])
    >>> len(traj.events[0])
    1
    """
    return _distance("encounter", radius, groups, dim, -1, terminal)


def _distance(kind: str, radius: float, groups: Sequence[Sequence[int]] | None, dim: int, direction: int, terminal: bool | int) -> Event:
    radius = positive("radius", radius)
    if groups is not None:
        try:
            spec: Any = [[integer("groups", k) for k in g] for g in groups]
        except TypeError:
            raise TypeError(f"groups: expected sequences of coordinate indices, got {groups!r}") from None
    else:
        spec = positive_int("dim", dim)
    return Event(None, direction, terminal, name=f"{kind}({radius:g})", native=(kind, (radius, spec)))


def _event(i: int, e: Event | EventFunction) -> Event:
    """The Event of an events item: an Event, or a function with solve_ivp's attributes."""
    if isinstance(e, Event):
        return e
    if not callable(e):
        raise TypeError(f"events[{i}]: expected a function g(t, q, p) or a varmech.events.Event, got {type(e).__name__}")
    return Event(e, getattr(e, "direction", 0), getattr(e, "terminal", False), getattr(e, "variables", "p"))


def _name(i: int, e: Event) -> str:
    return e.name or getattr(e.function, "__name__", "") or f"events[{i}]"


def _terminal(label: str, terminal: Any) -> int:
    """The terminal count: 0 for never."""
    if isinstance(terminal, (bool, np.bool_)):
        return int(terminal)
    if isinstance(terminal, (int, np.integer)) and terminal >= 1:
        return int(terminal)
    raise ValueError(f"{label}: terminal must be True, False or a count ≥ 1, got {terminal!r}")


def _direction(label: str, direction: Any) -> int:
    try:
        d = number("direction", direction)
    except TypeError:
        raise TypeError(f"{label}: direction must be a number (its sign counts), got {direction!r}") from None
    except ValueError:
        raise ValueError(f"{label}: direction must be a number (its sign counts), got {direction!r}") from None
    if math.isnan(d):
        raise ValueError(f"{label}: direction must be a number (its sign counts), got {direction!r}")
    return int(np.sign(d))


def _check_signature(label: str, e: Event) -> None:
    """A TypeError naming the event unless its function takes (t, q, p) positionally."""
    try:
        signature = inspect.signature(e.function)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return  # no signature to check (some builtins): the call will tell
    try:
        signature.bind(0.0, None, None)
    except TypeError:
        x = "v" if e.variables == "v" else "p"
        raise TypeError(f"{label}: an event function takes (t, q, {x}), got {signature}") from None


def specs(events: Sequence[Event | EventFunction], model: Any) -> tuple[list[Event], list[tuple[str, int, int, str, Any]]]:
    """The events as Events, and the spec tuples the binding takes (name, direction, terminal,
    kind, payload) for ``model`` (its coordinates, and its constraint rows, holonomic and
    velocity). Malformed ones are refused naming them."""
    n, rows = model.dim, model.constraints + model.velocity_constraints
    if isinstance(events, (Event,)) or callable(events) or isinstance(events, (str, bytes)):
        raise TypeError("events: expected a list of event functions or varmech.events.Event")
    items = [_event(i, e) for i, e in enumerate(events)]
    out = []
    for i, e in enumerate(items):
        name = _name(i, e)
        label = f"events[{i}] ({name})"
        direction, terminal = _direction(label, e.direction), _terminal(label, e.terminal)
        if e.native is not None:
            kind, payload = e.native
            if kind in ("escape", "encounter") and isinstance(payload[1], int):
                radius, dim = payload
                if n % dim:
                    raise ValueError(f"{label}: {n} coordinates are not blocks of dim = {dim}; pass dim or groups")
                payload = (radius, [list(range(j, j + dim)) for j in range(0, n, dim)])
            if kind == "multiplier" and payload >= rows:
                has = f"{rows} constraint rows (holonomic, then velocity)" if rows else "no constraints"
                raise ValueError(f"{label}: the model has {has}; λ_{payload} is not one of them")
        else:
            if e.variables not in ("p", "v"):
                raise ValueError(f"{label}: variables must be 'p' or 'v', got {e.variables!r}")
            if not callable(e.function):
                raise TypeError(f"{label}: the function must be callable, got {type(e.function).__name__}")
            _check_signature(label, e)
            kind, payload = e.variables, e.function
        out.append((name, direction, terminal, kind, payload))
    return items, out


def occurrences(record: _core.TrajectoryRecord | _core.Stepper, events: Sequence[Event]) -> tuple[Occurrences, ...]:
    """Each event's located crossings, from the binding's record of a run (or a stepper's so far)."""
    if not events:
        return ()
    index, t, q, p = record.events[:4]
    return tuple(
        Occurrences(_name(i, e), t[index == i], q[index == i], p[index == i]) for i, e in enumerate(events)
    )


def occurrences_of(events: Sequence[Event]) -> tuple[Occurrences, ...]:
    """No crossings yet of each event (their names)."""
    empty = np.empty(0)
    return tuple(Occurrences(_name(i, e), empty, empty, empty) for i, e in enumerate(events))


def going_on(specs: list[Any], found: Sequence[int], initial_energy: float) -> list[Any]:
    """The spec tuples of a run resumed after ``found`` crossings of each event: terminal
    counts less those found, and the energy error measured from the whole run's E₀."""
    out = []
    for (name, direction, terminal, kind, payload), k in zip(specs, found):
        if kind == "energy_error":
            payload = (payload[0] if isinstance(payload, tuple) else payload, initial_energy)
        out.append((name, direction, terminal - k if terminal else 0, kind, payload))
    return out


def termination(record: _core.TrajectoryRecord, events: Sequence[Event], found: tuple[Occurrences, ...]) -> dict[str, Any]:
    """The status and message of a run a terminal event stopped (solve_ivp's status 1), else
    nothing."""
    i = record.terminated_by
    if i is None:
        return {}
    last = found[i]
    return {"status": 1, "message": termination_message(last, len(last))}


def termination_message(last: Occurrences, count: int) -> str:
    """What stopped a run: the ``count``-th crossing of an event, the last of ``last``."""
    return f"A termination event occurred: {last.name} (occurrence {count}) at t = {last.t[-1]:.6g}."


def found_before(previous: Sequence[Occurrences], events: Sequence[Event]) -> list[int]:
    """The crossings of each of ``events`` in a run gone on from, ``previous``: its counts when
    they are the same events (by name), none otherwise."""
    names = [o.name for o in occurrences_of(events)]
    return [len(o) for o in previous] if [o.name for o in previous] == names else [0] * len(names)


def first_energy(model: Any, run: Any) -> float:
    """E at the first state of ``run`` (a trajectory, lazy or not, or the binding's record): the
    E₀ an energy-error event measures from, read as one row."""
    t = np.array([float(run.t[0])])
    q, p = (np.atleast_2d(np.asarray(x[0], dtype=float)) for x in (run.q, run.p))
    return float(_core.energy_terms(model._core, t, q, p)[0][0])


__all__ = ["Event", "Occurrences", "crossing", "encounter", "energy_error", "escape", "multiplier"]
