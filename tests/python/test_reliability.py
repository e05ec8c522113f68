"""Issue 64, the reliability list: allocations sized from user data refused by name, never an
abort; time carried so that a run takes its steps or refuses; an edited checkpoint's derived
values recomputed; generators checked against the model; tangent vectors that overflow, and
enormous stiffness, reported rather than NaN or 0. (The damaged file that hung resume and the
load that skipped resume's cross-check are in test_file_safety.py.) Cases that aborted the
interpreter run in a process of their own."""

import math
import struct
import subprocess
import sys

import numpy as np
import pytest

import varmech
from conftest import refix_crc
from varmech import scenes


def _in_a_process(code, timeout=60):
    """stdout and stderr of ``code`` run by a Python of its own (a case that aborted)."""
    try:
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        pytest.fail("hung")
    return done.returncode, done.stdout + done.stderr


_DELAYED = """
import sympy as sp, varmech
from varmech.symbolic import Delayed, lagrangian
q, w, q_past, t = sp.symbols("q w q_past t")
def model(tau):
    return lagrangian((w**2 - q**2) / 2, [q], [w], t=t, delayed=Delayed(tau, [-0.5 * q_past], q_past=[q_past]),
                      history=[sp.Integer(0)])
"""


def test_a_delay_whose_history_would_not_fit_is_refused_naming_delays(tmp_path):
    # delay-abort.py: τ = 1e10 at dt = 0.01, a history of 10¹² states, 16 TB: the ring's
    # allocation aborted the interpreter, and a stored model edited to that delay aborted resume.
    path = tmp_path / "d.h5"
    code = _DELAYED + f"""
import json, h5py
try:
    varmech.integrate(model(1e10), [1.0], v0=[0.0], dt=0.01, steps=100)
except ValueError as e:
    print("integrate", e)
varmech.integrate(model(0.5), [1.0], v0=[0.0], dt=0.01, steps=100, output={str(path)!r})
with h5py.File({str(path)!r}, "r+") as f:
    recipe = json.loads(f["model"][()])
    recipe["delays"] = [1e10]
    del f["model"]
    f.create_dataset("model", data=json.dumps(recipe))
try:
    varmech.resume({str(path)!r}, steps=10)
except ValueError as e:
    print("resume", e)
"""
    rc, out = _in_a_process(code)
    lines = [line for line in out.splitlines() if line.startswith(("integrate", "resume"))]
    assert rc == 0 and len(lines) == 2, out
    assert lines[0].startswith("integrate delays: needs ") and "τ = 1e10" in lines[0] and "larger dt" in lines[0], lines
    assert lines[1].startswith("resume path: ") and "model stored in it: delays: needs " in lines[1], lines


def test_t_eval_beyond_the_memory_available_is_refused_naming_it():
    # t-eval-memory.py: 10⁸ times under an address-space limit aborted the interpreter. Here 3·10⁷
    # (1.7 GB of rows) under a limit 1 GiB above what the process maps.
    code = """
import resource, numpy as np, varmech
mapped = int([l for l in open("/proc/self/status") if l.startswith("VmSize")][0].split()[1]) * 1024
resource.setrlimit(resource.RLIMIT_AS, (mapped + 2**30, resource.RLIM_INFINITY))
ho = varmech.scenes.harmonic_oscillator()
try:
    varmech.integrate(ho, dt=0.01, steps=100, t_eval=np.linspace(0, 1, 3 * 10**7))
except ValueError as e:
    print("refused", e)
"""
    rc, out = _in_a_process(code)
    assert rc == 0 and "refused t_eval: needs " in out and "pass fewer t_eval times" in out, out


def test_steps_below_the_resolution_of_the_time_are_refused_naming_dt():
    # large-t0.py and the fuzz's 1 112 cases: t0 of Unix time against steps of 0.1 µs, or 1e17
    # against 0.1, ended early and dropped rows with status 0.
    ho, kepler = scenes.harmonic_oscillator(), scenes.kepler()
    match = r"^dt: .* below the resolution of the time .* ulp\(t\)"
    for run in (
        lambda: varmech.integrate(ho, dt=1e-7, steps=1000, t0=1.7e9),
        lambda: varmech.integrate(kepler, dt=0.1, steps=1000, t0=1e17),
        lambda: varmech.integrate(kepler, dt=0.1, t_end=1e17 + 1600, t0=1e17),
        lambda: varmech.integrate(kepler, dt=0.1, steps=100, t0=2.0**52),
        lambda: varmech.Stepper(kepler, dt=1e-7, t0=1.7e9),
        lambda: varmech.ensemble(kepler.model, [kepler.q0] * 2, [kepler.p0] * 2, dt=0.1, steps=10, t0=1e17, progress=False),
    ):
        with pytest.raises(ValueError, match=match):
            run()
    # At 4 ulp every step is its own time: the asked steps and rows, the states of t0 = 0.
    ulp = math.ulp(1.7e9)
    traj = varmech.integrate(ho, dt=4 * ulp, steps=1000, t0=1.7e9)
    ref = varmech.integrate(ho, dt=4 * ulp, steps=1000)
    assert (traj.status, traj.steps, len(traj.t)) == (0, 1000, 1001)
    assert np.all(np.diff(traj.t) > 0) and np.array_equal(traj.q, ref.q)
    # Runs that go on past where the steps are told apart are refused the same way.
    edge = 2.0**50
    first = varmech.integrate(ho, dt=0.6, steps=4, t0=edge - 4.8)
    with pytest.raises(ValueError, match=match):
        varmech.integrate(first, steps=10)
    stepper = varmech.Stepper(ho, dt=0.6, t0=edge - 4.8)
    stepper.advance(7)
    with pytest.raises(ValueError, match=match):
        stepper.advance(2)
    assert stepper.steps == 7


def test_an_edited_checkpoints_coefficients_and_cached_force_are_refused():
    # checkpoint-values.py: every float of the payload scaled by 1.02, the CRC recomputed; the
    # stage coefficients and the cached force steered the continued run with status 0.
    k = scenes.kepler()
    tr = varmech.integrate(k, dt=k.dt, steps=2000, save_every=10, method="verlet")
    ref = varmech.integrate(k, dt=k.dt, steps=3000, save_every=10, method="verlet")
    ck = tr.checkpoint
    assert refix_crc(ck) == ck
    silent, refused = [], 0
    for i in range(12, len(ck) - 12):
        v = struct.unpack("<d", ck[i:i + 8])[0]
        if not 1e-3 <= abs(v) <= 1e3:
            continue
        bad = bytearray(ck)
        bad[i:i + 8] = struct.pack("<d", v * 1.02)
        edited = varmech.Trajectory(tr.t, tr.q, tr.p, tr.model, tr.method, tr.dt, tr.steps, tr.nfev, tr.newton, tr.work,
                                    checkpoint=refix_crc(bytes(bad)))
        try:
            more = varmech.integrate(edited, steps=1000, save_every=10)
        except ValueError as e:
            assert str(e).startswith("checkpoint: "), e
            refused += 1
            continue
        if not np.array_equal(more.q[-1], ref.q[-1]):
            silent.append((i, v))
    # The dt/2, dt, dt/2 of Verlet's stages and the two components of its cached force.
    assert silent == [] and refused >= 5, (silent, refused)


@pytest.mark.parametrize(
    "generator, why",
    [
        (varmech.Cyclic(7), r"Cyclic\(7\) does not apply to a model of 2 coordinates: its index must be below 2"),
        (varmech.Cyclic(2), r"Cyclic\(2\) does not apply to a model of 2 coordinates"),
        (varmech.Translation(0, spatial_dim=3), r"Translation\(axis=0, spatial_dim=3\) does not apply to a model of 2"),
        (varmech.Translation(2, spatial_dim=2), r"Translation\(axis=2, spatial_dim=2\) does not apply"),
        (varmech.Rotation(2, spatial_dim=3), r"Rotation\(axis=2, spatial_dim=3\) does not apply to a model of 2"),
        (varmech.Rotation(0, spatial_dim=1), r"Rotation\(axis=0, spatial_dim=1\) does not apply"),
    ],
)
def test_a_generator_that_does_not_fit_the_model_is_refused_naming_it(generator, why):
    # The fuzz's 736 cases: check_conservation(tr, [Cyclic(7)]) on Kepler raised IndexError.
    traj = varmech.integrate(scenes.kepler(), dt=0.01, steps=2)
    with pytest.raises(ValueError, match=f"^generators\\[1\\]: {why}"):
        varmech.check_conservation(traj, [varmech.Rotation(spatial_dim=2), generator])
    with pytest.raises(ValueError, match=f"^generator: {why}"):
        varmech.momentum(traj, generator)
    with pytest.raises(ValueError, match=f"^symmetries\\[0\\]: {why}"):
        varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: 0 * q, symmetries=[generator])


def _inverted(k):
    """V = −k q²/2, at its top q = 0 a state that stays there."""
    return varmech.MechanicalSystem(1, lambda q: -0.5 * k * float(q @ q), lambda q: -k * q)


def test_tangent_vectors_that_overflow_are_a_divergence_not_nan_exponents():
    # Verlet's map at the top of V = −10³⁰⁰q²/2 stretches a vector by about k·h² = 10³¹⁰ a step:
    # past any float in one step, whatever the re-orthonormalization. The exponents were NaN,
    # status 0; a stepper's vectors came back inf.
    model = _inverted(1e300)
    for method in ("verlet", "yoshida4"):
        with pytest.raises(varmech.DivergenceError, match="tangent vectors overflowed .* take a smaller dt"):
            varmech.lyapunov_spectrum(model, [0.0], [0.0], dt=1e5, steps=20, every=1, segments=2, method=method)
    with pytest.raises(varmech.DivergenceError, match="tangent vectors overflowed"):
        varmech.megno(model, [0.0], [0.0], dt=1e5, steps=20)
    stepper = varmech.Stepper(model, [0.0], [0.0], dt=1e5)
    with pytest.raises(varmech.DivergenceError, match="tangent vectors overflowed"):
        stepper.advance_tangent([1.0, 0.0], steps=5)
    # Where a step's stretch fits a float, the top exponent is the step map's own, ln(λ)/h.
    h, k = 1.0, 1e6
    found = varmech.lyapunov_spectrum(_inverted(k), [0.0], [0.0], dt=h, steps=400, every=1, k=1, segments=2)
    a = 1 + k * h * h / 2
    assert abs(found.exponents[0] / (math.log(a + math.sqrt(a * a - 1)) / h) - 1) < 0.01


@pytest.mark.parametrize("n", [1, 2, 3])
@pytest.mark.parametrize("k", [1e100, 1e200, 1e300, 1e306])
def test_the_fastest_frequency_at_enormous_stiffness_is_sqrt_k(n, k):
    # V = k|q|²/2: ω = √k. Two or more coordinates gave 0 from k = 1e200 on: the Lanczos
    # products' squares overflowed.
    model = varmech.MechanicalSystem(n, lambda q: 0.5 * k * float(q @ q), lambda q: k * q)
    assert abs(varmech.fastest_frequency(model, np.zeros(n)) / math.sqrt(k) - 1) < 1e-6


def test_a_fastest_frequency_whose_square_is_not_a_float_is_refused():
    # ω² = k/m = 10⁶⁰⁰: no float holds it, so the core cannot take it; a clear error, not 0.
    model = varmech.MechanicalSystem(2, lambda q: 0.5e300 * float(q @ q), lambda q: 1e300 * q,
                                     mass=lambda q: 1e-300 * np.eye(2), mass_derivative=lambda q: np.zeros((2, 2, 2)))
    with pytest.raises(ValueError, match="ω_max² at q, .* is past the largest float"):
        varmech.fastest_frequency(model, np.zeros(2))

