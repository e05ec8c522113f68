"""Ensembles: many runs of one model (or of one model at many parameter values) at once.

Member i of an ensemble is :func:`varmech.integrate` of its model from row i of ``q0`` and
``p0``, bit for bit, whatever the number of threads or the chunking. Native and compiled
models run in the Rust core on every core of the machine (Rayon threads, the GIL released, no
Python per step). Closure models hold the GIL: they run member by member, serially, or, with
``workers`` given, in that many processes.
"""

from __future__ import annotations

import math
import multiprocessing
import signal
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from . import events as _events
from ._progress import progress_bar, thread_lock
from ._runspec import RunSpec
from ._util import floats, positive_int
from .conservation import NOT_JUDGED, VERDICTS, ConservationReport, check_conservation
from .impacts import Contact
from .impulses import Impulse
from .integrate import integrate
from .model import Model, NativeSystem, scene_model
from .scenes import Scene
from .scenes._scene import contacts_of, model_and_state
from .trajectory import Trajectory, labelled_dataset, of_record

if TYPE_CHECKING:
    import xarray


@dataclass
class EnsembleConservation:
    """The conservation reports of an ensemble's members and their summary.

    The record :meth:`Ensemble.check_conservation` returns; printing it gives a one-line summary.

    Attributes
    ----------
    reports : list of ConservationReport or None
        ``reports[i]`` is :func:`varmech.check_conservation` of member i (None for a member that
        saved fewer than two states).
    worst_energy_error : float
        The largest max |ΔE| / scale over the members (of the balance E − W for forced models),
        the scale being each run's mean kinetic energy.
    not_bounded : list of int
        The members whose energy verdict is worse than ``"bounded"`` (a secular drift or a
        failure).

    See Also
    --------
    varmech.InvariantStatistics : The verdicts and the scale.

    Examples
    --------
    >>> import numpy as np, varmech
    >>> q0 = np.array([[0.5, 0.0], [0.6, 0.0]])
    >>> p0 = np.array([[0.0, 1.5], [0.0, 1.4]])
    >>> runs = varmech.ensemble(varmech.scenes.kepler(), q0, p0, dt=0.01, steps=200, save_every=50,
    ...                         method="verlet", progress=False)
    >>> print(runs.check_conservation())  # doctest: +ELLIPSIS
    Ensemble conservation: 2 of 2 members judged, worst energy error ...e-05 × scale, not bounded: none
    """

    reports: list[ConservationReport | None]
    worst_energy_error: float
    not_bounded: list[int]

    def __str__(self) -> str:
        judged = sum(r is not None for r in self.reports)
        return (
            f"Ensemble conservation: {judged} of {len(self.reports)} members judged, worst energy error "
            f"{self.worst_energy_error:.3e} × scale, not bounded: {self.not_bounded or 'none'}"
        )


@dataclass(eq=False)
class Ensemble:
    """The members' runs of :func:`ensemble`, stacked.

    ``q`` and ``p`` have shape (members, saved, n) and ``t`` shape (saved,): the saved times of a
    complete member. A member that stopped early (``status`` -1, see ``failed``) has NaN rows
    after its last state; its own states, its ``message`` and its exception (``errors[i]``, with
    ``step`` and ``time``) are kept, and ``ensemble[i]`` is its :class:`~varmech.Trajectory`
    (the partial one of a failure). ``parameters`` holds each member's parameter values by
    name.

    Attributes
    ----------
    trajectories : list of Trajectory
        Each member's run (the partial one of a failure).
    errors : list of BaseException or None
        Each member's exception, with ``step`` and ``time`` (None for a member that finished).
    parameters : dict of str to ndarray
        Each member's parameter values by name.
    t : ndarray, shape (saved,)
        The saved times of a complete member.
    q, p : ndarray, shape (members, saved, n)
        The members' states, NaN after the last state of a member that stopped early.
    status : ndarray of int, shape (members,)
        Each member's status (0 finished, 1 stopped by a terminal event, -1 failed or
        interrupted).
    messages : list of str
        Each member's message.
    failed : list of int
        The members that failed (status -1).

    Examples
    --------
    >>> import numpy as np
    >>> import varmech
    >>> runs = varmech.ensemble(varmech.scenes.pendulum(), np.zeros((4, 1)), [[0.5], [1.0], [1.5], [2.5]],
    ...                         dt=0.01, steps=1000, save_every=100)
    >>> runs.q.shape, runs.failed, len(runs)
    ((4, 11, 1), [], 4)
    >>> runs[3].method
    'verlet'
    """

    trajectories: list[Trajectory]
    errors: list[BaseException | None]
    parameters: dict[str, np.ndarray]
    t: np.ndarray = field(init=False, repr=False)
    q: np.ndarray = field(init=False, repr=False)
    p: np.ndarray = field(init=False, repr=False)
    status: np.ndarray = field(init=False, repr=False)
    messages: list[str] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        trajs = self.trajectories
        saved = max((len(tr) for tr in trajs), default=0)
        n = trajs[0].model.dim if trajs else 0
        self.q = np.full((len(trajs), saved, n), np.nan)
        self.p = np.full((len(trajs), saved, n), np.nan)
        for i, tr in enumerate(trajs):
            self.q[i, : len(tr)] = tr.q
            self.p[i, : len(tr)] = tr.p
        longest = max(trajs, key=len, default=None)
        self.t = np.asarray(longest.t) if longest is not None else np.empty(0)
        self.status = np.array([tr.status for tr in trajs], dtype=int)
        self.messages = [tr.message for tr in trajs]

    @property
    def failed(self) -> list[int]:
        """The members that failed (status -1: diverged, failed Newton, met bad data or were
        interrupted), in member order; a member a terminal event stopped (status 1) did not."""
        return [i for i, s in enumerate(self.status) if s < 0]

    def __getitem__(self, i: int) -> Trajectory:
        return self.trajectories[i]

    def __len__(self) -> int:
        return len(self.trajectories)

    def __iter__(self) -> Iterator[Trajectory]:
        return iter(self.trajectories)

    def energy(self) -> np.ndarray:
        """The energy function E(q, p, t) = p·q̇ − L at every saved state.

        Returns
        -------
        numpy.ndarray
            Shape (members, saved); NaN after a member's last state.

        Examples
        --------
        >>> import numpy as np, varmech
        >>> q0 = np.array([[0.5, 0.0], [0.6, 0.0]])
        >>> p0 = np.array([[0.0, 1.5], [0.0, 1.4]])
        >>> runs = varmech.ensemble(varmech.scenes.kepler(), q0, p0, dt=0.01, steps=200,
        ...                         save_every=50, method="verlet", progress=False)
        >>> runs.energy()[:, 0].round(4)          # H = |p|²/2 − 1/|q|
        array([-0.875 , -0.6867])
        """
        out = np.full(self.q.shape[:2], np.nan)
        for i, tr in enumerate(self.trajectories):
            if len(tr):
                out[i, : len(tr)] = tr.energy()
        return out

    def check_conservation(self) -> EnsembleConservation:
        """:func:`varmech.check_conservation` of every member, and the summary.

        Returns
        -------
        EnsembleConservation
            The members' reports, the worst energy error and the members not bounded.

        Examples
        --------
        >>> import numpy as np, varmech
        >>> from varmech import scenes
        >>> q0 = np.array([[0.5, 0.0], [0.6, 0.0]])
        >>> p0 = np.array([[0.0, 1.5], [0.0, 1.4]])
        >>> runs = varmech.ensemble(scenes.kepler(), q0, p0, dt=0.01, steps=20_000, method="verlet", progress=False)
        >>> summary = runs.check_conservation()
        >>> summary.not_bounded, summary.worst_energy_error < 1e-2
        ([], True)
        """
        reports = [check_conservation(tr) if len(tr) >= 2 else None for tr in self.trajectories]
        worst, not_bounded = 0.0, []
        for i, report in enumerate(reports):
            stats = None if report is None else report.energy
            if stats is None or stats.verdict == NOT_JUDGED:
                continue
            worst = max(worst, stats.max_rel_error)
            if VERDICTS.index(stats.verdict) > VERDICTS.index("bounded"):
                not_bounded.append(i)
        return EnsembleConservation(reports, worst, not_bounded)

    def to_xarray(self) -> xarray.Dataset:
        """The ensemble as a labelled :class:`xarray.Dataset` (needs xarray, the extra ``xarray``).

        Returns
        -------
        xarray.Dataset
            ``q`` and ``p`` with dims (member, time, coordinate), the coordinate axis labelled
            with the model's names, ``status`` by member, the parameters as coordinates of
            ``member``; each variable's ``long_name`` and (where the model states them)
            ``units``, and the run's ``method``, ``dt``, ``model``, ``members`` and
            ``varmech_version`` as attributes, as :meth:`varmech.Trajectory.to_xarray` gives
            them.

        Raises
        ------
        ImportError
            xarray is missing.

        Examples
        --------
        >>> import numpy as np, varmech
        >>> q0 = np.array([[0.5, 0.0], [0.6, 0.0]])
        >>> p0 = np.array([[0.0, 1.5], [0.0, 1.4]])
        >>> runs = varmech.ensemble(varmech.scenes.kepler(), q0, p0, dt=0.01, steps=200,
        ...                         save_every=50, method="verlet", progress=False)
        >>> data = runs.to_xarray()
        >>> dict(data.sizes), list(data.data_vars)
        ({'member': 2, 'time': 5, 'coordinate': 2}, ['q', 'p', 'status'])
        """
        dims = ("member", "time", "coordinate")
        coords: dict[str, Any] = {"member": np.arange(len(self)), "time": self.t}
        coords.update({name: ("member", values) for name, values in self.parameters.items()})
        data = {"q": (dims, self.q), "p": (dims, self.p), "status": ("member", self.status)}
        first = self.trajectories[0]
        return labelled_dataset(data, coords, first.model, first.method, first.dt, {"members": len(self)})

    def __repr__(self) -> str:
        shape = "×".join(map(str, self.q.shape))
        return f"Ensemble(members={len(self)}, q: {shape}, failed={len(self.failed)})"


def ensemble(
    model: Model | Scene,
    q0: ArrayLike,
    p0: ArrayLike | None = None,
    *,
    v0: ArrayLike | None = None,
    parameters: Mapping[str, ArrayLike] | None = None,
    dt: float,
    steps: int | None = None,
    t_end: float | None = None,
    method: str | None = None,
    save_every: int = 1,
    compensated: bool = True,
    max_energy_error: float | None | Literal["auto"] = "auto",
    t0: float | None = None,
    newton_tolerance: float = 1e-14,
    newton_max_iterations: int = 50,
    events: Sequence[_events.Event | _events.EventFunction] | None = None,
    contacts: Sequence[Contact] | None = None,
    impulses: Sequence[Impulse] | None = None,
    t_eval: ArrayLike | None = None,
    workers: int | None = None,
    client: Any = None,
    chunk_size: int | None = None,
    progress: bool | None = None,
) -> Ensemble:
    """Integrate many members of ``model`` at once: member i from (``q0[i]``, ``p0[i]``).

    Each member is exactly :func:`varmech.integrate` of its model and initial state with the
    other arguments, which mean what they mean there: its result is bit for bit the single
    run's, whatever ``workers`` or ``chunk_size``.

    Native and compiled models run in the Rust core on ``workers`` threads with the GIL
    released. Closure models (:class:`~varmech.MechanicalSystem`, :class:`~varmech.Lagrangian`)
    call Python at every step and hold the GIL, so threads would only take turns: they run
    member by member, serially, unless ``workers`` is given; then they run in that many
    processes (the model shipped by cloudpickle), which pays off once the serial run would take
    more than about a second (the user guide's *Ensembles* page gives the figures). As with
    any process pool, a script that does this needs the ``if __name__ == "__main__":`` guard.

    Parameters
    ----------
    model
        A model or a :class:`~varmech.scenes.Scene` (its model).
    q0, p0, v0
        Initial positions (members, n), and momenta ``p0`` or velocities ``v0`` of the same
        shape (exactly one of them).
    parameters
        Per-member values of the model's named parameters, ``{name: array (members,)}`` (a
        scalar is every member's): the parameters of a native scene
        (:func:`varmech.scenes.get`) or of a symbolic model (:mod:`varmech.symbolic`); the
        others keep the model's values.
    dt, steps, t_end, method, save_every, compensated, max_energy_error, t0, newton_tolerance, newton_max_iterations
        As in :func:`varmech.integrate`, for every member.
    events
        Event functions every member watches, as in :func:`varmech.integrate` (each member's
        crossings in ``ensemble[i].events``, a terminal one stopping that member alone). The
        built-in ones (:func:`varmech.events.crossing`, ``energy_error``, ``escape``,
        ``encounter``) run in the core's parallel loop, a copy for each member; a Python
        function holds the GIL, so with one the members run as a closure model's do.
    contacts
        Unilateral contacts, as in :func:`varmech.integrate` (default a scene's): each member
        goes through its impacts. Native surfaces (``Contact.wall``, ``Contact.ellipsoid``) run
        on the threads; a contact of Python functions runs the members as a closure model's.
    impulses, t_eval
        Blows at given times and the times whose states each member keeps, as in
        :func:`varmech.integrate`. Impulses given as numbers (``Impulse(generalized=[...])``)
        run on the threads; one of Python functions runs the members as a closure model's.
    workers
        The most threads to use; default: one a core (with ``client``: on each Dask worker, its
        own thread count). For a closure model, the number of processes; default: none, the
        members run serially in this process.
    client
        A :class:`dask.distributed.Client`: the members run on its cluster in chunks of
        ``chunk_size``, each chunk one task that runs this same parallel loop in a worker
        process, and the results are gathered in member order (needs the extra ``cluster``;
        the user guide's *Ensembles* page gives the costs). The model is shipped by pickling (a native scene
        as its name and parameters, a symbolic model as its expressions, a closure model by
        cloudpickle); one that cannot be is a TypeError naming ``model``. A task lost with its
        worker is run again by Dask, bit for bit the same.
    chunk_size
        Members a task runs one after the other (default 1: the threads balance the load; with
        ``client`` or closure processes, about four chunks a worker thread or process).
    progress
        A progress bar of the steps of all members (tqdm, on stderr) once the run has taken a
        second; ``None`` (default): only on a terminal (stderr) or in a Jupyter notebook, unless
        ``TQDM_DISABLE`` is set, so that a log file gets none.

    Returns
    -------
    Ensemble
        The stacked states; a member that failed (diverged, failed Newton, met bad data) is in
        ``ensemble.failed``, with its message, exception and partial trajectory, and the other
        members are complete. The memory for every saved state is checked before the run: an
        ensemble that cannot fit is a ValueError naming ``save_every``.

    Raises
    ------
    ValueError
        Naming ``q0`` (not (members, n), or not finite numbers), ``p0`` or ``v0`` (likewise), ``parameters`` (a name
        the model does not have, or not one value a member), ``workers`` or ``chunk_size``
        (not a positive integer), ``save_every`` (the output would not fit in memory), or an
        argument of :func:`varmech.integrate`.
    KeyboardInterrupt
        Ctrl-C stops every member within about 0.1 s; ``err.partial`` is the
        :class:`Ensemble` of what was computed (the stopped members have status -1).

    Examples
    --------
    >>> import numpy as np, varmech
    >>> from varmech import scenes
    >>> scene = scenes.damped_driven_pendulum()
    >>> amplitudes = np.array([0.9, 1.07, 1.5])
    >>> runs = varmech.ensemble(scene, np.zeros((3, 1)), np.zeros((3, 1)), dt=0.05, steps=400,
    ...                         parameters={"amplitude": amplitudes}, save_every=10, progress=False)
    >>> runs.q.shape, runs.failed
    ((3, 41, 1), [])
    >>> single = varmech.integrate(scenes.damped_driven_pendulum(amplitude=1.07), [0.0], [0.0],
    ...                            dt=0.05, steps=400, save_every=10)
    >>> bool(np.array_equal(runs[1].q, single.q))
    True
    """
    contacts = list(contacts_of(model, contacts))
    model, _, _ = model_and_state(model, None, None, None)
    n = model.dim
    q = np.array(floats("q0", q0))
    if q.ndim != 2 or q.shape[1] != n or q.shape[0] == 0:
        raise ValueError(f"q0: must have shape (members, {n}) with at least one member, got shape {q.shape}")
    _finite_rows("q0", q)
    members = q.shape[0]
    values = _parameter_values(model, parameters, members)
    models = _member_models(model, values, members)
    # Each member's integrate keywords, where the members run one integrate each (serially, in
    # processes, on a cluster), which builds each one's spec.
    settings: dict[str, Any] = dict(
        dt=dt, steps=steps, t_end=t_end, method=method, save_every=save_every, compensated=compensated, t0=t0,
        newton_tolerance=newton_tolerance, newton_max_iterations=newton_max_iterations, max_energy_error=max_energy_error,
        events=events, contacts=contacts, impulses=impulses, t_eval=t_eval,
    )
    spec = RunSpec.checked(model, members, **settings)
    workers = None if workers is None else positive_int("workers", workers)
    chunk_size = None if chunk_size is None else positive_int("chunk_size", chunk_size)
    p = _momenta(models, q, p0, v0, spec.t0)
    if client is not None:
        return _on_cluster(client, model, q, p, values, settings | dict(workers=workers), chunk_size, progress)
    cores = [m._core for m in (models if values else models[:1])]
    released = [c for c in cores if isinstance(c, (_core.NativeModel, _core.CompiledModel))]
    native = (
        all(e.native is not None for e in spec.jumps.events)
        and all(c.native for c in contacts)
        and all(kind == "generalized" for _, kind, _ in spec.jumps.impulse_specs)
    )
    if len(released) == len(cores) and native:
        # The members' run, each member's as integrate would specify it.
        results, interrupted = _on_threads(released, q, p, spec, workers, chunk_size, members, progress)
        trajs, errors = [], []
        for i, (record, error) in enumerate(results):
            status: dict[str, Any] = {} if error is None else {"status": -1, "message": str(error)}
            trajs.append(of_record(record, models[i], spec, **status))
            errors.append(error)
        result = Ensemble(trajs, errors, values)
        if interrupted is not None:
            interrupted.partial = result  # type: ignore[attr-defined]
            raise interrupted
        return result
    if workers is not None and workers > 1 and members > 1:
        return _in_processes(model, q, p, values, settings, workers, chunk_size, progress)
    return _serial(models, q, p, values, settings, progress)


def _on_threads(
    released: list[Any],
    q: np.ndarray,
    p: np.ndarray,
    spec: RunSpec,
    workers: int | None,
    chunk_size: int | None,
    members: int,
    progress: bool | None,
) -> tuple[list[tuple[Any, BaseException | None]], BaseException | None]:
    """The members run as ``spec`` specifies, in the core's parallel loop on ``workers``
    threads: each member's record and error, and the KeyboardInterrupt that stopped them (or
    None)."""
    bar = progress_bar(total=spec.steps * members, unit="step", desc=f"{spec.method} ×{members}", enabled=progress)
    try:
        report = None if bar.disable else (lambda done: bar.update(done - bar.n))
        return _core.ensemble(released, q, p, spec.binding(), workers=workers, chunk_size=chunk_size, progress=report)
    finally:
        bar.close()


def _on_cluster(
    client: Any,
    model: Model,
    q: np.ndarray,
    p: np.ndarray,
    values: dict[str, np.ndarray],
    settings: dict[str, Any],
    chunk_size: int | None,
    progress: bool | None,
) -> Ensemble:
    """The ensemble on a Dask cluster: chunks of members as tasks (:func:`_chunk`), gathered in
    member order."""
    from distributed import as_completed

    _shipped(model, settings, "the cluster")
    members = len(q)
    if chunk_size is None:
        chunk_size = _default_chunk(members, sum(client.nthreads().values()) or 1)
    starts = range(0, members, chunk_size)
    futures = [
        client.submit(
            _chunk, model, q[a : a + chunk_size], p[a : a + chunk_size],
            {k: v[a : a + chunk_size] for k, v in values.items()}, settings, pure=False,
        )
        for a in starts
    ]
    order = {future.key: i for i, future in enumerate(futures)}
    chunks: list[Any] = [None] * len(futures)
    bar = progress_bar(total=members, unit="member", desc=f"{settings['method']} on {client.id}", enabled=progress)
    try:
        for future, result in as_completed(futures, with_results=True):
            chunks[order[future.key]] = result
            bar.update(len(result[0]))
    except BaseException as err:
        client.cancel(futures)
        if isinstance(err, KeyboardInterrupt):
            err.partial = _gathered(chunks, values, _unfinished(model, settings, members, chunk_size, err))  # type: ignore[attr-defined]
        raise
    finally:
        bar.close()
    return _gathered(chunks, values)


def _shipped(model: Model, settings: dict[str, Any], where: str) -> bytes:
    """The model and the run's settings (its events among them) pickled by cloudpickle, as they
    go to worker processes; one that cannot be is a TypeError naming ``model``."""
    import cloudpickle

    try:
        return cloudpickle.dumps((model, settings))
    except Exception as err:
        raise TypeError(f"model: {model.name} or its events cannot be shipped to {where} ({err})") from err


def _default_chunk(members: int, workers: int) -> int:
    """Members a task runs when ``chunk_size`` is not given to a cluster or to processes: about
    four tasks a worker, so that the faster ones take more."""
    return max(1, math.ceil(members / (4 * workers)))


def _gathered(chunks: list[Any], values: dict[str, np.ndarray], unfinished: Any = None) -> Ensemble:
    """The ensemble of the chunks' (trajectories, errors), in member order; a chunk not gathered
    (None) is ``unfinished(k)``."""
    chunks = [unfinished(k) if chunk is None else chunk for k, chunk in enumerate(chunks)]
    trajs = [tr for chunk, _ in chunks for tr in chunk]
    errors = [e for _, chunk in chunks for e in chunk]
    return Ensemble(trajs, errors, values)


def _unfinished(model: Model, settings: dict[str, Any], members: int, chunk_size: int, err: BaseException) -> Any:
    """Chunk k as Ctrl-C left it before it was gathered: members that saved no state."""

    def chunk(k: int) -> tuple[list[Trajectory], list[BaseException | None]]:
        size = min(chunk_size, members - k * chunk_size)
        return [_empty(model, settings, "interrupted before it finished")] * size, [err] * size

    return chunk


def _in_processes(
    model: Model,
    q: np.ndarray,
    p: np.ndarray,
    values: dict[str, np.ndarray],
    settings: dict[str, Any],
    workers: int,
    chunk_size: int | None,
    progress: bool | None,
) -> Ensemble:
    """A closure model's ensemble in ``workers`` processes: chunks of members, each one task
    (:func:`_closure_chunk`), gathered in member order. The processes start clean (forkserver or
    spawn: forking a process that runs threads is unsafe) and ignore SIGINT: Ctrl-C reaches this
    process, which stops them and keeps the chunks gathered."""
    import cloudpickle

    shipped = _shipped(model, settings, "worker processes")
    members = len(q)
    workers = min(workers, members)
    if chunk_size is None:
        chunk_size = _default_chunk(members, workers)
    tasks = [(shipped, q[a : a + chunk_size], p[a : a + chunk_size]) for a in range(0, members, chunk_size)]
    chunks: list[Any] = [None] * len(tasks)
    start = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    pool = multiprocessing.get_context(start).Pool(workers, initializer=_worker_start)
    bar = progress_bar(total=members, unit="member", desc=f"{settings['method']} ({workers} processes)", enabled=progress)
    try:
        for k, result in enumerate(pool.imap(_closure_chunk, tasks)):
            chunks[k] = cloudpickle.loads(result)
            bar.update(len(chunks[k][0]))
        # Done: the workers exit on their own, running their finalizers.
        pool.close()
    except BaseException as err:
        if isinstance(err, KeyboardInterrupt):
            err.partial = _gathered(chunks, values, _unfinished(model, settings, members, chunk_size, err))  # type: ignore[attr-defined]
        pool.terminate()
        raise
    finally:
        pool.join()
        bar.close()
    return _gathered(chunks, values)


def _worker_start() -> None:
    """A worker process's start: Ctrl-C is the parent's to handle, and its progress bars (all
    off) lock with a thread lock, not a named semaphore that would leak when it is terminated."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    thread_lock()


def _closure_chunk(task: tuple[bytes, np.ndarray, np.ndarray]) -> bytes:
    """One process task: the members of a chunk, serially; the result by cloudpickle (a
    user's exception class may live in ``__main__``)."""
    import cloudpickle

    shipped, q, p = task
    model, settings = cloudpickle.loads(shipped)
    run = _serial([model] * len(q), q, p, {}, settings, False)
    return cloudpickle.dumps((run.trajectories, run.errors))


def _chunk(
    model: Model, q: np.ndarray, p: np.ndarray, values: dict[str, np.ndarray], settings: dict[str, Any]
) -> tuple[list[Trajectory], list[BaseException | None]]:
    """One cluster task: :func:`ensemble` of a chunk of members in the worker process, on the
    worker's threads unless ``workers`` says otherwise."""
    from distributed import get_worker

    settings = dict(settings)
    if settings["workers"] is None:
        settings["workers"] = get_worker().state.nthreads
    run = ensemble(model, q, p, parameters=values or None, progress=False, **settings)
    return run.trajectories, run.errors


def _serial(
    models: Sequence[Model],
    q: np.ndarray,
    p: np.ndarray,
    values: dict[str, np.ndarray],
    settings: dict[str, Any],
    progress: bool | None,
) -> Ensemble:
    """A closure model's ensemble: :func:`varmech.integrate` member by member (the closures
    hold the GIL, so threads would not run them in parallel)."""
    trajs: list[Trajectory] = []
    errors: list[BaseException | None] = []
    bar = progress_bar(total=len(q), unit="member", desc=f"{settings['method']} (serial)", enabled=progress)
    try:
        for i, model in enumerate(models):
            try:
                trajs.append(integrate(model, q[i], p[i], **settings, progress=False))
                errors.append(None)
            except Exception as err:
                partial = getattr(err, "partial", None) or _empty(model, settings, str(err))
                trajs.append(partial)
                errors.append(err)
            except KeyboardInterrupt as err:
                partial = getattr(err, "partial", None)
                rest = [_empty(m, settings, "interrupted before it started") for m in models[len(trajs) + (partial is not None) :]]
                stopped = [partial] if partial is not None else []
                err.partial = Ensemble(trajs + stopped + rest, errors + [err] * (len(stopped) + len(rest)), values)  # type: ignore[attr-defined]
                raise
            bar.update(1)
    finally:
        bar.close()
    return Ensemble(trajs, errors, values)


def _empty(model: Model, run: dict[str, Any], message: str) -> Trajectory:
    """The trajectory of a member that saved no state."""
    n = model.dim
    empty = np.empty((0, n))
    return Trajectory(np.empty(0), empty, empty.copy(), model, run["method"], run["dt"], 0, 0, status=-1, message=message)


def _parameter_values(model: Model, parameters: Mapping[str, ArrayLike] | None, members: int) -> dict[str, np.ndarray]:
    """Each named parameter's value per member, checked against the model's parameters."""
    if parameters is None:
        return {}
    if not isinstance(parameters, Mapping):
        raise ValueError(f"parameters: expected a dict {{name: values}}, got {type(parameters).__name__}")
    known = getattr(model, "parameters", None) or {}
    values = {}
    for name, given in parameters.items():
        name = str(name)
        if name not in known:
            has = ", ".join(known) if known else "none"
            raise ValueError(f"parameters: {name} is not a parameter of {model.name} (it has {has})")
        x = floats("parameters", given)
        x = np.broadcast_to(x, (members,)) if x.ndim == 0 else x
        if x.shape != (members,) or not np.all(np.isfinite(x)):
            raise ValueError(f"parameters: {name} needs one finite value a member ({members}), got shape {x.shape}")
        values[name] = np.array(x)
    return values


def _member_models(model: Model, values: dict[str, np.ndarray], members: int) -> list[Model]:
    """One model shared by all members, or each member's model at its parameter values: a
    native scene built again by the core, a symbolic model with its compiled code kept."""
    if not values:
        return [model] * members
    if isinstance(model, NativeSystem):
        assert model.parameters is not None
        base = model.parameters
        return [scene_model(model.name, {**base, **{k: float(v[i]) for k, v in values.items()}}) for i in range(members)]
    return [model.with_parameters(**{k: float(v[i]) for k, v in values.items()}) for i in range(members)]


def _finite_rows(name: str, x: np.ndarray) -> None:
    """Refuses members whose initial data are not finite, as integrate refuses them."""
    bad = np.flatnonzero(~np.all(np.isfinite(x), axis=1))
    if bad.size:
        raise ValueError(f"{name}: must be finite, got non-finite values for members {bad[:10].tolist()}")


def _momenta(models: Sequence[Model], q: np.ndarray, p0: ArrayLike | None, v0: ArrayLike | None, t0: float) -> np.ndarray:
    """p0 checked against q0, or p0 = ∂L/∂q̇(q0, v0, t0) of each member's model."""
    if (p0 is None) == (v0 is None):
        raise ValueError("p0, v0: give exactly one of the initial momenta p0 and velocities v0")
    name, given = ("p0", p0) if p0 is not None else ("v0", v0)
    x = np.array(floats(name, given))
    if x.ndim != 2 or x.shape[1] != q.shape[1]:
        raise ValueError(f"{name}: must have shape (members, {q.shape[1]}), got shape {x.shape}")
    if x.shape[0] != q.shape[0]:
        raise ValueError(f"{name}: {x.shape[0]} members, but q0 has {q.shape[0]}")
    _finite_rows(name, x)
    if name == "p0":
        return x
    if all(m is models[0] for m in models):
        return np.ascontiguousarray(models[0].momentum(q, x, t0))
    return np.array([m.momentum(qi, vi, t0) for m, qi, vi in zip(models, q, x)])


__all__ = ["Ensemble", "EnsembleConservation", "ensemble"]
