"""varmech.Stepper: its steps are integrate's, bit for bit; reset starts afresh; bad arguments
are named; failures leave the last good state."""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import varmech
from conftest import Boom, raising_after, refix_crc
from varmech import examples, scenes


def _same(a, b):
    """Bit for bit (so that -0.0 ≠ 0.0)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def _cases():
    kepler = scenes.kepler()
    closure = examples.kepler()
    chain = scenes.planar_chain(4)
    forced = scenes.damped_driven_pendulum()
    return [
        pytest.param(kepler.model, kepler.q0, kepler.p0, "verlet", id="native-verlet"),
        pytest.param(kepler.model, kepler.q0, kepler.p0, "midpoint", id="native-midpoint"),
        pytest.param(closure, kepler.q0, kepler.p0, "kahan_li6", id="closure-kahan_li6"),
        pytest.param(closure, kepler.q0, kepler.p0, "midpoint", id="closure-midpoint"),
        pytest.param(chain.model, chain.q0, chain.p0, "rattle", id="native-rattle"),
        pytest.param(forced.model, forced.q0, forced.p0, "midpoint", id="forced-midpoint"),
    ]


@pytest.mark.parametrize("model, q0, p0, method", _cases())
def test_stepping_n_times_is_integrate_bit_for_bit(model, q0, p0, method):
    n = 60
    traj = varmech.integrate(model, q0, p0, dt=0.02, steps=n, method=method, t0=0.5)
    one_by_one = varmech.Stepper(model, q0, p0, dt=0.02, method=method, t0=0.5)
    for _ in range(n):
        one_by_one.step()
    at_once = varmech.Stepper(model, q0, p0, dt=0.02, method=method, t0=0.5)
    at_once.advance(n // 2)
    at_once.advance(t_end=traj.t[-1])
    for stepper in (one_by_one, at_once):
        assert _same(stepper.q, traj.q[-1]) and _same(stepper.p, traj.p[-1])
        assert stepper.t == traj.t[-1] and stepper.steps == n and stepper.method == method
        assert stepper.force_evaluations == traj.nfev
        assert stepper.newton_iterations == traj.newton_iterations
        assert stepper.work == traj.work[-1]


@pytest.mark.parametrize("model, q0, p0, method", _cases())
def test_advance_after_reset_reproduces_a_fresh_run(model, q0, p0, method):
    stepper = varmech.Stepper(model, q0, p0, dt=0.02, method=method)
    stepper.advance(25)
    q1, p1, t1 = stepper.q, stepper.p, stepper.t
    stepper.advance(10)
    stepper.reset(q1, p1, t0=t1)
    stepper.dt = 0.013
    stepper.advance(30)
    fresh = varmech.integrate(model, q1, p1, dt=0.013, steps=30, method=method, t0=t1)
    assert _same(stepper.q, fresh.q[-1]) and _same(stepper.p, fresh.p[-1])
    assert stepper.t == fresh.t[-1] and stepper.steps == 30


def test_a_scene_gives_its_initial_state_and_velocities_give_the_momenta():
    scene = scenes.kepler()
    stepper = varmech.Stepper(scene, dt=0.01)
    assert _same(stepper.q, scene.q0) and _same(stepper.p, scene.p0) and stepper.t == 0.0
    assert stepper.method == scene.model.kind.default_method and stepper.model is scene.model
    from_velocities = varmech.Stepper(scene.model, scene.q0, v0=scene.p0, dt=0.01)
    assert _same(from_velocities.p, scene.p0)
    from_velocities.reset(scene.q0, v0=2 * np.asarray(scene.p0))
    assert _same(from_velocities.p, 2 * np.asarray(scene.p0))
    assert "kepler" in repr(stepper)


def test_the_state_is_a_copy():
    stepper = varmech.Stepper(scenes.kepler(), dt=0.01)
    q = stepper.q
    q[0] = 123.0
    assert stepper.q[0] != 123.0


@pytest.mark.parametrize(
    "kwargs, argument",
    [
        (dict(dt=0.0), "dt"),
        (dict(dt=-0.1), "dt"),
        (dict(dt=math.nan), "dt"),
        (dict(dt=math.inf), "dt"),
        (dict(q0=[0.4]), "q0"),
        (dict(q0=[0.4, math.nan]), "q0"),
        (dict(p0=[[0.0, 2.0]]), "p0"),
        (dict(p0=[0.0, math.inf]), "p0"),
        (dict(v0=[0.0, 2.0]), "p0, v0"),
        (dict(t0=math.nan), "t0"),
        (dict(method="leapfrog"), "method"),
        (dict(method="rattle"), "method"),
        (dict(newton_tolerance=0.0), "newton_tolerance"),
        (dict(newton_max_iterations=0), "newton_max_iterations"),
    ],
)
def test_bad_arguments_raise_value_error_naming_them(kepler, kwargs, argument):
    args = dict(q0=[0.4, 0.0], p0=[0.0, 2.0], dt=0.1) | kwargs
    with pytest.raises(ValueError, match=f"^{argument}:"):
        varmech.Stepper(kepler.model, **args)


def test_bad_arguments_to_a_stepper_leave_it_alone(kepler):
    stepper = varmech.Stepper(kepler, dt=0.01)
    stepper.advance(5)
    q, p, t = stepper.q, stepper.p, stepper.t
    for dt in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(ValueError, match="^dt:"):
            stepper.dt = dt
    with pytest.raises(TypeError, match="^dt: must be a number"):
        stepper.dt = "a"
    with pytest.raises(ValueError, match="^q0:"):
        stepper.reset([1.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="^p0:"):
        stepper.reset([1.0, 0.0], [0.0, math.nan])
    with pytest.raises(ValueError, match="^t0:"):
        stepper.reset([1.0, 0.0], [0.0, 1.0], t0=math.inf)
    with pytest.raises(ValueError, match="^steps:"):
        stepper.advance(-1)
    with pytest.raises(ValueError, match="^t_end:"):
        stepper.advance(t_end=stepper.t + 0.015)
    with pytest.raises(ValueError, match="^steps, t_end:"):
        stepper.advance()
    assert _same(stepper.q, q) and _same(stepper.p, p) and stepper.t == t and stepper.dt == 0.01 and stepper.steps == 5


def test_a_model_that_is_not_one_is_refused():
    with pytest.raises(TypeError, match="^model:"):
        varmech.Stepper("kepler", [0.0], [0.0], dt=0.1)  # type: ignore[arg-type]


def test_a_closure_exception_propagates_and_the_state_stays_at_the_last_good_step():
    gradient = raising_after(20, lambda q: q, "no more forces")
    model = varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2, gradient)
    stepper = varmech.Stepper(model, [1.0], [0.0], dt=0.1, method="verlet")
    reference = varmech.integrate(scenes.harmonic_oscillator().model, [1.0], [0.0], dt=0.1, steps=30, method="verlet")
    with pytest.raises(Boom, match="no more forces") as info:
        stepper.advance(30)
    good = stepper.steps
    assert 0 < good < 30 and info.value.step == good + 1
    assert info.value.time == pytest.approx(good * 0.1)
    np.testing.assert_allclose(stepper.q, reference.q[good], rtol=1e-15)
    np.testing.assert_allclose(stepper.p, reference.p[good], rtol=1e-15)
    assert stepper.t == pytest.approx(good * 0.1)


def test_a_divergence_raises_divergence_error_and_keeps_the_last_finite_state():
    stepper = varmech.Stepper(scenes.harmonic_oscillator(), dt=2.02, method="verlet")
    with pytest.raises(varmech.DivergenceError, match="diverged at step") as info:
        stepper.advance(100_000)
    assert info.value.step == stepper.steps + 1 > 1
    assert np.all(np.isfinite(stepper.q)) and np.all(np.isfinite(stepper.p))
    with pytest.raises(varmech.DivergenceError):
        stepper.step()


def test_ctrl_c_stops_advance_at_a_good_state(interrupt_after):
    stepper = varmech.Stepper(scenes.kepler(), dt=1e-3)
    timer, _ = interrupt_after(0.2)
    with pytest.raises(KeyboardInterrupt):
        stepper.advance(10**10)
    timer.join()
    assert 0 < stepper.steps < 10**10
    assert np.all(np.isfinite(stepper.q)) and stepper.t == pytest.approx(stepper.steps * 1e-3)
    stepper.step()


def test_every_path_that_goes_on_keeps_the_runs_forces_and_parameters(tmp_path):
    # Issue 32's audit: besides contacts (tests/python/test_impacts.py), the forces and the
    # parameters of a run change its motion; continuing in memory, resuming its file and a
    # stepper from its checkpoint each land bit for bit on the one run of the whole length.
    sp = pytest.importorskip("sympy")
    import varmech.symbolic as symbolic

    x, v, k, c = sp.symbols("x v k c")
    model = symbolic.lagrangian(v**2 / 2 - k * x**2 / 2, [x], [v], parameters={k: 1.0, c: 0.0}, force=[-c * v])
    run = dict(dt=0.01, method="midpoint", parameters={"k": 4.0, "c": 0.3})
    half = varmech.integrate(model, [1.0], [0.0], steps=100, **run)
    whole = varmech.integrate(model, [1.0], [0.0], steps=200, **run)
    assert not np.array_equal(whole.q[-1], varmech.integrate(model, [1.0], [0.0], dt=0.01, steps=200, method="midpoint").q[-1])
    assert np.array_equal(varmech.integrate(half, steps=100).q[-1], whole.q[-1])
    assert np.array_equal(varmech.resume(half.save(tmp_path / "half.h5"), steps=100).q[-1], whole.q[-1])
    stepper = varmech.Stepper.from_checkpoint(half.model, half.checkpoint)
    stepper.advance(100)
    assert np.array_equal(stepper.q, whole.q[-1]) and stepper.work == pytest.approx(whole.work[-1], rel=1e-12)


def test_a_crafted_checkpoint_is_refused_naming_it_never_a_panic():
    kepler = scenes.kepler()
    # The reproducer (issue 32): format 2, two payload bytes changed and its CRC recomputed.
    reproducer = (Path(__file__).parents[1] / "rust" / "crafted_checkpoint.hex").read_text().strip()
    with pytest.raises(ValueError, match="^checkpoint: written in checkpoint format 2, this varmech reads format 7"):
        varmech.Stepper.from_checkpoint(kepler, bytes.fromhex(reproducer))
    stepper = varmech.Stepper(kepler, dt=0.05, method="kahan_li8")
    stepper.advance(5)
    good = stepper.checkpoint()
    # q's length and values in the payload: one coordinate dropped, or one added, CRC recomputed.
    q = np.asarray(stepper.q).tobytes()
    at = good.index(b"\x02" + q)
    for crafted_q in (b"\x01" + q[:8], b"\x03" + q + q[:8]):
        crafted = refix_crc(good[:at] + crafted_q + good[at + 17 :])
        with pytest.raises(ValueError, match="^checkpoint: "):
            varmech.Stepper.from_checkpoint(kepler, crafted).advance(20)


def test_a_checkpoint_of_another_model_method_or_step_is_refused_naming_the_difference(tmp_path):
    oscillator = scenes.harmonic_oscillator(1.0)
    traj = varmech.integrate(oscillator, dt=0.01, steps=10)
    with pytest.raises(ValueError, match="^checkpoint: it is of another model"):
        varmech.Stepper.from_checkpoint(scenes.harmonic_oscillator(1.5), traj.checkpoint)
    kepler = varmech.integrate(scenes.kepler(), dt=0.01, steps=10)
    with pytest.raises(ValueError, match="^checkpoint: it is of another model"):
        varmech.Stepper.from_checkpoint(scenes.henon_heiles(), kepler.checkpoint)
    with pytest.raises(ValueError, match="^checkpoint: it is of a run of method verlet, not kahan_li8"):
        varmech.Stepper.from_checkpoint(oscillator, traj.checkpoint, method="kahan_li8")
    with pytest.raises(ValueError, match=r"^checkpoint: it is of a run of dt = 0.01, not 0.02"):
        varmech.Stepper.from_checkpoint(oscillator, traj.checkpoint, dt=0.02)
    # The same model built again, in another process, takes it and goes on bit for bit.
    path = tmp_path / "ck.bin"
    path.write_bytes(traj.checkpoint)
    script = (
        "import sys, numpy as np, varmech\n"
        "s = varmech.Stepper.from_checkpoint(varmech.scenes.harmonic_oscillator(1.0), open(sys.argv[1], 'rb').read(), method='verlet', dt=0.01)\n"
        "s.advance(10)\n"
        "sys.stdout.write(np.concatenate([s.q, s.p]).tobytes().hex())\n"
    )
    out = subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True, text=True, check=True).stdout
    whole = varmech.integrate(oscillator, dt=0.01, steps=20)
    assert out == np.concatenate([whole.q[-1], whole.p[-1]]).tobytes().hex()
