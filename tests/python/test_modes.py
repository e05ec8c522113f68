"""Small oscillations (issue 35): equilibria, linearization and normal modes against closed forms,
and the step each method can take, checked where the methods fail.

- the linear triatomic molecule (the mechanics lecture, §5.2.1): ω = 0, √(k/m), √((k/m)(1 + 2m/M))
  with their shapes, the translation a zero mode;
- the double pendulum, equal masses and lengths: ω² = (2 ± √2)g/l;
- a bead on a hoop spinning at Ω: the bottom unstable for Ω² > g/R, the bead at rest where
  cos θ* = g/(RΩ²) with ω = Ω sin θ*;
- a charged particle in a Penning trap (gyroscopic): ω± = ω_c/2 ± √(ω_c²/4 − ω_z²/2), stable
  though the radial potential is a maximum, unstable for ω_c² < 2ω_z²;
- Byerly's two particles joined through a hole in a table (Art. 8(d)), ω² = 3g/(2a) about the
  circular motion, and the conical pendulum, ω² = (g/l)(1 + 3cos²θ₀)/cos θ₀: relative
  equilibria of Routh-reduced models;
- the spherical pendulum in Cartesian coordinates on its constraint: two modes √(g/l) on the
  sphere, none across it, the tension holding it;
- zero modes named after the symmetries they are (the molecule's translation; a planar
  diatomic's two translations and its rotation);
- the step at which a run first blows up is ``suggest_dt``'s limit to 1% (RATTLE's on the
  constrained pendulum too); the midpoint rule is unconditionally stable and stays bounded at
  10× it; ``integrate`` warns before stepping beyond the limit, and a blow-up names h·ω_max.
"""

import functools
import math
import warnings

import numpy as np
import pytest
import sympy as sp

import varmech

G = 9.81


def _molecule(m: float = 1.0, big: float = 3.0, k: float = 2.0, symmetries=()) -> varmech.MechanicalSystem:
    def potential(q):
        return 0.5 * k * ((q[1] - q[0]) ** 2 + (q[2] - q[1]) ** 2)

    def gradient(q):
        return k * np.array([q[0] - q[1], 2 * q[1] - q[0] - q[2], q[2] - q[1]])

    return varmech.MechanicalSystem(3, potential, gradient, mass=[m, big, m], symmetries=symmetries, name="triatomic")


def test_the_linear_triatomic_molecule_has_a_translation_and_two_vibrations_with_their_shapes():
    m, big, k = 1.0, 3.0, 2.0
    translation = varmech.Translation(0, spatial_dim=1)
    modes = varmech.normal_modes(_molecule(m, big, k, [translation]), np.zeros(3))
    exact = [0.0, math.sqrt(k / m), math.sqrt(k / m * (1 + 2 * m / big))]
    np.testing.assert_allclose(modes.frequencies, exact, rtol=1e-12, atol=1e-12)
    assert list(modes.zero_modes) == [0] and modes.stable and modes.inertia == (2, 1, 0)
    # The zero mode is the translation, named: its shape the generator (1, 1, 1), M-normalized.
    assert modes.symmetries == (translation, None, None)
    np.testing.assert_allclose(modes.shapes[:, 0], np.ones(3) / math.sqrt(2 * m + big), rtol=1e-13)
    assert "translation (P_x)" in str(modes)
    # Undeclared, the translation is a zero mode without a name.
    assert varmech.normal_modes(_molecule(m, big, k), np.zeros(3)).symmetries == (None, None, None)
    mass = np.diag([m, big, m])
    assert np.max(np.abs(modes.shapes.T @ mass @ modes.shapes - np.eye(3))) < 1e-13
    # Translation (1, 1, 1); the outer atoms against each other (1, 0, −1); both against the
    # centre (1, −2m/M, 1).
    for shape, column in zip([[1, 1, 1], [1, 0, -1], [1, -2 * m / big, 1]], modes.shapes.T):
        shape = np.array(shape, dtype=float)
        cosine = abs(shape @ mass @ column) / math.sqrt(shape @ mass @ shape)
        assert abs(cosine - 1) < 1e-13


def _double_pendulum(length: float = 1.0) -> varmech.Model:
    t1, t2, w1, w2 = sp.symbols("theta1 theta2 omega1 omega2")
    kinetic = length**2 * (w1**2 + w2**2 / 2 + w1 * w2 * sp.cos(t1 - t2))
    potential = -G * length * (2 * sp.cos(t1) + sp.cos(t2))
    return varmech.symbolic.lagrangian(kinetic - potential, [t1, t2], [w1, w2])


def test_the_double_pendulum_hangs_with_omega_squared_two_plus_or_minus_root_two_g_over_l():
    length = 0.7
    model = _double_pendulum(length)
    (down, up) = varmech.equilibria(model, [[0.2, -0.1], [3.0, 3.2]])
    np.testing.assert_allclose(down.q, [0.0, 0.0], atol=1e-14)
    np.testing.assert_allclose(up.q, [math.pi, math.pi], atol=1e-13)
    assert down.kind == "minimum" and up.kind == "maximum" and down.residual < 1e-14
    exact = np.array([2 - math.sqrt(2), 2 + math.sqrt(2)]) * G / length
    np.testing.assert_allclose(down.modes.frequencies**2, exact, rtol=1e-13)
    assert not up.modes.stable and len(up.modes.unstable_modes) == 2


def _bead(radius: float, spin: float) -> varmech.Model:
    theta, omega = sp.symbols("theta omega")
    lagrangian = radius**2 * (omega**2 + spin**2 * sp.sin(theta) ** 2) / 2 + G * radius * sp.cos(theta)
    return varmech.symbolic.lagrangian(lagrangian, [theta], [omega])


@pytest.mark.parametrize("spin", [2.0, 5.0, 9.0])
def test_a_bead_on_a_spinning_hoop_leaves_the_bottom_above_the_critical_spin(spin):
    # L is separable (constant mass R²): the compiled model gives V's gradient, and K comes from
    # its central differences, to about 1e-10 relative.
    radius = 0.5
    bottom = varmech.normal_modes(_bead(radius, spin), [0.0])
    critical = G / radius
    if spin**2 < critical:
        assert bottom.stable and abs(bottom.frequencies[0] / math.sqrt(critical - spin**2) - 1) < 1e-9
        # No rest off the axis: Newton from θ = 1 ends on it (the bottom or the top).
        (on_axis,) = varmech.equilibria(_bead(radius, spin), [1.0])
        assert abs(math.sin(on_axis.q[0])) < 1e-14
        return
    assert not bottom.stable and abs(bottom.growth[0] / math.sqrt(spin**2 - critical) - 1) < 1e-9
    (off,) = varmech.equilibria(_bead(radius, spin), [1.0])
    assert abs(math.cos(off.q[0]) - critical / spin**2) < 1e-14
    assert off.kind == "minimum" and abs(off.modes.frequencies[0] / (spin * math.sin(off.q[0])) - 1) < 1e-9


def _penning(cyclotron: float, axial: float) -> varmech.Model:
    x, y, z, vx, vy, vz = sp.symbols("x y z vx vy vz")
    kinetic = (vx**2 + vy**2 + vz**2) / 2
    magnetic = cyclotron / 2 * (x * vy - y * vx)  # q v·A, A = ½B × r, ω_c = qB/m
    electric = axial**2 / 2 * (z**2 - (x**2 + y**2) / 2)
    return varmech.symbolic.lagrangian(kinetic + magnetic - electric, [x, y, z], [vx, vy, vz])


def test_a_penning_trap_is_stable_though_its_radial_potential_is_a_maximum_until_the_field_is_too_weak():
    cyclotron, axial = 1.0, 0.6
    modes = varmech.normal_modes(_penning(cyclotron, axial), np.zeros(3))
    root = math.sqrt(cyclotron**2 / 4 - axial**2 / 2)
    np.testing.assert_allclose(modes.frequencies, [cyclotron / 2 - root, axial, cyclotron / 2 + root], rtol=1e-12)
    assert modes.stable and modes.gyroscopically_stable and modes.inertia == (1, 0, 2)
    lin = varmech.linearize(_penning(cyclotron, axial), np.zeros(3))
    np.testing.assert_allclose(lin.gyroscopic, [[0, -cyclotron, 0], [cyclotron, 0, 0], [0, 0, 0]], atol=1e-15)
    # Complex shapes, the null vectors of λ²M + λG + K at λ = iω: the magnetron and cyclotron
    # motions are circles in the plane (|x| = |y|, a quarter period apart), the axial one along z.
    assert np.iscomplexobj(modes.shapes) and modes.shapes.shape == (3, 3)
    for omega, x in zip(modes.frequencies, modes.shapes.T):
        lam = 1j * omega
        residual = (lam**2 * lin.mass + lam * lin.gyroscopic + lin.stiffness) @ x
        assert np.max(np.abs(residual)) < 1e-12 and abs(np.vdot(x, lin.mass @ x) - 1) < 1e-12
    for k in (0, 2):
        x = modes.shapes[:, k]
        assert abs(abs(x[0]) - abs(x[1])) < 1e-12 and abs(abs(x[0] / x[1]) - 1) < 1e-12
        assert abs(abs(np.angle(x[1] / x[0])) - math.pi / 2) < 1e-12 and abs(x[2]) < 1e-12
    np.testing.assert_allclose(np.abs(modes.shapes[:, 1]), [0, 0, 1], atol=1e-12)
    weak = varmech.normal_modes(_penning(0.8, 0.6), np.zeros(3))  # ω_c² = 0.64 < 2ω_z² = 0.72
    assert not weak.stable and len(weak.unstable_modes) == 1


def test_byerlys_particles_through_a_hole_in_a_table_oscillate_about_the_circle_with_omega_squared_3g_over_2a():
    # The particle on the table at (r, θ), the other hanging at depth ℓ − r, both of mass m:
    # L = mṙ² + ½mr²θ̇² − mgr; θ is cyclic, and r = a is a circle where μ² = m²ga³.
    m, a = 1.3, 0.4
    r, theta, vr, vtheta = sp.symbols("r theta v_r v_theta")
    full = varmech.symbolic.lagrangian(m * vr**2 + m * r**2 * vtheta**2 / 2 - m * G * r, [r, theta], [vr, vtheta])
    reduced = varmech.routh(full, cyclic=[1], momenta=[m * math.sqrt(G * a**3)])
    (circle,) = varmech.equilibria(reduced, [0.7 * a])
    assert abs(circle.q[0] - a) < 1e-14 and circle.kind == "minimum"
    assert abs(circle.modes.frequencies[0] ** 2 - 3 * G / (2 * a)) < 1e-12


def test_the_conical_pendulum_oscillates_about_its_cone_at_the_closed_form():
    # The spherical pendulum (θ from the downward vertical, φ cyclic): on the cone θ₀ the
    # precession φ̇² = g/(l cos θ₀), and small oscillations ω² = (g/l)(1 + 3cos²θ₀)/cos θ₀.
    length, theta0 = 1.2, 0.6
    theta, phi, w, spin = sp.symbols("theta phi w s")
    lagrangian = length**2 * (w**2 + sp.sin(theta) ** 2 * spin**2) / 2 + G * length * sp.cos(theta)
    full = varmech.symbolic.lagrangian(lagrangian, [theta, phi], [w, spin])
    precession = math.sqrt(G / (length * math.cos(theta0)))
    reduced = varmech.routh(full, cyclic=[1], momenta=[length**2 * math.sin(theta0) ** 2 * precession])
    (cone,) = varmech.equilibria(reduced, [0.5])
    assert abs(cone.q[0] - theta0) < 1e-13
    exact = G / length * (1 + 3 * math.cos(theta0) ** 2) / math.cos(theta0)
    assert abs(cone.modes.frequencies[0] ** 2 / exact - 1) < 1e-12


def _coupled_pendulums() -> varmech.MechanicalSystem:
    """Two pendulums (g = l = 1) joined by a spring of stiffness 3: ω² = 1 and 7."""

    def potential(q):
        return -np.cos(q[0]) - np.cos(q[1]) + 1.5 * (q[0] - q[1]) ** 2

    def gradient(q):
        return np.sin(q) + 3.0 * (q - q[::-1])

    return varmech.MechanicalSystem(2, potential, gradient, name="coupled pendulums")


def _spherical_pendulum(mass: float = 0.7, length: float = 1.3) -> varmech.MechanicalSystem:
    """A particle on a sphere |x| = l in Cartesian coordinates, V = mgz."""
    return varmech.MechanicalSystem(
        3,
        lambda q: mass * G * q[2],
        lambda q: np.array([0.0, 0.0, mass * G]),
        mass=mass,
        constraints=lambda q: [0.5 * (q @ q - length**2)],
        constraint_jacobian=lambda q: q[None, :],
        constraint_count=1,
        symmetries=[varmech.Rotation(2)],
        name="spherical pendulum",
    )


def test_the_spherical_pendulum_in_cartesian_coordinates_has_two_modes_on_its_sphere_and_none_across():
    mass, length = 0.7, 1.3
    model = _spherical_pendulum(mass, length)
    # Guesses off the sphere are brought onto it: the bottom (a minimum) and the top (a maximum).
    bottom, top = varmech.equilibria(model, [[0.2, -0.1, -1.0], [0.1, 0.0, 2.0]])
    np.testing.assert_allclose(bottom.q, [0, 0, -length], atol=1e-14)
    np.testing.assert_allclose(top.q, [0, 0, length], atol=1e-14)
    # The tension holds the bob: ṗ = −mg e_z + λ x = 0, λ = −mg/l.
    assert abs(bottom.multipliers[0] / (-mass * G / length) - 1) < 1e-13
    assert bottom.kind == "minimum" and top.kind == "maximum"
    lin = varmech.linearize(model, bottom.q)
    assert lin.basis.shape == (3, 2) and np.max(np.abs(lin.basis[2])) < 1e-15
    modes = bottom.modes
    # Two modes on the sphere, none across it.
    np.testing.assert_allclose(modes.frequencies, [math.sqrt(G / length)] * 2, rtol=1e-9)
    assert modes.shapes.shape == (3, 2) and np.max(np.abs(modes.shapes[2])) < 1e-13
    np.testing.assert_allclose(modes.shapes.T @ (mass * modes.shapes), np.eye(2), atol=1e-12)
    np.testing.assert_allclose(top.modes.growth, [math.sqrt(G / length)] * 2, rtol=1e-9)
    # The rotation about the vertical moves nothing at the bottom: no zero mode, none named.
    assert modes.symmetries == (None, None)
    assert abs(varmech.fastest_frequency(model, bottom.q) / math.sqrt(G / length) - 1) < 1e-8


def test_a_planar_diatomic_has_its_translations_and_its_rotation_as_named_zero_modes():
    # Two masses in the plane joined by a spring of rest length 1 (stretched along x).
    masses, k = np.array([1.0, 2.0]), 3.0

    def potential(q):
        return 0.5 * k * (np.hypot(q[2] - q[0], q[3] - q[1]) - 1.0) ** 2

    def gradient(q):
        d = q[2:] - q[:2]
        r = np.hypot(*d)
        f = k * (r - 1.0) * d / r
        return np.concatenate([-f, f])

    symmetries = [varmech.Translation(0, spatial_dim=2), varmech.Translation(1, spatial_dim=2), varmech.Rotation(spatial_dim=2)]
    model = varmech.MechanicalSystem(4, potential, gradient, mass=np.repeat(masses, 2), symmetries=symmetries)
    q = np.array([0.3, -0.2, 1.3, -0.2])
    modes = varmech.normal_modes(model, q)
    reduced = masses.prod() / masses.sum()
    np.testing.assert_allclose(modes.frequencies, [0, 0, 0, math.sqrt(k / reduced)], atol=1e-7, rtol=1e-9)
    assert modes.symmetries == (*symmetries, None)
    # Named shapes are M-orthonormal; the rotation's is orthogonal to the translations (about
    # the centre of mass), not the generator about the origin.
    mass = np.diag(np.repeat(masses, 2))
    np.testing.assert_allclose(modes.shapes.T @ mass @ modes.shapes, np.eye(4), atol=1e-7)
    rotation = modes.shapes[:, 2]
    assert abs(rotation[0]) < 1e-7 and abs(rotation[2]) < 1e-7 and rotation[3] * rotation[1] < 0
    assert "rotation (L)" in str(modes)


def _blows_up(model, method: str, q0, dt: float, steps: int, rest=None) -> bool:
    """Whether a run from rest at q0 leaves its small amplitude about ``rest`` (default 0)."""
    rest = np.zeros(len(q0)) if rest is None else np.asarray(rest)
    try:
        with np.errstate(over="ignore", invalid="ignore"), warnings.catch_warnings():  # the closures on the blown-up state
            warnings.simplefilter("ignore", varmech.StabilityWarning)
            traj = varmech.integrate(model, q0, np.zeros(len(q0)), method=method, dt=dt, steps=steps, max_energy_error=None)
    except (varmech.DivergenceError, varmech.ConvergenceError, varmech.SpuriousBranchError):
        return True
    # A softening model (the pendulums) stops growing where its amplitude has lowered ω below
    # the limit: far beyond the small amplitude it started from.
    return bool(np.max(np.abs(traj.q - rest)) > 1e3 * np.max(np.abs(q0 - rest)))


#: Every method of a separable model with a stability limit on the oscillator: the explicit ones.
EXPLICIT = [
    m.name
    for m in varmech.methods()
    if 0 < m.h_omega_max < math.inf and m.implicit is False and not (m.constrained or m.nonholonomic or m.nbody)
]


@functools.cache
def _first_window(method: str) -> tuple[float, int]:
    """hω just past ``method``'s limit, within its first unstable window and at most 1% above the
    limit, and the steps in which a small state grows 10⁸-fold there: some splittings (Blanes–Moan,
    the ABA ones) become stable again past a window narrower than 1%, which a run at 1.01 of the
    limit steps over."""
    limit = next(m.h_omega_max for m in varmech.methods() if m.name == method)
    ((start, end),) = varmech.analysis.stability.unstable_intervals(method, h_omega_max=1.01 * limit)[:1]
    assert abs(start / limit - 1) < 2e-5
    inside = min(0.5 * (start + end), 1.01 * limit)
    growth = varmech.analysis.stability.growth_factor(method, inside)
    return inside / limit, math.ceil(2 * math.log(1e4) / math.log(growth))


@pytest.mark.parametrize("method", EXPLICIT)
@pytest.mark.parametrize("scene", ["molecule", "pendulums"])
def test_a_small_amplitude_run_first_blows_up_at_the_suggested_limit_to_one_percent(method, scene):
    model, q0 = (_molecule(), np.array([1e-4, 0.0, -2e-4])) if scene == "molecule" else (_coupled_pendulums(), np.array([1e-5, -2e-5]))
    limit = varmech.suggest_dt(model, method, np.zeros(len(q0))).stable_dt
    past, steps = _first_window(method)
    assert past <= 1.01
    assert not _blows_up(model, method, q0, 0.99 * limit, max(4000, steps))
    assert _blows_up(model, method, q0, past * limit, max(4000, steps))


def test_the_double_pendulum_and_the_spinning_hoop_blow_up_at_the_suggested_limit_too():
    # A general Lagrangian under the trapezoidal rule (implicit, but Verlet's limit), and the bead
    # about its off-axis rest under Verlet (its compiled model separable): the limit from the
    # modes at the equilibrium, the runs at a small amplitude about it.
    for model, method, rest in [(_double_pendulum(0.7), "trapezoid", [0.0, 0.0]), (_bead(0.5, 9.0), "verlet", [1.0])]:
        (rest,) = varmech.equilibria(model, [rest])
        limit = varmech.suggest_dt(model, method, rest.q).stable_dt
        q0 = rest.q + 1e-5 * rest.modes.shapes[:, -1]
        assert not _blows_up(model, method, q0, 0.99 * limit, 4000, rest=rest.q)
        assert _blows_up(model, method, q0, 1.01 * limit, 4000, rest=rest.q)


@pytest.mark.parametrize("method", ["rattle", "shake", "rattle4"])
def test_rattle_on_the_spherical_pendulum_first_blows_up_at_the_suggested_limit_to_one_percent(method):
    length = 1.3
    model = _spherical_pendulum(length=length)
    bottom = np.array([0.0, 0.0, -length])
    # A small swing, on the sphere.
    angle = 1e-5
    q0 = length * np.array([math.sin(angle), 0.0, -math.cos(angle)])
    limit = varmech.suggest_dt(model, method, bottom).stable_dt
    assert abs(limit * math.sqrt(G / length) / {"rattle": 2.0, "shake": 2.0, "rattle4": 1.5734}[method] - 1) < 1e-6
    assert not _blows_up(model, method, q0, 0.99 * limit, 4000)
    assert _blows_up(model, method, q0, 1.01 * limit, 4000)


def test_integrate_warns_before_stepping_beyond_the_limit_and_a_blow_up_names_h_omega_max():
    model, q0 = _coupled_pendulums(), np.array([1e-5, -2e-5])
    limit = 2.0 / math.sqrt(7)
    with warnings.catch_warnings():
        warnings.simplefilter("error", varmech.StabilityWarning)
        varmech.integrate(model, q0, np.zeros(2), dt=0.999 * limit, steps=10, max_energy_error=None)
    warned = r"h·ω_max = 2\.02 .* beyond verlet's stability limit 2 .*take dt below 0\.7559"
    named = r"h·ω_max = 2\.0200 at the run's first state .* beyond verlet's stability limit 2"
    with pytest.warns(varmech.StabilityWarning, match=warned):
        with pytest.raises(varmech.DivergenceError, match=named) as caught:
            varmech.integrate(model, q0, np.zeros(2), dt=1.01 * limit, steps=4000)
    assert caught.value.partial.status == -1
    # The constrained pendulum under RATTLE, the same.
    model, length = _spherical_pendulum(length=1.3), 1.3
    q0 = length * np.array([math.sin(1e-5), 0.0, -math.cos(1e-5)])
    with pytest.warns(varmech.StabilityWarning, match="rattle's stability limit 2"):
        with pytest.raises((varmech.DivergenceError, varmech.ConvergenceError)):
            varmech.integrate(model, q0, np.zeros(3), dt=1.05 * 2 * math.sqrt(length / G), steps=4000)
    # An unconditionally stable method never warns.
    with warnings.catch_warnings():
        warnings.simplefilter("error", varmech.StabilityWarning)
        varmech.integrate(_coupled_pendulums(), np.array([1e-5, -2e-5]), np.zeros(2), dt=10 * limit, steps=10, method="midpoint")


def test_the_fastest_frequency_is_the_modes_largest_from_its_force_evaluations_alone():
    on_sphere = np.array([0.0, 0.6, -math.sqrt(1.3**2 - 0.6**2)])
    for model, q in [(_molecule(), np.zeros(3)), (_coupled_pendulums(), np.array([0.3, -1.2])), (_spherical_pendulum(), on_sphere)]:
        dense = varmech.normal_modes(model, q).omega_max
        assert abs(varmech.fastest_frequency(model, q) / dense - 1) < 5e-5


def test_the_midpoint_rule_is_unconditionally_stable_and_stays_bounded_at_ten_times_verlets_limit():
    model = _coupled_pendulums()
    assert varmech.suggest_dt(model, "midpoint", np.zeros(2)).stable_dt == math.inf
    verlet = varmech.suggest_dt(model, "verlet", np.zeros(2))
    q0 = np.array([1e-5, -2e-5])
    traj = varmech.integrate(model, q0, np.zeros(2), method="midpoint", dt=10 * verlet.stable_dt, steps=4000, max_energy_error=None)
    assert np.max(np.abs(traj.q)) < 1.01 * np.max(np.abs(q0)) * math.sqrt(7)


def test_the_step_for_a_phase_accuracy_has_the_methods_phase_error_and_order():
    # Verlet turns the oscillator by θ with cos θ = 1 − x²/2 (x = hω): its phase error a period
    # is 2π(θ/x − 1) exactly.
    model = _molecule()
    omega = varmech.normal_modes(model, np.zeros(3)).omega_max
    for accuracy in (1e-2, 1e-4):
        s = varmech.suggest_dt(model, "verlet", np.zeros(3), accuracy=accuracy)
        x = s.accurate_dt * omega
        assert abs(2 * math.pi * (math.acos(1 - x * x / 2) / x - 1) / accuracy - 1) < 1e-5
        assert s.dt == s.accurate_dt < 0.9 * s.stable_dt
    # Order 4: a 16-fold smaller accuracy halves yoshida4's step.
    steps = [varmech.suggest_dt(model, "yoshida4", np.zeros(3), accuracy=a).accurate_dt for a in (1.6e-5, 1e-6)]
    assert abs(steps[0] / steps[1] - 2) < 0.01


#: (model, q0, p0, methods) on which suggest_dt's step must run "bounded": the molecule, the
#: pendulum at a small and a large amplitude (near its top), the double pendulum of the README
#: from rest, Kepler at e = 0.6 from pericentre; the kind's default method, a fourth-order one
#: and an implicit one (whose step is the accurate step alone).
SUGGESTED = {
    "molecule": (lambda: _molecule(), [0.1, 0.0, -0.2], [0.0, 0.0, 0.0], ("verlet", "yoshida4", "midpoint")),
    "pendulum at 0.1": (lambda: varmech.scenes.pendulum().model, [0.1], [0.0], ("verlet", "yoshida4", "midpoint")),
    "pendulum at 3": (lambda: varmech.scenes.pendulum().model, [3.0], [0.0], ("verlet", "yoshida4", "midpoint")),
    "double pendulum": (lambda: varmech.scenes.double_pendulum().model, [0.5, 1.0], [0.0, 0.0], ("midpoint", "galerkin4")),
    "kepler": (lambda: varmech.scenes.kepler().model, [0.4, 0.0], [0.0, 2.0], ("verlet", "yoshida4", "midpoint")),
}


@pytest.mark.parametrize("case", SUGGESTED)
def test_the_suggested_step_runs_with_a_bounded_verdict(case):
    make, q0, p0, names = SUGGESTED[case]
    model = make()
    for method in names:
        s = varmech.suggest_dt(model, method, q0)
        # The accurate step at the default accuracy, finite for the implicit method too.
        assert s.accuracy == varmech.modes.ACCURACY == 1e-3 and s.dt == s.accurate_dt < math.inf, method
        traj = varmech.integrate(model, q0, p0, dt=s.dt, steps=10_000, method=method)
        report = varmech.check_conservation(traj).energy
        assert report.verdict in ("bounded", "conserved to round-off"), (method, report)


def test_bad_input_names_the_argument():
    model = _molecule()
    with pytest.raises(ValueError, match="q: must have shape"):
        varmech.normal_modes(model, [0.0, 0.0])
    with pytest.raises(ValueError, match="guesses"):
        varmech.equilibria(model, [[0.0, 0.0]])
    with pytest.raises(ValueError, match="method"):
        varmech.suggest_dt(model, "leapfrog", np.zeros(3))
    with pytest.raises(ValueError, match="method: explicit_euler has no stable step"):
        varmech.suggest_dt(model, "explicit_euler", np.zeros(3))
    with pytest.raises(ValueError, match="accuracy"):
        varmech.suggest_dt(model, "verlet", np.zeros(3), accuracy=-1.0)
    with pytest.raises(ValueError, match="margin"):
        varmech.suggest_dt(model, "verlet", np.zeros(3), margin=1.0)
    # The molecule's translation makes K singular: no isolated equilibrium, a typed error.
    with pytest.raises(varmech.ConvergenceError, match="singular") as caught:
        varmech.equilibria(model, [0.1, 0.0, 0.0])
    assert caught.value.residual > 0
    pendulum = varmech.MechanicalSystem(1, lambda q: -math.cos(q[0]), lambda q: np.sin(q), name="pendulum")
    x, y, vx, vy = sp.symbols("x y vx vy")
    singular = varmech.symbolic.lagrangian(vx**2 / 2 + x * vy - x**2 - y**2, [x, y], [vx, vy])
    with pytest.raises(ValueError, match="not positive definite"):
        varmech.normal_modes(singular, [0.0, 0.0])
    skate = varmech.scenes.chaplygin_sleigh().model
    with pytest.raises(ValueError, match="model: velocity constraints"):
        varmech.normal_modes(skate, np.zeros(skate.dim))
    with pytest.raises(ValueError, match="model: velocity constraints"):
        varmech.fastest_frequency(skate, np.zeros(skate.dim))
    assert varmech.equilibria(pendulum, [0.1])[0].kind == "minimum"
