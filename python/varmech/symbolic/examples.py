"""Symbolic models: a twin of every closure example of :mod:`varmech.examples` with a
Lagrangian (each the native scene's L in SymPy, with the scene's parameters as defaults),
two systems that only the symbolic path makes easy, the elastic pendulum and the bead on a
rotating hoop, and four bodies of variable mass (:class:`~varmech.symbolic.MassFlow`): the
rocket, Cayley's falling chain, the snowplough and the conveyor belt.

Each function returns a :class:`~varmech.symbolic.SymbolicModel` whose parameters are named
after its symbols: change them per run with ``model.with_parameters(...)`` or
``integrate(..., parameters={...})``. :func:`symbolic_of` gives the twin of a built-in scene.

Examples
--------
>>> import varmech
>>> from varmech import scenes
>>> from varmech.symbolic import examples
>>> scene = scenes.double_pendulum()
>>> twin = examples.symbolic_of(scene)
>>> twin.parameters
{'m1': 1.0, 'm2': 2.0, 'l1': 2.0, 'l2': 3.0, 'g': 9.80665}
>>> native = varmech.integrate(scene, dt=scene.dt, steps=100)
>>> compiled = varmech.integrate(twin, scene.q0, scene.p0, dt=scene.dt, steps=100)
>>> bool(abs(compiled.q - native.q).max() < 1e-12)
True
"""

from __future__ import annotations

import inspect
import math

import numpy as np
import sympy as sp

from .._catalogue import declared
from .._doc import documented, symbolic_doc
from ..model import Rotation
from ..scenes import CATALOGUE, LONG_RUNS, Scene
from ._constructors import lagrangian, mechanical
from ._mass_flow import MassFlow
from ._model import SymbolicModel

__all__ = [
    "cartesian_pendulum",
    "charged_particle",
    "charged_particle_nonuniform",
    "conveyor_belt",
    "damped_driven_pendulum",
    "double_pendulum",
    "elastic_pendulum",
    "elastic_pendulum_cartesian",
    "falling_chain",
    "heavy_top",
    "kepler",
    "kepler_polar",
    "rocket",
    "rotating_hoop",
    "scene",
    "snowplough",
    "spherical_pendulum",
    "symbolic_of",
]

_G = 9.80665


@symbolic_doc(
    "A general Lagrangian, n = 2.",
    parameters={
        "m1, m2": ("float, default 1.0, 2.0", "The bobs' masses."),
        "l1, l2": ("float, default 2.0, 3.0", "The rods' lengths."),
    },
)
def double_pendulum(
    m1: float = 1.0, m2: float = 2.0, l1: float = 2.0, l2: float = 3.0, g: float = _G, *, jit: bool = True
) -> SymbolicModel:
    """The planar double pendulum in its angles θ₁, θ₂ from the downward vertical (the
    Lagrangian of issue 14, word for word)::

        L = ½(m₁+m₂)l₁²θ̇₁² + ½m₂l₂²θ̇₂² + m₂l₁l₂θ̇₁θ̇₂cos(θ₁−θ₂) + (m₁+m₂)gl₁cos θ₁ + m₂gl₂cos θ₂

    with the native scene's l = (2, 3), m = (1, 2), g = 9.80665 by default. A general
    Lagrangian (its mass matrix depends on θ₁ − θ₂).

    Examples
    --------
    >>> from varmech.symbolic import examples
    >>> examples.double_pendulum(m2=1.0).parameters
    {'m1': 1.0, 'm2': 1.0, 'l1': 2.0, 'l2': 3.0, 'g': 9.80665}
    """
    q1, q2, v1, v2 = sp.symbols("q1 q2 v1 v2")
    m1_, m2_, l1_, l2_, g_ = sp.symbols("m1 m2 l1 l2 g", positive=True)
    L = (
        sp.Rational(1, 2) * (m1_ + m2_) * l1_**2 * v1**2
        + sp.Rational(1, 2) * m2_ * l2_**2 * v2**2
        + m2_ * l1_ * l2_ * v1 * v2 * sp.cos(q1 - q2)
        + (m1_ + m2_) * g_ * l1_ * sp.cos(q1)
        + m2_ * g_ * l2_ * sp.cos(q2)
    )
    parameters = {m1_: m1, m2_: m2, l1_: l1, l2_: l2, g_: g}
    return lagrangian(L, [q1, q2], [v1, v2], parameters=parameters, jit=jit, name="double_pendulum (symbolic)")


@symbolic_doc("A general Lagrangian, n = 2, φ cyclic.")
def spherical_pendulum(m: float = 1.0, l: float = 1.0, g: float = 1.0, *, jit: bool = True) -> SymbolicModel:
    """The spherical pendulum in its polar angle θ from the downward vertical and its azimuth
    φ::

        L = ½ml²(θ̇² + sin²θ φ̇²) + mgl cos θ

    (m = l = g = 1 by default). φ is cyclic: p_φ = ml² sin²θ φ̇ is conserved.

    Examples
    --------
    >>> from varmech.symbolic import examples
    >>> examples.spherical_pendulum(g=9.81).L
    g*l*m*cos(theta) + l**2*m*(v_phi**2*sin(theta)**2 + v_theta**2)/2
    """
    th, ph, vth, vph = sp.symbols("theta phi v_theta v_phi")
    m_, l_, g_ = sp.symbols("m l g", positive=True)
    L = m_ * l_**2 / 2 * (vth**2 + sp.sin(th) ** 2 * vph**2) + m_ * g_ * l_ * sp.cos(th)
    return lagrangian(
        L, [th, ph], [vth, vph], parameters={m_: m, l_: l, g_: g}, jit=jit, name="spherical_pendulum (symbolic)"
    )


@symbolic_doc(
    "A general Lagrangian, n = 3, φ and ψ cyclic.",
    parameters={"I1": "The transverse moment of inertia about the pivot."},
    see_also=["varmech.symbolic.routh : reduces it by its cyclic angles."],
)
def heavy_top(I1: float = 1.0, I3: float = 0.5, Mgl: float = 1.0, *, jit: bool = True) -> SymbolicModel:
    """The heavy symmetric top in Euler angles (θ, φ, ψ), θ from the upward vertical::

        L = ½I₁(θ̇² + sin²θ φ̇²) + ½I₃(ψ̇ + φ̇ cos θ)² − Mgl cos θ

    (I₁ = 1, I₃ = ½, Mgl = 1 by default). φ and ψ are cyclic: p_φ and p_ψ are conserved, and
    :func:`varmech.symbolic.routh` ignores them in closed form.

    Examples
    --------
    >>> from varmech.symbolic import examples
    >>> examples.heavy_top().L
    I1*(v_phi**2*sin(theta)**2 + v_theta**2)/2 + I3*(v_phi*cos(theta) + v_psi)**2/2 - Mgl*cos(theta)
    """
    th, ph, ps, vth, vph, vps = sp.symbols("theta phi psi v_theta v_phi v_psi")
    i1, i3 = sp.symbols("I1 I3", positive=True)
    mgl = sp.Symbol("Mgl")
    L = i1 / 2 * (vth**2 + sp.sin(th) ** 2 * vph**2) + i3 / 2 * (vps + vph * sp.cos(th)) ** 2 - mgl * sp.cos(th)
    return lagrangian(
        L,
        [th, ph, ps],
        [vth, vph, vps],
        parameters={i1: I1, i3: I3, mgl: Mgl},
        jit=jit,
        name="heavy_top (symbolic)",
    )


@symbolic_doc(
    "A separable mechanical system, n = 2, rotation invariant.",
    see_also=["kepler_polar : the same problem in polar coordinates."],
)
def kepler(*, jit: bool = True) -> SymbolicModel:
    """Kepler's problem in the plane as the native scene has it, the separable mechanical
    system with unit mass and no parameters::

        L = ½|q̇|² + 1/|q|,   H = |p|²/2 − 1/|q|

    rotation invariant: the angular momentum x p_y − y p_x is conserved.

    Examples
    --------
    >>> import varmech
    >>> from varmech.symbolic import examples
    >>> s = varmech.scenes.kepler()
    >>> twin = varmech.integrate(examples.kepler(), s.q0, s.p0, dt=s.dt, steps=10)
    >>> bool((twin.q == varmech.integrate(s, dt=s.dt, steps=10).q).all())
    True
    """
    x, y, vx, vy = sp.symbols("x y v_x v_y")
    return mechanical(
        -1 / sp.sqrt(x**2 + y**2),
        [x, y],
        1,
        v=[vx, vy],
        symmetries=[Rotation(spatial_dim=2)],
        jit=jit,
        name="kepler (symbolic)",
    )


@symbolic_doc("A general Lagrangian, n = 2, θ cyclic.")
def kepler_polar(m: float = 1.0, k: float = 1.0, *, jit: bool = True) -> SymbolicModel:
    """Kepler's problem in polar coordinates (r, θ)::

        L = ½m(ṙ² + r²θ̇²) + k/r

    (m = k = 1 by default). θ is cyclic: p_θ = mr²θ̇ is conserved.

    Examples
    --------
    >>> from varmech.symbolic import examples
    >>> model = examples.kepler_polar()
    >>> model.L, model.kind_name
    (k/r + m*(r**2*v_theta**2 + v_r**2)/2, 'lagrangian')
    """
    r, th, vr, vth = sp.symbols("r theta v_r v_theta")
    m_, k_ = sp.symbols("m k", positive=True)
    L = m_ / 2 * (vr**2 + r**2 * vth**2) + k_ / r
    return lagrangian(L, [r, th], [vr, vth], parameters={m_: m, k_: k}, jit=jit, name="kepler_polar (symbolic)")


@symbolic_doc(
    "A general Lagrangian (linear in the velocities), n = 2, rotation invariant.",
    parameters={
        "kappa": "Its growth κ with |q|².",
        "e": "The charge.",
    },
    see_also=["charged_particle_nonuniform : κ = 1/4."],
)
def charged_particle(
    B: float = 1.0, kappa: float = 0.0, m: float = 1.0, e: float = 1.0, *, jit: bool = True
) -> SymbolicModel:
    """A charge e of mass m in the plane, in the magnetic field B(q) = B(1 + κ|q|²) ẑ, in the
    symmetric gauge::

        L = ½m|q̇|² + e·a(|q|²)(x ẏ − y ẋ),   a(r²) = ½B(1 + κr²/2)

    (∇×A = B(q) for A = a(|q|²)(−y, x)). κ = 0 is the uniform field, in which the particle
    gyrates at Ω = eB/m. Rotation invariant: the canonical angular momentum x p_y − y p_x is
    conserved. The defaults are the native scene's (m = e = B = 1, κ = 0).

    Examples
    --------
    >>> from varmech.symbolic import examples
    >>> examples.charged_particle(B=2.0, e=-1.0).parameters
    {'B': 2.0, 'kappa': 0.0, 'm': 1.0, 'e': -1.0}
    """
    x, y, vx, vy = sp.symbols("x y v_x v_y")
    B_, kappa_, e_ = sp.symbols("B kappa e")
    m_ = sp.Symbol("m", positive=True)
    a = B_ / 2 * (1 + kappa_ * (x**2 + y**2) / 2)
    L = m_ / 2 * (vx**2 + vy**2) + e_ * a * (x * vy - y * vx)
    return lagrangian(
        L,
        [x, y],
        [vx, vy],
        parameters={B_: B, kappa_: kappa, m_: m, e_: e},
        symmetries=[Rotation(spatial_dim=2)],
        jit=jit,
        name="charged_particle (symbolic)",
    )


@symbolic_doc("As :func:`charged_particle` returns it.")
def charged_particle_nonuniform(*, jit: bool = True) -> SymbolicModel:
    """The charged particle in the native scene's non-uniform field B(q) = (1 + |q|²/4) ẑ:
    :func:`charged_particle` with B = 1, κ = ¼.

    Examples
    --------
    >>> from varmech.symbolic import examples
    >>> examples.charged_particle_nonuniform().parameters["kappa"]
    0.25
    """
    return charged_particle(kappa=0.25, jit=jit)


@symbolic_doc(
    "A forced general Lagrangian, n = 1.",
    parameters={
        "amplitude": "The torque's amplitude A.",
        "drive": ("float, default 2/3", "The driving frequency Ω."),
    },
)
def damped_driven_pendulum(
    gamma: float = 0.5,
    amplitude: float = 1.5,
    drive: float = 2.0 / 3.0,
    m: float = 1.0,
    l: float = 1.0,
    g: float = 1.0,
    *,
    jit: bool = True,
) -> SymbolicModel:
    """The damped, driven pendulum ml²θ̈ + γθ̇ + mgl sin θ = A cos Ωt::

        L = ½ml²θ̇² + mgl cos θ,   R = ½γθ̇²,   Q = A cos Ωt

    with the Rayleigh dissipation R and the driving torque Q as a force (``amplitude`` is A,
    ``drive`` is Ω). The defaults are the native scene's, Baker & Gollub's chaotic regime
    (γ = ½, A = 3/2, Ω = 2/3, m = l = g = 1).

    Examples
    --------
    >>> from varmech.symbolic import examples
    >>> examples.damped_driven_pendulum(gamma=0.0).parameters["gamma"]
    0.0
    """
    th, om, t = sp.symbols("theta omega t")
    gamma_, amplitude_, drive_ = sp.symbols("gamma amplitude drive")
    m_, l_, g_ = sp.symbols("m l g", positive=True)
    return lagrangian(
        m_ * l_**2 * om**2 / 2 + m_ * g_ * l_ * sp.cos(th),
        [th],
        [om],
        t=t,
        force=[amplitude_ * sp.cos(drive_ * t)],
        rayleigh=gamma_ * om**2 / 2,
        parameters={gamma_: gamma, amplitude_: amplitude, drive_: drive, m_: m, l_: l, g_: g},
        jit=jit,
        name="damped_driven_pendulum (symbolic)",
    )


@symbolic_doc(
    "A separable mechanical system, n = 2, with one holonomic constraint.",
    raises="Naming ``mass`` when ``m`` is not finite and positive.",
)
def cartesian_pendulum(m: float = 1.0, l: float = 1.0, g: float = 1.0, *, jit: bool = True) -> SymbolicModel:
    """The planar pendulum in Cartesian coordinates (x, y) on its circle::

        L = ½m(ẋ² + ẏ²) − mgy,   g(q) = ½(x² + y² − l²) = 0

    (m = l = g = 1 by default), integrated by ``rattle``.

    Examples
    --------
    >>> from varmech.symbolic import examples
    >>> examples.cartesian_pendulum(l=2.0).constraints
    1
    """
    x, y, vx, vy = sp.symbols("x y v_x v_y")
    m_, l_, g_ = sp.symbols("m l g", positive=True)
    return mechanical(
        m_ * g_ * y,
        [x, y],
        m_,
        v=[vx, vy],
        constraints=[(x**2 + y**2 - l_**2) / 2],
        parameters={m_: m, l_: l, g_: g},
        jit=jit,
        name="cartesian_pendulum (symbolic)",
    )


@documented(
    "A general Lagrangian, n = 2.",
    parameters={"k": "The spring's stiffness."},
    see_also=["elastic_pendulum_cartesian : the same pendulum, separable.", 'scene : its scene, ``scene("elastic_pendulum")``.'],
)
def elastic_pendulum(
    m: float = 1.0, k: float = 10.0, l0: float = 1.0, g: float = _G, *, jit: bool = True
) -> SymbolicModel:
    """The elastic (spring) pendulum: a mass m on a massless spring of stiffness k and rest
    length l₀ swinging in a vertical plane, in polar coordinates (r, θ), θ from the downward
    vertical::

        L = ½m(ṙ² + r²θ̇²) + mgr cos θ − ½k(r − l₀)²

    Its mass matrix diag(m, mr²) depends on r, so it is a general Lagrangian; nothing but the
    energy is conserved, and the motion is chaotic at large amplitude. It hangs at rest at
    r = l_eq = l₀ + mg/k, about which the small oscillations are the radial one at √(k/m) and
    the swing at √(g/l_eq). Defaults: m = 1, k = 10, l₀ = 1, g = 9.80665.

    Examples
    --------
    >>> import varmech
    >>> from varmech.symbolic import examples
    >>> model = examples.elastic_pendulum()
    >>> traj = varmech.integrate(model, [1.2, 0.5], [0.0, 0.0], dt=0.01, steps=1000, method="midpoint")
    >>> varmech.check_conservation(traj).verdict
    'bounded'
    """
    r, th, vr, vth = sp.symbols("r theta v_r v_theta")
    m_, k_, l0_, g_ = sp.symbols("m k l0 g", positive=True)
    L = m_ / 2 * (vr**2 + r**2 * vth**2) + m_ * g_ * r * sp.cos(th) - k_ / 2 * (r - l0_) ** 2
    return lagrangian(
        L,
        [r, th],
        [vr, vth],
        parameters={m_: m, k_: k, l0_: l0, g_: g},
        jit=jit,
        name="elastic_pendulum (symbolic)",
    )


@documented(
    "A separable mechanical system, n = 2.",
    parameters={"k": "The spring's stiffness."},
    raises="Naming ``mass`` when ``m`` is not finite and positive.",
    see_also=["elastic_pendulum : the same pendulum in polar coordinates."],
)
def elastic_pendulum_cartesian(
    m: float = 1.0, k: float = 10.0, l0: float = 1.0, g: float = _G, *, jit: bool = True
) -> SymbolicModel:
    """The elastic pendulum of :func:`elastic_pendulum` in the Cartesian coordinates (x, y) of
    the mass, y up from the pivot::

        L = ½m(ẋ² + ẏ²) − ½k(√(x² + y²) − l₀)² − mgy

    The same two degrees of freedom as in polar coordinates, but with a constant mass matrix:
    the model is separable, so every explicit composition applies (up to Kahan–Li's order 8),
    where the polar form takes only the implicit methods. Defaults as :func:`elastic_pendulum`.

    Examples
    --------
    >>> from varmech.symbolic import examples
    >>> examples.elastic_pendulum_cartesian().kind_name
    'separable'
    """
    x, y, vx, vy = sp.symbols("x y v_x v_y")
    m_, k_, l0_, g_ = sp.symbols("m k l0 g", positive=True)
    V = k_ / 2 * (sp.sqrt(x**2 + y**2) - l0_) ** 2 + m_ * g_ * y
    return mechanical(
        V, [x, y], m_, v=[vx, vy], parameters={m_: m, k_: k, l0_: l0, g_: g}, jit=jit,
        name="elastic_pendulum_cartesian (symbolic)",
    )


@documented(
    "A Lagrangian in t's presence, separable once simplified, n = 1.",
    parameters={
        "R": "The hoop's radius.",
        "Omega": "The hoop's rate of turn Ω.",
    },
    see_also=["varmech.symbolic.lagrangian : builds it from L(θ, θ̇, t)."],
)
def rotating_hoop(
    m: float = 1.0, R: float = 1.0, Omega: float = 5.0, g: float = _G, *, jit: bool = True
) -> SymbolicModel:
    """A bead of mass m sliding without friction on a hoop of radius R that a motor turns
    about its vertical diameter at the prescribed rate Ω, in the bead's angle θ from the
    bottom of the hoop.

    The Lagrangian is derived from the bead's inertial position at the hoop's azimuth
    φ = Ωt, r(θ, t) = R(sin θ cos Ωt, sin θ sin Ωt, −cos θ), as L = ½m|ṙ|² − mgz with
    ṙ = ∂r/∂θ θ̇ + ∂r/∂t::

        L = ½mR²(θ̇² + Ω² sin²θ) + mgR cos θ

    The explicit t of the inertial position cancels in |ṙ|² (the rotation is uniform about
    the axis of gravity), so L is autonomous and separable, L = ½mR²θ̇² − V_eff(θ) with
    V_eff = −½mR²Ω² sin²θ − mgR cos θ: its energy function, the Jacobi integral

        h = p θ̇ − L = ½mR²(θ̇² − Ω² sin²θ) − mgR cos θ,

    is conserved (it is the energy in the rotating frame), while the bead's inertial energy
    T + V = h + mR²Ω² sin²θ is not: the motor works on the bead at the rate
    d(T + V)/dt = mR²Ω² sin 2θ θ̇. For Ω² > g/R the bottom is unstable and the bead rests
    (relative to the hoop) at cos θ* = g/(RΩ²). Defaults: m = R = 1, Ω = 5, g = 9.80665.

    Examples
    --------
    >>> import math
    >>> import sympy as sp
    >>> import varmech
    >>> from varmech.symbolic import examples
    >>> model = examples.rotating_hoop()
    >>> sp.trigsimp(model.L)
    R*m*(Omega**2*R*sin(theta)**2/2 + R*omega**2/2 + g*cos(theta))
    >>> model.energy_name
    'Jacobi integral'
    >>> rest = math.acos(9.80665 / 25.0)  # cos θ* = g/(RΩ²)
    >>> traj = varmech.integrate(model, [rest], [0.0], dt=0.01, steps=1000, method="midpoint")
    >>> bool(abs(traj.q[-1, 0] - rest) < 1e-12)
    True
    """
    th, om, t = sp.symbols("theta omega t")
    m_, R_, Omega_, g_ = sp.symbols("m R Omega g", positive=True)
    position = R_ * sp.Matrix([sp.sin(th) * sp.cos(Omega_ * t), sp.sin(th) * sp.sin(Omega_ * t), -sp.cos(th)])
    velocity = position.diff(th) * om + position.diff(t)
    # Given as derived, t in it: varmech finds that t cancels (a moving frame).
    L = m_ * velocity.dot(velocity) / 2 - m_ * g_ * position[2]
    return lagrangian(
        L, [th], [om], t=t, parameters={m_: m, R_: R, Omega_: Omega, g_: g}, jit=jit, name="rotating_hoop (symbolic)"
    )


@documented(
    "A Lagrangian that depends on t, forced by the reactive force, n = 1.",
    parameters={
        "burn": "The burn rate k = −ṁ.",
        "exhaust": "The exhaust speed c relative to the rocket.",
    },
)
def rocket(
    m0: float = 10.0, burn: float = 0.4, exhaust: float = 400.0, g: float = _G, *, jit: bool = True
) -> SymbolicModel:
    """A rocket rising vertically in uniform gravity, burning its mass at a constant rate: its
    height x, its mass m(t) = m₀ − kt, its exhaust leaving at the speed c relative to it.

    L = ½m(t)ẋ² − m(t)gx, with the mass flow u = ẋ − c (:class:`~varmech.symbolic.MassFlow`):
    Meshchersky's d(mẋ)/dt = −mg + ṁu is m ẍ = −mg + kc, whose solution from (x₀, v₀) is
    Tsiolkovsky's with gravity:

        v(t) = v₀ + c ln(m₀/m(t)) − gt,
        x(t) = x₀ + v₀t + c(t + (m(t)/k) ln(m(t)/m₀)) − ½gt².

    The run stops with a :class:`~varmech.VarmechError` at the step where the mass has burnt
    out, t = m₀/k. Defaults: m₀ = 10, k = 0.4, c = 400, g = 9.80665: a thrust kc = 160 above
    the weight m₀g ≈ 98, burn-out at t = 25.

    Examples
    --------
    >>> import math
    >>> import varmech
    >>> from varmech.symbolic import examples
    >>> traj = varmech.integrate(examples.rocket(), [0.0], v0=[0.0], dt=0.01, t_end=10.0)
    >>> exact = 400.0 * math.log(10.0 / 6.0) - 9.80665 * 10.0
    >>> bool(abs(traj.v[-1, 0] - exact) < 1e-3 * exact)
    True
    """
    x, w, t = sp.symbols("x w t")
    m0_, k_, c_, g_ = sp.symbols("m0 k c g", positive=True)
    m = m0_ - k_ * t
    return lagrangian(
        m * w**2 / 2 - m * g_ * x, [x], [w], t=t, parameters={m0_: m0, k_: burn, c_: exhaust, g_: g},
        mass_flow=MassFlow(m, w - c_), jit=jit, name="rocket (symbolic)",
    )


@documented(
    "An autonomous Lagrangian forced by the reactive force, n = 1.",
    parameters={"rho": "The chain's mass per length ρ."},
)
def falling_chain(rho: float = 1.0, g: float = _G, *, jit: bool = True) -> SymbolicModel:
    """Cayley's falling chain: a chain heaped at the edge of a hole falls through it, its
    hanging part (length x, mass ρx) picking up links at rest from the heap.

    L = ½ρxẋ² + ½ρgx², with the mass flow u = 0 (the links join from rest): Meshchersky's
    d(ρxẋ)/dt = ρgx. From rest at x₀ (Cayley 1857)

        ẋ² = (2g/3)(x³ − x₀³)/x²,

    and the acceleration tends to g/3, not g. The energy E = ½ρxẋ² − ½ρgx² is not conserved:
    each link's pickup is an inelastic collision, and E − E₀ balances the reactive force's work
    −∫½ρẋ³ dt, which the run tracks (``traj.work``). The chain needs x₀ > 0 (no mass hangs at
    x = 0). Defaults: ρ = 1, g = 9.80665.

    Examples
    --------
    >>> import math
    >>> import varmech
    >>> from varmech.symbolic import examples
    >>> traj = varmech.integrate(examples.falling_chain(), [0.1], v0=[0.0], dt=0.001, t_end=1.0)
    >>> x, v = traj.q[-1, 0], traj.v[-1, 0]
    >>> bool(abs(v**2 - 2 * 9.80665 / 3 * (x**3 - 0.1**3) / x**2) < 1e-4)
    True
    """
    x, w = sp.symbols("x w")
    rho_, g_ = sp.symbols("rho g", positive=True)
    return lagrangian(
        rho_ * x * w**2 / 2 + rho_ * g_ * x**2 / 2, [x], [w], parameters={rho_: rho, g_: g},
        mass_flow=MassFlow(rho_ * x, 0), jit=jit, name="falling_chain (symbolic)",
    )


@documented(
    "An autonomous Lagrangian forced by the reactive force, n = 1.",
    parameters={
        "m0": "The plough's own mass m₀.",
        "rho": "The snow's mass per length ρ.",
    },
)
def snowplough(m0: float = 1.0, rho: float = 0.5, push: float = 0.0, *, jit: bool = True) -> SymbolicModel:
    """A snowplough of mass m₀ driven by a constant force F into snow of mass ρ per length at
    rest, which it gathers: at x its mass is m₀ + ρx.

    L = ½(m₀ + ρx)ẋ² + Fx, with the mass flow u = 0: d((m₀ + ρx)ẋ)/dt = F, so the momentum
    P = (m₀ + ρx)ẋ grows as P₀ + Ft (conserved when F = 0, a plough coasting), and

        m₀x + ½ρx² = P₀t + ½Ft²,   x(t) = (√(m₀² + 2ρ(P₀t + ½Ft²)) − m₀)/ρ   from x = 0.

    The kinetic energy is not conserved even coasting: gathering the snow is inelastic.
    Defaults: m₀ = 1, ρ = 0.5, F = 0.

    Examples
    --------
    >>> import varmech
    >>> from varmech.symbolic import examples
    >>> traj = varmech.integrate(examples.snowplough(), [0.0], v0=[2.0], dt=0.01, t_end=5.0)
    >>> P = (1.0 + 0.5 * traj.q[:, 0]) * traj.v[:, 0]   # coasting: P = m₀v₀ = 2
    >>> bool(abs(P - 2.0).max() < 1e-12)
    True
    """
    x, w = sp.symbols("x w")
    m0_, rho_, F_ = sp.symbols("m0 rho F")
    m = m0_ + rho_ * x
    return lagrangian(
        m * w**2 / 2 + F_ * x, [x], [w], parameters={m0_: m0, rho_: rho, F_: push},
        mass_flow=MassFlow(m, 0), jit=jit, name="snowplough (symbolic)",
    )


@documented(
    "A Lagrangian that depends on t, forced by the reactive force, n = 1.",
    parameters={
        "m0": "The belt's own mass m₀.",
        "rate": "The rate k at which sand falls on it.",
    },
)
def conveyor_belt(m0: float = 1.0, rate: float = 0.2, push: float = 0.2, *, jit: bool = True) -> SymbolicModel:
    """A conveyor belt of mass m₀ onto which sand falls vertically at the rate k (so that the
    mass it carries is m₀ + kt), driven along by a constant force F; its position x.

    L = ½(m₀ + kt)ẋ² + Fx, with the mass flow u = 0 (the sand has no horizontal velocity):
    d((m₀ + kt)ẋ)/dt = F, so

        v(t) = (m₀v₀ + Ft)/(m₀ + kt).

    With F = kv₀ the belt keeps its speed v₀: the force's power Fv₀ = kv₀² is twice the rate
    ½kv₀² at which the kinetic energy grows, the other half lost as the sand is brought up to
    speed (the energy balance carries it as −∂L/∂t = −½kẋ²). Defaults: m₀ = 1, k = 0.2,
    F = 0.2 (a belt at v₀ = 1 keeps its speed).

    Examples
    --------
    >>> import varmech
    >>> from varmech.symbolic import examples
    >>> traj = varmech.integrate(examples.conveyor_belt(), [0.0], v0=[1.0], dt=0.01, t_end=10.0)
    >>> bool(abs(traj.v[:, 0] - 1.0).max() < 1e-12)
    True
    """
    x, w, t = sp.symbols("x w t")
    m0_, k_, F_ = sp.symbols("m0 k F")
    m = m0_ + k_ * t
    return lagrangian(
        m * w**2 / 2 + F_ * x, [x], [w], t=t, parameters={m0_: m0, k_: rate, F_: push},
        mass_flow=MassFlow(m, 0), jit=jit, name="conveyor_belt (symbolic)",
    )


def symbolic_of(scene: Scene, *, jit: bool = True) -> SymbolicModel:
    """The symbolic twin of a built-in scene (declared with it, :mod:`varmech._catalogue`): the
    function of this module with the scene's name, at the scene's parameters (a catalogue parameter is passed on when the twin has a
    keyword of that name, compared without case — the charged particle's ``b`` is ``B``; the
    others, such as Kepler's eccentricity ``e``, set the initial state, not the model).

    Parameters
    ----------
    scene : Scene
        A scene of :mod:`varmech.scenes`.
    jit : bool, default True
        Compile the model's tapes (Cranelift), or interpret them.

    Returns
    -------
    SymbolicModel
        The symbolic model of the scene's Lagrangian at its parameters.

    Raises
    ------
    ValueError
        Naming ``scene`` for a scene without a symbolic twin.

    See Also
    --------
    varmech.examples.closure_of : the closure twin.

    Examples
    --------
    >>> import varmech
    >>> from varmech.symbolic import examples
    >>> examples.symbolic_of(varmech.scenes.kepler_polar()).parameters
    {'m': 1.0, 'k': 1.0}
    >>> examples.symbolic_of(varmech.scenes.pendulum())
    Traceback (most recent call last):
    ...
    ValueError: scene: 'pendulum' has no symbolic twin in varmech.symbolic.examples
    """
    if scene.name not in CATALOGUE or not declared(scene.name).symbolic:
        raise ValueError(f"scene: {scene.name!r} has no symbolic twin in varmech.symbolic.examples")
    twin = globals()[scene.name]
    keywords = {name.lower(): name for name in inspect.signature(twin).parameters if name != "jit"}
    given = {keywords[name.lower()]: value for name, value in scene.parameters.items() if name.lower() in keywords}
    return twin(**given, jit=jit)


def _elastic_pendulum_scene() -> Scene:
    # Released from rest 0.6 off the vertical, with the spring stretched to 1.5: a large swing
    # whose radial and angular motions exchange energy.
    model = elastic_pendulum_cartesian()
    return Scene(
        "elastic_pendulum",
        "elastic (spring) pendulum in Cartesian coordinates, a large swing: separable, chaotic",
        model,
        np.array([1.5 * math.sin(0.6), -1.5 * math.cos(0.6)]),
        np.zeros(2),
        t_end=1000.0,
        # Resolves the fastest (radial) period 2π/√10 ≈ 2 with 40 steps.
        dt=0.05,
        parameters=model.parameters,
        long_runs=LONG_RUNS,
    )


#: The symbolic scenes by name (their names are :data:`varmech.scenes.SYMBOLIC`): models with
#: initial data and a horizon, as the built-in scenes, for the measurement tools and charts.
_SCENES = {"elastic_pendulum": _elastic_pendulum_scene}


def scene(name: str) -> Scene:
    """The symbolic scene called ``name`` (one of :data:`varmech.scenes.SYMBOLIC`): a compiled
    model with its initial state and horizon, which :func:`varmech.scenes.get`, the
    measurement tools and ``python -m varmech chart`` take as they take a built-in scene.

    Parameters
    ----------
    name : str
        One of :data:`varmech.scenes.SYMBOLIC`.

    Returns
    -------
    Scene
        The compiled model with its initial state, horizon and step.

    Raises
    ------
    ValueError
        Naming ``name`` for another name.

    See Also
    --------
    varmech.scenes.get : the built-in scenes, and these by name.

    Examples
    --------
    >>> from varmech.symbolic import examples
    >>> s = examples.scene("elastic_pendulum")
    >>> s.dt, s.t_end, s.model.kind_name
    (0.05, 1000.0, 'separable')
    """
    if name not in _SCENES:
        raise ValueError(f"name: unknown symbolic scene {name!r}; choose from {', '.join(_SCENES)}")
    return _SCENES[name]()
