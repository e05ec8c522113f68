"""Trajectories in HDF5 files (h5py, the optional extra ``io``): :meth:`Trajectory.save` and
:func:`load`.

The layout, self-describing so that any HDF5 reader can use it (``docs/file_format.md``)::

    /            attrs: format = "varmech-trajectory", format_version = 1, varmech_version,
                        method, dt, steps, nfev, status, message, dim, model (its repr)
    /t           (N,)   float64   the saved times
    /q, /p       (N, n) float64   positions and momenta, one row a saved state
    /newton      (N,)   uint64    cumulative Newton iterations (only for methods that solve)
    /work        (N,)   float64   cumulative work of the forces (only for forced models)
    /model       opaque bytes     the model's pickle (what builds it: a scene's name and
                                  parameters, expressions, or closures by reference)

The arrays are chunked by rows. Loading unpickles the model, as :mod:`pickle` does: open only
files you trust, or pass ``model=`` to :func:`load` to skip the stored one.
"""

from __future__ import annotations

import os
import pickle
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .integrate import Trajectory
    from .model import Model

FORMAT = "varmech-trajectory"
FORMAT_VERSION = 1
#: Rows per chunk: about 64 kB of a (N, 2)-shaped q for the small systems, and whole arrays
#: below it.
CHUNK_ROWS = 4096


def _h5py() -> Any:
    try:
        import h5py
    except ImportError as e:  # pragma: no cover - the io extra is installed with the tests
        raise ImportError("varmech's files need h5py: pip install 'varmech[io]'") from e
    return h5py


def save(traj: Trajectory, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Writes ``traj`` to the HDF5 file ``path`` (see the module's layout) and returns its path.

    Raises ValueError naming ``path`` when the file exists and ``overwrite`` is False, or when it
    cannot be written.
    """
    from . import __version__

    h5py = _h5py()
    target = Path(path)
    if target.exists() and not overwrite:
        raise ValueError(f"path: {str(target)!r} exists; pass overwrite=True to replace it")
    if target.is_dir():
        raise ValueError(f"path: {str(target)!r} is a directory")
    model = np.void(pickle.dumps(traj.model))
    try:
        with h5py.File(target, "w") as f:
            attrs = {
                "format": FORMAT,
                "format_version": FORMAT_VERSION,
                "varmech_version": __version__,
                "method": traj.method,
                "dt": traj.dt,
                "steps": traj.steps,
                "nfev": traj.nfev,
                "status": traj.status,
                "message": traj.message,
                "dim": traj.q.shape[1],
                "model": repr(traj.model),
            }
            f.attrs.update(attrs)
            columns = {"t": traj.t, "q": traj.q, "p": traj.p}
            if traj.newton is not None and np.any(traj.newton):
                columns["newton"] = np.asarray(traj.newton, dtype=np.uint64)
            if traj.work is not None and traj.model.forced:
                columns["work"] = traj.work
            for name, data in columns.items():
                rows = max(1, min(len(data), CHUNK_ROWS))
                f.create_dataset(name, data=data, chunks=(rows, *data.shape[1:]))
            f.create_dataset("model", data=model)
    except OSError as e:
        raise ValueError(f"path: cannot write {str(target)!r}: {e}") from e
    return target


def load(path: str | os.PathLike[str], *, model: Model | None = None) -> Trajectory:
    """The trajectory saved in ``path`` by :meth:`Trajectory.save`, with its model unpickled,
    or ``model`` instead (which must have the file's dimension).

    Raises ValueError naming ``path`` for a missing, corrupt or truncated file, or one that is not
    a varmech trajectory; ValueError naming ``model`` for a model of another dimension.

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
        with h5py.File(source, "r") as f:
            if f.attrs.get("format") != FORMAT:
                raise ValueError(f"path: {str(source)!r} is not a varmech trajectory file")
            version = int(f.attrs["format_version"])
            if version > FORMAT_VERSION:
                raise ValueError(f"path: format version {version} is newer than this varmech reads ({FORMAT_VERSION})")
            a = dict(f.attrs)
            columns = {name: f[name][()] for name in ("t", "q", "p", "newton", "work") if name in f}
            blob: bytes = f["model"][()].tobytes() if model is None else b""
    except (OSError, KeyError) as e:
        raise ValueError(f"path: {str(source)!r} is corrupt or truncated: {e}") from e
    if model is None:
        try:
            model = pickle.loads(blob)  # noqa: S301 - documented: a file's model is its pickle
        except Exception as e:
            raise ValueError(f"path: cannot rebuild the model {a['model']!r}: {e}; pass model=") from e
    if model.dim != int(a["dim"]):
        raise ValueError(f"model: has dimension {model.dim}, the file's states {int(a['dim'])}")
    return Trajectory(
        columns["t"],
        columns["q"],
        columns["p"],
        model,
        str(a["method"]),
        float(a["dt"]),
        int(a["steps"]),
        int(a["nfev"]),
        columns.get("newton"),
        columns.get("work"),
        status=int(a["status"]),
        message=str(a["message"]),
    )
