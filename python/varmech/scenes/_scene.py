"""The scene: a model with its initial state and test protocol (:class:`Scene`), a reference
solution (:class:`Reference`), and the built-in scenes of the core's catalogue by name
(:func:`get`), with what :mod:`varmech._catalogue` declares of each."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from .. import _core
from .._catalogue import DECLARED, declared
from .._core import energy_terms
from .._util import positive
from ..impacts import Contact
from ..model import Model, NativeSystem, initial_state
from ..modes import step_by_trial

__all__ = [
    "CATALOGUE",
    "LONG_RUNS",
    "SYMBOLIC",
    "TIME_UNITS",
    "Reference",
    "Scene",
    "as_scene",
    "get",
]


@dataclass(frozen=True)
class Reference:
    """The solution at time ``t``, exact or published, and where it comes from.

    Attributes
    ----------
    t : float
        The time of the reference state.
    q, p : ndarray, shape (n,)
        The positions and momenta there (NaN where the source gives none, as the spherical
        pendulum's p_θ).
    source : str
        Where it comes from: "exact: …", a publication, a file of ``reference/``, or "computed: …"
        (:func:`varmech.analysis.reference.reference_solution`).
    tolerance : float or None
        The error the reference is known to within, where stated (a computed one's: the
        difference of its last two refinements); None for an exact or published one.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.pendulum()
    >>> ref = scene.reference
    >>> traj = varmech.integrate(scene, dt=scene.dt / 8, t_end=ref.t, method="kahan_li8")
    >>> bool(abs(traj.q[-1, 0] - ref.q[0]) < 1e-12), ref.source
    (True, 'Hairer, Lubich & Wanner, GNI I.1; GNI test codes')
    """

    t: float
    q: np.ndarray
    p: np.ndarray
    source: str
    tolerance: float | None = None


@dataclass(frozen=True)
class Scene:
    """A model with its initial state and test protocol: a native one of the core's catalogue
    (:func:`get`), a symbolic one (:func:`varmech.symbolic.examples.scene`), or the user's own
    model with its initial state and horizon (:meth:`Scene.of`).

    ``dt`` is a step that resolves the scene for a quick look (the tour uses it);
    ``invariants`` holds the values of the conserved quantities at t = 0; ``parameters`` the
    values the scene was built with; ``contacts`` the contact surfaces φ(q) ≥ 0 of an impact
    scene (:class:`varmech.Contact`), which :func:`varmech.integrate` goes through by default;
    ``time_unit`` the unit of t that charts label their axes with (:data:`TIME_UNITS`).

    Attributes
    ----------
    name : str
        The scene's name in the catalogue.
    description : str
        What it is, in a line.
    model : Model
        The model integrated.
    q0, p0 : ndarray, shape (n,)
        The initial state, which :func:`varmech.integrate` takes by default.
    t_end : float
        The horizon of its test protocol.
    dt : float
        A step that resolves the scene for a quick look.
    invariants : dict of str to float
        The conserved quantities' values at t = 0 (``"H"``, ``"L"``, …).
    reference : Reference or None
        A reference state (``t``, ``q``, ``p``) and its ``source``, where one is known.
    parameters : dict of str to float
        The values the scene was built with.
    contacts : tuple of Contact
        The contact surfaces of an impact scene (empty otherwise).
    time_unit : str
        The unit of t on charts' axes: ``"days"`` for the outer solar system, else
        ``"time units"``.
    long_runs : int
        Its long runs' length in horizons ``t_end``: :data:`LONG_RUNS` for a built-in scene,
        whose ``t_end`` is its test protocol's; 1 for one's own (:meth:`Scene.of`).
    long_run : float
        The horizon of its long runs (the energy-growth chart): ``long_runs`` × ``t_end``.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.kepler()
    >>> scene.q0, scene.reference.source
    (array([0.4, 0. ]), 'exact: 200 whole periods')
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)

    A model of one's own, with its initial state and horizon (:meth:`Scene.of`):

    >>> import numpy as np
    >>> def V(q): return -np.cos(q[0])
    >>> def dV(q): return np.sin(q)
    >>> mine = varmech.Scene.of(varmech.MechanicalSystem(1, V, dV), [1.0], [0.0], t_end=100.0)
    >>> mine.name, mine.dt          # 20 steps a period of the small oscillations at q0
    ('mechanical system', 0.427)
    """

    name: str
    description: str
    model: Model
    q0: np.ndarray
    p0: np.ndarray
    t_end: float
    dt: float
    invariants: dict[str, float] = field(default_factory=dict)
    reference: Reference | None = None
    parameters: dict[str, float] = field(default_factory=dict)
    contacts: tuple[Contact, ...] = ()
    time_unit: str = "time units"
    long_runs: int = 1

    @property
    def long_run(self) -> float:
        """The horizon of its long runs (the energy-growth chart): ``long_runs`` × ``t_end``."""
        return self.long_runs * self.t_end

    @classmethod
    def of(
        cls,
        model: Model,
        q0: ArrayLike,
        p0: ArrayLike | None = None,
        *,
        v0: ArrayLike | None = None,
        t_end: float,
        dt: float | None = None,
        name: str | None = None,
        description: str = "",
        reference: Reference | None = None,
        contacts: Sequence[Contact] = (),
        time_unit: str = "time units",
    ) -> Scene:
        """A scene of one's own model: what :func:`varmech.work_precision`,
        :func:`varmech.energy_growth`, the charts and the CLI take.

        Parameters
        ----------
        model : Model
            Any model (native, symbolic, closures, C pointers).
        q0, p0, v0 : array_like, shape (n,)
            The initial positions, and the momenta p0 or the velocities v0 (one of them).
        t_end : float
            The horizon of the scene's runs.
        dt : float, optional
            A step that resolves the motion for a quick look; the measurements sweep around
            it. Default: the step at which a short trial of the model's default method from
            q0 agrees with the trial at half the step to 2% of the motion, from a twentieth
            of the fastest small-oscillation period at q0 (:func:`varmech.fastest_frequency`),
            at most ``t_end``/100, halved up to four times (``varmech.modes.step_by_trial``:
            248 steps at most). The trial sees the motion's start: give ``dt`` where it
            speeds up later (a close approach).
        name, description : str, optional
            What charts and tables call it (default: the model's ``name``).
        reference : Reference, optional
            The solution at some time, where one is known; without it, the measurements that
            need one compute it (:func:`varmech.analysis.reference.reference_solution`).
        contacts : sequence of Contact, optional
            Contact surfaces that the runs go through.
        time_unit : str, default "time units"
            The unit of t on charts' axes.

        Returns
        -------
        Scene
            With ``invariants`` = {the energy's name: its value at t = 0} where the energy is
            conserved, empty otherwise.

        Raises
        ------
        TypeError
            ``model`` is not a varmech Model; a string where a number belongs.
        ValueError
            Malformed ``q0``, ``p0``/``v0``, ``t_end`` or ``dt``, named; naming ``dt``, no
            default step runs accurately from q0 (each step tried is named, with what it gave).

        Examples
        --------
        The elastic pendulum of :mod:`varmech.symbolic.examples`, released 0.6 off the vertical:

        >>> import varmech
        >>> from varmech.symbolic import examples
        >>> model = examples.elastic_pendulum_cartesian()
        >>> scene = varmech.Scene.of(model, [0.85, -1.24], v0=[0.0, 0.0], t_end=100.0)
        >>> scene.model.coordinates, round(scene.dt, 4), sorted(scene.invariants)
        (('x', 'y'), 0.0993, ['energy'])
        """
        if not isinstance(model, Model):
            raise TypeError(f"model: expected a varmech Model (MechanicalSystem, Lagrangian, symbolic, ...), got {type(model).__name__}")
        q, p = initial_state(model, q0, p0, v0, 0.0)
        horizon = positive("t_end", t_end)
        surfaces = tuple(contacts)
        if not all(isinstance(c, Contact) for c in surfaces):
            raise TypeError("contacts: expected varmech.Contact surfaces")
        step = step_by_trial(model, q, p, horizon, surfaces) if dt is None else positive("dt", dt)
        if step > horizon:
            raise ValueError(f"dt: must not exceed t_end = {horizon:g}, got {step:g}")
        if reference is not None and not isinstance(reference, Reference):
            raise TypeError(f"reference: expected a varmech.scenes.Reference, got {type(reference).__name__}")
        invariants = {}
        if model.conserves_energy:
            invariants[model.energy_name] = float(energy_terms(model._core, np.zeros(1), q[None], p[None])[0][0])
        label = model.name if name is None else name
        for argument, text in (("name", label), ("description", description), ("time_unit", time_unit)):
            if not isinstance(text, str):
                raise TypeError(f"{argument}: expected a str, got {type(text).__name__}")
        parameters = dict(getattr(model, "parameters", None) or {})
        return cls(label, description, model, q, p, horizon, step, invariants, reference, parameters, surfaces, time_unit)


def as_scene(
    subject: Scene | Model | str,
    *,
    q0: ArrayLike | None = None,
    p0: ArrayLike | None = None,
    v0: ArrayLike | None = None,
    t_end: float | None = None,
    dt: float | None = None,
) -> Scene:
    """The scene a measurement runs: ``subject`` itself (a Scene), the built-in or symbolic scene
    of that name, or :meth:`Scene.of` a model with ``q0``, ``p0``/``v0``, ``t_end`` and ``dt``.

    Parameters
    ----------
    subject : Scene, Model or str
        What the measurement was given.
    q0, p0, v0 : array_like, optional
        A model's initial state (ignored for a scene, which has its own).
    t_end, dt : float, optional
        A model's horizon (required) and step (default: :meth:`Scene.of`'s).

    Returns
    -------
    Scene
        The scene.

    Raises
    ------
    TypeError
        A model without ``q0`` or ``t_end`` (naming them, as for a missing argument), or a
        ``subject`` that is none of the three.
    ValueError
        An unknown scene name; a malformed state, horizon or step.

    Examples
    --------
    >>> import varmech
    >>> from varmech.scenes import as_scene
    >>> model = varmech.scenes.pendulum().model
    >>> as_scene(model, q0=[0.5], p0=[0.0], t_end=10.0).dt
    0.1
    >>> as_scene("kepler").name
    'kepler'
    """
    if isinstance(subject, Scene):
        return subject
    if isinstance(subject, str):
        return get(subject)
    if isinstance(subject, Model):
        missing = [name for name, value in (("q0", q0), ("t_end", t_end)) if value is None]
        if missing:
            raise TypeError(
                f"scene: a model needs its initial state and horizon: pass {' and '.join(missing)} "
                "(and p0 or v0), or a varmech.Scene.of(model, q0, p0, t_end=...)"
            )
        assert q0 is not None and t_end is not None
        return Scene.of(subject, q0, p0, v0=v0, t_end=t_end, dt=dt)
    raise TypeError(f"scene: expected a varmech Scene, a scene's name or a Model, got {type(subject).__name__}")


def model_and_state(
    model: Model | Scene, q0: ArrayLike | None, p0: ArrayLike | None, v0: ArrayLike | None
) -> tuple[Model, ArrayLike | None, ArrayLike | None]:
    """The model of a model or scene that a run or stepper is given, and (q0, p0), a scene's
    initial state by default; TypeError naming ``model`` for anything else."""
    if isinstance(model, Scene):
        if q0 is None:
            q0 = model.q0
            if p0 is None and v0 is None:
                p0 = model.p0
        model = model.model
    if not isinstance(model, Model):
        raise TypeError(f"model: expected a varmech model or scene, got {type(model).__name__}")
    return model, q0, p0


def contacts_of(model: Model | Scene, contacts: Sequence[Contact] | None) -> tuple[Contact, ...]:
    """The contacts a run or a stepper of ``model`` watches: ``contacts``, a scene's by default
    (``[]``: none)."""
    return tuple(model.contacts if contacts is None and isinstance(model, Scene) else contacts or ())


#: The core's catalogue of scenes by name, in the order of the tour: each entry's
#: ``parameters`` (with their defaults) and ``description``.
CATALOGUE: dict[str, _core.CatalogueEntry] = {entry.name: entry for entry in _core.catalogue()}


#: The unit of t of the scenes that have one, by name (as declared, :mod:`varmech._catalogue`);
#: every other scene is in the model's own (dimensionless) "time units".
TIME_UNITS: dict[str, str] = {name: d.units["t"] for name, d in DECLARED.items() if d.units is not None}


#: The symbolic scenes (:func:`varmech.symbolic.examples.scene`), which need SymPy.
SYMBOLIC = ("elastic_pendulum",)

#: A built-in scene's long runs (:attr:`Scene.long_run`), in horizons of its test protocol.
LONG_RUNS = 50


def get(name: str, **parameters: float) -> Scene:
    """The scene called ``name`` (one of :data:`CATALOGUE`) with ``parameters`` set by keyword
    and the others at their defaults, or the symbolic scene of that name (one of
    :data:`SYMBOLIC`, at its defaults; needs SymPy).

    Parameters
    ----------
    name : str
        The scene's name.
    **parameters : float
        The catalogue parameters to set (``e`` for Kepler, …).

    Returns
    -------
    Scene
        The model with its initial state, step, horizon, invariants and reference.

    Raises
    ------
    ValueError
        An unknown scene (naming ``name`` and listing the scenes) or parameter.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.get("kepler", e=0.3)
    >>> scene.parameters, scene.invariants["H"]
    ({'e': 0.3}, -0.5)
    """
    if name in SYMBOLIC and name not in CATALOGUE:
        if parameters:
            raise ValueError(f"parameters: the symbolic scene {name} takes none here; build its model with them")
        # Imported here, on first use: the symbolic scenes need SymPy, an optional extra.
        from ..symbolic import examples

        return examples.scene(name)
    record = _core.scene(name, **parameters)
    declaration = declared(name)
    ref = record.reference
    reference = Reference(ref.t, ref.q, ref.p, ref.source) if ref is not None else None
    return Scene(
        record.name,
        record.description,
        NativeSystem(record.model, record.parameters, declaration.coordinates),
        record.q0,
        record.p0,
        record.t_end,
        record.dt,
        record.invariants,
        reference,
        record.parameters,
        declaration.contacts(record.parameters) if declaration.contacts is not None else (),
        TIME_UNITS.get(name, "time units"),
        LONG_RUNS,
    )
