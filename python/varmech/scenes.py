"""Built-in scenes: native models in the fewest coordinates their physics needs, with initial
data, test horizon, invariants and, where known, a reference solution (sources in
``reference/`` of the repository).

Every scene, its parameters, description, step and invariants come from the core's catalogue
(``rust/core/src/scenes/catalogue.rs``): :func:`get` builds any of them by name, and the
functions below name them with their parameters for the reader."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from .impacts import Contact
from .model import Model, NativeSystem


@dataclass(frozen=True)
class Reference:
    """The solution at time ``t``, exact or published, and where it comes from."""

    t: float
    q: np.ndarray
    p: np.ndarray
    source: str


@dataclass(frozen=True)
class Scene:
    """A model with its initial state and test protocol: a native one of the core's catalogue
    (:func:`get`), or a symbolic one (:func:`varmech.symbolic.examples.scene`).

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

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.kepler()
    >>> scene.q0, scene.reference.source
    (array([0.4, 0. ]), 'exact: 200 whole periods')
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
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


#: The core's catalogue of scenes by name, in the order of the tour: each entry's
#: ``parameters`` (with their defaults) and ``description``.
CATALOGUE: dict[str, _core.CatalogueEntry] = {entry.name: entry for entry in _core.catalogue()}


#: The contact surfaces of the impact scenes from their parameters: the core's scenes use the
#: model layer only, so the surfaces are attached here (watched natively all the same).
CONTACTS: dict[str, Callable[[dict[str, float]], tuple[Contact, ...]]] = {
    "bouncing_ball": lambda p: (Contact.wall(0, restitution=p["restitution"], name="floor"),),
    "elliptic_billiard": lambda p: (Contact.ellipsoid((p["a"], p["b"]), name="wall"),),
}


#: The unit of t of the scenes that have one, by name; every other scene is in the model's own
#: (dimensionless) "time units".
TIME_UNITS: dict[str, str] = {"outer_solar_system": "days"}


#: The symbolic scenes (:func:`varmech.symbolic.examples.scene`), which need SymPy.
SYMBOLIC = ("elastic_pendulum",)


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
        from .symbolic import examples

        return examples.scene(name)
    record = _core.scene(name, **parameters)
    ref = record.reference
    reference = Reference(ref.t, ref.q, ref.p, ref.source) if ref is not None else None
    return Scene(
        record.name,
        record.description,
        NativeSystem(record.model, record.parameters),
        record.q0,
        record.p0,
        record.t_end,
        record.dt,
        record.invariants,
        reference,
        record.parameters,
        CONTACTS[name](record.parameters) if name in CONTACTS else (),
        TIME_UNITS.get(name, "time units"),
    )


def harmonic_oscillator(omega: float = 1.0) -> Scene:
    """H = p²/2 + ω²q²/2 from (q, p) = (0, 1); exact solution at t = 10."""
    return get("harmonic_oscillator", omega=omega)


def pendulum() -> Scene:
    """H = p²/2 − cos q in the angle from the downward vertical, from (0, 1) to t = 2π (HLW I.1)."""
    return get("pendulum")


def kepler(e: float = 0.6) -> Scene:
    """H = |p|²/2 − 1/|q| in the plane, eccentricity ``e``, 200 periods of 2π (HLW I.2)."""
    return get("kepler", e=e)


def henon_heiles() -> Scene:
    """The Hénon–Heiles system at H = 0.13 from q = (0.1, 0), p = (0, 0.5), to t = 5·10⁴."""
    return get("henon_heiles")


def fermi_pasta_ulam() -> Scene:
    """The Fermi–Pasta–Ulam chain of HLW I.5: m = 3 stiff springs, ω = 50."""
    return get("fermi_pasta_ulam")


def outer_solar_system() -> Scene:
    """Sun (with the inner planets), Jupiter, Saturn, Uranus, Neptune and Pluto over 500 000
    days (HLW I.2.4), against the reference state of the GNI test codes."""
    return get("outer_solar_system")


def double_pendulum() -> Scene:
    """The planar double pendulum in its two angles (l = (2, 3), m = (1, 2), g = 9.80665), a
    general Lagrangian (configuration-dependent mass), from θ = (π/4, π/2), θ̇ = (0, π/8) to
    T = 10 against the GeometricProblems.jl reference. Integrate it with ``midpoint`` or
    ``trapezoid``."""
    return get("double_pendulum")


def spherical_pendulum() -> Scene:
    """The spherical pendulum in (θ, φ), θ from the downward vertical (m = l = g = 1), from
    θ = 1, θ̇ = 0, φ̇ = 1.2 to T = 50 against the reference angles of reference/scenes.json. A
    general Lagrangian whose azimuth φ is cyclic: p_φ is conserved. The reference gives the
    angles only, so its p_θ is NaN."""
    return get("spherical_pendulum")


def heavy_top() -> Scene:
    """The heavy symmetric top in Euler angles (θ, φ, ψ), θ from the upward vertical:
    L = ½I₁(θ̇² + sin²θ φ̇²) + ½I₃(ψ̇ + φ̇ cos θ)² − Mgl cos θ with I₁ = 1, I₃ = ½, Mgl = 1. A
    fast top (p_ψ² = 6.25 > 4I₁Mgl) released at θ = 0.3 with θ̇ = φ̇ = 0 and ψ̇ = 5, to T = 50:
    it nutates in cusps between the turning points θ = 0.3 and 0.4794748702… A general
    Lagrangian whose angles φ and ψ are cyclic: p_φ and p_ψ are conserved. No reference state."""
    return get("heavy_top")


def kepler_polar(e: float = 0.6) -> Scene:
    """Kepler's problem in polar coordinates (r, θ): L = ½(ṙ² + r²θ̇²) + 1/r, the orbit of
    :func:`kepler` from the pericentre r = 1 − e, θ = 0, over 200 periods of 2π; exact reference
    r = 1 − e, θ = 400π, p = (0, √(1 − e²)). A general Lagrangian whose angle θ is cyclic: p_θ is
    conserved."""
    return get("kepler_polar", e=e)


def charged_particle(B: float = 1.0) -> Scene:
    """A unit charge of unit mass in the plane, in the uniform magnetic field B ẑ (symmetric
    gauge): L = ½|q̇|² + (B/2)(x ẏ − y ẋ). From q = (1, 0), q̇ = (0, −B) it gyrates on the unit
    circle at Ω = B, the exact solution at t = 10. A general Lagrangian, rotation invariant:
    the canonical angular momentum is conserved."""
    return get("charged_particle", b=B)


def charged_particle_nonuniform() -> Scene:
    """A unit charge of unit mass in the plane, in the field B(q) = (1 + |q|²/4) ẑ (symmetric
    gauge, as the closure example of the user guide's models page): L = ½|q̇|² + A(q)·q̇ with
    A(q) = ½(1 + |q|²/8)(−y, x). From q = (1, 0), q̇ = (0, −1) to t = 200; it gyrates and drifts
    about the origin. Rotation invariant: the canonical angular momentum is conserved."""
    return get("charged_particle_nonuniform")


def damped_driven_pendulum(gamma: float = 0.5, amplitude: float = 1.5, drive: float = 2.0 / 3.0) -> Scene:
    """The pendulum θ̈ + γθ̇ + sin θ = A cos Ωt (m = l = g = 1) from rest at the bottom to
    t = 100: L = ½θ̇² + cos θ with the Rayleigh dissipation R = ½γθ̇² and the driving torque
    A cos Ωt as a force. The defaults are Baker & Gollub's chaotic regime (q = 1/γ = 2,
    g = A = 1.5, ω_D = Ω = 2/3). Forced, so nothing is conserved; the energy changes by the
    tracked work ``traj.work``."""
    return get("damped_driven_pendulum", gamma=gamma, amplitude=amplitude, drive=drive)


def nbody(masses: ArrayLike, positions: ArrayLike, velocities: ArrayLike, G: float = 1.0, t_end: float = 1.0, dt: float = 1e-3) -> Scene:
    """A native gravitational N-body model in 3 dimensions from masses (N,), positions and
    velocities (N, 3)."""
    m = np.asarray(masses, dtype=float)
    x = np.asarray(positions, dtype=float)
    v = np.asarray(velocities, dtype=float)
    if m.ndim != 1 or x.shape != (len(m), 3) or v.shape != (len(m), 3):
        raise ValueError(f"positions, velocities: must have shape ({len(m)}, 3) to match masses")
    model = NativeSystem(_core.nbody(float(G), [float(mi) for mi in m]))
    p = (m[:, None] * v).ravel()
    return Scene("nbody", f"{len(m)}-body problem", model, x.ravel().copy(), p, float(t_end), float(dt))


def cartesian_pendulum() -> Scene:
    """The planar pendulum in Cartesian coordinates (x, y) on x² + y² = 1 (m = l = g = 1,
    U = gy), released from rest 2 rad from the downward vertical; RATTLE at h = 0.1 over
    T = 10⁴ is the published protocol (reference/scenes.json)."""
    return get("cartesian_pendulum")


def cartesian_spherical_pendulum() -> Scene:
    """The spherical pendulum in Cartesian coordinates on |x| = 1 from θ = 1, θ̇ = 0,
    φ̇ = 1.2 to T = 50; the reference holds the positions of the (θ, φ) reference angles, and
    L_z is conserved."""
    return get("cartesian_spherical_pendulum")


def planar_chain(links: int = 8) -> Scene:
    """A planar chain of ``links`` unit masses on unit links from the origin (g = 1), released
    from rest straight at 1 rad from the downward vertical: 2·links coordinates and ``links``
    constraints."""
    return get("planar_chain", links=links)


def rigid_body() -> Scene:
    """A rigid body about a fixed point in unit quaternions (scalar part first), I = (0.5, 0.9,
    1.0), U = q₁² − q₂² − q₃² + q₄², from q₀ = (0.4, 0.2, 0.4, 0.8) with body angular momentum
    (0.2, 1, 0.4) (HLW's rigid-body data): configuration-dependent mass on |q| = 1, integrated by
    the constrained DEL equations of ``trapezoid`` (the default) or ``midpoint``."""
    return get("rigid_body")


def bouncing_ball(g: float = 9.81, h0: float = 1.0, restitution: float = 1.0) -> Scene:
    """A ball of unit mass dropped from rest at height ``h0`` above the floor q ≥ 0 under
    gravity ``g`` (H = p²/2 + gq), with the coefficient of ``restitution`` e ∈ (0, 1]: the
    floor is ``contacts[0]``, a native wall. It hits the floor first at t₁ = √(2h₀/g), rises to
    h₀e²ᵏ after the k-th bounce, and is at the apex after the tenth at t_end, the exact
    reference (q = h₀e²⁰, p = 0). Elastic (e = 1), H = gh₀ is conserved.

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
    """A free particle of unit mass in the elliptic billiard x²/A² + y²/B² ≤ 1 (A ≥ B), from
    (x0, y0) inside with momenta (px0, py0), to t = 100: the wall is ``contacts[0]``, a native
    ellipse. Integrable: besides E = |p|²/2, the product L₁L₂ of the angular momenta about the
    foci (±c, 0), c² = A² − B², Lᵢ = (x ∓ c)p_y − y p_x, is conserved between and across the
    impacts (invariant ``"L1L2"``).

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
    return get("elliptic_billiard", a=A, b=B, x0=x0, y0=y0, px0=px0, py0=py0)


def rolling_disk(radius: float = 1.0, turn: float = 0.7, roll: float = 2.0) -> Scene:
    """A thin uniform disk (a coin) of unit mass and radius R rolling upright without slipping,
    q = (x, y, θ, φ): contact point, heading, rolling angle; L = ½(ẋ² + ẏ²) + ½Iθ̇² + ½Jφ̇²
    (I = R²/4, J = R²/2) with ẋ = Rφ̇cosθ, ẏ = Rφ̇sinθ. From θ₀ = 0.3 turning at θ̇ = ``turn``
    and rolling at φ̇ = ``roll``, to T = 100. Exact: θ̇, φ̇ and E constant, the contact point on
    the circle of radius Rφ̇/θ̇ (the reference). Conserved momenta: p_θ = Iθ̇ and p_φ = Jφ̇
    (invariants ``"p[2]"``, ``"p[3]"``); p_x and p_y are not, though L does not depend on x, y.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.rolling_disk()
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end, save_every=10)
    >>> report = varmech.check_conservation(traj)
    >>> report.verdict, [m.name for m in report.momenta], report.constraints[0].verdict
    ('conserved to round-off', ['p[2]', 'p[3]'], 'conserved to round-off')
    """
    return get("rolling_disk", radius=radius, turn=turn, roll=roll)


def chaplygin_sleigh(inertia: float = 1.0, blade: float = 1.0, spin: float = 1.0) -> Scene:
    """The Chaplygin sleigh: a body of unit mass, q = (x, y, θ) of its centre and heading, moment
    of inertia ``inertia`` about the centre, whose blade a distance b = ``blade`` behind the
    centre does not slip sideways: −ẋsinθ + ẏcosθ − bθ̇ = 0. Spinning in place at θ̇ = ``spin``
    from the origin, to T = 40, it relaxes to straight-line motion: u = U tanh κt,
    ω = ω₀ sech κt, U = √(2E), κ = bU/(I + b²) (the reference holds θ and the momenta at T).
    Energy conserved; no momentum is (the blade's force turns them all)."""
    return get("chaplygin_sleigh", inertia=inertia, blade=blade, spin=spin)


def rolling_sphere(alpha: float = 0.5, g: float = 9.81, radius: float = 1.0, vx0: float = 1.0, vy0: float = 0.3, spin: float = 1.0) -> Scene:
    """A homogeneous ball of unit mass (I = 2a²/5) rolling on a rough plane inclined at α, x
    down the slope, q = (x, y, φ, θ, ψ): its centre and ZXZ Euler angles. From the origin with
    centre velocity (vx0, vy0) and ``spin`` ω_z about the normal, to T = 1: Byerly's exact solution,
    the centre accelerating at (5/7)g sin α down the slope and moving uniformly across it, on
    a parabola (the reference holds the centre and p_x, p_y, p_φ). Conserved: E and p_φ = Iω_z
    (``"p[2]"``); p_y = ẏ by the exact motion but only to O(h²) by the discrete one, so it is
    not declared; p_x is not."""
    return get("rolling_sphere", alpha=alpha, g=g, radius=radius, vx0=vx0, vy0=vy0, spin=spin)


def ball_on_turntable(
    omega: float = 1.0, radius: float = 1.0, x0: float = 1.0, y0: float = 0.0, vx0: float = 0.0, vy0: float = 0.2, spin: float = 1.0
) -> Scene:
    """The ball of :func:`rolling_sphere` on a level table turning at Ω = ``omega`` about the
    origin: no slip relative to the table, affine constraints A(q)q̇ + b(q) = 0 with
    b = (Ωy, −Ωx). From centre (x0, y0) with velocity (vx0, vy0) and ``spin`` ω_z about the normal,
    its centre's velocity turns at ν = (2/7)Ω: it circles about r + (−ẏ, ẋ)/ν, back to its
    start at T = 14π/Ω (the reference). The table does work: E is not conserved (unless the
    circle is centred on the axis); the Jacobi integral J = E − Ω(x p_y − y p_x) is, with
    p_φ = Iω_z (invariants ``"J"``, ``"p[2]"``), the speed |ṙ| and the circle's centre."""
    return get("ball_on_turntable", omega=omega, radius=radius, x0=x0, y0=y0, vx0=vx0, vy0=vy0, spin=spin)
