"""Runs in segments: streamed to a file with checkpoints (``integrate(output=)``), and resumed
from one (:func:`resume`).

A long run is cut into segments of whole saving periods; each goes on from the last one's
checkpoint (``_core.resume``), so the states are those of one uninterrupted run, bit for bit.
After a segment its rows and checkpoint are appended to the file and committed
(``files.Writer``) and dropped from memory, so memory stays flat whatever the
length of the run. A segment lasts at most ``checkpoint_every`` (steps, or a
:class:`datetime.timedelta` of run time) and by default about :data:`SEGMENT_SECONDS`.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import datetime
import math
import os
import signal
import threading
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _core, files
from . import events as _events
from . import impacts as _impacts
from . import impulses as _impulses
from ._progress import progress_bar
from ._runspec import Jumps, RunSpec, continuing
from ._util import step_count
from .impacts import Contact
from .impulses import Impulse
from .model import Model
from .trajectory import Trajectory, crossings, going_on_from, load, take_partial

if TYPE_CHECKING:
    from tqdm import tqdm

__all__ = [
    "SEGMENT_SECONDS",
    "resume",
]

#: The default length of a segment in run time: what a crash can lose.
SEGMENT_SECONDS = 2.0
#: Saved states kept in memory at most between two appends.
SEGMENT_ROWS = 4 * files.CHUNK_ROWS


def checkpoint_period(checkpoint_every: int | datetime.timedelta | None, save_every: int) -> tuple[int | None, float]:
    """(the largest segment in steps, the target segment in seconds) of ``checkpoint_every``:
    a number of steps (rounded down to whole saving periods, at least one), or a duration."""
    if checkpoint_every is None:
        return None, SEGMENT_SECONDS
    if isinstance(checkpoint_every, datetime.timedelta):
        seconds = checkpoint_every.total_seconds()
        if not seconds > 0:
            raise ValueError(f"checkpoint_every: must be a positive duration, got {checkpoint_every}")
        return None, seconds
    if isinstance(checkpoint_every, bool) or not isinstance(checkpoint_every, int) or checkpoint_every < 1:
        raise ValueError(
            f"checkpoint_every: must be a number of steps ≥ 1 or a datetime.timedelta, got {checkpoint_every!r}"
        )
    return max(save_every, checkpoint_every // save_every * save_every), float("inf")


def stream(
    writer: files.Writer,
    model: Model,
    spec: RunSpec,
    bar: tqdm[Any],
    state: tuple[np.ndarray, np.ndarray] | None = None,
) -> None:
    """Runs ``spec.steps`` steps of ``model`` in segments appended to ``writer``: the first
    from ``state`` (q, p: a new run) or from ``spec.checkpoint`` (after ``spec.base`` steps),
    every other from the last checkpoint, each at most ``spec.checkpoint_every`` long. With
    events, each segment watches them from its start, their crossings are committed with the
    segment's rows, terminal counts run over the whole run, and an energy error is measured
    from ``spec.initial_energy`` (the run's first energy; by default taken at its first state)
    after the ``spec.found`` crossings of each so far; a continued run's energy check as
    ``spec.energy_check`` sets it. Closes the file with the run's status; an exception stops
    the run with every state up to it committed, and closes the file saying why. Each segment
    resolves the impacts on the spec's contacts, committed as the events after its events',
    and applies its impulses after its start."""
    steps, save_every, watched, contacts = spec.steps, spec.save_every, spec.jumps.events, spec.jumps.contacts
    base, checkpoint, initial_energy = spec.base, spec.checkpoint, spec.initial_energy
    cap, seconds = checkpoint_period(spec.checkpoint_every, save_every)
    contact_specs = spec.jumps.contact_specs or None
    found = list(spec.found) or [0] * len(watched)
    done, rate = 0, None
    segment = files.CHUNK_ROWS * save_every

    def report(s: int) -> None:
        bar.update(s - base - bar.n)

    # Each segment is committed on a thread while the next one runs (the core releases the GIL):
    # the commit's h5py calls (about 0.3 ms) are not added to the run's time. One thread keeps the
    # commits in order, and only the main thread receives Ctrl-C, so none is cut.
    committer = concurrent.futures.ThreadPoolExecutor(max_workers=1, thread_name_prefix="varmech-commit", initializer=_deaf)
    pending: concurrent.futures.Future[None] | None = None

    def committed() -> None:
        """Waits for the last segment's commit (Ctrl-C held back meanwhile), raising its error."""
        nonlocal pending
        if pending is not None:
            # A finished commit has nothing to wait for: no masking (two system calls a segment).
            with contextlib.nullcontext() if pending.done() else _uninterrupted():
                done, pending = pending, None
                done.result()

    try:
        if writer.rows == 0:
            # A new file commits the run's first state and its checkpoint at once, so that a run
            # killed in its first segment resumes too (and a continued run's file starts, as
            # its trajectory in memory does, with the state it goes on from); every segment
            # then goes on from a checkpoint.
            if checkpoint is None:
                assert state is not None
                record = spec.start(model, *state, 0, None)
            else:
                # A continued run's energy check, as the spec sets it, is its checkpoints' from here.
                record = _core.resume(model._core, checkpoint, _core.RunSpec(steps=0, save_every=save_every, **spec.energy_check))
            with _uninterrupted():
                writer.append(record)
            if watched and initial_energy is None:
                initial_energy = _events.first_energy(model, record)
            checkpoint = record.checkpoint
        while True:
            left = steps - done
            if rate is not None and math.isfinite(seconds):
                segment = max(save_every, int(rate * seconds) // save_every * save_every)
            take = min(left, segment, SEGMENT_ROWS * save_every, cap or left)
            started = time.perf_counter()
            assert checkpoint is not None  # committed before the first segment
            try:
                # Each segment goes on from the last one's checkpoint: its method, step and energy check.
                segment_spec = spec.continued(
                    found, initial_energy, method=None, dt=None, steps=take, save_every=save_every,
                    contacts=contact_specs, t_eval=None, keep_energy_check=True,
                )  # fmt: skip
                record = _core.resume(model._core, checkpoint, segment_spec, progress=None if bar.disable else report)
            except BaseException as err:
                # The segment's states and crossings up to the stop are committed; the file is
                # closed below.
                partial = take_partial(err)
                committed()
                if partial is not None:
                    with _uninterrupted():
                        writer.append(partial, skip_first=True, events=crossings(partial, watched, contacts))
                raise
            elapsed = time.perf_counter() - started
            found_now = crossings(record, watched, contacts)
            committed()
            pending = committer.submit(writer.append, record, skip_first=True, events=found_now)
            if watched and initial_energy is None:
                initial_energy = _events.first_energy(model, record)
            found = [k + len(o) for k, o in zip(found, found_now)]
            checkpoint = record.checkpoint
            if record.terminated_by is not None:
                i = record.terminated_by
                last = found_now[i]
                committed()
                with _uninterrupted():
                    writer.close(1, _events.termination_message(last, found[i]))
                return
            done += take
            bar.update(record.steps - base - bar.n)
            if elapsed > 0:
                rate = take / elapsed
            if done >= steps:
                break
        committed()
    except BaseException as err:
        # A segment's error, or a Ctrl-C between segments: what was committed stands.
        with _uninterrupted():
            committer.shutdown(wait=True)
        if writer.is_open:
            with _uninterrupted(), contextlib.suppress(ValueError):
                # A file that cannot be closed (a full disk) keeps its last commit.
                writer.close(-1, str(err) or type(err).__name__)
        raise
    finally:
        committer.shutdown(wait=True)
    with _uninterrupted():
        writer.close(0, "The integration reached its final time.")


def _deaf() -> None:
    """Blocks SIGINT in the calling (commit) thread, so the kernel delivers Ctrl-C to the main
    thread when it takes it, not while :func:`_uninterrupted` holds it back."""
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})


@contextlib.contextmanager
def _uninterrupted() -> Iterator[None]:
    """Holds Ctrl-C back while the file is written, and delivers it right after: an append is
    not cut in two, and h5py cannot swallow the KeyboardInterrupt (an exception raised while
    h5py frees an object is only printed)."""
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    held = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


def resume(
    path: str | os.PathLike[str],
    *,
    steps: int | None = None,
    t_end: float | None = None,
    save_every: int | None = None,
    checkpoint_every: int | datetime.timedelta | None = None,
    progress: bool | None = None,
    events: Sequence[_events.Event | _events.EventFunction] | None = None,
    model: Model | None = None,
    allow_pickle: bool = False,
    contacts: Sequence[Contact] | None = None,
    impulses: Sequence[Impulse] | None = None,
) -> Trajectory:
    """Goes on with the run in the file ``path`` (from ``integrate(output=)``, or
    :meth:`Trajectory.save`) for ``steps`` more steps or to ``t_end``, appending to the file;
    with neither, to the end its run was asked for (a killed ``integrate(steps=10**9,
    output=...)`` finishes its 10⁹ steps), which the file records.

    The run goes on from the file's last committed checkpoint, so the states are those of one
    run of the whole length, bit for bit, whether the run ended, failed, was stopped by Ctrl-C,
    or was killed (a streamed run commits its initial state at once, so even one killed in its
    first second resumes). ``save_every`` is the file's by default (its saving period).
    ``events`` (as :func:`varmech.integrate`'s; the same as the file's, if it has any) are
    watched from the checkpoint on, with terminal counts over the whole run and an energy error
    measured from the file's first state. The run's contacts and impulses still to come go on:
    the file stores the native contacts (``Contact.wall``, ``Contact.ellipsoid``) and the
    impulses given as numbers; those given by Python functions are given again as ``contacts``
    and ``impulses``.

    The file is loaded as :func:`varmech.load` loads it (no code run from it: a model of
    closures needs ``model=`` or ``allow_pickle=True``), and its checkpoint must be the state
    of its last committed row: the same step count as ``/committed`` records, and the same
    time, positions and momenta, to the bit. A file that disagrees (a damaged ``/committed``
    pointing at an older checkpoint, say) is refused rather than continued from the wrong
    state.

    Parameters
    ----------
    path : str or os.PathLike
        The run's HDF5 file.
    steps, t_end : int or float, optional
        How much further: a number of steps more, or a final time that is a whole number of
        steps. Neither: to the end the run was asked for (``planned_steps``), which
        ``integrate(output=)`` records and each ``resume`` moves to its own end.
    save_every : int, optional
        The saving period; default the file's.
    checkpoint_every : int or datetime.timedelta, optional
        Commit at least this often, as in :func:`varmech.integrate`.
    progress : bool, optional
        A progress bar, as in :func:`varmech.integrate`.
    events : sequence of Event or callable, optional
        Event functions, as in :func:`varmech.integrate`.
    model : Model, optional
        The model to go on with instead of the file's (as :func:`varmech.load` takes it).
    allow_pickle : bool, default False
        Unpickle a stored closure model, as :func:`varmech.load` does (only for files you
        trust).
    contacts : sequence of Contact, optional
        The run's contacts, for a file whose contacts were given by Python functions (the file
        stores their names, not their code): the same names, in the same order.
    impulses : sequence of Impulse, optional
        The run's impulses, for a file whose impulses were given by Python functions (the file
        stores their times): the same times.

    Returns
    -------
    Trajectory
        The whole run, read back from the file (lazily when it is large; see
        ``files.larger_than_memory``).

    Raises
    ------
    ValueError
        Naming ``path`` for a file without a checkpoint, a missing, truncated or damaged one
        (failed checksums, non-finite rows, a checkpoint that is not the last row's state),
        one that cannot be written (a full disk: the rows committed before are kept), a
        pickled model without ``model=`` or ``allow_pickle=True``; naming ``steps, t_end`` for
        neither given where the file records no planned end, or its run has reached it; naming ``contacts`` for
        contacts of Python functions not given again, or given with other names, and
        ``impulses`` likewise (other times); the arguments of
        :func:`varmech.integrate` as it names them.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np, varmech
    >>> s = varmech.scenes.kepler()
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "kepler.h5"
    >>> _ = varmech.integrate(s, dt=s.dt, steps=100, save_every=10, output=path)
    >>> traj = varmech.resume(path, steps=50)
    >>> once = varmech.integrate(s, dt=s.dt, steps=150, save_every=10)
    >>> traj.steps, bool(np.array_equal(traj.q, once.q))
    (150, True)
    """
    stored = load(path, lazy=True, model=model, allow_pickle=allow_pickle)
    going_on = _impacts.going_on(stored.contacts, contacts)
    if stored.checkpoint is None or not len(stored.t):
        raise ValueError(f"path: {str(path)!r} has no checkpoint to resume from")
    # Every row and both checkpoints read, as load reads them, before anything is written.
    files.read_through(Path(path))
    _check_checkpoint(path, stored, model is not None)
    t_now = float(stored.t[-1])
    still, blows = _impulses.going_on(stored.impulses, impulses, t_now)
    more = _further(path, stored, steps, t_end)
    if save_every is None:
        save_every = files.save_every_of(path)
    jumps = Jumps.of(stored.model, events, going_on, (still, blows))
    spec = RunSpec(
        stored.method,
        stored.dt,
        steps=more,
        save_every=save_every,
        jumps=jumps,
        checkpoint_every=checkpoint_every,
        progress=progress,
        **continuing(stored, jumps),
    )
    writer = files.Writer.reopen(Path(path), stored, spec)
    bar = progress_bar(total=more, unit="step", desc=stored.method, enabled=progress)
    try:
        stream(writer, stored.model, spec, bar)
    finally:
        bar.close()
    return load(path, model=stored.model, lazy=files.larger_than_memory(path))


def _further(path: str | os.PathLike[str], stored: Trajectory, steps: int | None, t_end: float | None) -> int:
    """The steps :func:`resume` takes: ``steps`` more, or to ``t_end``; with neither, to the end
    the run was asked for (``planned_steps``), or ValueError naming ``steps, t_end`` where the
    file records none or the run reached it."""
    if steps is not None or t_end is not None:
        return step_count(stored.dt, float(stored.t[-1]), steps, t_end)
    planned = files.planned_steps_of(path)
    if planned is None:
        raise ValueError(
            f"steps, t_end: give how much further: {str(path)!r} does not record the end its run was asked for "
            "(a saved trajectory, or a file of an older varmech)"
        )
    if planned <= stored.steps:
        raise ValueError(
            f"steps, t_end: the run in {str(path)!r} has reached the end it was asked for (step {planned}, "
            f"t = {float(stored.t[-1]):g}); give steps= (how many more) or t_end= to go further"
        )
    return planned - stored.steps


def _check_checkpoint(path: str | os.PathLike[str], stored: Trajectory, given: bool) -> None:
    """ValueError naming ``path`` unless the file's checkpoint goes on from its last committed
    row (:func:`varmech.trajectory.going_on_from`, the check ``integrate(traj)`` makes too) with
    its model (the one it stores, or the one ``given``), and that row is the run's own state
    (not a sample of ``t_eval``: the rows appended go on from the file's)."""
    try:
        at = going_on_from(stored, "path", repr(str(path)), "committed row")
    except ValueError as e:
        if str(e).startswith("path: "):
            raise
        whose = "model=" if given else "the model stored in it"
        raise ValueError(f"path: {str(path)!r} cannot go on from its checkpoint with {whose}: {e}") from e
    if at.t != float(stored.t[-1]):
        raise ValueError(
            f"path: {str(path)!r} cannot be resumed: its checkpoint (step {at.steps}, t = {at.t}) is not the state of "
            f"its last committed row (step {stored.steps}, t = {float(stored.t[-1])}): its rows are not the run's saved "
            "states (a trajectory of t_eval times)"
        )
