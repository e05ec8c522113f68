"""Trajectories in HDF5 files (h5py, the optional extra ``io``): :meth:`Trajectory.save`,
:func:`load`, and the files that runs stream to (``integrate(output=)``, :func:`varmech.resume`).

The layout, self-describing so that any HDF5 reader can use it (``docs/file_format.md``)::

    /            attrs: format = "varmech-trajectory", format_version = 2, varmech_version,
                        method, dt, dim, save_every (0: unknown), model (its repr), complete,
                        steps, nfev, status, message
    /t           (N,)   float64   the saved times
    /q, /p       (N, n) float64   positions and momenta, one row a saved state
    /newton      (N,)   uint64    cumulative Newton iterations (only for methods that solve)
    /work        (N,)   float64   cumulative work of the forces (only for forced models)
    /committed   (5,)   int64     rows, checkpoint slot, checkpoint length, steps, nfev
    /checkpoint0, /checkpoint1    uint8  the last committed state's checkpoint, in the slot
                                  /committed names (the other holds the one before)
    /events/<k>  attr name; t (k,), q, p (k, n): the crossings of the run's k-th event
    /model       opaque bytes     the model's pickle (what builds it: a scene's name and
                                  parameters, expressions, or closures by reference)

The arrays are chunked by rows and grow as a run appends to them. A writer appends the rows
and the checkpoint of a chunk, flushes them, and only then updates ``/committed`` (HDF5's
single-writer/multiple-reader mode keeps the file readable at every moment): a run killed at
any point leaves a file whose committed rows and checkpoint are intact. The root's ``complete``
is set when the writer closes; a file without it is a run that stopped without closing
(``status`` -1 on loading, and :func:`varmech.resume` continues it).

Loading unpickles the model, as :mod:`pickle` does: open only files you trust, or pass
``model=`` to :func:`load` to skip the stored one.
"""

from __future__ import annotations

import os
import pickle
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .events import Occurrences

if TYPE_CHECKING:
    from .integrate import Trajectory
    from .model import Model

__all__ = [
    "LAZY_BYTES",
    "Rows",
    "load",
]

FORMAT = "varmech-trajectory"
FORMAT_VERSION = 2
#: Rows per chunk: about 64 kB of a (N, 2)-shaped q for the small systems.
CHUNK_ROWS = 4096
_COLUMNS = ("t", "q", "p", "newton", "work")
#: A streamed run's file larger than this is read back lazily (its columns when used).
LAZY_BYTES = 256 * 2**20
_DTYPES = {"newton": np.uint64}


def _h5py() -> Any:
    try:
        import h5py
    except ImportError as e:  # pragma: no cover - the io extra is installed with the tests
        raise ImportError("varmech's files need h5py: pip install 'varmech[io]'") from e
    return h5py


def writable(path: str | os.PathLike[str], overwrite: bool, argument: str) -> Path:
    """``path`` as a Path, after checking that a new file can be made there; ValueError naming
    ``argument`` otherwise."""
    target = Path(path)
    if target.is_dir():
        raise ValueError(f"{argument}: {str(target)!r} is a directory")
    if target.exists() and not overwrite:
        raise ValueError(f"{argument}: {str(target)!r} exists; pass overwrite=True to replace it")
    if not target.parent.is_dir():
        raise ValueError(f"{argument}: cannot write {str(target)!r}: its directory does not exist")
    if not os.access(target.parent, os.W_OK):
        raise ValueError(f"{argument}: cannot write {str(target)!r}: its directory is not writable")
    return target


class Writer:
    """A trajectory file being written: :meth:`append` adds a run's rows and its checkpoint,
    committed together; :meth:`close` records how the run ended.

    ``columns`` are the optional columns the run has (``"newton"``, ``"work"``).
    """

    def __init__(
        self,
        path: Path,
        *,
        model: Model,
        method: str,
        dt: float,
        columns: tuple[str, ...],
        save_every: int = 0,
        events: Sequence[str] = (),
        argument: str = "path",
        contacts: Sequence[str] = (),
    ):
        from . import __version__

        h5py = _h5py()
        self.path = path
        self._argument = argument
        n = model.dim
        try:
            self._file = h5py.File(path, "w", libver="latest")
            f = self._file
            f.attrs.update(
                {
                    "format": FORMAT,
                    "format_version": FORMAT_VERSION,
                    "varmech_version": __version__,
                    "method": method,
                    "dt": dt,
                    "dim": n,
                    "save_every": save_every,
                    "model": repr(model),
                    "complete": False,
                    "steps": 0,
                    "nfev": 0,
                    "status": -1,
                    "message": "The run stopped before closing its file.",
                }
            )
            if contacts:
                # A run's contacts are not in its checkpoint: load marks it, and resume refuses it.
                f.attrs["contacts"] = list(contacts)
            for name in ("t", "q", "p", *columns):
                shape = (0, n) if name in ("q", "p") else (0,)
                f.create_dataset(
                    name,
                    shape=shape,
                    maxshape=(None, *shape[1:]),
                    chunks=(CHUNK_ROWS, *shape[1:]),
                    dtype=_DTYPES.get(name, np.float64),
                )
            for slot in (0, 1):
                f.create_dataset(f"checkpoint{slot}", shape=(0,), maxshape=(None,), chunks=(4096,), dtype=np.uint8)
            f.create_dataset("committed", data=np.zeros(5, dtype=np.int64))
            f.create_dataset("model", data=np.void(pickle.dumps(model)))
            _create_events(f, events, n)
            f.swmr_mode = True
        except OSError as e:
            raise ValueError(f"{argument}: cannot write {str(path)!r}: {e}") from e
        self._columns = ("t", "q", "p", *columns)
        self.rows = 0
        self._slot = 1
        self.is_open = True
        self._datasets: dict[str, Any] | None = None

    @classmethod
    def reopen(cls, path: Path, stored: Trajectory, events: Sequence[str] = ()) -> Writer:
        """The writer appending to the file ``path`` (loaded as ``stored``) after its committed
        rows, marked incomplete until it closes again, with the crossings of ``events`` (named
        as the file's, if it has any)."""
        h5py = _h5py()
        writer = cls.__new__(cls)
        writer.path, writer._argument = path, "path"
        try:
            try:
                f = h5py.File(path, "r+", libver="latest")
            except OSError as e:
                if "already open for write" not in str(e):
                    raise
                # A writer killed in SWMR mode leaves the file marked open: copy what it committed.
                _recover(path)
                f = h5py.File(path, "r+", libver="latest")
            f.attrs.update({"complete": False, "status": -1, "message": "The run stopped before closing its file."})
            rows, slot = (int(x) for x in f["committed"][:2])
            stored_names = [o.name for o in stored.events]
            if events and stored_names and list(events) != stored_names:
                f.close()
                raise ValueError(f"events: the file's events are {stored_names}, not {list(events)}")
            if events and "events" not in f:
                _create_events(f, events, int(f.attrs["dim"]))
            f.swmr_mode = True
        except OSError as e:
            raise ValueError(f"path: cannot append to {str(path)!r}: {e}") from e
        writer._file = f
        writer._columns = tuple(name for name in _COLUMNS if name in f)
        writer.rows, writer._slot, writer.is_open = rows, slot, True
        writer._datasets = None
        return writer

    def append(self, record: Any, *, skip_first: bool = False, events: Sequence[Occurrences] = ()) -> None:
        """Appends the rows of ``record`` (a :class:`Trajectory` or the binding's record; its
        first row left out when it repeats the last one written) and commits them with its
        checkpoint, its steps and its evaluations: rows and checkpoint are written and flushed
        first, ``/committed`` last.

        Through h5py's low-level API (extent, hyperslab, write): about 0.2 ms a commit, where
        the high-level indexing took 1.5 ms."""
        h5py = _h5py()
        f, start = self._file, int(skip_first)
        if self._datasets is None:
            # h5py's lookup by name costs about 0.1 ms; a commit would spend more on it than on writing.
            names = (*self._columns, "checkpoint0", "checkpoint1", "committed")
            self._datasets = {name: f[name] for name in names}
        datasets = self._datasets
        added = len(record.t) - start
        if added > 0:
            for name in self._columns:
                ds = datasets[name]
                data = np.ascontiguousarray(np.asarray(getattr(record, name))[start:], dtype=ds.dtype)
                ds.id.set_extent((self.rows + added, *data.shape[1:]))
                space = ds.id.get_space()
                space.select_hyperslab((self.rows, *(0,) * (data.ndim - 1)), data.shape)
                ds.id.write(h5py.h5s.create_simple(data.shape), space, data)
        for k, occurrences in enumerate(events):
            group = f["events"][str(k)]
            for name in ("t", "q", "p"):
                ds, data = group[name], np.asarray(getattr(occurrences, name), dtype=np.float64)
                if len(data):
                    start = ds.shape[0]
                    ds.resize(start + len(data), axis=0)
                    ds[start:] = data
        slot = 1 - self._slot
        checkpoint = np.frombuffer(record.checkpoint or b"", dtype=np.uint8)
        ds = datasets[f"checkpoint{slot}"]
        ds.id.set_extent((len(checkpoint),))
        if len(checkpoint):
            ds.id.write(h5py.h5s.ALL, h5py.h5s.ALL, checkpoint)
        f.flush()
        nfev = getattr(record, "nfev", None)
        nfev = record.force_evaluations if nfev is None else nfev
        committed = datasets["committed"]
        row = np.array([self.rows + added, slot, len(checkpoint), record.steps, nfev], dtype=np.int64)
        committed.id.write(h5py.h5s.ALL, h5py.h5s.ALL, row)
        committed.id.flush()
        self.rows += added
        self._slot = slot

    def close(self, status: int, message: str) -> None:
        """Records the end of the run (``status``, ``message`` and the committed counts) and
        closes the file."""
        self.abandon()
        with _h5py().File(self.path, "r+") as f:
            rows, _, _, steps, nfev = (int(x) for x in f["committed"][()])
            f.attrs.update({"complete": True, "status": status, "message": message, "steps": steps, "nfev": nfev})

    def abandon(self) -> None:
        """Closes the file as it is (a run stopped by an exception that could not be recorded)."""
        self._file.close()
        self.is_open = False


def _create_events(f: Any, names: Sequence[str], n: int) -> None:
    """The groups ``/events/<k>`` of the events ``names``, empty and growing."""
    if not names:
        return
    group = f.create_group("events")
    for k, name in enumerate(names):
        g = group.create_group(str(k))
        g.attrs["name"] = name
        for column, shape in (("t", (0,)), ("q", (0, n)), ("p", (0, n))):
            g.create_dataset(column, shape=shape, maxshape=(None, *shape[1:]), chunks=(256, *shape[1:]), dtype=np.float64)


def _recover(path: Path) -> None:
    """Rewrites the file of a killed writer with its committed rows and checkpoint (HDF5 copies
    the datasets chunk by chunk), replacing it atomically."""
    h5py = _h5py()
    part = path.with_name(path.name + ".recovering")
    with h5py.File(path, "r", swmr=True) as src, h5py.File(part, "w", libver="latest") as dst:
        dst.attrs.update(dict(src.attrs))
        rows, slot, length = (int(x) for x in src["committed"][:3])
        for name in src:
            src.copy(src[name], dst, name=name)
            if name in _COLUMNS:
                dst[name].resize(rows, axis=0)
        dst[f"checkpoint{slot}"].resize((length,))
    os.replace(part, path)


def save(traj: Trajectory, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Writes ``traj`` to the HDF5 file ``path`` (see the module's layout) and returns its path.

    Raises ValueError naming ``path`` when the file exists and ``overwrite`` is False, or when it
    cannot be written.
    """
    target = writable(path, overwrite, "path")
    columns, names = columns_of(traj.model, traj.method), [o.name for o in traj.events]
    writer = Writer(
        target, model=traj.model, method=traj.method, dt=traj.dt, columns=columns, events=names, contacts=traj.contacts
    )
    writer.append(traj, events=traj.events)
    writer.close(traj.status, traj.message)
    return target


def columns_of(model: Model, method: str) -> tuple[str, ...]:
    """The optional columns of a run of ``method`` on ``model``: Newton counts for the methods
    that solve equations, work for forced models."""
    from .methods import method_info

    info = method_info(method)
    return (*(("newton",) if info.implicit or info.constrained else ()), *(("work",) if model.forced else ()))


class Rows:
    """A column of a trajectory file, read when used: indexing reads the rows asked for, and
    NumPy (``np.asarray``, arithmetic) reads the whole column once and keeps it.

    :func:`load` with ``lazy=True`` gives each column of the trajectory as one; it is not made
    by hand.

    Parameters
    ----------
    path : pathlib.Path
        The HDF5 file.
    name : str
        The column's dataset in the file (``"t"``, ``"q"``, ``"p"``, ...).
    shape : tuple of int
        The committed rows and each row's shape.
    dtype : numpy.dtype or str
        The column's element type.

    Attributes
    ----------
    shape : tuple of int
        As given.
    dtype : numpy.dtype
        As given.
    ndim : int
        ``len(shape)``.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np, varmech
    >>> s = varmech.scenes.kepler()
    >>> traj = varmech.integrate(s, dt=s.dt, steps=100, save_every=10)
    >>> back = varmech.load(traj.save(pathlib.Path(tempfile.mkdtemp()) / "k.h5"), lazy=True)
    >>> back.q.shape, bool(np.array_equal(back.q[-1], traj.q[-1]))
    ((11, 2), True)
    """

    __array_priority__ = 1.0

    def __init__(self, path: Path, name: str, shape: tuple[int, ...], dtype: Any):
        self._path, self._name, self.shape, self.dtype = path, name, shape, np.dtype(dtype)
        self._data: np.ndarray | None = None

    @property
    def ndim(self) -> int:
        return len(self.shape)

    def __getitem__(self, key: Any) -> Any:
        if self._data is not None:
            return self._data[key]
        if isinstance(key, (int, np.integer)) or (
            isinstance(key, tuple) and key and isinstance(key[0], (int, np.integer))
        ):
            first = key[0] if isinstance(key, tuple) else key
            row = int(first) + (self.shape[0] if first < 0 else 0)
            if not 0 <= row < self.shape[0]:
                raise IndexError(f"row {first} out of range for {self.shape[0]} rows")
            with _h5py().File(self._path, "r", swmr=True) as f:
                data = f[self._name][row]
            return data[key[1:]] if isinstance(key, tuple) else data
        return np.asarray(self)[key]

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        if self._data is None:
            with _h5py().File(self._path, "r", swmr=True) as f:
                self._data = f[self._name][: self.shape[0]]
        return self._data if dtype is None else self._data.astype(dtype)

    def __array_ufunc__(self, ufunc: Any, method: str, *inputs: Any, **kwargs: Any) -> Any:
        inputs = tuple(np.asarray(x) if isinstance(x, Rows) else x for x in inputs)
        return getattr(ufunc, method)(*inputs, **kwargs)

    def __len__(self) -> int:
        return self.shape[0]

    def __iter__(self) -> Iterator[Any]:
        return iter(np.asarray(self))

    def __repr__(self) -> str:
        return f"Rows({str(self._path)!r}, {self._name!r}, shape={self.shape})"


def load(path: str | os.PathLike[str], *, model: Model | None = None, lazy: bool = False) -> Trajectory:
    """The trajectory saved in ``path`` by :meth:`Trajectory.save` or streamed there by a run
    (``integrate(output=)``), with its model unpickled, or ``model`` instead (which must have the
    file's dimension). Only the committed rows are read; a run that stopped without closing its
    file loads with ``status`` -1, and its checkpoint lets :func:`varmech.resume` go on.

    ``lazy=True`` reads no column until it is used (each a :class:`Rows`; indexing reads only
    the rows asked for), for files larger than memory.

    Parameters
    ----------
    path : str or os.PathLike
        The HDF5 file.
    model : Model, optional
        The model to attach instead of the file's pickled one (needed for a closure model whose
        closures do not unpickle).
    lazy : bool, default False
        Read each column only when used.

    Returns
    -------
    Trajectory
        The run in the file, with its checkpoint.

    Raises
    ------
    ValueError
        Naming ``path`` for a missing, corrupt or truncated file, or one that is not a varmech
        trajectory; naming ``model`` for a model of another dimension.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np, varmech
    >>> s = varmech.scenes.kepler()
    >>> traj = varmech.integrate(s, dt=s.dt, steps=100, save_every=10)
    >>> path = traj.save(pathlib.Path(tempfile.mkdtemp()) / "kepler.h5")
    >>> back = varmech.load(path)
    >>> bool(np.array_equal(back.q, traj.q)) and back.method == traj.method
    True
    """
    from .integrate import Trajectory

    h5py = _h5py()
    source = Path(path)
    if not source.is_file():
        raise ValueError(f"path: no file {str(source)!r}")
    try:
        with h5py.File(source, "r", swmr=True) as f:
            if f.attrs.get("format") != FORMAT:
                raise ValueError(f"path: {str(source)!r} is not a varmech trajectory file")
            version = int(f.attrs["format_version"])
            if version != FORMAT_VERSION:
                raise ValueError(f"path: format version {version}; this varmech reads version {FORMAT_VERSION}")
            a = dict(f.attrs)
            rows, slot, length, steps, nfev = (int(x) for x in f["committed"][()])
            present = [name for name in _COLUMNS if name in f]
            shapes = {name: (rows, *f[name].shape[1:]) for name in present}
            if any(f[name].shape[0] < rows for name in present):
                raise ValueError(f"path: {str(source)!r} is truncated: fewer rows than committed")
            columns: dict[str, Any] = {
                name: Rows(source, name, shapes[name], f[name].dtype) if lazy else f[name][:rows] for name in present
            }
            checkpoint = f[f"checkpoint{slot}"][:length].tobytes()
            # Crossings after the last committed state are a killed run's uncommitted segment's.
            t_last = float(f["t"][rows - 1]) if rows else -np.inf
            events = tuple(_occurrences(f["events"][str(k)], t_last) for k in range(len(f["events"]))) if "events" in f else ()
            blob: bytes = f["model"][()].tobytes() if model is None else b""
    except (OSError, KeyError, RuntimeError) as e:
        # h5py raises RuntimeError for some damaged structures (a bad heap signature).
        raise ValueError(f"path: {str(source)!r} is corrupt or truncated: {e}") from e
    if model is None:
        try:
            model = pickle.loads(blob)  # noqa: S301 - documented: a file's model is its pickle
        except Exception as e:
            raise ValueError(f"path: cannot rebuild the model {a['model']!r}: {e}; pass model=") from e
    if model.dim != int(a["dim"]):
        raise ValueError(f"model: has dimension {model.dim}, the file's states {int(a['dim'])}")
    complete = bool(a["complete"])
    return Trajectory(
        columns["t"],
        columns["q"],
        columns["p"],
        model,
        str(a["method"]),
        float(a["dt"]),
        steps,
        nfev,
        columns.get("newton"),
        columns.get("work"),
        status=int(a["status"]) if complete else -1,
        message=str(a["message"]) if complete else f"The run stopped at step {steps} without closing its file.",
        checkpoint=checkpoint or None,
        events=events,
        contacts=tuple(str(name) for name in a.get("contacts", ())),
    )


def save_every_of(path: str | os.PathLike[str]) -> int:
    """The saving period of the run in ``path``: its ``save_every`` attribute, or (for a saved
    trajectory, which has none) the steps between its first two states."""
    with _h5py().File(path, "r", swmr=True) as f:
        every = int(f.attrs.get("save_every", 0))
        if every > 0:
            return every
        t, dt = f["t"][:2], float(f.attrs["dt"])
    return max(1, round(float(t[1] - t[0]) / dt)) if len(t) > 1 else 1


def _occurrences(group: Any, t_last: float) -> Occurrences:
    """An event's crossings in the file, up to the committed time ``t_last``."""
    t = group["t"][()]
    keep = int(np.searchsorted(t, t_last, side="right"))
    return Occurrences(str(group.attrs["name"]), t[:keep], group["q"][:keep], group["p"][:keep])


def larger_than_memory(path: str | os.PathLike[str]) -> bool:
    """Whether a run's file is to be read back lazily: larger than :data:`LAZY_BYTES`."""
    return Path(path).stat().st_size > LAZY_BYTES
