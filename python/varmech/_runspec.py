"""The run specification: what describes a run beyond its model and initial state, checked once.

:func:`varmech.integrate`, :func:`varmech.ensemble`, :class:`varmech.Stepper`, continued runs
(``integrate(traj)``, :func:`varmech.resume`), the streaming of a run in segments
(:mod:`varmech.streaming`) and the file it streams to (:class:`varmech.files.Writer`) all take
one :class:`RunSpec` rather than passing its parts along as keywords, so that an option (a new
kind of jump, say) is one field here and one line where the binding is called. The public
keyword API checks the arguments (the checks below) and builds the spec; nothing in it changes
what the core computes.
"""

from __future__ import annotations

import datetime
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from . import _core, dense
from . import events as _events
from . import impacts as _impacts
from . import impulses as _impulses
from ._util import finite, positive, positive_int, step_count
from .events import Event
from .impacts import Contact
from .impulses import Impulse
from .model import Model


@dataclass(frozen=True, eq=False)
class Jumps:
    """What a run watches and applies besides its steps (events, contacts, impulses): each as
    the run's result reports it, beside the binding's tuples of it. A new kind of jump is a
    field here, made in :meth:`of`, and its keyword in :attr:`binding`."""

    #: The events watched, and the binding's tuples of them (checked against the model).
    events: tuple[Event, ...] = ()
    event_specs: list[tuple[str, int, int, str, Any]] = field(default_factory=list)
    #: The contacts, and the binding's tuples of them.
    contacts: tuple[Contact, ...] = ()
    contact_specs: list[_impacts.Spec] = field(default_factory=list)
    #: The impulses, and the binding's tuples of those within the run's span.
    impulses: tuple[Impulse, ...] = ()
    impulse_specs: list[_impulses.Spec] = field(default_factory=list)

    @classmethod
    def of(
        cls,
        model: Model,
        events: Sequence[Event | _events.EventFunction] | None,
        contacts: Sequence[Contact] | None,
        impulses: tuple[Sequence[Impulse], list[_impulses.Spec]] = ((), []),
    ) -> Jumps:
        """The jumps of a run of ``model``: ``events`` checked against it (None: none),
        ``contacts``, and ``impulses`` with their tuples (``impulses.specs`` over the run's span,
        or ``impulses.going_on`` for a continued run)."""
        watched, event_specs = _events.specs(events, model) if events is not None else ([], [])
        contacts = tuple(contacts or ())
        return cls(tuple(watched), event_specs, contacts, _impacts.specs(contacts), tuple(impulses[0]), impulses[1])

    def __bool__(self) -> bool:
        return bool(self.event_specs or self.contact_specs or self.impulse_specs)

    @property
    def binding(self) -> dict[str, Any]:
        """The binding's keywords of the jumps (None where there are none)."""
        return {
            "events": self.event_specs or None,
            "contacts": self.contact_specs or None,
            "impulses": self.impulse_specs or None,
        }


@dataclass(frozen=True, eq=False)
class RunSpec:
    """How a run goes, its arguments checked, with its :class:`Jumps`.

    A new run starts at ``t0`` from a state given beside the spec; a continued one goes on from
    ``checkpoint`` after ``base`` steps, its events watched after ``found`` crossings of each,
    an energy error measured from ``initial_energy``, and its energy check kept unless
    ``keep_energy_check`` is false (then ``max_energy_error`` sets it); the method's own state
    (``compensated``, ``t0``, the Newton options) is then the checkpoint's, and those fields are
    not read (nor by a stepper made from a checkpoint). ``steps`` are the steps this run takes
    (a stepper's spec: none), ``times`` the checked ``t_eval``, and ``output``, ``overwrite``,
    ``checkpoint_every`` and ``progress`` as :func:`varmech.integrate` takes them.
    """

    method: str
    dt: float
    steps: int = 0
    save_every: int = 1
    compensated: bool = True
    max_energy_error: float | None = None
    keep_energy_check: bool = True
    t0: float = 0.0
    newton_tolerance: float = 1e-14
    newton_max_iterations: int = 50
    jumps: Jumps = field(default_factory=Jumps)
    times: np.ndarray | None = None
    output: str | os.PathLike[str] | None = None
    overwrite: bool = False
    checkpoint_every: int | datetime.timedelta | None = None
    progress: bool | None = None
    checkpoint: bytes | None = None
    base: int = 0
    found: tuple[int, ...] = ()
    initial_energy: float | None = None

    @classmethod
    def checked(cls, model: Model, members: int = 1, **run: Any) -> RunSpec:
        """A new run's spec from :func:`varmech.integrate`'s keywords ``run`` (``dt``, ``steps``
        or ``t_end``, ``method``, ``save_every``, ``compensated``, ``max_energy_error``, ``t0``,
        the Newton options, ``events``, ``contacts``, ``impulses``, ``t_eval``, and any of
        ``output``, ``overwrite``, ``checkpoint_every``, ``progress``), each checked and named;
        ``t_eval``'s times are held for each of ``members`` runs (an ensemble's). Without
        ``steps`` and ``t_end`` the run has no horizon (a :class:`varmech.Stepper`'s)."""
        method = model.kind.default_method if run["method"] is None else run["method"]
        if run["dt"] is None:
            raise ValueError("dt: the step is required")
        dt = positive("dt", run["dt"])
        t0 = 0.0 if run["t0"] is None else finite("t0", run["t0"])
        open_ended = "steps" not in run and "t_end" not in run
        steps = 0 if open_ended else step_count(dt, t0, run["steps"], run["t_end"])
        save_every = positive_int("save_every", run.get("save_every", 1))
        threshold = energy_threshold(run.get("max_energy_error"))
        tolerance, iterations = newton_options(run["newton_tolerance"], run["newton_max_iterations"])
        # A horizon past the largest float is the core's to refuse (naming dt).
        t_end = math.inf if open_ended else t0 + steps * dt
        impulses = run["impulses"] or ()
        jumps = Jumps.of(model, run["events"], run["contacts"], (impulses, _impulses.specs(impulses, t0, t_end)))
        files = {k: run[k] for k in ("output", "overwrite", "checkpoint_every", "progress") if k in run}
        return cls(
            method,
            dt,
            steps=steps,
            save_every=save_every,
            compensated=bool(run["compensated"]),
            max_energy_error=threshold,
            t0=t0,
            newton_tolerance=tolerance,
            newton_max_iterations=iterations,
            jumps=jumps,
            times=sample_times(run.get("t_eval"), t0, t_end, save_every, files.get("output"), model.dim, members),
            **files,
        )

    @property
    def planned(self) -> int:
        """The step count the run is asked to reach: its file's planned end."""
        return self.base + self.steps

    @property
    def energy_check(self) -> dict[str, Any]:
        """The binding's arguments that set a continued run's energy check (none: its own)."""
        if self.keep_energy_check:
            return {}
        return {"keep_energy_check": False, "max_energy_error": self.max_energy_error}

    def start(
        self, model: Model, q: np.ndarray, p: np.ndarray, steps: int, progress: Callable[[int], None] | None
    ) -> _core.TrajectoryRecord:
        """The binding's record of the new run's first ``steps`` steps from (q, p) at
        :attr:`t0`, reporting its step count to ``progress``."""
        return _core.integrate(model._core, q, p, self.binding(steps=steps), progress=progress)

    def binding(self, **changes: Any) -> _core.RunSpec:
        """The binding's spec of a new run of :attr:`steps` steps, ``changes`` replacing its
        keywords: :func:`varmech.integrate`'s, :func:`varmech.ensemble`'s, a stepper's."""
        return _core.RunSpec(**({
            "dt": self.dt,
            "steps": self.steps,
            "method": self.method,
            "save_every": self.save_every,
            "compensated": self.compensated,
            "max_energy_error": self.max_energy_error,
            "t0": self.t0,
            "newton_tolerance": self.newton_tolerance,
            "newton_max_iterations": self.newton_max_iterations,
            "t_eval": self.times,
            **self.jumps.binding,
        } | changes))  # fmt: skip

    def continued(self, found: Sequence[int], initial_energy: float | None, **changes: Any) -> _core.RunSpec:
        """The binding's spec of the run going on from a checkpoint after ``found`` crossings of
        each event, an energy error measured from ``initial_energy`` (:meth:`events_from`),
        ``changes`` replacing its keywords: its method and step checked against the checkpoint,
        whose state sets the rest."""
        return _core.RunSpec(**({
            "method": self.method,
            "dt": self.dt,
            "steps": self.steps,
            "save_every": self.save_every,
            "events": self.events_from(found, initial_energy),
            "contacts": self.jumps.contact_specs or None,
            "impulses": self.jumps.impulse_specs or None,
            "t_eval": self.times,
            **self.energy_check,
        } | changes))  # fmt: skip

    def stepper(self, model: Model, q: np.ndarray, p: np.ndarray) -> _core.Stepper:
        """The binding's stepper of ``model`` from (q, p) at :attr:`t0`."""
        return _core.Stepper(model._core, q, p, self.binding())

    def occurrence_names(self) -> list[str]:
        """The names of the run's occurrences, as its result and its file list them: each
        event's, then each contact's."""
        jumps = self.jumps
        return [o.name for o in _events.occurrences_of(jumps.events)] + _impacts.occurrence_names(jumps.contacts)

    def events_from(self, found: Sequence[int], initial_energy: float | None) -> list[Any] | None:
        """The binding's tuples of the events watched from a checkpoint after ``found``
        crossings of each, an energy error measured from ``initial_energy``; None without
        events."""
        if not self.jumps.events:
            return None
        assert initial_energy is not None
        return _events.going_on(self.jumps.event_specs, found, initial_energy)


def continuing(previous: Any, jumps: Jumps) -> dict[str, Any]:
    """The :class:`RunSpec` fields of a run going on from ``previous`` (a trajectory, or a
    file's, lazy) watching ``jumps``: its checkpoint and steps, the crossings its events already
    had, and its first energy, from which an energy-error event measures (None without events)."""
    found = tuple(_events.found_before(previous.events, jumps.events))
    initial = _events.first_energy(previous.model, previous) if jumps.events else None
    return {"checkpoint": previous.checkpoint, "base": previous.steps, "found": found, "initial_energy": initial}


def energy_threshold(max_energy_error: float | None | Literal["auto"]) -> float | None:
    """The run's energy threshold: ``"auto"`` is the failure level of the verdicts, for the
    energy or its balance E − W (forced, L depending on t); the core checks neither where
    affine constraints do work."""
    if max_energy_error is None:
        return None
    if isinstance(max_energy_error, str) and max_energy_error == "auto":
        return _core.FAILURE
    return positive("max_energy_error", max_energy_error)


def newton_options(tolerance: float, max_iterations: int) -> tuple[float, int]:
    """The implicit methods' Newton tolerance and iteration cap, checked."""
    return positive("newton_tolerance", tolerance), positive_int("newton_max_iterations", max_iterations)


def sample_times(
    t_eval: ArrayLike | None,
    t0: float,
    t_end: float,
    save_every: int,
    output: str | os.PathLike[str] | None,
    dim: int,
    members: int = 1,
) -> np.ndarray | None:
    """``t_eval`` checked for a run over [t0, t_end] (``dense.eval_times``), refusing
    ``save_every`` and ``output`` with it, and more times than the memory available can hold
    the states of (t, q, p, Newton counts and work: 2·dim + 3 floats a row, and the times' two
    copies the core makes), for each of ``members`` runs (an ensemble's, whose rows are stacked
    too), before they are copied."""
    if t_eval is None:
        return None
    for name, clash in (("save_every", save_every != 1), ("output", output is not None)):
        if clash:
            raise ValueError(f"{name}: not with t_eval, which keeps the states at its times, not the run's own")
    times = dense.eval_times(t_eval, t0, t_end)
    try:
        _core.check_allocation("t_eval", times.size * members, 8 * (2 * dim + 5) * (1 if members == 1 else 2))
    except ValueError as e:
        raise ValueError(
            f"{e}: {members} × {times.size} states of {dim} coordinates; pass fewer t_eval times"
        ) from None
    return times
