"""Closure (NumPy) versions of the built-in scenes.

Each is an example of a :class:`~varmech.MechanicalSystem` written in Python, and each computes
the same formulas as its native scene, so the tests and benchmarks use them to check and time
the closure path against the native one.
"""

from __future__ import annotations

import math

import numpy as np

from ._catalogue import declared
from ._doc import closure_doc
from .model import Cyclic, Lagrangian, MechanicalSystem, Rotation, Translation
from .scenes import CATALOGUE, Scene

__all__ = [
    "ball_on_turntable",
    "bouncing_ball",
    "cartesian_pendulum",
    "chaplygin_sleigh",
    "charged_particle",
    "charged_particle_nonuniform",
    "closure_of",
    "damped_driven_pendulum",
    "double_pendulum",
    "elliptic_billiard",
    "fermi_pasta_ulam",
    "harmonic_oscillator",
    "heavy_top",
    "henon_heiles",
    "kepler",
    "kepler_polar",
    "nbody",
    "pendulum",
    "rigid_body",
    "rolling_disk",
    "rolling_sphere",
    "spherical_pendulum",
]


@closure_doc("n = 1, with V and ∇V as NumPy closures.", parameters={"omega": "The angular frequency ω."})
def harmonic_oscillator(omega: float = 1.0) -> MechanicalSystem:
    """The harmonic oscillator H = p²/2 + ω²q²/2 as a separable closure model.

    Examples
    --------
    >>> from varmech import examples, integrate
    >>> traj = integrate(examples.harmonic_oscillator(2.0), [1.0], [0.0], dt=0.01, steps=100)
    >>> round(float(traj.energy()[-1]), 3)
    2.0
    """
    w2 = omega * omega
    return MechanicalSystem(1, lambda q: 0.5 * w2 * q[0] * q[0], lambda q: w2 * q, name="harmonic_oscillator (closure)")


@closure_doc("n = 1, with V = −cos q and ∇V = sin q.")
def pendulum() -> MechanicalSystem:
    """The pendulum H = p²/2 − cos q as a separable closure model.

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.pendulum()
    >>> twin = integrate(examples.pendulum(), s.q0, s.p0, dt=s.dt, steps=10)
    >>> bool((twin.q == integrate(s, dt=s.dt, steps=10).q).all())
    True
    """
    return MechanicalSystem(1, lambda q: -math.cos(q[0]), np.sin, name="pendulum (closure)")


@closure_doc(
    "n = 2, with the symmetry ``Rotation(spatial_dim=2)`` (angular momentum).",
    see_also=["varmech.examples.kepler_polar : the same problem in polar coordinates."],
)
def kepler() -> MechanicalSystem:
    """Kepler's problem H = |p|²/2 − 1/|q| in the plane as a closure model, rotation invariant.

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.kepler()
    >>> traj = integrate(examples.kepler(), s.q0, s.p0, dt=s.dt, steps=100)
    >>> round(float(traj.q[-1, 0] * traj.p[-1, 1] - traj.q[-1, 1] * traj.p[-1, 0]), 12), s.invariants["L"]
    (0.8, 0.8)
    """
    def potential(q: np.ndarray) -> float:
        return -1.0 / math.hypot(q[0], q[1])

    def gradient(q: np.ndarray) -> np.ndarray:
        r2 = q[0] * q[0] + q[1] * q[1]
        return q * (1.0 / (r2 * math.sqrt(r2)))

    return MechanicalSystem(2, potential, gradient, symmetries=[Rotation(spatial_dim=2)], name="kepler (closure)")


@closure_doc("n = 2, separable.")
def henon_heiles() -> MechanicalSystem:
    """The Hénon–Heiles potential V = (x² + y²)/2 + x²y − y³/3 as a closure model.

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.henon_heiles()
    >>> traj = integrate(examples.henon_heiles(), s.q0, s.p0, dt=0.01, steps=1000)
    >>> round(float(traj.energy()[-1]), 4), s.invariants["H"]
    (0.13, 0.13)
    """
    def potential(q: np.ndarray) -> float:
        x, y = q
        return 0.5 * (x * x + y * y) + x * x * y - y * y * y / 3.0

    def gradient(q: np.ndarray) -> np.ndarray:
        x, y = q
        return np.array([x + 2.0 * x * y, y + x * x - y * y])

    return MechanicalSystem(2, potential, gradient, name="henon_heiles (closure)")


@closure_doc(
    "n = 2m.",
    parameters={
        "m": "The number of stiff springs; the chain has 2m masses.",
        "omega": "The stiff springs' frequency ω.",
    },
    raises="Naming ``m`` when below 1.",
)
def fermi_pasta_ulam(m: int = 3, omega: float = 50.0) -> MechanicalSystem:
    """The Fermi–Pasta–Ulam chain: m stiff linear springs of frequency ω alternating with soft
    quartic ones, fixed ends, as a closure model with the springs vectorised.

    Examples
    --------
    >>> from varmech import examples
    >>> examples.fermi_pasta_ulam(m=2).dim
    4
    """
    if m < 1:
        raise ValueError(f"m: must be at least 1, got {m}")

    def springs(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        stiff = q[1::2] - q[0::2]
        ends = np.concatenate(([0.0], q, [0.0]))
        soft = ends[1::2] - ends[0::2]
        return stiff, soft

    def potential(q: np.ndarray) -> float:
        stiff, soft = springs(q)
        return 0.25 * omega * omega * float(stiff @ stiff) + float(np.sum(soft**4))

    def gradient(q: np.ndarray) -> np.ndarray:
        stiff, soft = springs(q)
        g = np.zeros(2 * m)
        d = 0.5 * omega * omega * stiff
        g[1::2] += d
        g[0::2] -= d
        f = 4.0 * soft**3
        g[0::2] += f[:-1]
        g[1::2] -= f[1:]
        return g

    return MechanicalSystem(2 * m, potential, gradient, name="fermi_pasta_ulam (closure)")


@closure_doc(
    "n = 3N, mass diag(m₁, m₁, m₁, m₂, …), with the three translations and the three rotations as symmetries.",
    parameters={
        "G": "The gravitational constant.",
        "masses": ("array_like, shape (N,)", "The bodies' masses."),
    },
    raises="Naming ``mass`` for a mass that is not finite and positive.",
    see_also=["varmech.scenes.nbody : the native N-body scene it twins."],
)
def nbody(G: float, masses: np.ndarray) -> MechanicalSystem:
    """The gravitational N-body problem in 3 dimensions, V = −Σ G mᵢmⱼ/|qᵢ − qⱼ|, vectorised
    over the pairs.

    Examples
    --------
    >>> from varmech import examples
    >>> model = examples.nbody(1.0, [1.0, 1e-3])
    >>> model.dim, model.separable
    (6, True)
    """
    m = np.asarray(masses, dtype=float)
    n = len(m)
    i, j = np.triu_indices(n, 1)
    gmm = G * m[i] * m[j]

    def potential(q: np.ndarray) -> float:
        x = q.reshape(n, 3)
        d = x[i] - x[j]
        return -float(np.sum(gmm / np.sqrt(np.einsum("ij,ij->i", d, d))))

    def gradient(q: np.ndarray) -> np.ndarray:
        x = q.reshape(n, 3)
        d = x[i] - x[j]
        r2 = np.einsum("ij,ij->i", d, d)
        f = (gmm / (r2 * np.sqrt(r2)))[:, None] * d
        g = np.zeros((n, 3))
        np.add.at(g, i, f)
        np.add.at(g, j, -f)
        return g.ravel()

    symmetries = [Translation(a) for a in range(3)] + [Rotation(a) for a in range(3)]
    return MechanicalSystem(3 * n, potential, gradient, mass=np.repeat(m, 3), symmetries=symmetries, name="nbody (closure)")


@closure_doc(
    "n = 2, with ∂L/∂q, ∂L/∂v and the three Hessians as closures.",
    parameters={
        "m1, m2": ("float, default 1.0, 2.0", "The bobs' masses."),
        "l1, l2": ("float, default 2.0, 3.0", "The rods' lengths."),
    },
)
def double_pendulum(m1: float = 1.0, m2: float = 2.0, l1: float = 2.0, l2: float = 3.0, g: float = 9.80665) -> Lagrangian:
    """The planar double pendulum in its two angles as a general Lagrangian with exact first and
    second derivatives.

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.double_pendulum()
    >>> traj = integrate(examples.double_pendulum(), s.q0, s.p0, dt=0.001, steps=100)
    >>> round(float(traj.energy()[-1]), 3), round(s.invariants["E"], 3)
    (-40.218, -40.218)
    """

    def mass(q: np.ndarray) -> np.ndarray:
        c = m2 * l1 * l2 * math.cos(q[0] - q[1])
        return np.array([[(m1 + m2) * l1 * l1, c], [c, m2 * l2 * l2]])

    def lagrangian(q: np.ndarray, v: np.ndarray, t: float) -> float:
        potential = -(m1 + m2) * g * l1 * math.cos(q[0]) - m2 * g * l2 * math.cos(q[1])
        return 0.5 * float(v @ mass(q) @ v) - potential

    def dl_dq(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        k = m2 * l1 * l2 * v[0] * v[1] * math.sin(q[0] - q[1])
        return np.array([-k - (m1 + m2) * g * l1 * math.sin(q[0]), k - m2 * g * l2 * math.sin(q[1])])

    def dl_dv(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        return mass(q) @ v

    def hessians(q: np.ndarray, v: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        k = m2 * l1 * l2
        s, c = math.sin(q[0] - q[1]), math.cos(q[0] - q[1])
        w = k * v[0] * v[1] * c
        lqq = np.array([[-w - (m1 + m2) * g * l1 * math.cos(q[0]), w], [w, -w - m2 * g * l2 * math.cos(q[1])]])
        lqv = k * s * np.array([[-v[1], -v[0]], [v[1], v[0]]])
        return lqq, lqv, mass(q)

    return Lagrangian(2, lagrangian, dl_dq=dl_dq, dl_dv=dl_dv, hessians=hessians, name="double_pendulum (closure)")


@closure_doc("n = 2, with the symmetry ``Cyclic(1)`` (the momentum p_φ).", parameters={"m": "The bob's mass."})
def spherical_pendulum(m: float = 1.0, l: float = 1.0, g: float = 1.0) -> Lagrangian:
    """The spherical pendulum in (θ, φ) as a general Lagrangian; φ is cyclic.

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.spherical_pendulum()
    >>> traj = integrate(examples.spherical_pendulum(), s.q0, s.p0, dt=s.dt, steps=100)
    >>> bool(abs(traj.p[-1, 1] - s.invariants["p_phi"]) < 1e-12)
    True
    """
    ml2 = m * l * l

    def lagrangian(q: np.ndarray, v: np.ndarray, t: float) -> float:
        s = math.sin(q[0])
        return 0.5 * ml2 * (v[0] ** 2 + s * s * v[1] ** 2) + m * g * l * math.cos(q[0])

    def dl_dq(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        s, c = math.sin(q[0]), math.cos(q[0])
        return np.array([ml2 * s * c * v[1] ** 2 - m * g * l * s, 0.0])

    def dl_dv(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        s = math.sin(q[0])
        return np.array([ml2 * v[0], ml2 * s * s * v[1]])

    def hessians(q: np.ndarray, v: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, c = math.sin(q[0]), math.cos(q[0])
        qq = np.array([[ml2 * (c * c - s * s) * v[1] ** 2 - m * g * l * c, 0.0], [0.0, 0.0]])
        qv = np.array([[0.0, 2.0 * ml2 * s * c * v[1]], [0.0, 0.0]])
        return qq, qv, np.diag([ml2, ml2 * s * s])

    return Lagrangian(
        2, lagrangian, dl_dq=dl_dq, dl_dv=dl_dv, hessians=hessians, symmetries=[Cyclic(1)], name="spherical_pendulum (closure)"
    )


@closure_doc(
    "n = 3, with the symmetries ``Cyclic(1)`` and ``Cyclic(2)``.",
    parameters={"i1": "The moment of inertia about a transverse axis through the pivot."},
)
def heavy_top(i1: float = 1.0, i3: float = 0.5, mgl: float = 1.0) -> Lagrangian:
    """The heavy symmetric top in Euler angles (θ, φ, ψ), θ from the upward vertical, as a
    general Lagrangian with exact first and second derivatives; φ and ψ are cyclic.

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.heavy_top()
    >>> twin = integrate(examples.heavy_top(), s.q0, s.p0, dt=s.dt, steps=10)
    >>> bool(abs(twin.q - integrate(s, dt=s.dt, steps=10).q).max() < 1e-12)
    True
    """

    def lagrangian(q: np.ndarray, v: np.ndarray, t: float) -> float:
        s, c = math.sin(q[0]), math.cos(q[0])
        spin = v[2] + v[1] * c
        return 0.5 * i1 * (v[0] ** 2 + s * s * v[1] ** 2) + 0.5 * i3 * spin**2 - mgl * c

    def dl_dq(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        s, c = math.sin(q[0]), math.cos(q[0])
        spin = v[2] + v[1] * c
        return np.array([s * (i1 * v[1] ** 2 * c - i3 * spin * v[1] + mgl), 0.0, 0.0])

    def dl_dv(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        s, c = math.sin(q[0]), math.cos(q[0])
        p_psi = i3 * (v[2] + v[1] * c)
        return np.array([i1 * v[0], i1 * s * s * v[1] + p_psi * c, p_psi])

    def hessians(q: np.ndarray, v: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, c = math.sin(q[0]), math.cos(q[0])
        spin = v[2] + v[1] * c
        lqq = np.zeros((3, 3))
        lqq[0, 0] = i1 * v[1] ** 2 * (c * c - s * s) + i3 * v[1] ** 2 * s * s - i3 * spin * v[1] * c + mgl * c
        lqv = np.zeros((3, 3))
        lqv[0, 1] = 2 * i1 * s * c * v[1] - i3 * s * (spin + v[1] * c)
        lqv[0, 2] = -i3 * s * v[1]
        lvv = np.array([[i1, 0.0, 0.0], [0.0, i1 * s * s + i3 * c * c, i3 * c], [0.0, i3 * c, i3]])
        return lqq, lqv, lvv

    return Lagrangian(
        3, lagrangian, dl_dq=dl_dq, dl_dv=dl_dv, hessians=hessians, symmetries=[Cyclic(1), Cyclic(2)],
        name="heavy_top (closure)",
    )


@closure_doc("n = 2, with the symmetry ``Cyclic(1)`` (the angular momentum p_θ).")
def kepler_polar(m: float = 1.0, k: float = 1.0) -> Lagrangian:
    """Kepler's problem in polar coordinates (r, θ), L = ½m(ṙ² + r²θ̇²) + k/r, as a general
    Lagrangian with exact first and second derivatives; θ is cyclic.

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.kepler_polar()
    >>> traj = integrate(examples.kepler_polar(), s.q0, s.p0, dt=s.dt, steps=100)
    >>> round(float(traj.p[-1, 1]), 12), s.invariants["p_theta"]
    (0.8, 0.8)
    """

    def lagrangian(q: np.ndarray, v: np.ndarray, t: float) -> float:
        return 0.5 * m * (v[0] ** 2 + q[0] ** 2 * v[1] ** 2) + k / q[0]

    def dl_dq(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        return np.array([m * q[0] * v[1] ** 2 - k / q[0] ** 2, 0.0])

    def dl_dv(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        return np.array([m * v[0], m * q[0] ** 2 * v[1]])

    def hessians(q: np.ndarray, v: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r = q[0]
        lqq = np.array([[m * v[1] ** 2 + 2 * k / r**3, 0.0], [0.0, 0.0]])
        lqv = np.array([[0.0, 2 * m * r * v[1]], [0.0, 0.0]])
        return lqq, lqv, np.diag([m, m * r * r])

    return Lagrangian(2, lagrangian, dl_dq=dl_dq, dl_dv=dl_dv, hessians=hessians, symmetries=[Cyclic(1)], name="kepler_polar (closure)")


@closure_doc("n = 2, rotation invariant.", see_also=["charged_particle_nonuniform : κ = 1/4."])
def charged_particle(B: float = 1.0, kappa: float = 0.0) -> Lagrangian:
    """A unit charge of unit mass in the plane, in the field B(q) = B(1 + κ|q|²) ẑ, in the
    symmetric gauge: L = ½|v|² + a(|q|²)(x v_y − y v_x) with a(r²) = ½B(1 + κr²/2).

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.charged_particle()
    >>> traj = integrate(examples.charged_particle(), s.q0, s.p0, dt=s.dt, steps=100)
    >>> round(float(traj.energy()[-1]), 12), s.invariants["E"]
    (0.5, 0.5)
    """

    def gauge(q: np.ndarray) -> tuple[float, float]:
        c = 0.5 * B
        return c * (1.0 + 0.5 * kappa * (q[0] * q[0] + q[1] * q[1])), 0.5 * c * kappa

    def lagrangian(q: np.ndarray, v: np.ndarray, t: float) -> float:
        a, _ = gauge(q)
        return 0.5 * (v[0] * v[0] + v[1] * v[1]) + a * (q[0] * v[1] - q[1] * v[0])

    def dl_dq(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        a, da = gauge(q)
        w = 2.0 * da * (q[0] * v[1] - q[1] * v[0])
        return np.array([a * v[1] + w * q[0], -a * v[0] + w * q[1]])

    def dl_dv(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        a, _ = gauge(q)
        return np.array([v[0] - a * q[1], v[1] + a * q[0]])

    return Lagrangian(2, lagrangian, dl_dq=dl_dq, dl_dv=dl_dv, symmetries=[Rotation(spatial_dim=2)], name="charged_particle (closure)")


@closure_doc("n = 2, rotation invariant.")
def charged_particle_nonuniform() -> Lagrangian:
    """The charged particle in the native scene's non-uniform field B(q) = (1 + |q|²/4) ẑ:
    :func:`charged_particle` with B = 1, κ = 1/4.

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.charged_particle_nonuniform()
    >>> twin = integrate(examples.charged_particle_nonuniform(), s.q0, s.p0, dt=s.dt, steps=10)
    >>> bool(abs(twin.p - integrate(s, dt=s.dt, steps=10).p).max() < 1e-12)
    True
    """
    return charged_particle(kappa=0.25)


@closure_doc(
    "n = 1, forced: its energy is not conserved but balanced against the work done.",
    parameters={"drive": ("float, default 2/3", "The driving frequency Ω.")},
)
def damped_driven_pendulum(gamma: float = 0.5, amplitude: float = 1.5, drive: float = 2.0 / 3.0) -> Lagrangian:
    """The damped, driven pendulum θ̈ + γθ̇ + sin θ = A cos Ωt: L = ½θ̇² + cos θ, the Rayleigh
    dissipation ½γθ̇² and the driving torque as a force.

    Examples
    --------
    >>> from varmech import examples
    >>> examples.damped_driven_pendulum().forced
    True
    """
    return Lagrangian(
        1,
        lambda q, v, t: 0.5 * v[0] ** 2 + math.cos(q[0]),
        dl_dq=lambda q, v, t: np.array([-math.sin(q[0])]),
        dl_dv=lambda q, v, t: v.copy(),
        force=lambda q, v, t: np.array([amplitude * math.cos(drive * t)]),
        rayleigh=gamma,
        name="damped_driven_pendulum (closure)",
    )


@closure_doc(
    "n = 2 with one holonomic constraint.",
    parameters={"m": "The bob's mass."},
    raises="Naming ``mass`` when ``m`` is not finite and positive.",
)
def cartesian_pendulum(m: float = 1.0, l: float = 1.0, g: float = 1.0) -> MechanicalSystem:
    """The planar pendulum in Cartesian coordinates (x, y): V = mgy on the constraint
    g(q) = ½(x² + y² − l²) = 0.

    Examples
    --------
    >>> import numpy as np
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.cartesian_pendulum()
    >>> traj = integrate(examples.cartesian_pendulum(), s.q0, s.p0, dt=s.dt, steps=100)
    >>> round(float(np.hypot(*traj.q[-1])), 12)
    1.0
    """
    return MechanicalSystem(
        2,
        lambda q: m * g * q[1],
        lambda q: np.array([0.0, m * g]),
        mass=m,
        constraints=lambda q: np.array([0.5 * (q @ q - l * l)]),
        constraint_jacobian=lambda q: q.reshape(1, 2),
        constraint_count=1,
        name="cartesian_pendulum (closure)",
    )


def _e(q: np.ndarray) -> np.ndarray:
    """E(q) (3 × 4) with the body angular velocity ω = 2E(q)q̇, scalar part first."""
    s, v = q[0], q[1:]
    cross = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.column_stack([-v, s * np.eye(3) - cross])


@closure_doc(
    "n = 4 with a configuration-dependent mass and the constraint |q|² = 1.",
    parameters={"inertia": ("tuple of 3 float, default (0.5, 0.9, 1.0)", "The principal moments of inertia I.")},
)
def rigid_body(inertia: tuple[float, float, float] = (0.5, 0.9, 1.0)) -> MechanicalSystem:
    """The free rigid body in unit quaternions as a natural system on |q| = 1:
    M(q) = 4EᵀIE + αqqᵀ (α = 4 tr I/3 fills the direction q, which the constraint freezes),
    U = q₁² − q₂² − q₃² + q₄².

    Examples
    --------
    >>> import numpy as np
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.rigid_body()
    >>> traj = integrate(examples.rigid_body(), s.q0, s.p0, dt=s.dt, steps=20)
    >>> round(float(np.linalg.norm(traj.q[-1])), 12)
    1.0
    """
    i = np.diag(inertia)
    alpha = 4.0 * sum(inertia) / 3.0
    sign = np.array([1.0, -1.0, -1.0, 1.0])

    def mass(q: np.ndarray) -> np.ndarray:
        e = _e(q)
        return 4.0 * e.T @ i @ e + alpha * np.outer(q, q)

    def mass_derivative(q: np.ndarray) -> np.ndarray:
        e = _e(q)
        parts = []
        for k in range(4):
            ek, unit = _e(np.eye(4)[k]), np.eye(4)[k]
            parts.append(4.0 * (ek.T @ i @ e + e.T @ i @ ek) + alpha * (np.outer(unit, q) + np.outer(q, unit)))
        return np.array(parts)

    return MechanicalSystem(
        4,
        lambda q: float(sign @ (q * q)),
        lambda q: 2.0 * sign * q,
        mass=mass,
        mass_derivative=mass_derivative,
        constraints=lambda q: np.array([0.5 * (q @ q - 1.0)]),
        constraint_jacobian=lambda q: q.reshape(1, 4),
        constraint_count=1,
        name="rigid_body (closure)",
    )


@closure_doc("n = 1, without the floor.")
def bouncing_ball(g: float = 9.81) -> MechanicalSystem:
    """The ball above its floor, H = p²/2 + gq; the floor q = 0 is a contact, which in the closure
    twin is ``Contact(lambda q: q[0], lambda q: [1.0])``.

    Examples
    --------
    >>> from varmech import Contact, examples, integrate, scenes
    >>> s = scenes.bouncing_ball()
    >>> floor = Contact(lambda q: q[0], lambda q: [1.0])
    >>> traj = integrate(examples.bouncing_ball(), s.q0, s.p0, dt=0.01, t_end=2.0, contacts=[floor])
    >>> bool(traj.q.min() > -1e-15), round(float(traj.energy()[-1]), 2), s.invariants["H"]   # above the floor to round-off
    (True, 9.81, 9.81)
    """
    return MechanicalSystem(1, lambda q: g * q[0], lambda q: np.array([g]), name="bouncing_ball (closure)")


@closure_doc("n = 2, without the table's wall.")
def elliptic_billiard() -> MechanicalSystem:
    """The elliptic billiard's free particle, H = |p|²/2; the table x²/A² + y²/B² ≤ 1 is a
    contact (:class:`varmech.surfaces.Ellipsoid`).

    Examples
    --------
    >>> from varmech import examples
    >>> model = examples.elliptic_billiard()
    >>> model.dim, model.separable
    (2, True)
    """
    return MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2), name="elliptic_billiard (closure)")


@closure_doc(
    "n = 4 with two velocity (nonholonomic) constraints.",
    parameters={"radius": "The disk's radius R."},
    raises="Naming ``mass`` when ``radius`` is 0.",
)
def rolling_disk(radius: float = 1.0) -> MechanicalSystem:
    """The vertical disk of radius R rolling on a plane, q = (x, y, θ, φ), mass
    diag(1, 1, R²/4, R²/2), with ẋ = Rφ̇cosθ, ẏ = Rφ̇sinθ as velocity constraints.

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.rolling_disk()
    >>> traj = integrate(examples.rolling_disk(), s.q0, s.p0, dt=s.dt, steps=100)
    >>> round(float(traj.energy()[-1]), 12), s.invariants["E"]
    (3.06125, 3.06125)
    """
    r2 = radius * radius

    def rolling(q: np.ndarray) -> np.ndarray:
        s, c = math.sin(q[2]), math.cos(q[2])
        return np.array([[1.0, 0.0, 0.0, -radius * c], [0.0, 1.0, 0.0, -radius * s]])

    return MechanicalSystem(
        4, lambda q: 0.0, lambda q: np.zeros(4), mass=np.array([1.0, 1.0, 0.25 * r2, 0.5 * r2]),
        velocity_constraints=rolling, velocity_constraint_count=2, symmetries=[Cyclic(2), Cyclic(3)],
        name="rolling_disk (closure)",
    )


@closure_doc(
    "n = 3 with one velocity constraint.",
    raises="Naming ``mass`` when ``inertia`` is not finite and positive.",
)
def chaplygin_sleigh(inertia: float = 1.0, blade: float = 1.0) -> MechanicalSystem:
    """The Chaplygin sleigh, q = (x, y, θ), mass diag(1, 1, I), its blade b behind the centre:
    −ẋ sin θ + ẏ cos θ − bθ̇ = 0.

    Examples
    --------
    >>> from varmech import examples
    >>> model = examples.chaplygin_sleigh()
    >>> model.dim, model.velocity_constraints
    (3, 1)
    """

    def no_slip(q: np.ndarray) -> np.ndarray:
        return np.array([[-math.sin(q[2]), math.cos(q[2]), -blade]])

    return MechanicalSystem(
        3, lambda q: 0.0, lambda q: np.zeros(3), mass=np.array([1.0, 1.0, inertia]),
        velocity_constraints=no_slip, velocity_constraint_count=1, name="chaplygin_sleigh (closure)",
    )


@closure_doc(
    "n = 5 with two velocity constraints and the symmetry ``Cyclic(2)``.",
    parameters={
        "omega": "The table's rate of turn Ω.",
        "name": 'The model\'s name, less " (closure)".',
    },
    see_also=["ball_on_turntable : the level turning table."],
)
def rolling_sphere(alpha: float = 0.5, g: float = 9.81, radius: float = 1.0, omega: float = 0.0, name: str = "rolling_sphere") -> Lagrangian:
    """The ball (unit mass, I = 2a²/5) rolling on a rough plane inclined at α, or on a level table
    turning at Ω, q = (x, y, φ, θ, ψ) in ZXZ Euler angles:
    L = ½(ẋ² + ẏ²) + ½I(φ̇² + θ̇² + ψ̇² + 2φ̇ψ̇cosθ) + g sinα x, with
    ẋ − aω_y + Ωy = 0, ẏ + aω_x − Ωx = 0 (affine for Ω ≠ 0).

    Examples
    --------
    >>> from varmech import examples, integrate, scenes
    >>> s = scenes.rolling_sphere()
    >>> traj = integrate(examples.rolling_sphere(), s.q0, s.p0, dt=s.dt, steps=100)
    >>> round(float(traj.energy()[-1]), 3), round(s.invariants["E"], 3)
    (0.963, 0.963)
    """
    inertia, slope = 0.4 * radius * radius, g * math.sin(alpha)

    def lagrangian(q: np.ndarray, v: np.ndarray, t: float) -> float:
        spin = v[2] * v[2] + v[3] * v[3] + v[4] * v[4] + 2.0 * v[2] * v[4] * math.cos(q[3])
        return 0.5 * (v[0] * v[0] + v[1] * v[1]) + 0.5 * inertia * spin + slope * q[0]

    def dl_dq(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        return np.array([slope, 0.0, 0.0, -(inertia * v[2] * v[4] * math.sin(q[3])), 0.0])

    def dl_dv(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        c = math.cos(q[3])
        return np.array([v[0], v[1], inertia * (v[2] + v[4] * c), inertia * v[3], inertia * (v[4] + v[2] * c)])

    def contact(q: np.ndarray) -> np.ndarray:
        sp, cp, st = math.sin(q[2]), math.cos(q[2]), math.sin(q[3])
        return np.array([[1.0, 0.0, 0.0, -radius * sp, radius * (st * cp)], [0.0, 1.0, 0.0, radius * cp, radius * (st * sp)]])

    def table(q: np.ndarray) -> np.ndarray:
        return np.array([omega * q[1], -(omega * q[0])])

    return Lagrangian(
        5, lagrangian, dl_dq=dl_dq, dl_dv=dl_dv, velocity_constraints=contact, velocity_constraint_count=2,
        velocity_constraint_offset=table if omega != 0.0 else None, symmetries=[Cyclic(2)], name=f"{name} (closure)",
    )


@closure_doc("n = 5 with two affine velocity constraints.", parameters={"omega": "The table's rate of turn Ω."})
def ball_on_turntable(omega: float = 1.0, radius: float = 1.0) -> Lagrangian:
    """The ball of :func:`rolling_sphere` on a level table turning at Ω: its velocity
    constraints are affine, so the table does work and the energy is not conserved.

    Examples
    --------
    >>> from varmech import examples, scenes
    >>> examples.ball_on_turntable().affine, scenes.ball_on_turntable().model.affine
    (True, True)
    """
    return rolling_sphere(alpha=0.0, radius=radius, omega=omega, name="ball_on_turntable")


def closure_of(scene: Scene) -> MechanicalSystem | Lagrangian:
    """The closure twin of a built-in scene (declared with it, :mod:`varmech._catalogue`): the
    function of this module with the scene's name, at its default parameters (an N-body scene's twin has the scene's G and masses).

    Parameters
    ----------
    scene : Scene
        A scene of :mod:`varmech.scenes`.

    Returns
    -------
    MechanicalSystem or Lagrangian
        The closure model that computes the scene's formulas.

    Raises
    ------
    ValueError
        Naming ``scene`` for a scene without a twin here.

    See Also
    --------
    varmech.symbolic.examples.symbolic_of : the symbolic twin.

    Examples
    --------
    >>> from varmech import examples, scenes
    >>> examples.closure_of(scenes.outer_solar_system()).dim
    18
    >>> examples.closure_of(scenes.planar_chain())
    Traceback (most recent call last):
    ...
    ValueError: scene: 'planar_chain' has no closure twin in varmech.examples
    """
    gravity = getattr(scene.model._core, "gravity", None)
    if gravity is not None:
        return nbody(*gravity)
    if scene.name not in CATALOGUE or not declared(scene.name).closure:
        raise ValueError(f"scene: {scene.name!r} has no closure twin in varmech.examples")
    return globals()[scene.name]()
