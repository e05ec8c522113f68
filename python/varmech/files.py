"""Trajectories in HDF5 files (h5py, the optional extra ``io``): :meth:`Trajectory.save`,
:func:`varmech.load` (in :mod:`varmech.trajectory`, which builds the Trajectory), and the files
that runs stream to (``integrate(output=)``, :func:`varmech.resume`).

The layout, self-describing so that any HDF5 reader can use it (``docs/file_format.md``)::

    /            attrs: format = "varmech-trajectory", format_version = 3, varmech_version,
                        method, dt, dim, save_every (0: unknown), model (its repr), complete,
                        steps, nfev, status, message
    /t           (N,)   float64   the saved times
    /q, /p       (N, n) float64   positions and momenta, one row a saved state
    /newton      (N,)   uint64    cumulative Newton iterations (only for methods that solve)
    /work        (N,)   float64   cumulative energy put in, W (only where something can put it in or take it out)
    /committed   (5,)   int64     rows, checkpoint slot, checkpoint length, steps, nfev
    /checkpoint0, /checkpoint1    uint8  the last committed state's checkpoint, in the slot
                                  /committed names (the other holds the one before)
    /events/<k>  attr name; t (k,), q, p (k, n): the crossings of the run's k-th event
    /model       string           what builds the model, as JSON data (Model._recipe): a
                                  scene's name and parameters, G and the masses, a symbolic
                                  model's expressions and tapes; or {"kind": "pickle"}
    /model_pickle opaque bytes    the pickle of a model only pickle carries (closures)

The arrays are chunked by rows, carry HDF5's Fletcher-32 checksum and grow as a run appends to
them. A writer appends the rows
and the checkpoint of a chunk, flushes them, and only then updates ``/committed`` (HDF5's
single-writer/multiple-reader mode keeps the file readable at every moment): a run killed at
any point leaves a file whose committed rows and checkpoint are intact. The root's ``complete``
is set when the writer closes; a file without it is a run that stopped without closing
(``status`` -1 on loading, and :func:`varmech.resume` continues it).

Loading runs no code from the file: the model is built from its data, and a pickle
(``/model_pickle``, or the ``/model`` of a format-2 file) is unpickled only when the caller
passes ``allow_pickle=True``. Before libhdf5 opens a file its superblock is checked against the
file's size (libhdf5 can hang on a truncated file).
"""

from __future__ import annotations

import errno
import json
import os
import pickle
import shutil
import subprocess
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from . import impacts as _impacts
from . import impulses as _impulses
from ._runspec import Jumps, RunSpec
from ._version import __version__
from .events import Occurrences
from .impacts import Contact
from .impulses import Impulse
from .methods import method_info
from .model import Model, from_recipe, variable_attributes

if TYPE_CHECKING:
    from .trajectory import Trajectory

__all__ = [
    "LAZY_BYTES",
    "Rows",
]

FORMAT = "varmech-trajectory"
FORMAT_VERSION = 3
#: The versions this varmech reads: 2 differs only in its ``/model``, a pickle.
READS = (2, 3)
#: Rows per chunk: about 64 kB of a (N, 2)-shaped q for the small systems.
CHUNK_ROWS = 4096
COLUMNS = ("t", "q", "p", "newton", "work")
#: A streamed run's file larger than this is read back lazily (its columns when used).
LAZY_BYTES = 256 * 2**20
_DTYPES = {"newton": np.uint64}
#: Room kept free on the disk beyond what a commit writes: the file's metadata and its closing.
SPARE_BYTES = 2**16


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

    The file is laid out for a run of ``model`` as ``spec`` specifies it: its method, step,
    saving period (0: unknown), contacts and impulses, the optional columns they call for
    (:func:`columns_of`), the crossings of its occurrences (``events``, their names; by default
    the spec's, :meth:`RunSpec.occurrence_names`), and, where ``planned``, the end the run is
    asked to reach (``spec.planned``; a saved trajectory has none). Errors name ``argument``.
    """

    def __init__(
        self,
        path: Path,
        model: Model,
        spec: RunSpec,
        *,
        events: Sequence[str] | None = None,
        argument: str = "path",
        planned: bool = True,
    ):
        method, contacts, impulses = spec.method, spec.jumps.contacts, spec.jumps.impulses
        columns = columns_of(model, method, contacts, impulses)
        if events is None:
            events = spec.occurrence_names()
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
                    "dt": spec.dt,
                    "dim": n,
                    "save_every": spec.save_every,
                    "model": repr(model),
                    "complete": False,
                    "steps": 0,
                    "nfev": 0,
                    "status": -1,
                    "message": "The run stopped before closing its file.",
                }
            )
            if planned:
                f.attrs["planned_steps"] = spec.planned
            if contacts:
                # The native ones as data; one of Python functions by its name (resume takes it again).
                f.attrs["contacts"] = [_impacts.name(c) for c in contacts]
                f.attrs["contact_surfaces"] = _impacts.stored(contacts)
            if impulses:
                # Likewise: the components given as numbers; one of Python functions by its time.
                f.attrs["impulses"] = _impulses.stored(impulses)
            labels = variable_attributes(model)
            for name in ("t", "q", "p", *columns):
                shape = (0, n) if name in ("q", "p") else (0,)
                f.create_dataset(
                    name,
                    shape=shape,
                    maxshape=(None, *shape[1:]),
                    chunks=(CHUNK_ROWS, *shape[1:]),
                    dtype=_DTYPES.get(name, np.float64),
                    fletcher32=True,
                ).attrs.update(labels[name])
            for slot in (0, 1):
                f.create_dataset(
                    f"checkpoint{slot}", shape=(0,), maxshape=(None,), chunks=(4096,), dtype=np.uint8, fletcher32=True
                )
            f.create_dataset("committed", data=np.zeros(5, dtype=np.int64), chunks=(5,), fletcher32=True)
            _store_model(f, model)
            _create_events(f, events, n, labels)
            f.swmr_mode = True
        except OSError as e:
            raise ValueError(f"{argument}: cannot write {str(path)!r}: {e}") from e
        self._columns = ("t", "q", "p", *columns)
        self._row_bytes = 8 * (1 + 2 * n + len(columns))
        self.rows = 0
        self._slot = 1
        self.is_open = True
        self._datasets: dict[str, Any] | None = None

    @classmethod
    def reopen(cls, path: Path, stored: Trajectory, spec: RunSpec) -> Writer:
        """The writer appending to the file ``path`` (loaded as ``stored``) after its committed
        rows the run ``spec`` specifies, marked incomplete until it closes again, with the
        crossings of its occurrences (named as the file's, if it has any), its run's planned
        end now ``spec.planned``."""
        events = spec.occurrence_names()
        h5py = _h5py()
        writer = cls.__new__(cls)
        writer.path, writer._argument = path, "path"
        _fresh(path)
        check_intact(path)
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
            f.attrs["planned_steps"] = spec.planned
            rows, slot = (int(x) for x in f["committed"][:2])
            stored_names = [o.name for o in stored.events]
            if events and stored_names and list(events) != stored_names:
                f.close()
                raise ValueError(f"events: the file's events are {stored_names}, not {list(events)}")
            if events and "events" not in f:
                _create_events(f, events, int(f.attrs["dim"]), variable_attributes(stored.model))
            f.swmr_mode = True
        except OSError as e:
            raise ValueError(f"path: cannot append to {str(path)!r}: {e}") from e
        writer._file = f
        writer._columns = tuple(name for name in COLUMNS if name in f)
        writer._row_bytes = 8 * (1 + 2 * int(f.attrs["dim"]) + len(writer._columns) - 3)
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
        # A full disk is refused before the write: a write that fails leaves libhdf5 holding
        # the file in a state no later open in this process can use (see _fresh).
        need = (2 * len(record.t) + CHUNK_ROWS) * self._row_bytes + 2 * len(record.checkpoint or b"") + SPARE_BYTES
        free = shutil.disk_usage(self.path.parent).free
        if free < need:
            raise self._failed(f"[Errno {errno.ENOSPC}] {os.strerror(errno.ENOSPC)}: {free} bytes free, a commit needs {need}")
        try:
            self._append(record, skip_first, events)
        except (OSError, RuntimeError) as e:
            stat = self.path.stat()
            _FAILED.add((stat.st_dev, stat.st_ino))
            raise self._failed(str(e)) from e

    def _failed(self, why: str) -> ValueError:
        """The error of a write that failed (a full disk, say): the rows committed before stay
        the run's, as the file says."""
        if not self.rows:
            return ValueError(f"{self._argument}: cannot write to {str(self.path)!r} ({why}); nothing was committed")
        return ValueError(
            f"{self._argument}: cannot write to {str(self.path)!r} ({why}); its {self.rows} rows committed before are "
            "kept: free some space, then varmech.resume(path) goes on from them"
        )

    def _append(self, record: Any, skip_first: bool, events: Sequence[Occurrences]) -> None:
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
        try:
            _fresh(self.path)
            with _h5py().File(self.path, "r+") as f:
                rows, _, _, steps, nfev = (int(x) for x in f["committed"][()])
                f.attrs.update({"complete": True, "status": status, "message": message, "steps": steps, "nfev": nfev})
        except (OSError, RuntimeError) as e:
            raise ValueError(
                f"{self._argument}: cannot close {str(self.path)!r} ({e}); its committed rows are kept, and "
                "varmech.resume(path) goes on from them"
            ) from e

    def abandon(self) -> None:
        """Closes the file as it is (a run stopped by an exception that could not be recorded);
        a close that fails (a full disk) leaves the file as its last commit left it."""
        self.is_open = False
        try:
            self._file.close()
        except (OSError, RuntimeError):
            pass


def _store_model(f: Any, model: Model) -> None:
    """``/model``: the model's recipe as JSON, or ``{"kind": "pickle"}`` and its pickle in
    ``/model_pickle`` (a model no pickle carries, such as one of lambdas, stores nothing and
    loads only with ``model=``)."""
    recipe = model._recipe()
    if recipe is None:
        try:
            f.create_dataset("model_pickle", data=np.void(pickle.dumps(model)))
            recipe = {"kind": "pickle"}
        except (pickle.PicklingError, TypeError, AttributeError):
            recipe = {"kind": "none"}
    f.create_dataset("model", data=json.dumps(recipe, allow_nan=True))


def stored_model(f: Any, source: Path, version: int, allow_pickle: bool) -> Model:
    """The model the file stores, built from its data; a pickle only with ``allow_pickle``."""
    if version >= 3:
        text = f["model"][()]
        try:
            recipe = json.loads(text.decode() if isinstance(text, bytes) else text)
        except (ValueError, RecursionError) as e:
            raise ValueError(f"path: {str(source)!r} is corrupt: its /model is not JSON ({e})") from None
        kind = recipe.get("kind") if isinstance(recipe, dict) else None
        blob = f["model_pickle"][()].tobytes() if kind == "pickle" else None
    else:
        kind, blob = "pickle", f["model"][()].tobytes()
    if kind == "none":
        raise ValueError(f"path: {str(source)!r} stores no model (its closures did not pickle); pass model=")
    if blob is None:
        try:
            return from_recipe(recipe)
        except ValueError as e:
            raise ValueError(f"path: cannot rebuild the model of {str(source)!r}: {e}; pass model=") from e
    if not allow_pickle:
        raise ValueError(
            f"path: the model of {str(source)!r} is a pickle (a model of Python closures), and unpickling a "
            "file can run any code: pass model= (the model, built by you), or allow_pickle=True if you trust the file"
        )
    try:
        model = pickle.loads(blob)  # noqa: S301 - the caller trusts the file (allow_pickle=True)
    except Exception as e:
        raise ValueError(f"path: cannot unpickle the model of {str(source)!r}: {e}; pass model=") from e
    if not isinstance(model, Model):
        raise ValueError(f"path: the pickle in {str(source)!r} is a {type(model).__name__}, not a varmech model")
    return model


def _create_events(f: Any, names: Sequence[str], n: int, labels: dict[str, dict[str, Any]]) -> None:
    """The groups ``/events/<k>`` of the events ``names``, empty and growing, their columns
    labelled as the run's (``labels``, :func:`varmech.model.variable_attributes`)."""
    if not names:
        return
    group = f.create_group("events")
    for k, name in enumerate(names):
        g = group.create_group(str(k))
        g.attrs["name"] = name
        for column, shape in (("t", (0,)), ("q", (0, n)), ("p", (0, n))):
            g.create_dataset(
                column, shape=shape, maxshape=(None, *shape[1:]), chunks=(256, *shape[1:]), dtype=np.float64, fletcher32=True
            ).attrs.update(labels[column])


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
            if name in COLUMNS:
                dst[name].resize(rows, axis=0)
        dst[f"checkpoint{slot}"].resize((length,))
    os.replace(part, path)


#: HDF5's file signature, found at byte 0 or a power of two from 512 on (after a user block).
_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def check_intact(path: Path) -> bool:
    """Whether a writer has the file open (a live run, or a killed one), by its superblock;
    ValueError naming ``path`` when the file is shorter than its superblock's end-of-file
    address (or has none): libhdf5 can hang, deaf to Ctrl-C, reading past a truncated file's
    end, so the file is checked before libhdf5 opens it."""
    size = path.stat().st_size
    with open(path, "rb") as f:
        base = 0
        while base + 8 <= size:
            f.seek(base)
            if f.read(8) == _SIGNATURE:
                break
            base = 512 if base == 0 else 2 * base
        else:
            raise ValueError(f"path: {str(path)!r} is corrupt or truncated: no HDF5 superblock")
        head = f.read(64)
    # The superblock's version decides where the end-of-file address lies (HDF5 file format
    # specification, section II.A): after the base address and one (versions 2, 3) or two
    # (versions 0, 1) other addresses.
    version = head[0] if head else -1
    if version in (2, 3) and len(head) >= 4:
        width, at, flags = head[1], 4 + 2 * head[1], head[3]
    elif version in (0, 1) and len(head) >= 16:
        width, flags = head[5], int.from_bytes(head[12:16], "little")
        at = (16 if version == 0 else 20) + 2 * width
    else:
        raise ValueError(f"path: {str(path)!r} is corrupt or truncated: a superblock of unknown version {version}")
    if width not in (2, 4, 8) or len(head) < at + width:
        raise ValueError(f"path: {str(path)!r} is corrupt or truncated: a damaged superblock")
    end = int.from_bytes(head[at : at + width], "little") + int.from_bytes(head[at - 2 * width: at - width], "little")
    if end > size:
        raise ValueError(f"path: {str(path)!r} is corrupt or truncated: {size} bytes of the {end} its superblock records")
    # The file consistency flags: opened for writing (bit 0), for single-writer/multiple-reader
    # writing (bit 2).
    return bool(flags & 0b101)


def open_read(path: Path, *, probe: bool = False) -> Any:
    """The h5py file ``path`` opened for reading, after :func:`check_intact`: in SWMR mode only
    when a writer has it open, since libhdf5 retries a failed metadata checksum in SWMR mode
    without end (a damaged file hangs it, deaf to Ctrl-C), where a plain read fails at once.
    With ``probe``, such a file is first read by another process, which can be stopped
    (:func:`_probe`)."""
    _fresh(path)
    swmr = check_intact(path)
    if swmr and probe and sys.executable:
        _probe(path)
    return _h5py().File(path, "r", swmr=swmr)


#: How long another process may take to read the metadata of a file a writer holds open before
#: the file is called damaged (s): a healthy file takes a fraction of a second.
PROBE_SECONDS = 30.0
#: What that process reads: every object's header, the committed counts, the checkpoints and
#: each column's last committed row (the metadata a load or a resume then reads).
_PROBE = """
import sys, h5py
with h5py.File(sys.argv[1], "r", swmr=True) as f:
    f.visititems(lambda name, obj: None)
    rows, slot, length = (int(x) for x in f["committed"][:3])
    f["checkpoint0"][:], f["checkpoint1"][:]
    for name in ("t", "q", "p", "newton", "work"):
        if name in f and rows:
            f[name][rows - 1]
"""


def _probe(path: Path) -> None:
    """Reads the metadata of ``path`` in SWMR mode in another process (:data:`_PROBE`);
    ValueError naming ``path`` when that fails or takes longer than :data:`PROBE_SECONDS`."""
    try:
        done = subprocess.run(
            [sys.executable, "-c", _PROBE, str(path)], capture_output=True, text=True, timeout=PROBE_SECONDS
        )
    except subprocess.TimeoutExpired:
        raise ValueError(
            f"path: {str(path)!r} is corrupt: reading its metadata took over {PROBE_SECONDS:g} s "
            "(libhdf5 retries a damaged file that a writer had open without end)"
        ) from None
    if done.returncode:
        last = (done.stderr.strip().splitlines() or ["no message"])[-1]
        raise ValueError(f"path: {str(path)!r} is corrupt or truncated: {last}")


#: The files (device, inode) whose write failed in this process.
_FAILED: set[tuple[int, int]] = set()


def _fresh(path: Path) -> None:
    """Replaces a file whose write failed in this process by a copy of its bytes: libhdf5 keeps
    the failed file open with metadata it could not write, and would share that state with any
    later open of the same file (the same inode), where the copy opens afresh."""
    try:
        stat = path.stat()
    except OSError:
        return
    if (stat.st_dev, stat.st_ino) in _FAILED:
        part = path.with_name(path.name + ".recovering")
        try:
            shutil.copyfile(path, part)
            os.replace(part, path)
        except OSError as e:
            part.unlink(missing_ok=True)
            raise ValueError(f"path: cannot copy {str(path)!r}, whose write failed, to reopen it: {e}; free some space") from e
        _FAILED.discard((stat.st_dev, stat.st_ino))


def save(traj: Trajectory, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Writes ``traj`` to the HDF5 file ``path`` (see the module's layout) and returns its path.

    Raises ValueError naming ``path`` when the file exists and ``overwrite`` is False, or when it
    cannot be written.
    """
    target = writable(path, overwrite, "path")
    # A loaded trajectory's contacts and impulses of Python functions are their names and times,
    # which the writer stores as such; its saving period is unknown (0).
    contacts = cast("tuple[Contact, ...]", traj.contacts)
    impulses = cast("tuple[Impulse, ...]", traj.impulses)
    spec = RunSpec(traj.method, traj.dt, save_every=0, jumps=Jumps(contacts=contacts, impulses=impulses))
    writer = Writer(target, traj.model, spec, events=[o.name for o in traj.events], planned=False)
    writer.append(traj, events=traj.events)
    writer.close(traj.status, traj.message)
    return target


def columns_of(
    model: Model, method: str, contacts: Sequence[Contact | str] = (), impulses: Sequence[Impulse | float] = ()
) -> tuple[str, ...]:
    """The optional columns of a run of ``method`` on ``model`` watching ``contacts`` and
    applying ``impulses``: Newton counts for the methods that solve equations, work where
    anything can put energy in or take it out (``impacts.exchanges``)."""
    info = method_info(method)
    worked = _impacts.exchanges(model, contacts, impulses)
    return (*(("newton",) if info.implicit or info.constrained else ()), *(("work",) if worked else ()))


class Rows:
    """A column of a trajectory file, read when used: indexing reads the rows asked for, and
    NumPy (``np.asarray``, arithmetic) reads the whole column once and keeps it.

    :func:`varmech.load` with ``lazy=True`` gives each column of the trajectory as one; it is not made
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
            data = self._checked(lambda ds: ds[row])
            return data[key[1:]] if isinstance(key, tuple) else data
        return np.asarray(self)[key]

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        if self._data is None:
            self._data = self._checked(lambda ds: ds[: self.shape[0]])
        return self._data if dtype is None else self._data.astype(dtype)

    def _checked(self, read: Any) -> np.ndarray:
        """``read(dataset)``, refused (ValueError naming ``path``) when its checksum fails or a
        value is not finite."""
        try:
            with open_read(self._path) as f:
                data = read(f[self._name])
        except OSError as e:
            raise ValueError(f"path: {str(self._path)!r} is corrupt: {e}") from e
        if data.dtype.kind == "f" and not np.isfinite(data).all():
            raise ValueError(f"path: {str(self._path)!r} holds non-finite {self._name} rows: damaged")
        return data

    def __array_ufunc__(self, ufunc: Any, method: str, *inputs: Any, **kwargs: Any) -> Any:
        inputs = tuple(np.asarray(x) if isinstance(x, Rows) else x for x in inputs)
        return getattr(ufunc, method)(*inputs, **kwargs)

    def __len__(self) -> int:
        return self.shape[0]

    def __iter__(self) -> Iterator[Any]:
        return iter(np.asarray(self))

    def __repr__(self) -> str:
        return f"Rows({str(self._path)!r}, {self._name!r}, shape={self.shape})"


#: Rows read at a time by :func:`read_through`.
_BLOCK_ROWS = 2**16


def read_through(path: Path) -> None:
    """Reads every part of ``path`` that :func:`varmech.load` reads eagerly and a writer
    appending to it touches (each column's committed rows, a block at a time, so memory stays
    flat; both checkpoint slots; the committed counts), refusing it (ValueError naming
    ``path``) where a checksum fails or a row is not finite: :func:`varmech.resume` reads a
    file so before it writes, since libhdf5 can hang, deaf to Ctrl-C, writing into damaged
    metadata that a lazy load never read."""
    try:
        with open_read(path) as f:
            rows = int(f["committed"][0])
            f["checkpoint0"][:], f["checkpoint1"][:]
            for name in COLUMNS:
                if name not in f:
                    continue
                for start in range(0, rows, _BLOCK_ROWS):
                    block = f[name][start : min(rows, start + _BLOCK_ROWS)]
                    if block.dtype.kind == "f" and not np.isfinite(block).all():
                        raise ValueError(f"path: {str(path)!r} holds non-finite {name} rows: damaged")
    except (OSError, KeyError, RuntimeError) as e:
        raise ValueError(f"path: {str(path)!r} is corrupt or truncated: {e}") from e


def planned_steps_of(path: str | os.PathLike[str]) -> int | None:
    """The step at which the run in ``path`` was asked to end (its ``planned_steps``), or None
    for a file that does not record it (a saved trajectory, or one from before format 3.1)."""
    with open_read(Path(path)) as f:
        planned = f.attrs.get("planned_steps")
    return None if planned is None else int(planned)


def save_every_of(path: str | os.PathLike[str]) -> int:
    """The saving period of the run in ``path``: its ``save_every`` attribute, or (for a saved
    trajectory, which has none) the steps between its first two states."""
    with open_read(Path(path)) as f:
        every = int(f.attrs.get("save_every", 0))
        if every > 0:
            return every
        t, dt = f["t"][:2], float(f.attrs["dt"])
    return max(1, round(float(t[1] - t[0]) / dt)) if len(t) > 1 else 1


def larger_than_memory(path: str | os.PathLike[str]) -> bool:
    """Whether a run's file is to be read back lazily: larger than :data:`LAZY_BYTES`."""
    return Path(path).stat().st_size > LAZY_BYTES
