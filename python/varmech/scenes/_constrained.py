"""The built-in scenes on constraints: holonomic ones g(q) = 0 (pendulums and a chain in Cartesian
coordinates, the rigid body in quaternions), contacts φ(q) ≥ 0 (a bouncing ball, a billiard) and
velocity constraints (rolling without slipping, a skate's blade)."""

from __future__ import annotations

from .._doc import FETECAU, bloch, hlw, scene_doc
from ._scene import Scene, get

__all__ = [
    "ball_on_turntable",
    "bouncing_ball",
    "cartesian_pendulum",
    "cartesian_spherical_pendulum",
    "chaplygin_sleigh",
    "elliptic_billiard",
    "planar_chain",
    "rigid_body",
    "rolling_disk",
    "rolling_sphere",
]


@scene_doc(
    'A native constrained separable model (n = 2, one constraint), with step h = 0.1 and invariant ``"H"``; '
    'integrated by ``rattle`` by default.',
    see_also=["pendulum : the same pendulum in its angle."],
    references=[hlw("VII.1")],
)
def cartesian_pendulum() -> Scene:
    """The planar pendulum in Cartesian coordinates (x, y) on the constraint x² + y² = 1.

    L = ½(ẋ² + ẏ²) − gy with g = 1 (m = l = 1), subject to g(q) = x² + y² − 1 = 0, released
    from rest 2 rad from the downward vertical: a constrained mechanical system as in Hairer,
    Lubich & Wanner [1]_. RATTLE at h = 0.1 over T = 10⁴ is its protocol
    (``reference/scenes.json``). Its exact solution is the pendulum's.

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


@scene_doc(
    'A native constrained separable model (n = 3, one constraint) with the symmetry '
    ':class:`~varmech.Rotation` about z, step h = 0.01, invariants ``"H"`` and ``"L_z"``, and the reference '
    'at T = 50.',
    see_also=["spherical_pendulum : the same pendulum in its angles."],
)
def cartesian_spherical_pendulum() -> Scene:
    """The spherical pendulum in Cartesian coordinates on |x| = 1 (m = l = g = 1).

    L = ½|ẋ|² − z on g(x) = |x|² − 1 = 0, from θ = 1, θ̇ = 0, φ̇ = 1.2 (θ from the
    downward vertical) to T = 50: the initial state of :func:`spherical_pendulum`. The
    reference holds the positions of that scene's reference angles; the angular momentum
    L_z = x p_y − y p_x about the vertical is conserved.

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


@scene_doc(
    "A native constrained separable model (n = 2·links), with step h = 0.01; integrated by ``rattle`` by "
    "default.",
    parameters={"links": "The number of links, at least 1."},
    raises="``links`` not a whole number, or below 1.",
)
def planar_chain(links: int = 8) -> Scene:
    """A planar chain of ``links`` unit masses on unit links hanging from the origin (g = 1).

    L = ½Σ|ẋᵢ|² − Σyᵢ in the positions xᵢ = (xᵢ, yᵢ) of the masses, subject to
    |x₁|² = 1 and |xᵢ − xᵢ₋₁|² = 1: 2·links coordinates and ``links`` constraints.
    Released from rest straight at 1 rad from the downward vertical, to t = 100. No reference
    state; the energy is the invariant to check.

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


@scene_doc(
    "A native constrained general Lagrangian (n = 4, one constraint), with step h = 0.01.",
    references=[hlw("VII.5")],
)
def rigid_body() -> Scene:
    """A rigid body about a fixed point in unit quaternions, Hairer, Lubich & Wanner's example [1]_.

    q = (q₁, q₂, q₃, q₄), scalar part first, on the constraint |q|² = 1; principal moments
    I = (0.5, 0.9, 1.0) and the potential U = q₁² − q₂² − q₃² + q₄², from q = (0.4, 0.2, 0.4,
    0.8) with body angular momentum (0.2, 1, 0.4), to t = 10. The kinetic energy's mass
    depends on q, so its discrete Euler–Lagrange equations are solved with the constraint by
    ``trapezoid`` (the default) or ``midpoint``.

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


@scene_doc(
    'A separable native model (n = 1) with its floor in ``contacts``, the exact reference at the last apex, '
    'and invariant ``"H"``.',
    parameters={
        "g": "The gravitational acceleration, positive.",
        "h0": "The height of the drop, positive.",
        "restitution": "The coefficient of restitution e, in (0, 1] (1: elastic).",
    },
    raises="``g`` or ``h0`` not finite and positive, or ``restitution`` not in (0, 1].",
    see_also=["varmech.Contact.wall : the floor."],
    references=[FETECAU],
)
def bouncing_ball(g: float = 9.81, h0: float = 1.0, restitution: float = 1.0) -> Scene:
    """A ball of unit mass dropped on a floor, H = p²/2 + gq with the contact q ≥ 0.

    Dropped from rest at height ``h0`` under gravity ``g``, with the coefficient of
    ``restitution`` e: the floor is ``contacts[0]``, a native wall. It hits the floor first at
    t₁ = √(2h₀/g), rises to h₀e²ᵏ after the k-th bounce, and is at the apex after the K-th at
    t_end, the exact reference (q = h₀e²ᴷ, p = 0) [1]_: K = 10, or fewer for a small e, where
    the flights would shrink below 10⁻⁴ of the first sooner (K ≤ ln 10⁻⁴ / ln e: 3 at e = 0.05),
    so that ``dt``, which resolves the shortest flight, still reaches t_end in a few 10⁵ steps.
    Elastic (e = 1), H = gh₀ is conserved.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.bouncing_ball(restitution=0.9)
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> len(traj.events[0]), round(float(traj.q[-1, 0]), 6) == round(0.9**20, 6)
    (10, True)
    """
    return get("bouncing_ball", g=g, h0=h0, restitution=restitution)


@scene_doc(
    'A separable native model (n = 2) with its wall in ``contacts`` and invariants ``"E"`` and ``"L1L2"``; '
    'no reference state.',
    parameters={
        "A, B": "The semi-axes, A ≥ B > 0 (the foci on the x axis).",
        "x0, y0": "The initial position, strictly inside the table.",
        "px0, py0": "The initial momenta (finite).",
    },
    raises="``B`` not finite and positive, ``A`` below ``B``, a start value not finite (naming it), or (x0, y0) "
        "not strictly inside (naming ``x0``).",
    see_also=["varmech.Contact.ellipsoid : the wall."],
    references=[FETECAU],
)
def elliptic_billiard(A: float = 2.0, B: float = 1.0, x0: float = 0.3, y0: float = 0.1, px0: float = 0.6, py0: float = 0.8) -> Scene:
    """A free particle of unit mass in the elliptic billiard x²/A² + y²/B² ≤ 1, H = |p|²/2.

    From (x0, y0) inside with momenta (px0, py0), to t = 100: the wall is ``contacts[0]``, a
    native ellipse, with elastic impacts. Integrable: besides E, the product L₁L₂ of the
    angular momenta about the foci (±c, 0), c² = A² − B², Lᵢ = (x ∓ c)p_y − y p_x, is
    conserved between and across the impacts [1]_ (it fixes the orbit's confocal caustic).

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


@scene_doc(
    'A native nonholonomic model (n = 4, two velocity constraints) with the symmetries ``Cyclic(2)`` and '
    '``Cyclic(3)``, invariants ``"E"``, ``"p[2]"`` and ``"p[3]"``, and the exact reference at T = 100.',
    parameters={
        "radius": "The disk's radius R, positive.",
        "turn": "The turning rate θ̇, non-zero.",
        "roll": "The rolling rate φ̇ (finite).",
    },
    raises="``radius`` not finite and positive, ``turn`` zero or not finite, or ``roll`` not finite.",
)
def rolling_disk(radius: float = 1.0, turn: float = 0.7, roll: float = 2.0) -> Scene:
    """A thin uniform disk (a coin) of unit mass rolling upright without slipping.

    q = (x, y, θ, φ): contact point, heading, rolling angle; L = ½(ẋ² + ẏ²) + ½Iθ̇² + ½Jφ̇²
    (I = R²/4, J = R²/2) with the velocity constraints ẋ = Rφ̇cosθ, ẏ = Rφ̇sinθ. From
    θ₀ = 0.3 turning at θ̇ = ``turn`` and rolling at φ̇ = ``roll``, to T = 100. Exact: θ̇, φ̇
    and E constant, the contact point on the circle of radius Rφ̇/θ̇ (the reference). Conserved
    momenta: p_θ = Iθ̇ and p_φ = Jφ̇; p_x and p_y are not, though L does not depend on x, y.

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


@scene_doc(
    'A native nonholonomic model (n = 3, one velocity constraint), with step h = 0.01, invariant ``"E"`` and '
    'the closed-form reference at T = 40.',
    parameters={
        "inertia": "The moment of inertia I about the centre, positive.",
        "blade": "The distance b of the blade behind the centre, positive.",
        "spin": "The initial spin ω₀ (finite).",
    },
    raises="``inertia`` or ``blade`` not finite and positive, or ``spin`` not finite.",
    references=[bloch("1.7")],
)
def chaplygin_sleigh(inertia: float = 1.0, blade: float = 1.0, spin: float = 1.0) -> Scene:
    """The Chaplygin sleigh: a body of unit mass on a blade that does not slip sideways.

    q = (x, y, θ) of its centre and heading, L = ½(ẋ² + ẏ²) + ½Iθ̇² with the moment of
    inertia I about the centre; the blade, a distance b behind the centre, gives the velocity
    constraint −ẋ sin θ + ẏ cos θ − bθ̇ = 0 [1]_. Spinning in place at θ̇ = ω₀ from the origin,
    to T = 40, it relaxes to straight-line motion: u = U tanh κt, ω = ω₀ sech κt, U = √(2E),
    κ = bU/(I + b²) (the reference holds θ and the momenta at T). Energy conserved; no
    momentum is (the blade's force turns them all).

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.chaplygin_sleigh()
    >>> traj = varmech.integrate(scene, dt=scene.dt, steps=100)
    >>> round(float(traj.energy()[-1]), 5)
    1.0
    """
    return get("chaplygin_sleigh", inertia=inertia, blade=blade, spin=spin)


@scene_doc(
    "A native nonholonomic model (n = 5) with the symmetry ``Cyclic(2)``, step h = 0.01, invariants ``\"E\"`` "
    "and ``\"p[2]\"``, and Byerly's exact reference at T = 1.",
    parameters={
        "alpha": "The inclination α in radians, in [0, π/2).",
        "g": "The gravitational acceleration (finite).",
        "radius": "The ball's radius a, positive.",
        "vx0, vy0": "The initial velocity of the centre, down and across the slope.",
    },
    raises="``alpha`` not in [0, π/2), ``radius`` not finite and positive, or ``g``, ``vx0``, ``vy0`` or "
        "``spin`` not finite (naming it).",
    see_also=["ball_on_turntable : the same ball on a turning table."],
    references=["W. E. Byerly, *An Introduction to the Use of Generalized Coordinates in Mechanics and Physics*, "
        "Ginn, 1916, ch. I."],
)
def rolling_sphere(alpha: float = 0.5, g: float = 9.81, radius: float = 1.0, vx0: float = 1.0, vy0: float = 0.3, spin: float = 1.0) -> Scene:
    """A homogeneous ball of unit mass rolling on a rough plane inclined at α, Byerly's problem [1]_.

    q = (x, y, φ, θ, ψ): its centre (x down the slope) and ZXZ Euler angles; I = 2a²/5 for the
    radius a, L = ½(ẋ² + ẏ²) + ½I(φ̇² + θ̇² + ψ̇² + 2φ̇ψ̇ cos θ) + g sin α x, with the no-slip
    constraints ẋ = aω_y, ẏ = −aω_x on the angular velocity ω of the Euler angles. From the
    origin with centre velocity (vx0, vy0) and spin ω_z about the normal, to T = 1: the centre
    accelerates at (5/7)g sin α down the slope and moves uniformly across it, on a parabola (the
    reference holds the centre and p_x, p_y, p_φ). Conserved: E and p_φ = Iω_z; p_y = ẏ by the
    exact motion but only to O(h²) by the discrete one, so it is not declared; p_x is not.

    Examples
    --------
    >>> import varmech
    >>> scene = varmech.scenes.rolling_sphere()
    >>> traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    >>> round(float(traj.q[-1, 0]), 3), round(1.0 + 5 / 14 * 9.81 * 0.479425538604203, 3)
    (2.68, 2.68)
    """
    return get("rolling_sphere", alpha=alpha, g=g, radius=radius, vx0=vx0, vy0=vy0, spin=spin)


@scene_doc(
    'A native nonholonomic model (n = 5, affine constraints) with the symmetry ``Cyclic(2)``, invariants '
    '``"J"`` and ``"p[2]"``, and the exact reference at 14π/Ω.',
    parameters={
        "omega": "The table's angular velocity Ω, positive.",
        "radius": "The ball's radius, positive.",
        "x0, y0": "The initial centre.",
        "vx0, vy0": "The initial velocity of the centre.",
        "spin": "The initial spin ω_z about the normal.",
    },
    raises="``omega`` or ``radius`` not finite and positive, or ``x0``, ``y0``, ``vx0``, ``vy0`` or ``spin`` "
        "not finite (naming it).",
    references=[bloch("5.2")],
)
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
