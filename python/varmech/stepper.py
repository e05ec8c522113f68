"""A model, a method and the state, advanced step by step."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from . import events as _events
from . import impacts as _impacts
from . import impulses as _impulses
from ._runspec import Jumps, RunSpec
from ._util import finite, floats, positive, step_count
from .events import Event, EventFunction, Occurrences
from .impacts import Contact
from .impulses import Impulse
from .model import Model, check_delays, initial_state
from .scenes import Scene
from .scenes._scene import contacts_of, model_and_state

__all__ = [
    "Stepper",
]


class Stepper:
    """One model, one method and the state (t, q, p), advanced one step or n steps at a time.

    :func:`varmech.integrate` is a stepper run to the end with its states saved; a stepper
    keeps only the current state, so that a caller can look at it between steps: locate an
    event, change the step size, start again from another state. Its steps are exactly
    ``integrate``'s: n calls of :meth:`step` land bit for bit on the final state of
    ``integrate(..., steps=n)`` with the same arguments, contacts included: a step that crosses
    a contact is split at the impact as a run's is (see :mod:`varmech.impacts`), and the
    impacts gone through are :attr:`impacts`; so is a step that holds an impulse's time. Events
    are located as a run's are (:attr:`events`); a terminal one stops :meth:`advance` at the end
    of the step of its crossing (:attr:`terminated_by`), and the next call goes on.

    Parameters
    ----------
    model, q0, p0, v0, method, t0
        As for :func:`varmech.integrate`: the model or scene (whose initial state is then the
        default), the initial state (n,), with the velocities ``v0`` instead of the momenta
        ``p0`` if given, the method (by default the model kind's) and the initial time.
    dt
        The step h > 0; settable between steps (:attr:`dt`).
    compensated, newton_tolerance, newton_max_iterations
        As for :func:`varmech.integrate`.
    contacts : sequence of Contact, optional
        The unilateral contacts φ(q) ≥ 0 whose impacts the steps go through, as for
        :func:`varmech.integrate`. Default: a scene's ``contacts``; ``contacts=[]`` steps
        without them.
    impulses : sequence of Impulse, optional
        Blows at their times ``impulse.t`` ≥ t0, as for :func:`varmech.integrate`: the step that
        holds one is split there (one at t0 acts at once).
    events : sequence of callable or Event, optional
        Event functions g(t, q, p) or :mod:`varmech.events` helpers, as for
        :func:`varmech.integrate`: their crossings accumulate in :attr:`events`; terminal counts
        carry over from call to call (as a run gone on from counts them), and ``energy_error``
        measures from the state the stepper starts (or is reset) at.

    Raises
    ------
    ValueError
        Malformed arguments (the message starts with the argument's name), a method that does
        not integrate the model, or initial data off a constrained model's constraints; naming
        ``contacts`` for a contact that does not fit the model or method (a restitution outside
        [0, 1], a coordinate out of range, the variational law on a method without a discrete
        energy) and ``q0`` for an initial state outside a contact (φ < 0), as ``integrate``.
        Naming ``impulses`` for an impulse before t0 or of another number of components, and
        ``events`` or ``events[i]`` for a malformed event, as ``integrate``.
    TypeError
        Naming ``contacts[i]`` or ``impulses[i]`` for an entry that is not a
        :class:`~varmech.Contact` or :class:`~varmech.Impulse`, ``events`` for a single event
        rather than a list.

    Notes
    -----
    :meth:`step` and :meth:`advance` raise what :func:`varmech.integrate` raises
    (:class:`~varmech.DivergenceError`, :class:`~varmech.ConvergenceError`,
    :class:`~varmech.ContactError` for an impact that cannot be resolved, a closure's own
    exception, KeyboardInterrupt on Ctrl-C during :meth:`advance`), with ``err.step`` and
    ``err.time`` where the exception allows; the stepper then stays at the last good step.
    Native models step with the GIL released.

    Examples
    --------
    >>> import varmech
    >>> kepler = varmech.scenes.kepler()
    >>> stepper = varmech.Stepper(kepler, dt=0.01, method="verlet")
    >>> stepper.advance(100)
    >>> round(stepper.t, 12), stepper.steps
    (1.0, 100)
    >>> traj = varmech.integrate(kepler, dt=0.01, steps=100, method="verlet")
    >>> bool((stepper.q == traj.q[-1]).all() and (stepper.p == traj.p[-1]).all())
    True
    >>> stepper.reset(traj.q[0], traj.p[0], t0=0.0)
    >>> stepper.dt = 0.005
    >>> stepper.advance(t_end=0.5)
    >>> stepper.steps
    100

    A bouncing ball goes through its floor's impacts (the scene's contact), step by step, as
    ``integrate`` does; the first impact is at √(2h₀/g), to round-off:

    >>> ball = varmech.scenes.bouncing_ball()
    >>> stepper = varmech.Stepper(ball, dt=0.01)
    >>> for _ in range(300):
    ...     stepper.step()
    >>> floor = stepper.impacts[0]
    >>> floor.name, len(floor), round(float(floor.t[0]), 12), round((2 / 9.81) ** 0.5, 12)
    ('floor', 3, 0.451523640986, 0.451523640986)
    >>> traj = varmech.integrate(ball, dt=0.01, steps=300)
    >>> bool((stepper.q == traj.q[-1]).all() and (stepper.p == traj.p[-1]).all())
    True

    A terminal event stops ``advance`` after the step of its crossing: the pendulum released
    from q = 1 passes q = 0 downwards after a quarter period, K(sin ½) = 1.67499:

    >>> from varmech.events import crossing
    >>> stepper = varmech.Stepper(varmech.scenes.pendulum(), [1.0], [0.0], dt=0.01,
    ...                           events=[crossing(0, 0.0, direction=-1, terminal=True)])
    >>> stepper.advance(1000)
    >>> stepper.terminated_by, stepper.steps, round(float(stepper.events[0].t[0]), 5)
    ('q[0] = 0', 168, 1.67499)
    """

    def __init__(
        self,
        model: Model | Scene,
        q0: ArrayLike | None = None,
        p0: ArrayLike | None = None,
        *,
        v0: ArrayLike | None = None,
        dt: float,
        method: str | None = None,
        t0: float = 0.0,
        compensated: bool = True,
        newton_tolerance: float = 1e-14,
        newton_max_iterations: int = 50,
        contacts: Sequence[Contact] | None = None,
        impulses: Sequence[Impulse] | None = None,
        events: Sequence[Event | EventFunction] | None = None,
    ) -> None:
        contacts = contacts_of(model, contacts)
        model, q0, p0 = model_and_state(model, q0, p0, v0)
        # What it was built with; its state, dt included, is the core stepper's from here on.
        self._spec = RunSpec.checked(
            model, dt=dt, method=method, t0=t0, compensated=compensated, newton_tolerance=newton_tolerance,
            newton_max_iterations=newton_max_iterations, contacts=contacts, impulses=impulses, events=events,
        )
        check_delays(model, bool(self._spec.jumps))
        q, p = initial_state(model, q0, p0, v0, self._spec.t0)
        self._model = model
        self._stepper = self._spec.stepper(model, q, p)

    def step(self) -> None:
        """Advance one step, from tₙ to tₙ₊₁ = tₙ + h.

        Raises
        ------
        DivergenceError
            The new state is not finite; the stepper stays at tₙ.
        ConvergenceError
            An implicit method's Newton iteration failed (or, as
            :class:`~varmech.SpuriousBranchError`, converged beyond a fold); the stepper stays
            at tₙ.
        ContactError
            An impact in the step that cannot be resolved (a resting contact, an accumulation
            of impacts); the stepper stays at tₙ.
        Exception
            A closure's own exception, unchanged.

        Examples
        --------
        One Störmer–Verlet step of the pendulum from (q, p) = (0, 1): q₁ = q₀ + hp₀ − ½h² sin q₀
        and p₁ = p₀ − ½h(sin q₀ + sin q₁).

        >>> import varmech
        >>> stepper = varmech.Stepper(varmech.scenes.pendulum(), dt=0.1)
        >>> stepper.step()
        >>> stepper.t, stepper.steps, stepper.q.tolist(), stepper.p.round(8).tolist()
        (0.1, 1, [0.1], [0.99500833])
        """
        self._stepping(self._stepper.step)

    def advance(self, steps: int | None = None, *, t_end: float | None = None) -> None:
        """Advance ``steps`` steps, or to ``t_end``, a whole number of steps from :attr:`t`.

        A terminal event stops it at the end of the step of its crossing (:attr:`terminated_by`
        names it). Ctrl-C stops it with KeyboardInterrupt, at the last step completed.

        Parameters
        ----------
        steps : int, optional
            How many steps to take.
        t_end : float, optional
            The time to reach instead, a whole number of steps h from :attr:`t`.

        Raises
        ------
        ValueError
            Naming ``steps, t_end`` when not exactly one is given, ``steps`` when it is not a
            non-negative integer, or ``t_end`` when it is before :attr:`t` or not a whole number
            of steps away.
        DivergenceError, ConvergenceError, ContactError
            As :meth:`step`, with ``err.step`` and ``err.time``; the stepper stays at the last
            good step.
        KeyboardInterrupt
            Ctrl-C, at the last step completed.

        Examples
        --------
        >>> import varmech
        >>> stepper = varmech.Stepper(varmech.scenes.pendulum(), dt=0.01)
        >>> stepper.advance(t_end=0.25)
        >>> stepper.steps, round(stepper.t, 12)
        (25, 0.25)
        >>> stepper.advance(t_end=0.255)
        Traceback (most recent call last):
            ...
        ValueError: t_end: 0.255 is not a whole number of steps dt = 0.01 from t0 = 0.25 (0.5 steps); adjust dt or pass steps
        """
        n = step_count(self.dt, self.t, steps, t_end)
        self._stepping(lambda: self._stepper.advance(n))

    def advance_tangent(self, tangent: ArrayLike, steps: int | None = None, *, t_end: float | None = None) -> np.ndarray:
        """Advance as :meth:`advance` does, carrying tangent vectors by the steps' own tangent map.

        Each step's linearization DΨ_h (a kick–drift step's shears, an implicit step's equations
        differentiated at their solution; see :func:`varmech.lyapunov_spectrum`) maps each
        vector (δq, δp) from the step's start to its end, in the core, with no Python call per
        step. The states are those of :meth:`advance`, bit for bit. The vectors are not
        renormalized: in a chaotic run they grow as e^(λ₁t), so a long one belongs to
        :func:`varmech.lyapunov_spectrum`; a step that takes them past the largest float is a
        :class:`~varmech.DivergenceError` (the step kept), never vectors of inf or NaN:
        renormalize them between shorter calls.

        Parameters
        ----------
        tangent : array_like, shape (2n,) or (2n, k)
            The vectors (δq, δp), one a column.
        steps, t_end
            As for :meth:`advance`.

        Returns
        -------
        numpy.ndarray
            The vectors carried to the last step, of ``tangent``'s shape.

        Raises
        ------
        ValueError
            ``tangent`` of another shape or not finite; a method or model without a tangent
            map (a kick–drift method on a model that is not separable, constraints, delayed
            forces), naming it; a stepper with contacts, impulses or events; ``steps, t_end``
            as for :meth:`advance`.
        DivergenceError, ConvergenceError
            As :meth:`step`; DivergenceError too where the vectors overflow.

        Examples
        --------
        One Verlet step of the harmonic oscillator (ω = 1) maps (δq, δp) by
        [[1 − h²/2, h], [−h(1 − h²/4), 1 − h²/2]], of determinant 1.

        >>> import numpy as np
        >>> import varmech
        >>> stepper = varmech.Stepper(varmech.scenes.get("harmonic_oscillator"), dt=0.1)
        >>> psi = stepper.advance_tangent(np.eye(2), steps=1)
        >>> psi.round(6).tolist(), bool(abs(np.linalg.det(psi) - 1) < 1e-15)
        ([[0.995, 0.1], [-0.09975, 0.995]], True)
        """
        dim = 2 * self.model.dim
        x = floats("tangent", tangent)
        if not (x.shape == (dim,) or (x.ndim == 2 and x.shape[0] == dim and x.shape[1] > 0)):
            raise ValueError(f"tangent: must have shape ({dim},) or ({dim}, k), columns (δq, δp), got {x.shape}")
        if not np.all(np.isfinite(x)):
            raise ValueError("tangent: must be finite")
        columns = x.reshape(dim, -1)
        n = step_count(self.dt, self.t, steps, t_end)
        carried = self._stepper.advance_tangent(n, np.ascontiguousarray(columns.T).ravel())
        return carried.reshape(-1, dim).T.reshape(x.shape).copy()

    def _stepping(self, steps: Callable[[], None]) -> None:
        """Takes the ``steps``, warning of their grazing impacts (as a run does)."""
        grazing = self._stepper.grazing
        steps()
        _impacts.warn_grazing(self._stepper.grazing - grazing, stacklevel=3)

    def reset(self, q0: ArrayLike, p0: ArrayLike | None = None, *, v0: ArrayLike | None = None, t0: float | None = None) -> None:
        """Start afresh from (q0, p0) (or q0 and the velocities v0) at ``t0`` (default: the
        current time), with :attr:`steps` at 0, no :attr:`impacts` and no :attr:`events` (their
        terminal counts whole again): the next steps are those of a new stepper from there. The
        work counts go on.

        Parameters
        ----------
        q0 : array_like, shape (n,)
            The positions.
        p0 : array_like, shape (n,), optional
            The momenta (or give ``v0``).
        v0 : array_like, shape (n,), optional
            The velocities, p0 = ∂L/∂q̇(q0, v0, t0) (M v0 for mechanical systems).
        t0 : float, optional
            The time (default: the current :attr:`t`).

        Raises
        ------
        ValueError
            Naming the argument: a state of the wrong shape or not finite, both or neither of
            ``p0`` and ``v0``, ``t0`` not finite, or velocities off a model's velocity
            constraints (a state off holonomic constraints names ``q0`` or ``p0``, one outside a
            contact ``q0``); the stepper is then unchanged.

        Examples
        --------
        From the velocities, at the current time, with the step count back at 0:

        >>> import varmech
        >>> stepper = varmech.Stepper(varmech.scenes.pendulum(), dt=0.01)
        >>> stepper.advance(10)
        >>> stepper.reset([0.0], v0=[2.0])
        >>> stepper.steps, round(stepper.t, 12), stepper.p.tolist()
        (0, 0.1, [2.0])
        """
        t0 = self.t if t0 is None else finite("t0", t0)
        q, p = initial_state(self._model, q0, p0, v0, t0)
        self._stepper.reset(q, p, t0, events=self._spec.jumps.event_specs or None)

    @property
    def model(self) -> Model:
        """The model stepped."""
        return self._model

    @property
    def contacts(self) -> tuple[Contact, ...]:
        """The contacts whose impacts the steps go through (empty without them)."""
        return self._spec.jumps.contacts

    @property
    def impacts(self) -> tuple[Occurrences, ...]:
        """Each contact's impacts since the start or the last :meth:`reset`, in the order of
        :attr:`contacts`: the times, the contact configurations q̃ and the momenta p⁻ just before
        the jump, as a run's ``traj.events`` holds them (:attr:`impacts_after` has p⁺)."""
        return _impacts.occurrences(self._stepper, self._spec.jumps.contacts)

    @property
    def impacts_after(self) -> tuple[Occurrences, ...]:
        """As :attr:`impacts`, with the momenta p⁺ just after each jump (a run's saved state
        just after the impact)."""
        return _impacts.occurrences(self._stepper, self._spec.jumps.contacts, after=True)

    @property
    def switches(self) -> tuple[Occurrences, ...]:
        """Each contact's closures since the start or the last :meth:`reset`, in the order of
        :attr:`contacts` (``"<name>.closed"``), then each one's releases (``"<name>.released"``),
        as a run's ``traj.events`` holds them after the impacts (see :mod:`varmech.impacts`)."""
        return _impacts.switches(self._stepper, self._spec.jumps.contacts)

    @property
    def events(self) -> tuple[Occurrences, ...]:
        """Each event's located crossings since the start or the last :meth:`reset`, in the order
        of the ``events`` given, as a run's ``traj.events``."""
        return _events.occurrences(self._stepper, self._spec.jumps.events)

    @property
    def terminated_by(self) -> str | None:
        """The name of the event whose terminal count stopped the last :meth:`step` or
        :meth:`advance`, or None."""
        i = self._stepper.terminated_by
        return None if i is None else str(self._spec.jumps.event_specs[i][0])

    @property
    def method(self) -> str:
        """The method's name."""
        return self._stepper.method

    @property
    def t(self) -> float:
        """The time tₙ = t₀ + n·h (from the last change of :attr:`dt`)."""
        return self._stepper.t

    @property
    def q(self) -> np.ndarray:
        """The positions qₙ, shape (n,) (a copy)."""
        return self._stepper.q

    @property
    def p(self) -> np.ndarray:
        """The momenta pₙ, shape (n,) (a copy)."""
        return self._stepper.p

    @property
    def steps(self) -> int:
        """Steps completed since the start or the last :meth:`reset`."""
        return self._stepper.steps

    @property
    def dt(self) -> float:
        """The step h; set it to take the next steps with another (from the current time on)."""
        return self._stepper.dt

    @dt.setter
    def dt(self, dt: float) -> None:
        self._stepper.dt = positive("dt", dt)

    @property
    def force_evaluations(self) -> int:
        """Force evaluations so far (for the implicit methods, of the discrete Lagrangian's slot
        derivatives), those of the impacts' partial steps included."""
        return self._stepper.force_evaluations

    @property
    def newton_iterations(self) -> int:
        """The implicit methods' Newton iterations so far (0 for explicit methods)."""
        return self._stepper.newton_iterations

    @property
    def work(self) -> float:
        """Work done by the non-conservative forces so far (0 without forces)."""
        return self._stepper.work

    def checkpoint(self) -> bytes:
        """The stepper's whole state as bytes: :meth:`from_checkpoint` rebuilds a stepper that
        goes on bit for bit (its method's caches, Newton predictor and compensated-summation
        carries included). A run's last checkpoint is :attr:`Trajectory.checkpoint`.

        Returns
        -------
        bytes
            The checkpoint (it records the model's kind and the method, not the model itself
            nor the contacts and impulses: give them to :meth:`from_checkpoint` again, a scene's
            contacts by default).

        Examples
        --------
        Taken at t = 0.1, it still holds that state after the stepper has gone on:

        >>> import varmech
        >>> kepler = varmech.scenes.kepler()
        >>> stepper = varmech.Stepper(kepler, dt=0.01)
        >>> stepper.advance(10)
        >>> saved = stepper.checkpoint()
        >>> stepper.advance(10)
        >>> type(saved).__name__, varmech.Stepper.from_checkpoint(kepler, saved)
        ('bytes', Stepper('kepler', method='verlet', dt=0.01, t=0.1, steps=10))
        """
        return bytes(self._stepper.checkpoint())

    @classmethod
    def from_checkpoint(
        cls,
        model: Model | Scene,
        checkpoint: bytes,
        *,
        method: str | None = None,
        dt: float | None = None,
        contacts: Sequence[Contact] | None = None,
        impulses: Sequence[Impulse] | None = None,
        events: Sequence[Event | EventFunction] | None = None,
    ) -> Stepper:
        """The stepper of ``model`` at the state of ``checkpoint``, going through the impacts on
        ``contacts`` (a scene's by default), applying the ``impulses`` after the checkpoint's
        time and watching the ``events`` from there as the constructor's does.

        A checkpoint records a fingerprint of what it was taken of: the model's kind, size and
        constraints, what the model computes at the checkpoint's state (its Lagrangian, forces
        and constraints there, which tells apart another model of the same size or the same
        model with another parameter), the method, the step, the summation and the Newton
        options. Every length and index of its state is checked against the model and method
        before a step is taken.

        Parameters
        ----------
        model : Model or Scene
            The model the checkpoint was taken of (or its scene).
        checkpoint : bytes
            From :meth:`checkpoint`, or a trajectory's :attr:`~Trajectory.checkpoint`.
        method, dt : optional
            The method and step the caller goes on with (a file's or a trajectory's): a
            checkpoint of another is refused.
        contacts : sequence of Contact, optional
            The contacts the stepper goes on with (the checkpointed stepper's or run's, for bit
            for bit): default a scene's ``contacts``; ``[]`` for none.
        impulses : sequence of Impulse, optional
            The impulses the stepper goes on with; those at or before the checkpoint's time
            were its run's.
        events : sequence of callable or Event, optional
            The events the stepper watches from the checkpoint's state on (their counts and an
            ``energy_error``'s E₀ start there).

        Returns
        -------
        Stepper
            A stepper that goes on bit for bit as the one checkpointed would have.

        Raises
        ------
        ValueError
            Naming ``checkpoint`` for bytes that are not one (damaged, truncated, of another
            checkpoint format, or crafted so that its state does not fit the model and method),
            or the checkpoint of another model, method, step or options, saying which; naming
            ``model`` or ``method`` for a model of another size or kind; naming ``contacts``
            for contacts that do not fit (as the constructor), and ``checkpoint`` for a state
            outside a contact.
        TypeError
            Naming ``model``: not a varmech model or scene; ``checkpoint``: not bytes; or
            ``contacts[i]`` or ``impulses[i]``: not a :class:`~varmech.Contact` or
            :class:`~varmech.Impulse`.

        Examples
        --------
        A run's checkpoint, stepped on, lands bit for bit where the whole run does:

        >>> import varmech
        >>> kepler = varmech.scenes.kepler()
        >>> stepper = varmech.Stepper.from_checkpoint(kepler, varmech.integrate(kepler, dt=0.01, steps=50).checkpoint)
        >>> stepper.advance(50)
        >>> whole = varmech.integrate(kepler, dt=0.01, steps=100)
        >>> stepper.steps, bool((stepper.q == whole.q[-1]).all() and (stepper.p == whole.p[-1]).all())
        (100, True)
        """
        if not isinstance(checkpoint, (bytes, bytearray, memoryview)):
            # bytes() would read a str as an error and an int n as n zero bytes.
            raise TypeError(f"checkpoint: expected the bytes of Stepper.checkpoint(), got {type(checkpoint).__name__}")
        contacts = contacts_of(model, contacts)
        blows = _impulses.specs(impulses or (), -math.inf, math.inf)
        model, _, _ = model_and_state(model, None, None, None)
        jumps = Jumps.of(model, events, contacts, (impulses or (), blows))
        core = _core.Stepper.from_checkpoint(model._core, bytes(checkpoint), _core.RunSpec(method=method, dt=dt, **jumps.binding))
        stepper = cls.__new__(cls)
        stepper._model = model
        # What it watches; its step, summation and Newton options are the checkpoint's.
        stepper._spec = RunSpec(
            core.method,
            core.dt,
            jumps=jumps,
        )
        stepper._stepper = core
        return stepper

    def __reduce__(self) -> tuple[object, ...]:
        # By its model, checkpoint, contacts, impulses and events: the unpickled stepper goes on
        # bit for bit (its impacts and crossings counted from there).
        return (_unpickled, (self._model, self.checkpoint(), self._spec.jumps.contacts, self._spec.jumps.impulses, self._spec.jumps.events))

    def __repr__(self) -> str:
        return f"Stepper({self._model.name!r}, method={self.method!r}, dt={self.dt:g}, t={self.t:g}, steps={self.steps})"


def _unpickled(
    model: Model, checkpoint: bytes, contacts: tuple[Contact, ...], impulses: tuple[Impulse, ...] = (), events: tuple[Event, ...] = ()
) -> Stepper:
    """A pickled stepper, from its model, checkpoint, contacts, impulses and events."""
    return Stepper.from_checkpoint(model, checkpoint, contacts=contacts, impulses=impulses, events=events or None)
