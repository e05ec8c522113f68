"""Lyapunov spectra from the step's tangent map (issue 37): the Hénon–Heiles chaotic sea and a
torus, the same spectrum from a native scene (exact Hessian), closures and a SymPy model
(differenced Hessians), the run's states bit for bit, the implicit rules' tangent maps on the
damped, driven pendulum (Taylor's chaos past his cascade, Σλ = −2β to order 2, the same
spectrum from the scene, closures and SymPy), and bad requests refused by name."""

import math

import numpy as np
import pytest
import sympy as sp

import varmech
from varmech.analysis.baselines import restore_sigint

CHAOTIC = ([0.0, -0.25], [0.42, 0.0])  # H = 0.1247, in the chaotic sea
REGULAR = ([0.1, 0.0], [0.0, 0.5])  # H = 0.13, on a torus


def henon_heiles_closures():
    def potential(q):
        x, y = q
        return 0.5 * (x * x + y * y) + x * x * y - y**3 / 3

    def gradient(q):
        x, y = q
        return np.array([x + 2 * x * y, y + x * x - y * y])

    return varmech.MechanicalSystem(2, potential, gradient)


def henon_heiles_sympy():
    x, y, vx, vy = sp.symbols("x y vx vy")
    L = (vx**2 + vy**2) / 2 - ((x**2 + y**2) / 2 + x**2 * y - y**3 / 3)
    return varmech.symbolic.lagrangian(L, [x, y], [vx, vy])


def test_the_chaotic_sea_has_one_positive_exponent_its_mirror_and_two_near_zero():
    hh = varmech.scenes.henon_heiles().model
    s = varmech.lyapunov_spectrum(hh, *CHAOTIC, dt=0.05, steps=200_000)
    lam, err = s.exponents, s.stderr
    assert lam[0] > 10 * err[0] and lam[0] > 0.04
    # Symplectic: the pairs are mirror images within their errors, and the sum is 0 at every time.
    assert abs(lam[0] + lam[3]) < err[0] + err[3]
    assert abs(lam[1] + lam[2]) < err[1] + err[2]
    assert np.all(np.abs(s.running.sum(axis=1)) < 1e-13)
    # The two along the flow and across the shell: 0 within 3 standard errors.
    assert abs(lam[1]) < 3 * err[1] and abs(lam[2]) < 3 * err[2]
    assert s.running.shape == (len(s.t), 4) and s.t[-1] == pytest.approx(1e4)
    # The run is the plain run, bit for bit.
    traj = varmech.integrate(hh, *CHAOTIC, dt=0.05, steps=200_000, method="verlet", save_every=200_000)
    np.testing.assert_array_equal(s.q, traj.q[-1])
    np.testing.assert_array_equal(s.p, traj.p[-1])
    assert "Σλ" in str(s)


def test_a_torus_exponents_fall_towards_zero():
    hh = varmech.scenes.henon_heiles().model
    s = varmech.lyapunov_spectrum(hh, *REGULAR, dt=0.05, steps=200_000, k=1)
    early = s.running[np.searchsorted(s.t, 1e3), 0]
    assert s.exponents.shape == (1,)
    # λ₁ ≈ c ln T/T: a factor ln(10³)/ln(10⁴)·10 ≈ 7.7 from T = 10³ to 10⁴.
    assert 0 < s.exponents[0] < early / 4


@pytest.mark.parametrize("build", [henon_heiles_closures, henon_heiles_sympy], ids=["closures", "sympy"])
def test_a_differenced_hessian_gives_the_exact_ones_spectrum(build):
    # The largest exponent of the chaotic orbit over T = 10³: a Hessian right to ~1e-10 moves
    # the tangent vectors by that much a step, which the exponent's average keeps small.
    exact = varmech.lyapunov_spectrum(varmech.scenes.henon_heiles().model, *CHAOTIC, dt=0.05, steps=20_000)
    other = varmech.lyapunov_spectrum(build(), *CHAOTIC, dt=0.05, steps=20_000)
    np.testing.assert_allclose(other.exponents, exact.exponents, atol=1e-6)
    assert abs(other.sum) < 1e-13
    assert other.evaluations > exact.evaluations  # 2n gradients a Hessian


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"k": 5}, "k"),
        ({"k": 0}, "k"),
        ({"every": 0}, "every"),
        ({"segments": 1}, "segments"),
        ({"steps": 50}, "segments"),
        ({"method": "rk4"}, "method"),
        ({"method": "rattle"}, "method"),
        ({"dt": -0.1}, "dt"),
    ],
)
def test_bad_requests_are_refused_naming_the_argument(kwargs, name):
    hh = varmech.scenes.henon_heiles().model
    args = {"dt": 0.05, "steps": 1000, **kwargs}
    with pytest.raises(ValueError, match=f"^{name}:"):
        varmech.lyapunov_spectrum(hh, *CHAOTIC, **args)


def test_a_model_that_is_not_separable_is_refused_naming_it():
    pendulum = varmech.scenes.double_pendulum().model
    with pytest.raises(ValueError, match="^model:.*separable"):
        varmech.lyapunov_spectrum(pendulum, [0.1, 0.2], [0.0, 0.0], dt=0.01, steps=1000, method="verlet")


def test_a_vector_that_would_overflow_is_renormalized_first():
    # λ₁ ≈ 0.059: between re-orthonormalizations 5000 time units apart the vector would grow
    # by e²⁹⁵, past any float; it is renormalized once past 1e100 (230 e-folds, t ≈ 3900),
    # and λ₁ is that of frequent re-orthonormalizations (one vector's direction does not
    # depend on when it is rescaled).
    hh = varmech.scenes.henon_heiles().model
    rare = varmech.lyapunov_spectrum(hh, *CHAOTIC, dt=0.05, steps=200_000, k=1, every=100_000, segments=2)
    often = varmech.lyapunov_spectrum(hh, *CHAOTIC, dt=0.05, steps=200_000, k=1, every=10, segments=2)
    assert np.isfinite(rare.running).all() and 3500 < rare.t[0] < 4500 and 5000.0 in rare.t
    np.testing.assert_allclose(rare.exponents, often.exponents, rtol=1e-9)


def test_the_standard_error_comes_from_the_segments():
    hh = varmech.scenes.henon_heiles().model
    s = varmech.lyapunov_spectrum(hh, *CHAOTIC, dt=0.05, steps=20_000, segments=4)
    sums = s.running * s.t[:, None]
    quarters = [np.searchsorted(s.t, s.t[-1] * f) for f in (0.25, 0.5, 0.75, 1.0)]
    ends = [sums[i] for i in quarters]
    times = [s.t[i] for i in quarters]
    pieces = np.array([(b - a) / (tb - ta) for a, b, ta, tb in zip([np.zeros(4)] + ends[:-1], ends, [0.0] + times[:-1], times)])
    np.testing.assert_allclose(s.stderr, pieces.std(axis=0, ddof=1) / math.sqrt(4), rtol=1e-12)


def test_megno_is_two_on_quasi_periodic_orbits_zero_near_a_centre_and_grows_as_lambda_t_over_two_in_chaos():
    kepler = varmech.scenes.get("kepler", e=0.5)
    m = varmech.megno(kepler.model, kepler.q0, kepler.p0, dt=0.01, steps=200_000)
    assert abs(m.value - 2.0) < 0.01 and m.y.shape == m.t.shape == m.mean.shape
    torus = varmech.megno(varmech.scenes.henon_heiles().model, *REGULAR, dt=0.05, steps=200_000)
    assert abs(torus.value - 2.0) < 0.1
    oscillator = varmech.megno(varmech.scenes.get("harmonic_oscillator").model, [1.0], [0.0], dt=0.05, steps=20_000)
    assert abs(oscillator.value) < 1e-6
    # Chaos: ⟨Y⟩ ≈ λ₁t/2, λ₁ that of the spectrum on the same orbit.
    hh = varmech.scenes.henon_heiles().model
    chaotic = varmech.megno(hh, *CHAOTIC, dt=0.05, steps=200_000)
    spectrum = varmech.lyapunov_spectrum(hh, *CHAOTIC, dt=0.05, steps=200_000, k=1)
    assert 2 * chaotic.value / chaotic.t[-1] == pytest.approx(spectrum.exponents[0], rel=0.05)


# The damped, driven pendulum at Taylor's parameters in the scene's time unit 1/ω₀: damping
# 2β/ω₀ = 0.5, drive 2/3 (period 3π), amplitude γ; from φ = −π/2 at rest.
TAYLOR = ([-math.pi / 2], [0.0])


def taylor(gamma):
    return varmech.scenes.get("damped_driven_pendulum", amplitude=gamma).model


def test_the_driven_pendulum_has_a_negative_spectrum_on_its_attractor_and_a_positive_exponent_past_the_cascade():
    # Each run ~ 200 drive periods after none discarded: λ₁(1.06) < 0 (the period-1 orbit), and
    # λ₁ > 0 in Taylor's chaotic example γ = 1.105; both sum to the damping's −0.5.
    periodic = varmech.lyapunov_spectrum(taylor(1.06), *TAYLOR, dt=3 * math.pi / 200, steps=40_000)
    chaotic = varmech.lyapunov_spectrum(taylor(1.105), *TAYLOR, dt=3 * math.pi / 200, steps=40_000)
    assert periodic.method == "midpoint"
    assert periodic.exponents[0] < -0.02 < 0.05 < chaotic.exponents[0]
    for s in (periodic, chaotic):
        assert s.sum == pytest.approx(-0.5, abs=2e-4)


def test_chaos_sets_in_past_taylors_accumulation_point():
    # λ₁ over γ ∈ [1.080, 1.086] by 0.0005 (200 drive periods each, from φ = −π/2): negative
    # through the last doublings, positive from the first γ past Taylor's γ∞ ≈ 1.0829 on.
    gammas = np.round(np.arange(1.080, 1.08601, 0.0005), 4)
    lam = np.array([
        varmech.lyapunov_spectrum(taylor(g), *TAYLOR, dt=3 * math.pi / 100, steps=20_000, k=1).exponents[0] for g in gammas
    ])
    onset = gammas[np.argmax(lam > 0)]
    assert onset == pytest.approx(1.0829, abs=0.0005), list(zip(gammas, lam))
    assert np.all(lam[gammas < onset] < 0) and np.all(lam[gammas >= onset] > 0), list(zip(gammas, lam))


def test_the_driven_pendulums_sum_is_minus_two_beta_to_second_order():
    # Σλ = (1/T)Σ ln det DΨ_h = −2β(1 + O(h²)): the error falls by 4 from h to h/2.
    errors = []
    for dt in (3 * math.pi / 100, 3 * math.pi / 200):
        s = varmech.lyapunov_spectrum(taylor(1.077), *TAYLOR, dt=dt, steps=round(60 * math.pi / dt), every=5)
        errors.append(abs(s.sum + 0.5))
    assert math.log2(errors[0] / errors[1]) == pytest.approx(2.0, abs=0.1)


def driven_closures(gamma):
    return varmech.Lagrangian(
        1,
        lambda q, v, t: 0.5 * v[0] ** 2 + math.cos(q[0]),
        force=lambda q, v, t: np.array([-0.5 * v[0] + gamma * math.cos(2.0 / 3.0 * t)]),
        dl_dq=lambda q, v, t: np.array([-math.sin(q[0])]),
        dl_dv=lambda q, v, t: v.copy(),
    )


def driven_sympy(gamma):
    phi, w, t = sp.symbols("phi w t")
    return varmech.symbolic.lagrangian(
        w**2 / 2 + sp.cos(phi), [phi], [w], t=t, rayleigh=w**2 / 4, force=[gamma * sp.cos(2 * t / 3)]
    )


@pytest.mark.parametrize("build", [driven_closures, driven_sympy])
def test_the_implicit_spectrum_of_a_users_model_is_the_scenes(build):
    # Chaotic: round-off apart, the orbits part as e^(λ₁t), 1e-8 of the state by the end here.
    args = {"dt": 3 * math.pi / 200, "steps": 2000}
    native = varmech.lyapunov_spectrum(taylor(1.105), *TAYLOR, **args)
    own = varmech.lyapunov_spectrum(build(1.105), *TAYLOR, **args)
    np.testing.assert_allclose(own.exponents, native.exponents, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(own.q, native.q, rtol=1e-6)


def test_a_constrained_model_or_delayed_forces_are_refused_naming_the_model():
    pendulum = varmech.scenes.get("cartesian_pendulum")
    with pytest.raises(ValueError, match="^model:.*constraints"):
        varmech.lyapunov_spectrum(pendulum.model, pendulum.q0, pendulum.p0, dt=0.01, steps=1000, method="trapezoid")
    q, w, w_past = sp.symbols("q w w_past")
    delayed = varmech.symbolic.lagrangian(
        (w**2 - q**2) / 2, [q], [w], delayed=varmech.symbolic.Delayed(1.0, [-0.5 * w_past], v_past=[w_past])
    )
    with pytest.raises(ValueError, match="^model:.*delayed forces"):
        varmech.lyapunov_spectrum(delayed, [1.0], [0.0], dt=0.01, steps=1000)


def test_megno_of_the_outer_solar_system_is_rebounds_from_the_same_start():
    # REBOUND's init_megno(seed=1) draws (δx, δv); varmech started there (δp = mδv) gives its
    # ⟨Y⟩ at 10⁶ days (verlet against WHFast, both h = 50 days): 2.0583 against 2.0582.
    rebound = pytest.importorskip("rebound")
    scene = varmech.scenes.outer_solar_system()
    G, masses = scene.model._core.gravity
    sim = rebound.Simulation()
    sim.G = G
    for m, x, p in zip(masses, scene.q0.reshape(-1, 3), scene.p0.reshape(-1, 3)):
        sim.add(m=m, x=x[0], y=x[1], z=x[2], vx=p[0] / m, vy=p[1] / m, vz=p[2] / m)
    sim.integrator, sim.dt = "whfast", 50.0
    sim.init_megno(seed=1)
    particles = sim.var_config[0].particles
    start = [c for b in particles for c in (b.x, b.y, b.z)] + [c for b in particles for c in (b.vx, b.vy, b.vz)]
    try:
        sim.integrate(1e6, exact_finish_time=0)
    finally:
        restore_sigint()  # REBOUND keeps SIGINT, which the later tests' Ctrl-C needs
    mine = varmech.megno(scene.model, scene.q0, scene.p0, dt=50.0, steps=20_000, method="verlet", tangent0=start)
    assert mine.value == pytest.approx(sim.megno(), abs=2e-3)
    assert abs(mine.value - 2.0) < 0.1


def test_tangent0_is_checked_by_name():
    hh = varmech.scenes.henon_heiles().model
    with pytest.raises(ValueError, match="^tangent0: must have shape"):
        varmech.megno(hh, *CHAOTIC, dt=0.05, steps=10, tangent0=[1.0, 0.0])
    with pytest.raises(ValueError, match="^tangent0:.*independent"):
        varmech.lyapunov_spectrum(hh, *CHAOTIC, dt=0.05, steps=1000, k=2, tangent0=np.ones((4, 2)))
    s = varmech.lyapunov_spectrum(hh, *CHAOTIC, dt=0.05, steps=1000, k=2, tangent0=np.eye(4)[:, :2])
    assert s.exponents.shape == (2,)


def test_a_steppers_tangent_map_is_the_closed_form_and_leaves_its_states_as_they_are():
    # Verlet on the oscillator ω = 1: DΨ_h = [[1 − h²/2, h], [−h(1 − h²/4), 1 − h²/2]], ten steps its
    # tenth power (to the round-off of the scene's differenced Hessian, ε/ε^⅓); the states those
    # of advance, bit for bit.
    h = 0.1
    scene = varmech.scenes.get("harmonic_oscillator")
    stepper, plain = varmech.Stepper(scene, dt=h), varmech.Stepper(scene, dt=h)
    psi = stepper.advance_tangent(np.eye(2), steps=10)
    plain.advance(10)
    one = np.array([[1 - h**2 / 2, h], [-h * (1 - h**2 / 4), 1 - h**2 / 2]])
    np.testing.assert_allclose(psi, np.linalg.matrix_power(one, 10), rtol=0, atol=1e-11)
    np.testing.assert_array_equal(stepper.q, plain.q)
    np.testing.assert_array_equal(stepper.p, plain.p)
    assert stepper.advance_tangent([1.0, 0.0], steps=1).shape == (2,)


def test_a_steppers_implicit_tangent_map_is_the_difference_of_its_steps():
    # The driven pendulum under the midpoint rule, 20 steps: against central differences of two
    # nearby runs (1e-6 apart, right to about 1e-10).
    model = taylor(1.105)
    dt, x0 = 3 * math.pi / 200, np.array([0.3, 0.2])
    psi = varmech.Stepper(model, x0[:1], x0[1:], dt=dt).advance_tangent(np.eye(2), steps=20)
    columns = []
    for j in range(2):
        ends = []
        for sign in (1, -1):
            x = x0.copy()
            x[j] += sign * 1e-6
            s = varmech.Stepper(model, x[:1], x[1:], dt=dt)
            s.advance(20)
            ends.append(np.concatenate([s.q, s.p]))
        columns.append((ends[0] - ends[1]) / 2e-6)
    np.testing.assert_allclose(psi, np.array(columns).T, rtol=1e-8)


def test_a_steppers_tangent_is_refused_where_it_has_none():
    stepper = varmech.Stepper(varmech.scenes.get("harmonic_oscillator"), dt=0.1)
    with pytest.raises(ValueError, match="^tangent: must have shape"):
        stepper.advance_tangent(np.eye(3), steps=1)
    ball = varmech.scenes.get("bouncing_ball")
    watched = varmech.Stepper(ball, dt=0.01)
    with pytest.raises(ValueError, match="^tangent: a stepper with contacts"):
        watched.advance_tangent(np.eye(2), steps=1)
    rk4 = varmech.Stepper(varmech.scenes.get("harmonic_oscillator"), dt=0.1, method="rk4")
    with pytest.raises(ValueError, match="^method:"):
        rk4.advance_tangent(np.eye(2), steps=1)


def test_the_exponents_along_the_flow_fall_as_one_over_t_and_keplers_all_fall_to_zero():
    # Hénon–Heiles' chaotic orbit: λ₂ and λ₃ (along the flow and across the energy shell) fall
    # as 1/T, λ₂T staying of order 1 (measured 3.1, 5.1, 7.0 at T = 10², 10³, 10⁴) while λ₁
    # converges. Kepler (e = 0.5, integrable): all four fall, λ₁ as ln T/T (λ₁T = 6.8, 9.0,
    # 10.6), λ₁ + λ₄ ≈ 0.
    hh = varmech.lyapunov_spectrum(varmech.scenes.henon_heiles().model, *CHAOTIC, dt=0.05, steps=200_000)
    at = lambda s, T: s.running[np.searchsorted(s.t, T)]  # noqa: E731
    for j in (1, 2):
        early, late = abs(at(hh, 1e3)[j]), abs(at(hh, 1e4 - 1)[j])
        assert late < early / 4 and late * 1e4 < 20, (early, late)
    assert at(hh, 1e4 - 1)[0] > 0.05
    kepler = varmech.scenes.get("kepler", e=0.5)
    s = varmech.lyapunov_spectrum(kepler.model, kepler.q0, kepler.p0, dt=0.01, steps=1_000_000)
    early, late = at(s, 1e3), at(s, 1e4 - 1)
    assert np.all(np.abs(late) < 2e-3), late
    assert late[0] < early[0] / 5 and late[0] * 1e4 < 3 * early[0] * 1e3, (early, late)


def test_rattle_gives_the_cartesian_double_pendulum_the_angle_pendulums_spectrum():
    # The same double pendulum (unit masses and links, g = 1, both arms horizontal at rest):
    # in its two angles under the midpoint rule, and in the Cartesian coordinates of its two
    # bodies on their two links under RATTLE, whose tangent map acts on the constraint
    # manifold's tangent space (4 exponents of the 8 coordinates). λ₁ 0.309 ± 0.024 and
    # 0.311 ± 0.021. RATTLE's Σλ·T, the log of the Euclidean volume of the tangent space's
    # parallelepiped, stays bounded (1/T in Σλ): that volume is not the symplectic one, which
    # the step keeps, but their ratio is a function of the state.
    q1, q2, v1, v2 = sp.symbols("q1 q2 v1 v2")
    angles = varmech.symbolic.lagrangian(v1**2 + v2**2 / 2 + v1 * v2 * sp.cos(q1 - q2) + 2 * sp.cos(q1) + sp.cos(q2), [q1, q2], [v1, v2])
    chain = varmech.scenes.get("planar_chain", links=2).model
    a = varmech.lyapunov_spectrum(angles, [math.pi / 2, math.pi / 2], [0.0, 0.0], dt=0.01, steps=50_000)
    c = varmech.lyapunov_spectrum(chain, [1.0, 0.0, 2.0, 0.0], [0.0] * 4, dt=0.01, steps=50_000, method="rattle")
    assert c.exponents.shape == (4,)
    assert abs(a.exponents[0] - c.exponents[0]) < 2 * (a.stderr[0] + c.stderr[0])
    assert c.exponents[0] > 0.2 and abs(c.exponents[0] + c.exponents[3]) < 2 * c.stderr[0]
    assert np.max(np.abs(c.running.sum(axis=1) * (c.t - c.t0))) < 3.0


@pytest.mark.parametrize(("kwargs", "name"), [({"k": 5}, "k"), ({"method": "rattle4"}, "method"), ({"method": "trapezoid"}, "model")])
def test_a_constrained_spectrum_is_refused_by_name_where_it_has_none(kwargs, name):
    chain = varmech.scenes.get("planar_chain", links=2).model
    args = {"method": "rattle", **kwargs}
    with pytest.raises(ValueError, match=f"^{name}:"):
        varmech.lyapunov_spectrum(chain, [1.0, 0.0, 2.0, 0.0], [0.0] * 4, dt=0.01, steps=100, **args)
