"""Symbolic twins of native scenes, shared by the symbolic tests: each the scene's Lagrangian in
SymPy with the scene's parameters (read off ``varmech.scenes`` and ``rust/core/src/scenes``)."""

import sympy as sp

import varmech
import varmech.symbolic as symbolic

Q1, Q2, V1, V2 = sp.symbols("q1 q2 v1 v2")
M1, M2, L1, L2, G = sp.symbols("m1 m2 l1 l2 g", positive=True)
#: The double pendulum of issue 14, word for word.
DOUBLE_PENDULUM = (
    sp.Rational(1, 2) * (M1 + M2) * L1**2 * V1**2
    + sp.Rational(1, 2) * M2 * L2**2 * V2**2
    + M2 * L1 * L2 * V1 * V2 * sp.cos(Q1 - Q2)
    + (M1 + M2) * G * L1 * sp.cos(Q1)
    + M2 * G * L2 * sp.cos(Q2)
)
#: scenes.double_pendulum: l = (2, 3), m = (1, 2), g = 9.80665.
DOUBLE_PENDULUM_PARAMETERS = {M1: 1.0, M2: 2.0, L1: 2.0, L2: 3.0, G: 9.80665}


def double_pendulum(parameters=DOUBLE_PENDULUM_PARAMETERS, **options):
    return symbolic.lagrangian(DOUBLE_PENDULUM, q=[Q1, Q2], v=[V1, V2], parameters=parameters, **options)


def kepler():
    """scenes.kepler: H = |p|²/2 − 1/|q| in the plane, rotation invariant."""
    x, y, vx, vy = sp.symbols("x y v_x v_y")
    return symbolic.mechanical(
        -1 / sp.sqrt(x**2 + y**2), [x, y], 1, v=[vx, vy], symmetries=[varmech.Rotation(spatial_dim=2)]
    )


def heavy_top():
    """scenes.heavy_top: L = ½I₁(θ̇² + sin²θ φ̇²) + ½I₃(ψ̇ + φ̇ cos θ)² − Mgl cos θ, I₁ = 1,
    I₃ = ½, Mgl = 1."""
    th, ph, ps, vth, vph, vps = sp.symbols("theta phi psi v_theta v_phi v_psi")
    i1, i3, mgl = sp.symbols("I1 I3 Mgl", positive=True)
    L = i1 / 2 * (vth**2 + sp.sin(th) ** 2 * vph**2) + i3 / 2 * (vps + vph * sp.cos(th)) ** 2 - mgl * sp.cos(th)
    return symbolic.lagrangian(L, [th, ph, ps], [vth, vph, vps], parameters={i1: 1.0, i3: 0.5, mgl: 1.0})


def cartesian_pendulum():
    """scenes.cartesian_pendulum: V = mgy on g(q) = ½(x² + y² − l²), m = l = g = 1."""
    x, y, vx, vy = sp.symbols("x y v_x v_y")
    m, l, g = sp.symbols("m l g", positive=True)
    return symbolic.mechanical(
        m * g * y,
        [x, y],
        m,
        v=[vx, vy],
        constraints=[(x**2 + y**2 - l**2) / 2],
        parameters={m: 1.0, l: 1.0, g: 1.0},
    )


def damped_driven_pendulum():
    """scenes.damped_driven_pendulum: L = ½θ̇² + cos θ, R = ½γθ̇², Q = A cos Ωt."""
    th, om, t = sp.symbols("theta omega t")
    gamma, A, W = sp.symbols("gamma A Omega")
    return symbolic.lagrangian(
        om**2 / 2 + sp.cos(th),
        [th],
        [om],
        t=t,
        force=[A * sp.cos(W * t)],
        rayleigh=gamma * om**2 / 2,
        parameters={gamma: 0.5, A: 1.5, W: 2.0 / 3.0},
    )


#: The twin of each scene by the scene's name.
TWINS = {
    "double_pendulum": double_pendulum,
    "kepler": kepler,
    "heavy_top": heavy_top,
    "cartesian_pendulum": cartesian_pendulum,
    "damped_driven_pendulum": damped_driven_pendulum,
}
