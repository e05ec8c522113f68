"""The built-in scenes of separable Hamiltonians H = T(p) + V(q): the oscillators, Kepler's
problem, Hénon–Heiles, the Fermi–Pasta–Ulam chain and the gravitational N-body problems."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .. import _core
from .._doc import hlw, scene_doc
from .._util import floats, positive
from ..model import NativeSystem
from ._scene import Scene, get

__all__ = [
    "fermi_pasta_ulam",
    "harmonic_oscillator",
    "henon_heiles",
    "kepler",
    "nbody",
    "outer_solar_system",
    "pendulum",
]


@scene_doc(
    'A separable native model (n = 1), with step h = 0.1, invariant ``"H"`` = 1/2 and the exact reference at '
    't = 10.',
    parameters={"omega": "The angular frequency ω > 0, in inverse time units."},
    raises="``omega`` not finite and positive.",
    see_also=["varmech.analysis.stability.growth_factor : the methods' linear stability on this equation."],
)
def harmonic_oscillator(omega: float = 1.0) -> Scene:
    """The harmonic oscillator H = p²/2 + ω²q²/2, the linear test equation q̈ = −ω²q.

    From (q, p) = (0, 1) to t = 10, against the exact solution q = sin(ωt)/ω, p = cos ωt.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.harmonic_oscillator(omega=2.0)
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> round(float(traj.energy()[-1]), 2), traj.method
    (0.5, 'verlet')
    """
    return get("harmonic_oscillator", omega=omega)


@scene_doc(
    'A separable native model (n = 1), with invariant ``"H"`` and the reference at t = 2π.',
    see_also=["cartesian_pendulum : the same pendulum in (x, y) on a constraint."],
    references=[hlw("I.1")],
)
def pendulum() -> Scene:
    """The mathematical pendulum H = p²/2 − cos q in its angle q from the downward vertical.

    Hairer, Lubich & Wanner's protocol [1]_ (g/l = 1, unit mass): from (q, p) = (0, 1), H = −1/2,
    to t = 2π, against the reference state of the GNI test codes.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.pendulum()
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> round(float(traj.energy()[-1]), 3), scene.invariants["H"]
    (-0.5, -0.5)
    """
    return get("pendulum")


@scene_doc(
    'A separable native model (n = 2) with the symmetry :class:`~varmech.Rotation` (in the plane), step h = '
    '2π/200 (up to e = 0.6; beyond, shorter as the pericentre passage, 2π/200·((1 − e)/0.4)^(3/2)), '
    'invariants ``"H"`` = −1/2 and ``"L"``, and the exact reference (the pericentre again at t = 400π).',
    parameters={"e": "The eccentricity, in [0, 1)."},
    raises="``e`` not in [0, 1).",
    see_also=["kepler_polar : the same orbit in polar coordinates."],
    references=[hlw("I.2")],
)
def kepler(e: float = 0.6) -> Scene:
    """The Kepler problem H = |p|²/2 − 1/|q| in the plane, q = (x, y).

    Hairer, Lubich & Wanner's work–precision protocol [1]_: from the pericentre q = (1 − e, 0),
    p = (0, √((1 + e)/(1 − e))), an orbit of semi-major axis 1 and period 2π, over 200 periods.
    Rotation invariant: the angular momentum L = x p_y − y p_x = √(1 − e²) is conserved.

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


@scene_doc(
    'A separable native model (n = 2), with step h = 0.1 and invariant ``"H"`` = 0.13.',
    see_also=["varmech.poincare_section : its sections, the classic picture of its chaos."],
    references=['M. Hénon and C. Heiles, "The applicability of the third integral of motion: some numerical '
        'experiments", *Astron. J.* 69 (1964) 73–79; Hairer, Lubich & Wanner, *Geometric Numerical '
        'Integration*, 2nd ed., Springer, 2006, Sec. I.3.'],
)
def henon_heiles() -> Scene:
    """The Hénon–Heiles system H = (p₁² + p₂²)/2 + (q₁² + q₂²)/2 + q₁²q₂ − q₂³/3.

    Orbits are bounded below the escape energy 1/6 and chaotic in part of the energy shell
    near it [1]_. The long-run protocol of the SciML benchmarks: from q = (0.1, 0), p = (0, 0.5),
    H = 0.13, to t = 5·10⁴, with no reference state (the energy is the invariant to check).

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.henon_heiles()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=1000)
    >>> round(float(traj.energy()[-1]), 3)
    0.13
    """
    return get("henon_heiles")


@scene_doc(
    'A separable native model (n = 6), with step h = 0.001 and invariants ``"H"`` and ``"I"`` = 1.',
    references=[hlw("I.5")],
)
def fermi_pasta_ulam() -> Scene:
    """The Fermi–Pasta–Ulam chain of Hairer, Lubich & Wanner [1]_: stiff and soft springs.

    2m unit masses in a chain with fixed ends, stiff linear springs (frequency ω) alternating
    with soft quartic ones, H = Σpᵢ²/2 + (ω²/4)Σᵢ₌₁ᵐ(q₂ᵢ − q₂ᵢ₋₁)² + Σᵢ₌₀ᵐ(q₂ᵢ₊₁ − q₂ᵢ)⁴ with
    q₀ = q₂ₘ₊₁ = 0; m = 3 and ω = 50, from the first stiff spring excited, H₀ = 2.00120008, to
    t = 200. The total oscillatory energy I of the stiff springs is an adiabatic invariant.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.fermi_pasta_ulam()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=1000)
    >>> round(float(traj.energy()[-1]), 2)
    2.0
    """
    return get("fermi_pasta_ulam")


@scene_doc(
    'A native N-body model (n = 18) with translation and rotation symmetries (total linear and angular '
    'momentum), step h = 50 days, invariant ``"H"`` and the reference; its ``time_unit`` is ``"days"``.',
    see_also=["nbody : any gravitational N-body problem."],
    references=[hlw("I.2.4")],
)
def outer_solar_system() -> Scene:
    """The outer solar system of Hairer, Lubich & Wanner [1]_ as a gravitational 6-body problem.

    The Sun (with the inner planets' masses), Jupiter, Saturn, Uranus, Neptune and Pluto in
    3 dimensions, H = Σ|pᵢ|²/2mᵢ − G Σ_{i<j} mᵢmⱼ/|qᵢ − qⱼ|, in AU, days and solar
    masses, over 500 000 days against the reference state of the GNI test codes
    (``reference/outer_solar_system.json``).

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


@scene_doc(
    "The model with its initial state, horizon and step; no invariants or reference.",
    parameters={
        "masses": ("array_like, shape (N,)", "The masses, finite and positive; at least two bodies."),
        "positions, velocities": ("array_like, shape (N, 3)", "The initial positions and velocities (finite); the momenta are pᵢ = mᵢvᵢ."),
        "G": "The gravitational constant, positive.",
        "t_end": "The scene's horizon, positive.",
        "dt": ("float, default 1e-3", "The scene's step, positive."),
    },
    raises="Naming the argument: shapes that do not match ``masses``, masses not finite and positive (or fewer "
        "than two), positions or velocities not finite, or ``G``, ``t_end`` or ``dt`` not finite and "
        "positive.",
    see_also=["outer_solar_system : the outer planets."],
)
def nbody(masses: ArrayLike, positions: ArrayLike, velocities: ArrayLike, G: float = 1.0, t_end: float = 1.0, dt: float = 1e-3) -> Scene:
    """A native gravitational N-body model in 3 dimensions from masses (N,), positions and
    velocities (N, 3).

    H = Σᵢ |pᵢ|²/2mᵢ − G Σ_{i<j} mᵢmⱼ/|qᵢ − qⱼ| in the coordinates of the bodies, one after
    the other (n = 3N); evaluated in O(N) memory, so that 10⁵ bodies fit. The model declares
    the translations and rotations (total linear and angular momentum).

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
