"""Bad input gets a clear error naming the argument; failures keep the partial trajectory."""

import math
import time
import traceback

import numpy as np
import pytest

import varmech
from conftest import releases_the_gil
from varmech import examples, scenes


@pytest.mark.parametrize(
    "kwargs, argument",
    [
        (dict(q0=[0.4], p0=[0.0, 2.0]), "q0"),
        (dict(q0=[[0.4, 0.0]], p0=[0.0, 2.0]), "q0"),
        (dict(q0=[0.4, math.nan], p0=[0.0, 2.0]), "q0"),
        (dict(q0=[0.4, 0.0], p0=[0.0, math.inf]), "p0"),
        (dict(q0=[0.4, 0.0], v0=[0.0, math.nan]), "v0"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], v0=[0.0, 2.0]), "p0, v0"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], dt=0.0), "dt"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], dt=-0.1), "dt"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], dt=math.nan), "dt"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], dt=math.inf), "dt"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], method="leapfrog"), "method"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], steps=None, t_end=None), "steps, t_end"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], steps=None, t_end=0.15), "t_end"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], steps=-1), "steps"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], steps=2**64), "steps"),
        # 2⁴⁰ states do not fit in memory; past 2⁵³ steps a step count is no float's (issue 64).
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], steps=2**40), "save_every"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], steps=2**62), "steps"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], save_every=0), "save_every"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], max_energy_error=0.0), "max_energy_error"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], newton_tolerance=0.0), "newton_tolerance"),
        (dict(q0=[0.4, 0.0], p0=[0.0, 2.0], newton_max_iterations=0), "newton_max_iterations"),
    ],
)
def test_bad_input_raises_value_error_naming_the_argument(kepler, kwargs, argument):
    args = dict(dt=0.1, steps=10) | kwargs
    with pytest.raises(ValueError, match=f"^{argument}:"):
        varmech.integrate(kepler.model, **args)


def test_strings_where_numbers_belong_are_a_type_error_naming_the_argument(kepler):
    with pytest.raises(TypeError, match="^p0: must be numbers, not strings"):
        varmech.integrate(kepler.model, [0.4, 0.0], ["a", 2.0], dt=0.1, steps=10)
    with pytest.raises(TypeError, match="^q0: must be numbers, not strings"):
        varmech.integrate(kepler.model, ["0", "0.1"], [0.0, 2.0], dt=0.1, steps=10)
    with pytest.raises(TypeError, match="^dt: must be a number, not str"):
        varmech.integrate(kepler.model, [0.4, 0.0], [0.0, 2.0], dt="0.1", steps=10)


def test_bad_models_are_refused():
    with pytest.raises(ValueError, match="^mass:"):
        varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: q, mass=[1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="^mass:"):
        varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: q, mass=[[1.0, 2.0], [2.0, 1.0]])
    with pytest.raises(ValueError, match="^mass:"):
        varmech.MechanicalSystem(1, lambda q: 0.0, lambda q: q, mass=-1.0)
    with pytest.raises(ValueError, match="^dim:"):
        varmech.MechanicalSystem(0, lambda q: 0.0, lambda q: q)
    with pytest.raises(TypeError, match="^potential:"):
        varmech.MechanicalSystem(1, 3.0, lambda q: q)
    with pytest.raises(ValueError, match=r"^symmetries\[0\]: Cyclic\(5\) does not apply to a model of 3 coordinates"):
        varmech.MechanicalSystem(3, lambda q: 0.0, lambda q: q, symmetries=[varmech.Cyclic(5)])
    with pytest.raises(ValueError, match="^e:"):
        scenes.kepler(e=1.0)
    with pytest.raises(TypeError, match="^model:"):
        varmech.integrate("kepler", [0.0], [1.0], dt=0.1, steps=1)


class Boom(Exception):
    pass


def exploding_gradient(after):
    calls = {"n": 0}

    def gradient(q):
        calls["n"] += 1
        if calls["n"] > after:
            raise Boom(f"boom at call {calls['n']}")
        return np.sin(q)

    return gradient


def test_closure_exception_propagates_unchanged_with_partial_trajectory():
    model = varmech.MechanicalSystem(1, lambda q: -math.cos(q[0]), exploding_gradient(after=12))
    with pytest.raises(Boom, match="boom at call 13") as info:
        varmech.integrate(model, [0.0], [1.0], dt=0.1, steps=100, method="verlet")
    err = info.value
    # Evaluation 13 is step 10's (two for the pre-run check of the step, ω_max by Lanczos, which
    # on one coordinate takes one iteration; one before step 1, then one a step): steps 0..9
    # are kept.
    assert err.step == 10 and err.time == pytest.approx(0.9)
    partial = err.partial
    assert partial.status == -1 and partial.steps == 9 and len(partial) == 10
    clean = varmech.integrate(varmech.MechanicalSystem(1, lambda q: -math.cos(q[0]), np.sin), [0.0], [1.0], dt=0.1, steps=9)
    np.testing.assert_array_equal(partial.q, clean.q)
    # The traceback still reaches into the closure.
    frames = [f.name for f in traceback.extract_tb(err.__traceback__)]
    assert "gradient" in frames


@pytest.mark.parametrize(
    "returned, error, match",
    [
        (lambda q: np.zeros(3), ValueError, r"gradient\(q\) returned 3 values, expected 2"),
        (lambda q: [1.0], ValueError, r"gradient\(q\) returned 1 values, expected 2"),
        (lambda q: "ab", TypeError, r"gradient\(q\) must return a 1-d array of 2 floats, got str"),
        (lambda q: None, TypeError, r"gradient\(q\) must return .* got NoneType"),
        (lambda q: np.zeros((2, 2)), TypeError, r"gradient\(q\) must return .* shape \(2, 2\)"),
    ],
)
def test_closure_returning_the_wrong_shape_or_type_is_named(returned, error, match):
    model = varmech.MechanicalSystem(2, lambda q: 0.0, returned)
    with pytest.raises(error, match=match) as info:
        varmech.integrate(model, [1.0, 0.0], [0.0, 1.0], dt=0.1, steps=5)
    assert info.value.partial.steps == 0


def test_potential_returning_a_non_float_is_named():
    model = varmech.MechanicalSystem(1, lambda q: [1.0, 2.0], lambda q: q)
    # The run's energy check evaluates V at the initial state; without it, the report does.
    with pytest.raises(TypeError, match=r"potential\(q\) must return a float, got list"):
        varmech.integrate(model, [1.0], [0.0], dt=0.1, steps=3)
    traj = varmech.integrate(model, [1.0], [0.0], dt=0.1, steps=3, max_energy_error=None)
    with pytest.raises(TypeError, match=r"potential\(q\) must return a float, got list"):
        traj.energy()


def test_integer_gradients_and_sequences_are_accepted():
    model = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: [0, 0])
    traj = varmech.integrate(model, [1.0, 0.0], [0.0, 1.0], dt=0.5, steps=4)
    np.testing.assert_allclose(traj.q[-1], [1.0, 2.0])


def test_blow_up_raises_divergence_error_with_finite_partial_trajectory():
    scene = scenes.harmonic_oscillator()
    # Without the energy check, which stops the run at its first step (see below), the state
    # grows until it is not finite.
    with pytest.raises(varmech.DivergenceError, match="diverged at step") as info:
        varmech.integrate(scene, dt=2.02, steps=100_000, method="verlet", max_energy_error=None)
    err = info.value
    assert isinstance(err, varmech.VarmechError)
    assert err.step > 1 and err.time == pytest.approx((err.step - 1) * 2.02)
    assert np.all(np.isfinite(err.partial.q)) and np.all(np.isfinite(err.partial.p))
    assert err.partial.steps == err.step - 1


def test_energy_threshold_raises_divergence_error():
    # Explicit Euler multiplies the oscillator's energy by 1 + h² a step. The documented rule by
    # hand: the first step k where |E_k − E_0| reaches the mean kinetic energy of states 0..k.
    q, p, kinetic, k = 0.0, 1.0, [0.5], 0
    while abs(0.5 * (q * q + p * p) - 0.5) < np.mean(kinetic):
        q, p, k = q + 0.1 * p, p - 0.1 * q, k + 1
        kinetic.append(0.5 * p * p)
    for threshold in (1.0, "auto"):
        with pytest.raises(varmech.DivergenceError, match="max_energy_error") as info:
            varmech.integrate(scenes.harmonic_oscillator(), dt=0.1, steps=10_000, method="explicit_euler", max_energy_error=threshold)
        assert info.value.step == k and 40 < k < 70
        assert len(info.value.partial) == k + 1


def test_a_method_that_is_not_symplectic_is_told_its_error_grows_and_what_bounds_it():
    # Explicit Euler multiplies the oscillator's energy by 1 + h² a step, so its error passes
    # the scale at a time that goes as 1/h: a step 4 times smaller fails 4 times later, and no
    # step runs for ever. Verlet's error, at the same step, stays bounded.
    failed = {}
    for dt in (0.1, 0.025):
        with pytest.raises(varmech.DivergenceError) as info:
            varmech.integrate(scenes.harmonic_oscillator(), dt=dt, steps=round(400 / dt), method="explicit_euler")
        message = str(info.value)
        assert "explicit_euler is not symplectic: its energy error grows along the run" in message
        assert "by order 1), or take a symplectic method, whose error stays bounded: verlet" in message
        failed[dt] = info.value.time
    assert failed[0.025] / failed[0.1] == pytest.approx(4, rel=0.1)
    verlet = varmech.integrate(scenes.harmonic_oscillator(), dt=0.1, steps=4000, method="verlet")
    assert varmech.check_conservation(verlet).energy.verdict == "bounded"


@pytest.mark.parametrize("native", [True, False])
def test_ctrl_c_interrupts_a_long_run_and_keeps_the_partial_trajectory(native, interrupt_after):
    scene = scenes.kepler()
    model = scene.model if native else examples.kepler()
    steps = 10**10 if native else 10**8
    timer, sent = interrupt_after(0.3)
    with pytest.raises(KeyboardInterrupt) as info:
        varmech.integrate(model, scene.q0, scene.p0, dt=1e-3, steps=steps, save_every=10**5)
    latency = time.perf_counter() - sent["at"]
    timer.join()
    partial = info.value.partial
    assert 0 < partial.steps < steps
    assert np.all(np.isfinite(partial.q))
    # Responsiveness, not speed: the poll runs every 10-40 ms, so well under a second.
    assert latency < 1.0, f"interrupt took {latency:.3f} s"


def test_native_runs_release_the_gil():
    scene = scenes.outer_solar_system()
    assert releases_the_gil(lambda: varmech.integrate(scene, dt=1.0, steps=5_000_000, save_every=1_000_000))


@pytest.mark.parametrize("method", ["verlet", "midpoint", "explicit_euler"])
def test_a_motion_below_the_differences_resolution_is_told_to_supply_derivatives(method):
    # Differences step by 6e-6 at |q| < 1: at an amplitude of 1e-30 the term 2qh of
    # V(q + h) − V(q − h) is below their rounding, the force comes out 0 and the particle
    # flies off its potential's minimum, at every step. The advice names what helps.
    potential = lambda q: float(0.5 * q[0] ** 2 + 2.0 * (1.0 - np.cos(q[0])))  # noqa: E731
    with pytest.warns(varmech.DerivativeWarning):
        bare = varmech.MechanicalSystem(1, potential, mass=[1.0])
    for dt in (0.05, 0.05 / 16):
        with pytest.raises(varmech.DivergenceError, match="supply the model's derivatives") as info:
            varmech.integrate(bare, q0=[0.0], p0=[1e-30], dt=dt, steps=int(200 / dt), method=method)
        assert "reduce dt" not in str(info.value)
    exact = varmech.MechanicalSystem(1, potential, lambda q: q + 2.0 * np.sin(q), mass=[1.0])
    traj = varmech.integrate(exact, q0=[0.0], p0=[1e-30], dt=0.05, steps=4000, method="verlet")
    # ω² = 3: the amplitude is v0/√3, which the exact gradient keeps.
    assert np.max(np.abs(traj.q)) == pytest.approx(1e-30 / np.sqrt(3.0), rel=0.01, abs=0.0)
    # The same particle at amplitude 1e-3 moves its differenced forces' rounding far less than its
    # energy: explicit Euler's own growth is told to reduce dt.
    with pytest.raises(varmech.DivergenceError, match="reduce dt"):
        varmech.integrate(bare, q0=[0.0], p0=[1e-3], dt=0.05, steps=100_000, method="explicit_euler")


def test_newton_failure_raises_convergence_error_with_partial_trajectory():
    # V = |q|: at h = 1 from q0 = 0.001 the midpoint equation q1 = q0 - (h²/2) sign((q0 + q1)/2)
    # has no solution, and Newton's iterates flip sides for ever.
    model = varmech.MechanicalSystem(1, lambda q: abs(q[0]), np.sign)
    with pytest.raises(varmech.ConvergenceError, match="did not converge at step 1") as info:
        varmech.integrate(model, [0.001], [0.0], dt=1.0, steps=10, method="midpoint")
    err = info.value
    assert err.step == 1 and err.time == 0.0 and err.iterations == 50 and err.residual > 0.1
    assert err.partial.steps == 0 and len(err.partial) == 1
    # The iteration cap is the user's.
    with pytest.raises(varmech.ConvergenceError) as info:
        varmech.integrate(model, [0.001], [0.0], dt=1.0, steps=10, method="midpoint", newton_max_iterations=7)
    assert info.value.iterations == 7


@pytest.mark.parametrize("native", [True, False])
def test_a_step_beyond_a_fold_raises_spurious_branch_error(native):
    # Pendulum from rest at q0 = 3 with h = 3: the midpoint equation's derivative
    # -1/h - (h/4)cos(q̄) changes sign near the top, and Newton lands on a branch that jumps over
    # it although E < 1 (tests/rust/spurious_branch.rs has the theory).
    model = scenes.pendulum().model if native else examples.closure_of(scenes.pendulum())
    with pytest.raises(varmech.SpuriousBranchError, match="spurious branch at step 1 .*fold") as info:
        varmech.integrate(model, [3.0], [0.0], dt=3.0, steps=10, method="midpoint")
    err = info.value
    assert isinstance(err, varmech.ConvergenceError)
    assert err.step == 1 and err.time == 0.0 and len(err.partial) == 1


def test_newton_tolerance_sets_how_far_the_implicit_equations_are_solved():
    # A loose tolerance stops Newton earlier: fewer iterations, a larger error in L.
    scene = scenes.kepler()
    tight = varmech.integrate(scene, dt=scene.dt, steps=2000, method="midpoint")
    loose = varmech.integrate(scene, dt=scene.dt, steps=2000, method="midpoint", newton_tolerance=1e-6)
    assert loose.newton_iterations < tight.newton_iterations
    err = lambda t: np.max(np.abs(varmech.momentum(t, varmech.Rotation(spatial_dim=2)) - 0.8))  # noqa: E731
    assert err(tight) < 1e-14 < err(loose)
