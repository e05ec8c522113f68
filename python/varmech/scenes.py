"""Built-in scenes: native models in the fewest coordinates their physics needs, with initial
data, test horizon, invariants and, where known, a reference solution (sources in
``reference/`` of the repository).

Every scene, its parameters, description, step and invariants come from the core's catalogue
(``rust/core/src/scenes/catalogue.rs``): :func:`get` builds any of them by name, and the
functions below name them with their parameters for the reader."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from ._core import energy_terms
from ._util import floats, positive
from .impacts import Contact
from .model import SCENE_COORDINATES, SCENE_UNITS, Model, NativeSystem, initial_state
from .modes import step_by_trial

__all__ = [
    "CATALOGUE",
    "SYMBOLIC",
    "TIME_UNITS",
    "Reference",
    "Scene",
    "as_scene",
    "ball_on_turntable",
    "bouncing_ball",
    "cartesian_pendulum",
    "cartesian_spherical_pendulum",
    "chaplygin_sleigh",
    "charged_particle",
    "charged_particle_nonuniform",
    "damped_driven_pendulum",
    "double_pendulum",
    "elliptic_billiard",
    "fermi_pasta_ulam",
    "get",
    "harmonic_oscillator",
    "heavy_top",
    "henon_heiles",
    "kepler",
    "kepler_polar",
    "nbody",
    "outer_solar_system",
    "pendulum",
    "planar_chain",
    "rigid_body",
    "rolling_disk",
    "rolling_sphere",
    "spherical_pendulum",
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


#: The core's catalogue of scenes by name, in the order of the tour: each entry's
#: ``parameters`` (with their defaults) and ``description``.
CATALOGUE: dict[str, _core.CatalogueEntry] = {entry.name: entry for entry in _core.catalogue()}


#: The contact surfaces of the impact scenes from their parameters: the core's scenes use the
#: model layer only, so the surfaces are attached here (watched natively all the same).
CONTACTS: dict[str, Callable[[dict[str, float]], tuple[Contact, ...]]] = {
    "bouncing_ball": lambda p: (Contact.wall(0, restitution=p["restitution"], name="floor"),),
    "elliptic_billiard": lambda p: (Contact.ellipsoid((p["A"], p["B"]), name="wall"),),
}


#: The unit of t of the scenes that have one, by name (:data:`varmech.model.SCENE_UNITS`); every
#: other scene is in the model's own (dimensionless) "time units".
TIME_UNITS: dict[str, str] = {name: units["t"] for name, units in SCENE_UNITS.items()}


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
        from .symbolic import examples

        return examples.scene(name)
    record = _core.scene(name, **parameters)
    ref = record.reference
    reference = Reference(ref.t, ref.q, ref.p, ref.source) if ref is not None else None
    return Scene(
        record.name,
        record.description,
        NativeSystem(record.model, record.parameters, SCENE_COORDINATES.get(name)),
        record.q0,
        record.p0,
        record.t_end,
        record.dt,
        record.invariants,
        reference,
        record.parameters,
        CONTACTS[name](record.parameters) if name in CONTACTS else (),
        TIME_UNITS.get(name, "time units"),
        LONG_RUNS,
    )


def harmonic_oscillator(omega: float = 1.0) -> Scene:
    """The harmonic oscillator H = p²/2 + ω²q²/2, the linear test equation q̈ = −ω²q.

    From (q, p) = (0, 1) to t = 10, against the exact solution q = sin(ωt)/ω, p = cos ωt.

    Parameters
    ----------
    omega : float, default 1.0
        The angular frequency ω > 0, in inverse time units.

    Returns
    -------
    Scene
        A separable native model (n = 1), with step h = 0.1, invariant ``"H"`` = 1/2 and the
        exact reference at t = 10.

    Raises
    ------
    ValueError
        ``omega`` not finite and positive.

    See Also
    --------
    varmech.analysis.stability.growth_factor : the methods' linear stability on this equation.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.harmonic_oscillator(omega=2.0)
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> round(float(traj.energy()[-1]), 2), traj.method
    (0.5, 'verlet')
    """
    return get("harmonic_oscillator", omega=omega)


def pendulum() -> Scene:
    """The mathematical pendulum H = p²/2 − cos q in its angle q from the downward vertical.

    Hairer, Lubich & Wanner's protocol [1]_ (g/l = 1, unit mass): from (q, p) = (0, 1), H = −1/2,
    to t = 2π, against the reference state of the GNI test codes.

    Returns
    -------
    Scene
        A separable native model (n = 1), with invariant ``"H"`` and the reference at t = 2π.

    See Also
    --------
    cartesian_pendulum : the same pendulum in (x, y) on a constraint.

    References
    ----------
    .. [1] E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
       Springer, 2006, Sec. I.1.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.pendulum()
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> round(float(traj.energy()[-1]), 3), scene.invariants["H"]
    (-0.5, -0.5)
    """
    return get("pendulum")


def kepler(e: float = 0.6) -> Scene:
    """The Kepler problem H = |p|²/2 − 1/|q| in the plane, q = (x, y).

    Hairer, Lubich & Wanner's work–precision protocol [1]_: from the pericentre q = (1 − e, 0),
    p = (0, √((1 + e)/(1 − e))), an orbit of semi-major axis 1 and period 2π, over 200 periods.
    Rotation invariant: the angular momentum L = x p_y − y p_x = √(1 − e²) is conserved.

    Parameters
    ----------
    e : float, default 0.6
        The eccentricity, in [0, 1).

    Returns
    -------
    Scene
        A separable native model (n = 2) with the symmetry :class:`~varmech.Rotation` (in the
        plane), step h = 2π/200 (up to e = 0.6; beyond, shorter as the pericentre passage,
        2π/200·((1 − e)/0.4)^(3/2)), invariants ``"H"`` = −1/2 and ``"L"``, and the exact
        reference (the pericentre again at t = 400π).

    Raises
    ------
    ValueError
        ``e`` not in [0, 1).

    See Also
    --------
    kepler_polar : the same orbit in polar coordinates.

    References
    ----------
    .. [1] E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
       Springer, 2006, Sec. I.2.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.kepler(e=0.3)
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=200)    # one period
    >>> L = varmech.momentum(traj, varmech.Rotation(spatial_dim=2))
    >>> round(float(L[-1]), 12), round(0.91**0.5, 12)
    (0.953939201417, 0.953939201417)
    """
    return get("kepler", e=e)


def henon_heiles() -> Scene:
    """The Hénon–Heiles system H = (p₁² + p₂²)/2 + (q₁² + q₂²)/2 + q₁²q₂ − q₂³/3.

    Orbits are bounded below the escape energy 1/6 and chaotic in part of the energy shell
    near it [1]_. The long-run protocol of the SciML benchmarks: from q = (0.1, 0), p = (0, 0.5),
    H = 0.13, to t = 5·10⁴, with no reference state (the energy is the invariant to check).

    Returns
    -------
    Scene
        A separable native model (n = 2), with step h = 0.1 and invariant ``"H"`` = 0.13.

    See Also
    --------
    varmech.poincare_section : its sections, the classic picture of its chaos.

    References
    ----------
    .. [1] M. Hénon and C. Heiles, "The applicability of the third integral of motion: some
       numerical experiments", *Astron. J.* 69 (1964) 73–79; Hairer, Lubich & Wanner,
       *Geometric Numerical Integration*, 2nd ed., Springer, 2006, Sec. I.3.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.henon_heiles()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=1000)
    >>> round(float(traj.energy()[-1]), 3)
    0.13
    """
    return get("henon_heiles")


def fermi_pasta_ulam() -> Scene:
    """The Fermi–Pasta–Ulam chain of Hairer, Lubich & Wanner [1]_: stiff and soft springs.

    2m unit masses in a chain with fixed ends, stiff linear springs (frequency ω) alternating
    with soft quartic ones, H = Σpᵢ²/2 + (ω²/4)Σᵢ₌₁ᵐ(q₂ᵢ − q₂ᵢ₋₁)² + Σᵢ₌₀ᵐ(q₂ᵢ₊₁ − q₂ᵢ)⁴ with
    q₀ = q₂ₘ₊₁ = 0; m = 3 and ω = 50, from the first stiff spring excited, H₀ = 2.00120008, to
    t = 200. The total oscillatory energy I of the stiff springs is an adiabatic invariant.

    Returns
    -------
    Scene
        A separable native model (n = 6), with step h = 0.001 and invariants ``"H"`` and
        ``"I"`` = 1.

    References
    ----------
    .. [1] E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
       Springer, 2006, Sec. I.5.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.fermi_pasta_ulam()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=1000)
    >>> round(float(traj.energy()[-1]), 2)
    2.0
    """
    return get("fermi_pasta_ulam")


def outer_solar_system() -> Scene:
    """The outer solar system of Hairer, Lubich & Wanner [1]_ as a gravitational 6-body problem.

    The Sun (with the inner planets' masses), Jupiter, Saturn, Uranus, Neptune and Pluto in
    3 dimensions, H = Σ|pᵢ|²/2mᵢ − G Σ_{i<j} mᵢmⱼ/|qᵢ − qⱼ|, in AU, days and solar
    masses, over 500 000 days against the reference state of the GNI test codes
    (``reference/outer_solar_system.json``).

    Returns
    -------
    Scene
        A native N-body model (n = 18) with translation and rotation symmetries (total linear
        and angular momentum), step h = 50 days, invariant ``"H"`` and the reference; its
        ``time_unit`` is ``"days"``.

    See Also
    --------
    nbody : any gravitational N-body problem.

    References
    ----------
    .. [1] E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
       Springer, 2006, Sec. I.2.4.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.outer_solar_system()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=200)    # 10 000 days
    >>> E = traj.energy()
    >>> bool(abs(E[-1] / E[0] - 1) < 1e-3), scene.time_unit
    (True, 'days')
    """
    return get("outer_solar_system")


def double_pendulum() -> Scene:
    """The planar double pendulum in its two angles, a Lagrangian with configuration-dependent mass.

    L = ½(m₁ + m₂)l₁²θ̇₁² + ½m₂l₂²θ̇₂² + m₂l₁l₂θ̇₁θ̇₂cos(θ₁ − θ₂) + (m₁ + m₂)gl₁cos θ₁ +
    m₂gl₂cos θ₂ with l = (2, 3), m = (1, 2), g = 9.80665, from θ = (π/4, π/2),
    θ̇ = (0, π/8) to T = 10, against the reference of GeometricProblems.jl (accurate to about
    1e-11). A general Lagrangian: integrate it with ``midpoint`` (the default) or
    ``trapezoid``.

    Returns
    -------
    Scene
        A native general Lagrangian (n = 2), with step h = 0.01, invariant ``"E"`` and the
        reference at T = 10.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.double_pendulum()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> round(float(traj.energy()[-1]), 2), traj.method
    (-40.22, 'midpoint')
    """
    return get("double_pendulum")


def spherical_pendulum() -> Scene:
    """The spherical pendulum in (θ, φ), θ from the downward vertical (m = l = g = 1).

    L = ½(θ̇² + sin²θ φ̇²) + cos θ, from θ = 1, θ̇ = 0, φ̇ = 1.2 to T = 50 against the
    reference angles of ``reference/scenes.json`` (the reference gives the angles only, so its
    p_θ is NaN). The azimuth φ is cyclic: p_φ = sin²θ φ̇ is conserved.

    Returns
    -------
    Scene
        A native general Lagrangian (n = 2) with the symmetry ``Cyclic(1)``, step h = 0.01,
        invariants ``"E"`` and ``"p_phi"``, and the reference at T = 50.

    See Also
    --------
    cartesian_spherical_pendulum : the same pendulum in (x, y, z) on the unit sphere.
    varmech.routh : the pendulum reduced by its cyclic φ.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.spherical_pendulum()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> round(float(traj.p[-1, 1]), 12) == round(scene.invariants["p_phi"], 12)
    True
    """
    return get("spherical_pendulum")


def heavy_top() -> Scene:
    """The heavy symmetric top in Euler angles (θ, φ, ψ), θ from the upward vertical.

    L = ½I₁(θ̇² + sin²θ φ̇²) + ½I₃(ψ̇ + φ̇ cos θ)² − Mgl cos θ [1]_ with I₁ = 1, I₃ = ½,
    Mgl = 1. A fast top (p_ψ² = 6.25 > 4I₁Mgl) released at θ = 0.3 with θ̇ = φ̇ = 0 and
    ψ̇ = 5, to T = 50: it nutates in cusps between the turning points θ = 0.3 and
    0.4794748702… The angles φ and ψ are cyclic: p_φ and p_ψ are conserved. No reference state.

    Returns
    -------
    Scene
        A native general Lagrangian (n = 3) with the symmetries ``Cyclic(1)`` and ``Cyclic(2)``,
        step h = 0.01, and invariants ``"E"``, ``"p_phi"`` and ``"p_psi"``.

    See Also
    --------
    varmech.routh : the top reduced to θ alone.

    References
    ----------
    .. [1] H. Goldstein, C. Poole and J. Safko, *Classical Mechanics*, 3rd ed., Addison-Wesley,
       2002, Sec. 5.7.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.heavy_top()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> round(float(traj.energy()[-1]), 6), round(float(traj.p[-1, 2]), 12)
    (7.205336, 2.5)
    """
    return get("heavy_top")


def kepler_polar(e: float = 0.6) -> Scene:
    """Kepler's problem in polar coordinates (r, θ): L = ½(ṙ² + r²θ̇²) + 1/r.

    The orbit of :func:`kepler` from the pericentre r = 1 − e, θ = 0, over 200 periods of 2π,
    against the exact reference r = 1 − e, θ = 400π, p = (0, √(1 − e²)). A general Lagrangian
    whose angle θ is cyclic: p_θ = r²θ̇ is conserved.

    Parameters
    ----------
    e : float, default 0.6
        The eccentricity, in [0, 1).

    Returns
    -------
    Scene
        A native general Lagrangian (n = 2) with the symmetry ``Cyclic(1)``, step h = 2π/200
        (up to e = 0.6; 2π/200·((1 − e)/0.4)^(3/2) beyond),
        invariants ``"E"`` = −1/2 and ``"p_theta"``, and the exact reference.

    Raises
    ------
    ValueError
        ``e`` not in [0, 1).

    See Also
    --------
    kepler : the same orbit in Cartesian coordinates.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.kepler_polar(e=0.6)
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=200)
    >>> round(float(traj.p[-1, 1]), 14)
    0.8
    """
    return get("kepler_polar", e=e)


def charged_particle(B: float = 1.0) -> Scene:
    """A unit charge of unit mass in the plane, in the uniform magnetic field B ẑ.

    In the symmetric gauge, L = ½|q̇|² + (B/2)(x ẏ − y ẋ). From q = (1, 0), q̇ = (0, −B) it
    gyrates on the unit circle at Ω = B, the exact solution at t = 10. A general Lagrangian,
    rotation invariant: the energy ½|q̇|² and the canonical angular momentum
    x p_y − y p_x are conserved.

    Parameters
    ----------
    B : float, default 1.0
        The field strength (any finite value; 0 is a free particle).

    Returns
    -------
    Scene
        A native general Lagrangian (n = 2) with the symmetry :class:`~varmech.Rotation`,
        step h = 0.05, invariants ``"E"`` and ``"L"``, and the exact reference at t = 10.

    Raises
    ------
    ValueError
        ``B`` not finite.

    See Also
    --------
    charged_particle_nonuniform : the same charge in a field that varies.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.charged_particle(B=2.0)
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> round(float(traj.energy()[-1]), 12)
    2.0
    """
    return get("charged_particle", B=B)


def charged_particle_nonuniform() -> Scene:
    """A unit charge of unit mass in the plane, in the field B(q) = (1 + |q|²/4) ẑ.

    In the symmetric gauge (the closure example of the user guide's models page),
    L = ½|q̇|² + A(q)·q̇ with A(q) = ½(1 + |q|²/8)(−y, x). From q = (1, 0), q̇ = (0, −1)
    to t = 200 it gyrates and drifts about the origin. Rotation invariant: the energy and the
    canonical angular momentum are conserved. No reference state.

    Returns
    -------
    Scene
        A native general Lagrangian (n = 2) with the symmetry :class:`~varmech.Rotation`,
        step h = 0.05, and invariants ``"E"`` and ``"L"``.

    See Also
    --------
    charged_particle : the uniform field, with an exact solution.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.charged_particle_nonuniform()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> L = varmech.momentum(traj, varmech.Rotation(spatial_dim=2))
    >>> round(float(L[-1]), 12), scene.invariants["L"]
    (-0.4375, -0.4375)
    """
    return get("charged_particle_nonuniform")


def damped_driven_pendulum(gamma: float = 0.5, amplitude: float = 1.5, drive: float = 2.0 / 3.0) -> Scene:
    """The damped, driven pendulum θ̈ + γθ̇ + sin θ = A cos Ωt (m = l = g = 1).

    L = ½θ̇² + cos θ with the Rayleigh dissipation R = ½γθ̇² and the driving torque A cos Ωt
    as a force, from rest at the bottom to t = 100. The defaults are Baker & Gollub's chaotic
    regime [1]_ (their q = 1/γ = 2, g = A = 1.5, ω_D = Ω = 2/3). Forced, so nothing is
    conserved: the energy changes by the work ``traj.work`` of the forces, E − E₀ = W.

    Parameters
    ----------
    gamma : float, default 0.5
        The damping coefficient γ ≥ 0.
    amplitude : float, default 1.5
        The amplitude A of the driving torque (finite).
    drive : float, default 2/3
        The driving frequency Ω (finite).

    Returns
    -------
    Scene
        A native, forced general Lagrangian (n = 1), with step h = 0.01 and no invariants.

    Raises
    ------
    ValueError
        ``gamma`` negative or not finite, or ``amplitude`` or ``drive`` not finite.

    References
    ----------
    .. [1] G. L. Baker and J. P. Gollub, *Chaotic Dynamics: An Introduction*, 2nd ed.,
       Cambridge University Press, 1996.

    Examples
    --------
    The energy balance E − E₀ − W stays at the discretization error:

    >>> import varmech
    >>> scene = varmech.scenes.damped_driven_pendulum()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> E = traj.energy()
    >>> round(float(E[-1] - E[0]), 3), round(float(traj.work[-1]), 3)
    (0.567, 0.567)
    """
    return get("damped_driven_pendulum", gamma=gamma, amplitude=amplitude, drive=drive)


def nbody(masses: ArrayLike, positions: ArrayLike, velocities: ArrayLike, G: float = 1.0, t_end: float = 1.0, dt: float = 1e-3) -> Scene:
    """A native gravitational N-body model in 3 dimensions from masses (N,), positions and
    velocities (N, 3).

    H = Σᵢ |pᵢ|²/2mᵢ − G Σ_{i<j} mᵢmⱼ/|qᵢ − qⱼ| in the coordinates of the bodies, one after
    the other (n = 3N); evaluated in O(N) memory, so that 10⁵ bodies fit. The model declares
    the translations and rotations (total linear and angular momentum).

    Parameters
    ----------
    masses : array_like, shape (N,)
        The masses, finite and positive; at least two bodies.
    positions, velocities : array_like, shape (N, 3)
        The initial positions and velocities (finite); the momenta are pᵢ = mᵢvᵢ.
    G : float, default 1.0
        The gravitational constant, positive.
    t_end : float, default 1.0
        The scene's horizon, positive.
    dt : float, default 1e-3
        The scene's step, positive.

    Returns
    -------
    Scene
        The model with its initial state, horizon and step; no invariants or reference.

    Raises
    ------
    ValueError
        Naming the argument: shapes that do not match ``masses``, masses not finite and
        positive (or fewer than two), positions or velocities not finite, or ``G``,
        ``t_end`` or ``dt`` not finite and positive.

    See Also
    --------
    outer_solar_system : the outer planets.

    Examples
    --------
    A light body on a circular orbit of radius 1 about a heavy one:

    >>> import varmech
    >>> scene = varmech.scenes.nbody([1.0, 1e-3], [[0, 0, 0], [1, 0, 0]], [[0, 0, 0], [0, 1, 0]], dt=0.01)
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> E = traj.energy()
    >>> round(float(E[-1]), 6), traj.method
    (-0.0005, 'verlet')
    """
    m, x, v = floats("masses", masses), floats("positions", positions), floats("velocities", velocities)
    if m.ndim != 1 or x.shape != (len(m), 3) or v.shape != (len(m), 3):
        raise ValueError(f"positions, velocities: must have shape ({len(m)}, 3) to match masses")
    bad = np.flatnonzero(~(np.isfinite(m) & (m > 0)))
    if bad.size:
        raise ValueError(f"masses: must be finite and positive, got masses[{bad[0]}] = {m[bad[0]]}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise ValueError("positions, velocities: must be finite")
    G, t_end, dt = positive("G", G), positive("t_end", t_end), positive("dt", dt)
    model = NativeSystem(_core.nbody(G, [float(mi) for mi in m]))
    p = (m[:, None] * v).ravel()
    return Scene("nbody", f"{len(m)}-body problem", model, x.ravel().copy(), p, t_end, dt)


def cartesian_pendulum() -> Scene:
    """The planar pendulum in Cartesian coordinates (x, y) on the constraint x² + y² = 1.

    L = ½(ẋ² + ẏ²) − gy with g = 1 (m = l = 1), subject to g(q) = x² + y² − 1 = 0, released
    from rest 2 rad from the downward vertical: a constrained mechanical system as in Hairer,
    Lubich & Wanner [1]_. RATTLE at h = 0.1 over T = 10⁴ is its protocol
    (``reference/scenes.json``). Its exact solution is the pendulum's.

    Returns
    -------
    Scene
        A native constrained separable model (n = 2, one constraint), with step h = 0.1 and
        invariant ``"H"``; integrated by ``rattle`` by default.

    See Also
    --------
    pendulum : the same pendulum in its angle.

    References
    ----------
    .. [1] E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
       Springer, 2006, Sec. VII.1.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.cartesian_pendulum()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> g, _ = traj.constraint_residuals()
    >>> round(float(traj.energy()[-1]), 2), bool(g.max() < 1e-14), traj.method
    (0.41, True, 'rattle')
    """
    return get("cartesian_pendulum")


def cartesian_spherical_pendulum() -> Scene:
    """The spherical pendulum in Cartesian coordinates on |x| = 1 (m = l = g = 1).

    L = ½|ẋ|² − z on g(x) = |x|² − 1 = 0, from θ = 1, θ̇ = 0, φ̇ = 1.2 (θ from the
    downward vertical) to T = 50: the initial state of :func:`spherical_pendulum`. The
    reference holds the positions of that scene's reference angles; the angular momentum
    L_z = x p_y − y p_x about the vertical is conserved.

    Returns
    -------
    Scene
        A native constrained separable model (n = 3, one constraint) with the symmetry
        :class:`~varmech.Rotation` about z, step h = 0.01, invariants ``"H"`` and ``"L_z"``,
        and the reference at T = 50.

    See Also
    --------
    spherical_pendulum : the same pendulum in its angles.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.cartesian_spherical_pendulum()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> Lz = varmech.momentum(traj, varmech.Rotation(2))
    >>> round(float(Lz[-1]), 12) == round(scene.invariants["L_z"], 12)
    True
    """
    return get("cartesian_spherical_pendulum")


def planar_chain(links: int = 8) -> Scene:
    """A planar chain of ``links`` unit masses on unit links hanging from the origin (g = 1).

    L = ½Σ|ẋᵢ|² − Σyᵢ in the positions xᵢ = (xᵢ, yᵢ) of the masses, subject to
    |x₁|² = 1 and |xᵢ − xᵢ₋₁|² = 1: 2·links coordinates and ``links`` constraints.
    Released from rest straight at 1 rad from the downward vertical, to t = 100. No reference
    state; the energy is the invariant to check.

    Parameters
    ----------
    links : int, default 8
        The number of links, at least 1.

    Returns
    -------
    Scene
        A native constrained separable model (n = 2·links), with step h = 0.01; integrated by
        ``rattle`` by default.

    Raises
    ------
    ValueError
        ``links`` not a whole number, or below 1.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.planar_chain(links=3)
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> E = traj.energy()
    >>> scene.model.dim, scene.model.constraints, bool(abs(E[-1] - E[0]) < 1e-4)
    (6, 3, True)
    """
    return get("planar_chain", links=links)


def rigid_body() -> Scene:
    """A rigid body about a fixed point in unit quaternions, Hairer, Lubich & Wanner's example [1]_.

    q = (q₁, q₂, q₃, q₄), scalar part first, on the constraint |q|² = 1; principal moments
    I = (0.5, 0.9, 1.0) and the potential U = q₁² − q₂² − q₃² + q₄², from q = (0.4, 0.2, 0.4,
    0.8) with body angular momentum (0.2, 1, 0.4), to t = 10. The kinetic energy's mass
    depends on q, so its discrete Euler–Lagrange equations are solved with the constraint by
    ``trapezoid`` (the default) or ``midpoint``.

    Returns
    -------
    Scene
        A native constrained general Lagrangian (n = 4, one constraint), with step h = 0.01.

    References
    ----------
    .. [1] E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
       Springer, 2006, Sec. VII.5.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.rigid_body()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> E = traj.energy()
    >>> traj.method, round(float(E[0]), 6), bool(abs(E[-1] - E[0]) < 1e-4)
    ('trapezoid', 1.275556, True)
    """
    return get("rigid_body")


def bouncing_ball(g: float = 9.81, h0: float = 1.0, restitution: float = 1.0) -> Scene:
    """A ball of unit mass dropped on a floor, H = p²/2 + gq with the contact q ≥ 0.

    Dropped from rest at height ``h0`` under gravity ``g``, with the coefficient of
    ``restitution`` e: the floor is ``contacts[0]``, a native wall. It hits the floor first at
    t₁ = √(2h₀/g), rises to h₀e²ᵏ after the k-th bounce, and is at the apex after the K-th at
    t_end, the exact reference (q = h₀e²ᴷ, p = 0) [1]_: K = 10, or fewer for a small e, where
    the flights would shrink below 10⁻⁴ of the first sooner (K ≤ ln 10⁻⁴ / ln e: 3 at e = 0.05),
    so that ``dt``, which resolves the shortest flight, still reaches t_end in a few 10⁵ steps.
    Elastic (e = 1), H = gh₀ is conserved.

    Parameters
    ----------
    g : float, default 9.81
        The gravitational acceleration, positive.
    h0 : float, default 1.0
        The height of the drop, positive.
    restitution : float, default 1.0
        The coefficient of restitution e, in (0, 1] (1: elastic).

    Returns
    -------
    Scene
        A separable native model (n = 1) with its floor in ``contacts``, the exact reference
        at the last apex, and invariant ``"H"``.

    Raises
    ------
    ValueError
        ``g`` or ``h0`` not finite and positive, or ``restitution`` not in (0, 1].

    See Also
    --------
    varmech.Contact.wall : the floor.

    References
    ----------
    .. [1] R. C. Fetecau, J. E. Marsden, M. Ortiz and M. West, "Nonsmooth Lagrangian mechanics
       and variational collision integrators", *SIAM J. Appl. Dyn. Syst.* 2 (2003) 381–416.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.bouncing_ball(restitution=0.9)
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> len(traj.events[0]), round(float(traj.q[-1, 0]), 6) == round(0.9**20, 6)
    (10, True)
    """
    return get("bouncing_ball", g=g, h0=h0, restitution=restitution)


def elliptic_billiard(A: float = 2.0, B: float = 1.0, x0: float = 0.3, y0: float = 0.1, px0: float = 0.6, py0: float = 0.8) -> Scene:
    """A free particle of unit mass in the elliptic billiard x²/A² + y²/B² ≤ 1, H = |p|²/2.

    From (x0, y0) inside with momenta (px0, py0), to t = 100: the wall is ``contacts[0]``, a
    native ellipse, with elastic impacts. Integrable: besides E, the product L₁L₂ of the
    angular momenta about the foci (±c, 0), c² = A² − B², Lᵢ = (x ∓ c)p_y − y p_x, is
    conserved between and across the impacts [1]_ (it fixes the orbit's confocal caustic).

    Parameters
    ----------
    A, B : float, default 2.0 and 1.0
        The semi-axes, A ≥ B > 0 (the foci on the x axis).
    x0, y0 : float, default 0.3 and 0.1
        The initial position, strictly inside the table.
    px0, py0 : float, default 0.6 and 0.8
        The initial momenta (finite).

    Returns
    -------
    Scene
        A separable native model (n = 2) with its wall in ``contacts`` and invariants ``"E"``
        and ``"L1L2"``; no reference state.

    Raises
    ------
    ValueError
        ``B`` not finite and positive, ``A`` below ``B``, a start value not finite (naming
        it), or (x0, y0) not strictly inside (naming ``x0``).

    See Also
    --------
    varmech.Contact.ellipsoid : the wall.

    References
    ----------
    .. [1] R. C. Fetecau, J. E. Marsden, M. Ortiz and M. West, "Nonsmooth Lagrangian mechanics
       and variational collision integrators", *SIAM J. Appl. Dyn. Syst.* 2 (2003) 381–416.

    Examples
    --------
    >>> import numpy as np, varmech
    >>> scene = varmech.scenes.elliptic_billiard()
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> c = np.sqrt(3.0)
    >>> focal = ((traj.q[:, 0] - c) * traj.p[:, 1] - traj.q[:, 1] * traj.p[:, 0]) * (
    ...     (traj.q[:, 0] + c) * traj.p[:, 1] - traj.q[:, 1] * traj.p[:, 0])
    >>> len(traj.events[0]), bool(np.max(np.abs(focal - scene.invariants["L1L2"])) < 1e-12)
    (50, True)
    """
    return get("elliptic_billiard", A=A, B=B, x0=x0, y0=y0, px0=px0, py0=py0)


def rolling_disk(radius: float = 1.0, turn: float = 0.7, roll: float = 2.0) -> Scene:
    """A thin uniform disk (a coin) of unit mass rolling upright without slipping.

    q = (x, y, θ, φ): contact point, heading, rolling angle; L = ½(ẋ² + ẏ²) + ½Iθ̇² + ½Jφ̇²
    (I = R²/4, J = R²/2) with the velocity constraints ẋ = Rφ̇cosθ, ẏ = Rφ̇sinθ. From
    θ₀ = 0.3 turning at θ̇ = ``turn`` and rolling at φ̇ = ``roll``, to T = 100. Exact: θ̇, φ̇
    and E constant, the contact point on the circle of radius Rφ̇/θ̇ (the reference). Conserved
    momenta: p_θ = Iθ̇ and p_φ = Jφ̇; p_x and p_y are not, though L does not depend on x, y.

    Parameters
    ----------
    radius : float, default 1.0
        The disk's radius R, positive.
    turn : float, default 0.7
        The turning rate θ̇, non-zero.
    roll : float, default 2.0
        The rolling rate φ̇ (finite).

    Returns
    -------
    Scene
        A native nonholonomic model (n = 4, two velocity constraints) with the symmetries
        ``Cyclic(2)`` and ``Cyclic(3)``, invariants ``"E"``, ``"p[2]"`` and ``"p[3]"``, and
        the exact reference at T = 100.

    Raises
    ------
    ValueError
        ``radius`` not finite and positive, ``turn`` zero or not finite, or ``roll`` not
        finite.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.rolling_disk()
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end, save_every=10)
    >>> report = varmech.check_conservation(traj)
    >>> report.verdict, [m.name for m in report.momenta], report.constraints[0].verdict
    ('conserved to round-off', ['p_theta', 'p_phi'], 'conserved to round-off')
    """
    return get("rolling_disk", radius=radius, turn=turn, roll=roll)


def chaplygin_sleigh(inertia: float = 1.0, blade: float = 1.0, spin: float = 1.0) -> Scene:
    """The Chaplygin sleigh: a body of unit mass on a blade that does not slip sideways.

    q = (x, y, θ) of its centre and heading, L = ½(ẋ² + ẏ²) + ½Iθ̇² with the moment of
    inertia I about the centre; the blade, a distance b behind the centre, gives the velocity
    constraint −ẋ sin θ + ẏ cos θ − bθ̇ = 0 [1]_. Spinning in place at θ̇ = ω₀ from the origin,
    to T = 40, it relaxes to straight-line motion: u = U tanh κt, ω = ω₀ sech κt, U = √(2E),
    κ = bU/(I + b²) (the reference holds θ and the momenta at T). Energy conserved; no
    momentum is (the blade's force turns them all).

    Parameters
    ----------
    inertia : float, default 1.0
        The moment of inertia I about the centre, positive.
    blade : float, default 1.0
        The distance b of the blade behind the centre, positive.
    spin : float, default 1.0
        The initial spin ω₀ (finite).

    Returns
    -------
    Scene
        A native nonholonomic model (n = 3, one velocity constraint), with step h = 0.01,
        invariant ``"E"`` and the closed-form reference at T = 40.

    Raises
    ------
    ValueError
        ``inertia`` or ``blade`` not finite and positive, or ``spin`` not finite.

    References
    ----------
    .. [1] A. M. Bloch, *Nonholonomic Mechanics and Control*, Springer, 2003, Sec. 1.7.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.chaplygin_sleigh()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> round(float(traj.energy()[-1]), 5)
    1.0
    """
    return get("chaplygin_sleigh", inertia=inertia, blade=blade, spin=spin)


def rolling_sphere(alpha: float = 0.5, g: float = 9.81, radius: float = 1.0, vx0: float = 1.0, vy0: float = 0.3, spin: float = 1.0) -> Scene:
    """A homogeneous ball of unit mass rolling on a rough plane inclined at α, Byerly's problem [1]_.

    q = (x, y, φ, θ, ψ): its centre (x down the slope) and ZXZ Euler angles; I = 2a²/5 for the
    radius a, L = ½(ẋ² + ẏ²) + ½I(φ̇² + θ̇² + ψ̇² + 2φ̇ψ̇ cos θ) + g sin α x, with the no-slip
    constraints ẋ = aω_y, ẏ = −aω_x on the angular velocity ω of the Euler angles. From the
    origin with centre velocity (vx0, vy0) and spin ω_z about the normal, to T = 1: the centre
    accelerates at (5/7)g sin α down the slope and moves uniformly across it, on a parabola (the
    reference holds the centre and p_x, p_y, p_φ). Conserved: E and p_φ = Iω_z; p_y = ẏ by the
    exact motion but only to O(h²) by the discrete one, so it is not declared; p_x is not.

    Parameters
    ----------
    alpha : float, default 0.5
        The inclination α in radians, in [0, π/2).
    g : float, default 9.81
        The gravitational acceleration (finite).
    radius : float, default 1.0
        The ball's radius a, positive.
    vx0, vy0 : float, default 1.0 and 0.3
        The initial velocity of the centre, down and across the slope.
    spin : float, default 1.0
        The initial spin ω_z about the plane's normal.

    Returns
    -------
    Scene
        A native nonholonomic model (n = 5) with the symmetry ``Cyclic(2)``, step h = 0.01,
        invariants ``"E"`` and ``"p[2]"``, and Byerly's exact reference at T = 1.

    Raises
    ------
    ValueError
        ``alpha`` not in [0, π/2), ``radius`` not finite and positive, or ``g``, ``vx0``,
        ``vy0`` or ``spin`` not finite (naming it).

    See Also
    --------
    ball_on_turntable : the same ball on a turning table.

    References
    ----------
    .. [1] W. E. Byerly, *An Introduction to the Use of Generalized Coordinates in Mechanics
       and Physics*, Ginn, 1916, ch. I.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.rolling_sphere()
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> round(float(traj.q[-1, 0]), 3), round(1.0 + 5 / 14 * 9.81 * 0.479425538604203, 3)
    (2.68, 2.68)
    """
    return get("rolling_sphere", alpha=alpha, g=g, radius=radius, vx0=vx0, vy0=vy0, spin=spin)


def ball_on_turntable(
    omega: float = 1.0, radius: float = 1.0, x0: float = 1.0, y0: float = 0.0, vx0: float = 0.0, vy0: float = 0.2, spin: float = 1.0
) -> Scene:
    """The ball of :func:`rolling_sphere` rolling on a level table that turns at Ω.

    No slip relative to the table: affine velocity constraints A(q)q̇ + b(q) = 0 with
    b = (Ωy, −Ωx) [1]_. From centre (x0, y0) with velocity (vx0, vy0) and spin ω_z about the
    normal, its centre's velocity turns at ν = (2/7)Ω: it circles about r + (−ẏ, ẋ)/ν, back to
    its start at T = 14π/Ω (the reference). The table does work: E is not conserved (unless
    the circle is centred on the axis); the Jacobi integral J = E − Ω(x p_y − y p_x) is, with
    p_φ = Iω_z, the speed |ṙ| and the circle's centre.

    Parameters
    ----------
    omega : float, default 1.0
        The table's angular velocity Ω, positive.
    radius : float, default 1.0
        The ball's radius, positive.
    x0, y0 : float, default 1.0 and 0.0
        The initial centre.
    vx0, vy0 : float, default 0.0 and 0.2
        The initial velocity of the centre.
    spin : float, default 1.0
        The initial spin ω_z about the normal.

    Returns
    -------
    Scene
        A native nonholonomic model (n = 5, affine constraints) with the symmetry
        ``Cyclic(2)``, invariants ``"J"`` and ``"p[2]"``, and the exact reference at 14π/Ω.

    Raises
    ------
    ValueError
        ``omega`` or ``radius`` not finite and positive, or ``x0``, ``y0``, ``vx0``, ``vy0``
        or ``spin`` not finite (naming it).

    References
    ----------
    .. [1] A. M. Bloch, *Nonholonomic Mechanics and Control*, Springer, 2003, Sec. 5.2.

    Examples
    --------
    The Jacobi integral, not the energy, is conserved:

    >>> import varmech
    >>> scene = varmech.scenes.ball_on_turntable()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> x, y, px, py = traj.q[-1, 0], traj.q[-1, 1], traj.p[-1, 0], traj.p[-1, 1]
    >>> E = traj.energy()[-1]
    >>> round(float(E - (x * py - y * px)), 5), round(scene.invariants["J"], 5), round(float(E), 3)
    (0.148, 0.148, 0.297)
    """
    return get("ball_on_turntable", omega=omega, radius=radius, x0=x0, y0=y0, vx0=vx0, vy0=vy0, spin=spin)
