"""A run's saved states: :class:`Trajectory`, the result of :func:`varmech.integrate`, made
from the binding's record of a run or read back from a file (:func:`load`)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from . import _core, dense, files
from . import events as _events
from . import impacts as _impacts
from . import impulses as _impulses
from ._runspec import RunSpec
from ._version import __version__
from .events import Occurrences
from .impacts import Contact
from .impulses import Impulse
from .model import Model, variable_attributes

if TYPE_CHECKING:
    import xarray

__all__ = [
    "Reactions",
    "Trajectory",
    "load",
]


@dataclass(frozen=True)
class Reactions:
    """The forces of constraint at a run's saved states (:meth:`Trajectory.reactions`).

    Attributes
    ----------
    multipliers : ndarray, shape (N, m)
        λ, one column per constraint row (holonomic rows first, then velocity rows).
    force : ndarray, shape (N, n)
        The generalized force of the constraints Cᵀλ (C = G, A or [G; A]).
    power : ndarray, shape (N,)
        Its power Cᵀλ·q̇ = λ·(Cq̇): 0 for fixed constraints on a consistent state, −λ·b for
        affine velocity constraints (a moving surface does work).

    Examples
    --------
    >>> import varmech
    >>> r = varmech.integrate(varmech.scenes.rolling_disk(), dt=0.05, steps=100, save_every=10).reactions()
    >>> r.multipliers.shape, r.force.shape, r.power.shape   # two rolling rows, q = (x, y, θ, φ)
    ((11, 2), (11, 4), (11,))
    """

    multipliers: np.ndarray
    force: np.ndarray
    power: np.ndarray


@dataclass
class Trajectory:
    """The saved states of a run (scipy-style result), as :func:`integrate` returns it.

    ``t`` has shape (N,), ``q`` and ``p`` shape (N, n); ``v`` = M⁻¹p is computed on demand.
    ``nfev`` counts force evaluations (for the implicit methods, evaluations of the discrete
    Lagrangian's slot derivatives); ``newton_iterations`` and ``newton_iterations_per_step``
    count the implicit methods' iterations.
    ``status`` is 0 when the run reached its end, 1 when a terminal event stopped it (see
    :mod:`varmech.events`), -1 for the partial trajectory attached to an error
    (``err.partial``); ``message`` says which. ``events`` holds each event's located crossings
    (:class:`varmech.events.Occurrences`, one per function given, in that order; empty without
    events).

    Attributes
    ----------
    t : ndarray, shape (N,)
        The saved times.
    q, p : ndarray, shape (N, n)
        The positions and the momenta p = ∂L/∂q̇ at the saved times.
    v : ndarray, shape (N, n)
        The velocities q̇ (M⁻¹p for mechanical systems), computed on first use.
    model : Model
        The model integrated.
    method : str
        The method's name (see :func:`varmech.methods`).
    dt : float
        The step h.
    steps : int
        Steps taken from the initial state.
    nfev : int
        Force evaluations made (the implicit methods: evaluations of the discrete Lagrangian's
        slot derivatives).
    newton : ndarray, shape (N,) or None
        Cumulative Newton iterations at each saved state (None for explicit methods).
    newton_iterations : int
        Newton iterations over the run (0 for explicit methods).
    newton_iterations_per_step : ndarray, shape (N − 1,)
        Mean Newton iterations a step between consecutive saved states.
    work : ndarray, shape (N,) or None
        The energy put in up to each saved state, which E − E₀ balances: the work of a forced
        model's forces and of its contacts' friction (:class:`varmech.Friction`), less
        ∫∂L/∂t dt for an L that depends on t (on the method's quadrature, Σ∂L_d/∂t), each
        impact's loss where e < 1 (its law's own; none for e = 1) and each impulse's energy
        change. Zeros (None from a file) where nothing puts energy in or takes it out.
    status : int
        0: the run reached its end; 1: a terminal event stopped it; -1: the partial trajectory
        of a failed run (``err.partial``).
    success : bool
        ``status == 0``.
    message : str
        Why the run stopped.
    checkpoint : bytes or None
        The last state's checkpoint: ``integrate(traj, steps=)`` goes on from it, bit for bit.
    events : tuple of Occurrences
        Each event's located crossings, in the order the events were given, then each
        contact's impacts (time, contact configuration, momenta just before), then each
        contact's closures (``"<name>.closed"``), each one's releases (``"<name>.released"``,
        lift-off), and the friction's switches, ``"<name>.stuck"`` and ``"<name>.slipped"``:
        see :mod:`varmech.impacts`.
    contacts : tuple of Contact
        The run's contacts (empty without them), which a continued run (``integrate(traj,
        steps=)``, :func:`varmech.resume`) goes on with. A file stores the native ones
        (``Contact.wall``, ``Contact.ellipsoid``); one given by Python functions is loaded as
        its name (a str), and a run goes on with it only when it is given again.
    impulses : tuple of Impulse
        The run's impulses (empty without them); a continued run (``integrate(traj, steps=)``,
        :func:`varmech.resume`) applies those still to come. A file stores those given as
        numbers; one given by Python functions is loaded as its time (a float), and a run goes
        on with it only when it is given again.

    Examples
    --------
    >>> import varmech
    >>> traj = varmech.integrate(varmech.scenes.pendulum(), dt=0.01, steps=1000, save_every=100)
    >>> traj.t.shape, traj.q.shape, traj.method, traj.status
    ((11,), (11, 1), 'verlet', 0)
    >>> more = varmech.integrate(traj, steps=1000)    # goes on, bit for bit
    >>> float(more.t[-1])
    20.0
    """

    t: np.ndarray
    q: np.ndarray
    p: np.ndarray
    model: Model
    method: str
    dt: float
    steps: int
    nfev: int
    newton: np.ndarray | None = field(default=None, repr=False)
    #: Work done by the non-conservative forces up to each saved state (zeros without forces).
    work: np.ndarray | None = field(default=None, repr=False)
    status: int = 0
    message: str = "The integration reached its final time."
    #: The last state's checkpoint (bytes): ``integrate(traj, steps=)`` goes on from it, bit for bit.
    checkpoint: bytes | None = field(default=None, repr=False)
    #: Each event's located crossings (times and states), in the order the events were given.
    events: tuple[_events.Occurrences, ...] = field(default=(), repr=False)
    #: The run's contacts, which a continued run goes on with (a loaded file's contacts given by
    #: Python functions are their names: pass them again to :func:`varmech.resume`).
    contacts: tuple[Contact | str, ...] = field(default=(), repr=False)
    #: The run's impulses, whose ones still to come a continued run applies (a loaded file's
    #: given by Python functions are their times: pass them again to :func:`varmech.resume`).
    impulses: tuple[Impulse | float, ...] = field(default=(), repr=False)
    _v: np.ndarray | None = field(default=None, repr=False)

    @property
    def success(self) -> bool:
        return self.status == 0

    @property
    def newton_iterations(self) -> int:
        """Newton iterations of the implicit methods over the run (0 for explicit methods)."""
        return int(self.newton[-1]) if self.newton is not None and len(self.newton) else 0

    @property
    def newton_iterations_per_step(self) -> np.ndarray:
        """Mean Newton iterations per step between consecutive saved states, shape (N − 1,)."""
        steps = np.diff(np.rint((self.t - self.t[0]) / self.dt))
        newton = self.newton if self.newton is not None else np.zeros(len(self.t))
        return np.diff(newton) / np.maximum(steps, 1)

    @property
    def v(self) -> np.ndarray:
        """Velocities q̇ (with ∂L/∂q̇ = p; M⁻¹p for mechanical systems), shape (N, n)."""
        if self._v is None:
            self._v = _core.derivative(self.model._core, "velocity", *self._arrays())
        return self._v

    def save(self, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
        """Writes the trajectory to the HDF5 file ``path`` (h5py, the extra ``io``); read it back
        with :func:`varmech.load`. See :mod:`varmech.files` for the layout.

        The model is stored as what builds it, as data: a scene's name and parameters, G and the
        masses, a symbolic model's expressions and tapes, a Routh model's full model and
        momenta; loading rebuilds it without running code from the file. A model of Python
        closures is stored as its pickle, which :func:`varmech.load` unpickles only with
        ``allow_pickle=True`` (or pass ``model=``). Every dataset carries a checksum.

        Parameters
        ----------
        path : str or os.PathLike
            The file to write.
        overwrite : bool, default False
            Replace an existing file.

        Returns
        -------
        pathlib.Path
            The path written.

        Raises
        ------
        ValueError
            Naming ``path``: the file exists and ``overwrite`` is False, or it cannot be written
            (its directory, or a full disk).
        ImportError
            h5py is not installed.

        See Also
        --------
        varmech.load : read it back (lazily, for runs larger than memory).

        Examples
        --------
        >>> import pathlib, tempfile, varmech
        >>> traj = varmech.integrate(varmech.scenes.pendulum(), dt=0.01, steps=100, save_every=10)
        >>> path = traj.save(pathlib.Path(tempfile.mkdtemp()) / "pendulum.h5")
        >>> path.name, len(varmech.load(path))
        ('pendulum.h5', 11)
        >>> import h5py, json
        >>> with h5py.File(path) as f:
        ...     json.loads(f["model"][()])
        {'kind': 'scene', 'name': 'pendulum', 'parameters': {}}
        """
        return files.save(self, path, overwrite=overwrite)

    def sol(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(q(t), p(t)) between the saved states, by cubic Hermite interpolation from q, q̇ and
        p, ṗ at the states on either side: error O(Δ⁴) in their spacing Δ. See
        ``dense.hermite``.

        Parameters
        ----------
        t : float or array_like
            Times within the saved span [t[0], t[-1]].

        Returns
        -------
        q, p : ndarray, shape t.shape + (n,)
            The interpolated positions and momenta.

        Raises
        ------
        ValueError
            Naming ``t``: times not finite or outside the saved span, fewer than two saved
            states, or a constrained model (whose ṗ holds the constraint forces).

        Examples
        --------
        Halfway between states saved 0.1 apart, against the state the run saved at every step:

        >>> import varmech
        >>> traj = varmech.integrate(varmech.scenes.pendulum(), dt=0.01, steps=100, save_every=10)
        >>> q, p = traj.sol(0.05)
        >>> fine = varmech.integrate(varmech.scenes.pendulum(), dt=0.01, steps=5)
        >>> q.shape, float(abs(q - fine.q[-1]).max()) < 1e-7
        ((1,), True)
        """
        return dense.hermite(self, t)

    def energy(self) -> np.ndarray:
        """The energy function E = p·q̇ − L (= ½pᵀM⁻¹p + V(q) for mechanical systems) at each
        saved state.

        Returns
        -------
        ndarray, shape (N,)
            E at each saved state (computed for any model; conserved only when L does not
            depend on t and no forces act).

        Raises
        ------
        Exception
            What a closure of the model raises, unchanged.

        Examples
        --------
        The pendulum's energy, from E = −1/2, stays within 10⁻⁵ over a second of Störmer–Verlet:

        >>> import varmech
        >>> E = varmech.integrate(varmech.scenes.pendulum(), dt=0.01, steps=100, save_every=10).energy()
        >>> E.shape, float(E[0]), float(abs(E - E[0]).max()) < 1e-5
        ((11,), -0.5, True)
        """
        return self.energy_terms()[0]

    def energy_terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(E, T, V) at each saved state: the energy function, its kinetic term T = E − V and its
        potential V = −L(q, 0, t), the energy of the configuration at rest (½pᵀM⁻¹p and V(q)
        for mechanical systems). The conservation verdicts measure energy errors against the
        mean of T.

        Returns
        -------
        E, T, V : ndarray, shape (N,)
            The energy and its kinetic and potential terms at each saved state.

        Raises
        ------
        Exception
            What a closure of the model raises, unchanged.

        Examples
        --------
        >>> import numpy as np, varmech
        >>> E, T, V = varmech.integrate(varmech.scenes.pendulum(), dt=0.01, steps=100, save_every=10).energy_terms()
        >>> float(T[0]), float(V[0]), bool(np.allclose(E, T + V))   # at rest at the bottom, struck: p = 1
        (0.5, -1.0, True)
        """
        return _core.energy_terms(self.model._core, *self._arrays())

    def constraint_residuals(self) -> tuple[np.ndarray, np.ndarray]:
        """How far each saved state is off the constraints.

        Returns
        -------
        position, velocity : ndarray, shape (N,)
            |g(q)|∞ and |G(q)M⁻¹p|∞ (the hidden constraint) for holonomic constraints;
            0 and |A(q)q̇|∞ for velocity constraints; |g(q)|∞ and |G(q)q̇, A(q)q̇ + b(q)|∞
            with both.

        Raises
        ------
        ValueError
            Naming ``model``: it has no constraints.

        Examples
        --------
        RATTLE keeps the Cartesian pendulum on its circle, and its velocity tangent to it:

        >>> import varmech
        >>> s = varmech.scenes.cartesian_pendulum()
        >>> position, velocity = varmech.integrate(s, dt=s.dt, steps=100, save_every=50).constraint_residuals()
        >>> position.shape, bool(position.max() < 1e-12), bool(velocity.max() < 1e-12)
        ((3,), True, True)
        """
        return _core.constraint_residuals(self.model._core, *self._arrays()[1:])[0]

    def reactions(self) -> Reactions:
        """The forces of constraint at each saved state: the multipliers λ of

        ṗ = ∂L/∂q + f + C(q)ᵀλ,   C(q)q̇ + b(q) = 0,

        with C = G = ∂g/∂q (b = 0) for holonomic constraints g(q) = 0, C = A for velocity
        constraints A(q)q̇ + b(q) = 0, both stacked for mixed ones. Lagrange's sign: the
        constraints' generalized force is Cᵀλ, so that a constraint written φ(q) ≥ 0 pushes with
        λ ≥ 0. Where the rows of C are the velocity of a point (a rolling contact), λ is the force
        vector at that point.

        λ is the state's own multiplier, the one that keeps C(q)q̇ + b(q) at 0 along the motion
        through (q, p, t) (computed in the core, with a fourth-order difference along the motion:
        about 1e-12 relative error). It therefore converges at the method's order with the
        states (RATTLE 2, rattle4 4, …); the multipliers a step solves internally are one-sided
        (RATTLE's λ and μ are O(h) off, their average O(h²) for its compositions too).

        Returns
        -------
        Reactions
            ``multipliers`` (N, m), ``force`` (N, n) and ``power`` (N,).

        Raises
        ------
        ValueError
            Naming ``model``: it has no constraints.
        Exception
            What a closure of the model raises, unchanged.

        Examples
        --------
        The pendulum in Cartesian coordinates (m = l = g = 1) on ½(x² + y² − 1) = 0: Gᵀλ = λ(x, y)
        is the string's pull, so λ = −T, the tension T = g cos θ + v²; released from rest at
        θ = 2, T = 3 cos θ − 2 cos 2:

        >>> import numpy as np, varmech
        >>> traj = varmech.integrate(varmech.scenes.cartesian_pendulum(), dt=0.001, steps=1000, save_every=500)
        >>> r = traj.reactions()
        >>> r.multipliers.shape, r.force.shape
        ((3, 1), (3, 2))
        >>> cos_theta = -traj.q[:, 1]
        >>> bool(np.allclose(-r.multipliers[:, 0], 3 * cos_theta - 2 * np.cos(2.0), atol=1e-5))
        True
        >>> bool(np.abs(r.power).max() < 1e-12)
        True
        """
        multipliers, force, (power, _) = _core.reactions(self.model._core, *self._arrays())
        return Reactions(multipliers, force, power)

    def to_xarray(self) -> xarray.Dataset:
        """The run as a labelled :class:`xarray.Dataset` (needs xarray, the extra ``xarray``).

        Returns
        -------
        xarray.Dataset
            ``q``, ``p`` and ``v`` with dims (time, coordinate), the coordinate axis labelled
            with the model's names (:attr:`varmech.Model.coordinates`), and ``work`` and
            ``newton`` by time where the run has them. Each variable's ``long_name`` and, where
            the model states them, ``units`` are its attributes (p's ``names`` the momenta's);
            the dataset's are the run's ``method``, ``dt``, ``model``, ``steps``, ``nfev``,
            ``status``, ``message`` and the ``varmech_version`` that ran it.

        Raises
        ------
        ImportError
            xarray is missing.

        See Also
        --------
        varmech.Ensemble.to_xarray : The same of many runs, by member.

        Examples
        --------
        >>> import varmech
        >>> traj = varmech.integrate(varmech.scenes.double_pendulum(), dt=0.01, steps=100, save_every=50)
        >>> data = traj.to_xarray()
        >>> dict(data.sizes), data.coordinate.values.tolist(), data.attrs["method"]
        ({'time': 3, 'coordinate': 2}, ['theta1', 'theta2'], 'midpoint')
        >>> data.p.attrs["names"], data.time.attrs["units"]
        (['p_theta1', 'p_theta2'], '1')
        """
        dims = ("time", "coordinate")
        data: dict[str, Any] = {"q": (dims, self.q), "p": (dims, self.p), "v": (dims, self.v)}
        data.update({name: ("time", values) for name, values in (("work", self.work), ("newton", self.newton)) if values is not None})
        run = {"steps": self.steps, "nfev": self.nfev, "status": self.status, "message": self.message}
        return labelled_dataset(data, {"time": self.t}, self.model, self.method, self.dt, run)

    def _arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, q, p) as arrays (read now from a file loaded lazily)."""
        return np.asarray(self.t), np.asarray(self.q), np.asarray(self.p)

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        return (
            f"Trajectory({self.model.name!r}, method={self.method!r}, dt={self.dt:g}, steps={self.steps}, "
            f"saved={len(self.t)}, nfev={self.nfev}, status={self.status})"
        )


def labelled_dataset(
    data: dict[str, Any], coords: dict[str, Any], model: Model, method: str, dt: float, run: dict[str, Any]
) -> xarray.Dataset:
    """The xarray Dataset of a run's (or an ensemble's) ``data``, labelled: the coordinate axis
    with the model's names, each variable (and the time axis) with its long name and unit
    (:func:`varmech.model.variable_attributes`), the dataset with the method, the step, the
    model, the varmech version and ``run``'s entries."""
    try:
        import xarray
    except ImportError as err:
        raise ImportError("to_xarray needs xarray: pip install 'varmech[xarray]'") from err
    labels = variable_attributes(model)
    coords = {
        **coords,
        "time": ("time", coords["time"], labels["t"]),
        "coordinate": ("coordinate", list(model.coordinates), {"long_name": "the model's coordinates"}),
    }
    data = {name: (*value, labels[name]) if name in labels else value for name, value in data.items()}
    attrs = {"method": method, "dt": dt, "model": repr(model), "varmech_version": __version__, **run}
    return xarray.Dataset(data, coords=coords, attrs=attrs)


def take_partial(err: BaseException) -> _core.TrajectoryRecord | None:
    """The binding's record of a failed run's states, taken off the exception it rides on
    (``_varmech_partial``), to be given as ``err.partial`` in the user's terms."""
    partial = getattr(err, "_varmech_partial", None)
    if partial is not None:
        delattr(err, "_varmech_partial")
    return partial


def of_record(record: _core.TrajectoryRecord, model: Model, spec: RunSpec, **status: Any) -> Trajectory:
    """The Trajectory of the binding's record of a run of ``model`` as ``spec`` specifies it,
    with its events' crossings and its contacts' impacts after them (and the status of a
    terminal event's stop, unless `status` is given)."""
    r = record
    found = crossings(r, spec.jumps.events, spec.jumps.contacts)
    status = status or _events.termination(r, spec.jumps.events, found)
    _impacts.warn_grazing(r.grazing, stacklevel=4)
    return Trajectory(
        r.t,
        r.q,
        r.p,
        model,
        spec.method,
        spec.dt,
        r.steps,
        r.force_evaluations,
        r.newton,
        r.work,
        checkpoint=r.checkpoint,
        events=found,
        contacts=spec.jumps.contacts,
        impulses=spec.jumps.impulses,
        **status,
    )


def crossings(record: Any, events: Sequence[_events.Event], contacts: Sequence[Contact | str]) -> tuple[Occurrences, ...]:
    """Each event's located crossings in the binding's record of a run, then each contact's
    impacts, closures and releases."""
    return _events.occurrences(record, events) + _impacts.occurrences(record, contacts) + _impacts.switches(record, contacts)


def load(
    path: str | os.PathLike[str], *, model: Model | None = None, lazy: bool = False, allow_pickle: bool = False
) -> Trajectory:
    """The trajectory saved in ``path`` by :meth:`Trajectory.save` or streamed there by a run
    (``integrate(output=)``), with its model built from the file's data, or ``model`` instead
    (which must have the file's dimension). Only the committed rows are read; a run that
    stopped without closing its file loads with ``status`` -1, and its checkpoint lets
    :func:`varmech.resume` go on.

    Loading runs no code from the file. Scenes, N-body models, symbolic and Routh-reduced
    models are stored as data (names, numbers, expressions, tapes) and built again by their
    constructors. A model of Python closures can travel only as a pickle, and unpickling runs
    whatever the file says: such a file loads with ``model=`` (yours) or, if you trust it, with
    ``allow_pickle=True``. A file whose superblock promises more bytes than it has (truncated),
    whose checksums fail, or whose rows are not finite is refused before anything is used.

    ``lazy=True`` reads no column until it is used (each a :class:`Rows`; indexing reads only
    the rows asked for), for files larger than memory.

    Parameters
    ----------
    path : str or os.PathLike
        The HDF5 file.
    model : Model, optional
        The model to attach instead of the file's stored one (needed for a closure model
        unless ``allow_pickle``).
    lazy : bool, default False
        Read each column only when used.
    allow_pickle : bool, default False
        Unpickle a stored closure model (which runs code from the file: only for files you
        trust).

    Returns
    -------
    Trajectory
        The run in the file, with its checkpoint.

    Raises
    ------
    ValueError
        Naming ``path`` for a missing, corrupt or truncated file, one that is not a varmech
        trajectory, or whose rows are not finite, and for a pickled model without ``model=`` or
        ``allow_pickle=True``; naming ``model`` for a model of another dimension.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np, varmech
    >>> s = varmech.scenes.kepler()
    >>> traj = varmech.integrate(s, dt=s.dt, steps=100, save_every=10)
    >>> path = traj.save(pathlib.Path(tempfile.mkdtemp()) / "kepler.h5")
    >>> back = varmech.load(path)
    >>> bool(np.array_equal(back.q, traj.q)) and back.method == traj.method
    True

    A model of closures (here V = q, by NumPy's functions) is not unpickled unless asked:

    >>> ramp = varmech.MechanicalSystem(1, np.sum, np.ones_like)
    >>> path = varmech.integrate(ramp, [0.0], [0.0], dt=0.1, steps=10).save(path.with_name("ramp.h5"))
    >>> varmech.load(path)
    Traceback (most recent call last):
    ...
    ValueError: path: the model of ... is a pickle (a model of Python closures), ...
    >>> varmech.load(path, model=ramp).steps, varmech.load(path, allow_pickle=True).steps
    (10, 10)
    """
    source = Path(path)
    if not source.is_file():
        raise ValueError(f"path: no file {str(source)!r}")
    try:
        with files.open_read(source, probe=True) as f:
            if not f.swmr_mode:
                # Every object's header is read (and its checksum checked) now, not first by a
                # writer appending to the file.
                f.visititems(lambda name, obj: None)
            if f.attrs.get("format") != files.FORMAT:
                raise ValueError(f"path: {str(source)!r} is not a varmech trajectory file")
            version = int(f.attrs["format_version"])
            if version not in files.READS:
                raise ValueError(f"path: format version {version}; this varmech reads versions {files.READS}")
            a = dict(f.attrs)
            rows, slot, length, steps, nfev = (int(x) for x in f["committed"][()])
            present = [name for name in files.COLUMNS if name in f]
            shapes = {name: (rows, *f[name].shape[1:]) for name in present}
            if any(f[name].shape[0] < rows for name in present) or slot not in (0, 1) or min(rows, length, steps) < 0:
                raise ValueError(f"path: {str(source)!r} is truncated: fewer rows than committed")
            columns: dict[str, Any] = {
                name: files.Rows(source, name, shapes[name], f[name].dtype) if lazy else f[name][:rows] for name in present
            }
            # A lazy file's rows are checked as they are read; its last (which a resume goes on
            # from) here.
            last = {name: f[name][rows - 1 : rows] for name in ("t", "q", "p")} if lazy and rows else columns
            for name in ("t", "q", "p", "work"):
                if name in last and not np.isfinite(last[name]).all():
                    raise ValueError(f"path: {str(source)!r} holds non-finite {name} rows: damaged")
            checkpoint = f[f"checkpoint{slot}"][:length].tobytes()
            # Crossings after the last committed state are a killed run's uncommitted segment's.
            t_last = float(f["t"][rows - 1]) if rows else -np.inf
            events = tuple(_occurrences(f["events"][str(k)], t_last) for k in range(len(f["events"]))) if "events" in f else ()
            if model is None:
                model = files.stored_model(f, source, version, allow_pickle)
    except (OSError, KeyError, RuntimeError) as e:
        # h5py raises RuntimeError for some damaged structures (a bad heap signature), and
        # OSError for a failed checksum.
        raise ValueError(f"path: {str(source)!r} is corrupt or truncated: {e}") from e
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
        contacts=_stored_contacts(a),
        impulses=_impulses.restored(str(a["impulses"])) if "impulses" in a else (),
    )


def going_on_from(traj: Trajectory, argument: str, what: str, row: str = "row") -> _core.Stepper:
    """The core's stepper at ``traj``'s checkpoint, cross-checked against ``traj``: the one
    check of every run that goes on from a trajectory or its file (``integrate(traj)``,
    :func:`varmech.resume`). The checkpoint must be of ``traj``'s model, method and step (and
    not edited: the core recomputes what it derives), at ``traj.steps``, and at its last row's
    state (t, q, p) to the bit, unless the rows end before it (the samples of a ``t_eval`` run,
    which went on to its checkpoint). A file whose ``/committed`` names another checkpoint
    than its last row's is refused so, rather than continued from an older state. ValueError
    naming ``argument``; ``what`` says what is refused (a file's path), ``row`` what its rows
    are; the core's refusals of the checkpoint as they are."""
    if traj.checkpoint is None:
        raise ValueError(f"{argument}: {what} has no checkpoint to go on from (it failed before its first state)")
    at = _core.Stepper.from_checkpoint(traj.model._core, traj.checkpoint, _core.RunSpec(method=traj.method, dt=traj.dt))
    rows = len(traj.t)
    last = (float(traj.t[-1]), traj.q[-1], traj.p[-1]) if rows else (-np.inf, None, None)
    sampled = last[0] < at.t
    if at.steps != traj.steps or not (sampled or all(_same(a, b) for a, b in zip((at.t, at.q, at.p), last))):
        raise ValueError(
            f"{argument}: {what} cannot go on: its checkpoint (step {at.steps}, t = {at.t}) is not the state of its "
            f"last {row} (step {traj.steps}, t = {last[0]}); it is damaged (a file's /committed naming an older "
            "checkpoint), or its rows were changed"
        )
    return at


def _same(a: Any, b: Any) -> bool:
    """Equal to the bit."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and bool(np.array_equal(a.view(np.uint64), b.view(np.uint64)))


def _stored_contacts(attrs: Any) -> tuple[Contact | str, ...]:
    """A file's contacts: the native ones rebuilt, the others (and all of a file written before
    contacts were stored) their names."""
    names = [str(name) for name in attrs.get("contacts", ())]
    if "contact_surfaces" not in attrs:
        return tuple(names)
    return _impacts.restored(str(attrs["contact_surfaces"]), names)


def _occurrences(group: Any, t_last: float) -> Occurrences:
    """An event's crossings in the file, up to the committed time ``t_last``."""
    t = group["t"][()]
    keep = int(np.searchsorted(t, t_last, side="right"))
    return Occurrences(str(group.attrs["name"]), t[:keep], group["q"][:keep], group["p"][:keep])
