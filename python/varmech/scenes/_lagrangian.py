"""The built-in scenes of general Lagrangians L(q, q̇, t): mass matrices that depend on q, magnetic
terms linear in q̇, and forces."""

from __future__ import annotations

from .._doc import scene_doc
from ._scene import Scene, get

__all__ = [
    "charged_particle",
    "charged_particle_nonuniform",
    "damped_driven_pendulum",
    "double_pendulum",
    "heavy_top",
    "kepler_polar",
    "spherical_pendulum",
]


@scene_doc('A native general Lagrangian (n = 2), with step h = 0.01, invariant ``"E"`` and the reference at T = 10.')
def double_pendulum() -> Scene:
    """The planar double pendulum in its two angles, a Lagrangian with configuration-dependent mass.

    L = ½(m₁ + m₂)l₁²θ̇₁² + ½m₂l₂²θ̇₂² + m₂l₁l₂θ̇₁θ̇₂cos(θ₁ − θ₂) + (m₁ + m₂)gl₁cos θ₁ +
    m₂gl₂cos θ₂ with l = (2, 3), m = (1, 2), g = 9.80665, from θ = (π/4, π/2),
    θ̇ = (0, π/8) to T = 10, against the reference of GeometricProblems.jl (accurate to about
    1e-11). A general Lagrangian: integrate it with ``midpoint`` (the default) or
    ``trapezoid``.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.double_pendulum()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> round(float(traj.energy()[-1]), 2), traj.method
    (-40.22, 'midpoint')
    """
    return get("double_pendulum")


@scene_doc(
    'A native general Lagrangian (n = 2) with the symmetry ``Cyclic(1)``, step h = 0.01, invariants ``"E"`` '
    'and ``"p_phi"``, and the reference at T = 50.',
    see_also=[
        "cartesian_spherical_pendulum : the same pendulum in (x, y, z) on the unit sphere.",
        "varmech.routh : the pendulum reduced by its cyclic φ.",
    ],
)
def spherical_pendulum() -> Scene:
    """The spherical pendulum in (θ, φ), θ from the downward vertical (m = l = g = 1).

    L = ½(θ̇² + sin²θ φ̇²) + cos θ, from θ = 1, θ̇ = 0, φ̇ = 1.2 to T = 50 against the
    reference angles of ``reference/scenes.json`` (the reference gives the angles only, so its
    p_θ is NaN). The azimuth φ is cyclic: p_φ = sin²θ φ̇ is conserved.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.spherical_pendulum()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> round(float(traj.p[-1, 1]), 12) == round(scene.invariants["p_phi"], 12)
    True
    """
    return get("spherical_pendulum")


@scene_doc(
    'A native general Lagrangian (n = 3) with the symmetries ``Cyclic(1)`` and ``Cyclic(2)``, step h = 0.01, '
    'and invariants ``"E"``, ``"p_phi"`` and ``"p_psi"``.',
    see_also=["varmech.routh : the top reduced to θ alone."],
    references=["H. Goldstein, C. Poole and J. Safko, *Classical Mechanics*, 3rd ed., Addison-Wesley, 2002, Sec. 5.7."],
)
def heavy_top() -> Scene:
    """The heavy symmetric top in Euler angles (θ, φ, ψ), θ from the upward vertical.

    L = ½I₁(θ̇² + sin²θ φ̇²) + ½I₃(ψ̇ + φ̇ cos θ)² − Mgl cos θ [1]_ with I₁ = 1, I₃ = ½,
    Mgl = 1. A fast top (p_ψ² = 6.25 > 4I₁Mgl) released at θ = 0.3 with θ̇ = φ̇ = 0 and
    ψ̇ = 5, to T = 50: it nutates in cusps between the turning points θ = 0.3 and
    0.4794748702… The angles φ and ψ are cyclic: p_φ and p_ψ are conserved. No reference state.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.heavy_top()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> round(float(traj.energy()[-1]), 6), round(float(traj.p[-1, 2]), 12)
    (7.205336, 2.5)
    """
    return get("heavy_top")


@scene_doc(
    'A native general Lagrangian (n = 2) with the symmetry ``Cyclic(1)``, step h = 2π/200 (up to e = 0.6; '
    '2π/200·((1 − e)/0.4)^(3/2) beyond), invariants ``"E"`` = −1/2 and ``"p_theta"``, and the exact '
    'reference.',
    parameters={"e": "The eccentricity, in [0, 1)."},
    raises="``e`` not in [0, 1).",
    see_also=["kepler : the same orbit in Cartesian coordinates."],
)
def kepler_polar(e: float = 0.6) -> Scene:
    """Kepler's problem in polar coordinates (r, θ): L = ½(ṙ² + r²θ̇²) + 1/r.

    The orbit of :func:`kepler` from the pericentre r = 1 − e, θ = 0, over 200 periods of 2π,
    against the exact reference r = 1 − e, θ = 400π, p = (0, √(1 − e²)). A general Lagrangian
    whose angle θ is cyclic: p_θ = r²θ̇ is conserved.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.kepler_polar(e=0.6)
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=200)
    >>> round(float(traj.p[-1, 1]), 14)
    0.8
    """
    return get("kepler_polar", e=e)


@scene_doc(
    'A native general Lagrangian (n = 2) with the symmetry :class:`~varmech.Rotation`, step h = 0.05, '
    'invariants ``"E"`` and ``"L"``, and the exact reference at t = 10.',
    parameters={"B": "The field strength (any finite value; 0 is a free particle)."},
    raises="``B`` not finite.",
    see_also=["charged_particle_nonuniform : the same charge in a field that varies."],
)
def charged_particle(B: float = 1.0) -> Scene:
    """A unit charge of unit mass in the plane, in the uniform magnetic field B ẑ.

    In the symmetric gauge, L = ½|q̇|² + (B/2)(x ẏ − y ẋ). From q = (1, 0), q̇ = (0, −B) it
    gyrates on the unit circle at Ω = B, the exact solution at t = 10. A general Lagrangian,
    rotation invariant: the energy ½|q̇|² and the canonical angular momentum
    x p_y − y p_x are conserved.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.charged_particle(B=2.0)
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> round(float(traj.energy()[-1]), 12)
    2.0
    """
    return get("charged_particle", B=B)


@scene_doc(
    'A native general Lagrangian (n = 2) with the symmetry :class:`~varmech.Rotation`, step h = 0.05, and '
    'invariants ``"E"`` and ``"L"``.',
    see_also=["charged_particle : the uniform field, with an exact solution."],
)
def charged_particle_nonuniform() -> Scene:
    """A unit charge of unit mass in the plane, in the field B(q) = (1 + |q|²/4) ẑ.

    In the symmetric gauge (the closure example of the user guide's models page),
    L = ½|q̇|² + A(q)·q̇ with A(q) = ½(1 + |q|²/8)(−y, x). From q = (1, 0), q̇ = (0, −1)
    to t = 200 it gyrates and drifts about the origin. Rotation invariant: the energy and the
    canonical angular momentum are conserved. No reference state.

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


@scene_doc(
    "A native, forced general Lagrangian (n = 1), with step h = 0.01 and no invariants.",
    parameters={
        "gamma": "The damping coefficient γ ≥ 0.",
        "amplitude": "The amplitude A of the driving torque (finite).",
        "drive": ("float, default 2/3", "The driving frequency Ω (finite)."),
    },
    raises="``gamma`` negative or not finite, or ``amplitude`` or ``drive`` not finite.",
    references=["G. L. Baker and J. P. Gollub, *Chaotic Dynamics: An Introduction*, 2nd ed., Cambridge University "
        "Press, 1996."],
)
def damped_driven_pendulum(gamma: float = 0.5, amplitude: float = 1.5, drive: float = 2.0 / 3.0) -> Scene:
    """The damped, driven pendulum θ̈ + γθ̇ + sin θ = A cos Ωt (m = l = g = 1).

    L = ½θ̇² + cos θ with the Rayleigh dissipation R = ½γθ̇² and the driving torque A cos Ωt
    as a force, from rest at the bottom to t = 100. The defaults are Baker & Gollub's chaotic
    regime [1]_ (their q = 1/γ = 2, g = A = 1.5, ω_D = Ω = 2/3). Forced, so nothing is
    conserved: the energy changes by the work ``traj.work`` of the forces, E − E₀ = W.

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
