"""Models whose functions are native function pointers (numba cfunc, ctypes, cffi,
scipy.LowLevelCallable): they reproduce the native and closure models, a wrong signature is
refused when the model is built, a failing status stops the run with a typed error, and a run
lets go of the GIL."""

import ctypes
import gc
import math

import numpy as np
import pytest

import varmech
from conftest import releases_the_gil
from varmech import examples, pointers, scenes

M1, M2, L1, L2, G = 1.0, 2.0, 2.0, 3.0, 9.80665


@pytest.fixture(scope="module")
def numba_kepler():
    """V = −1/r and ∇V = q/r³ in the native scene's operations: r² = x² + y², k = 1/(r²·√r²)."""
    numba = pytest.importorskip("numba")

    @numba.cfunc(pointers.SIGNATURE)
    def potential(q, v, t, n, out):
        out[0] = -1.0 / math.hypot(q[0], q[1])
        return 0

    @numba.cfunc(pointers.SIGNATURE)
    def gradient(q, v, t, n, out):
        r2 = q[0] * q[0] + q[1] * q[1]
        k = 1.0 / (r2 * math.sqrt(r2))
        out[0] = k * q[0]
        out[1] = k * q[1]
        return 0

    return potential, gradient


@pytest.fixture(scope="module")
def numba_double_pendulum():
    """L, ∂L/∂q, ∂L/∂q̇ and the Hessians of varmech.examples.double_pendulum, as cfuncs."""
    numba = pytest.importorskip("numba")

    @numba.cfunc(pointers.SIGNATURE)
    def lagrangian(q, v, t, n, out):
        c = M2 * L1 * L2 * math.cos(q[0] - q[1])
        kinetic = (M1 + M2) * L1 * L1 * v[0] * v[0] + 2.0 * c * v[0] * v[1] + M2 * L2 * L2 * v[1] * v[1]
        out[0] = 0.5 * kinetic + (M1 + M2) * G * L1 * math.cos(q[0]) + M2 * G * L2 * math.cos(q[1])
        return 0

    @numba.cfunc(pointers.SIGNATURE)
    def dl_dq(q, v, t, n, out):
        k = M2 * L1 * L2 * v[0] * v[1] * math.sin(q[0] - q[1])
        out[0] = -k - (M1 + M2) * G * L1 * math.sin(q[0])
        out[1] = k - M2 * G * L2 * math.sin(q[1])
        return 0

    @numba.cfunc(pointers.SIGNATURE)
    def dl_dv(q, v, t, n, out):
        c = M2 * L1 * L2 * math.cos(q[0] - q[1])
        out[0] = (M1 + M2) * L1 * L1 * v[0] + c * v[1]
        out[1] = c * v[0] + M2 * L2 * L2 * v[1]
        return 0

    @numba.cfunc(pointers.SIGNATURE)
    def hessians(q, v, t, n, out):
        k = M2 * L1 * L2
        s, c = math.sin(q[0] - q[1]), math.cos(q[0] - q[1])
        w = k * v[0] * v[1] * c
        # ∂²L/∂q², ∂²L/∂q∂q̇ and ∂²L/∂q̇², each row-major.
        out[0], out[1] = -w - (M1 + M2) * G * L1 * math.cos(q[0]), w
        out[2], out[3] = w, -w - M2 * G * L2 * math.cos(q[1])
        out[4], out[5] = -k * s * v[1], -k * s * v[0]
        out[6], out[7] = k * s * v[1], k * s * v[0]
        out[8], out[9] = (M1 + M2) * L1 * L1, k * c
        out[10], out[11] = k * c, M2 * L2 * L2
        return 0

    return {"lagrangian": lagrangian, "dl_dq": dl_dq, "dl_dv": dl_dv, "hessians": hessians}


def kepler_model(potential, gradient):
    return varmech.MechanicalSystem(2, potential, gradient, symmetries=[varmech.Rotation(spatial_dim=2)])


def test_a_numba_kepler_runs_bit_for_bit_as_the_native_scene(numba_kepler):
    scene = scenes.kepler()
    model = kepler_model(*numba_kepler)
    assert isinstance(model._core, varmech._core.PointerSystem) and model.separable
    native = varmech.integrate(scene, dt=0.01, steps=1000, method="verlet")
    pointer = varmech.integrate(model, scene.q0, scene.p0, dt=0.01, steps=1000, method="verlet")
    np.testing.assert_array_equal(pointer.q, native.q)
    np.testing.assert_array_equal(pointer.p, native.p)
    # The declared rotation's momentum is the scene's, conserved to round-off.
    (momentum,) = varmech.check_conservation(pointer).momenta
    assert momentum.name == "L" and momentum.verdict == "conserved to round-off"


@pytest.mark.parametrize("wrap", ["ctypes", "LowLevelCallable", "cffi"])
def test_ctypes_cffi_and_low_level_callable_pointers_to_the_same_code_run_alike(numba_kepler, wrap):
    scene = scenes.kepler()
    if wrap == "ctypes":
        functions = [pointers.CFUNCTYPE(f.address) for f in numba_kepler]
    elif wrap == "LowLevelCallable":
        scipy = pytest.importorskip("scipy")
        functions = [scipy.LowLevelCallable(f.ctypes) for f in numba_kepler]
    else:
        ffi = pytest.importorskip("cffi").FFI()
        functions = [ffi.cast("int32_t(*)(const double *, const double *, double, int64_t, double *)", f.address)
                     for f in numba_kepler]
    native = varmech.integrate(scene, dt=0.01, steps=1000, method="verlet")
    pointer = varmech.integrate(kepler_model(*functions), scene.q0, scene.p0, dt=0.01, steps=1000, method="verlet")
    np.testing.assert_array_equal(pointer.q, native.q)


@pytest.mark.parametrize("exact_hessians", [True, False])
def test_a_numba_double_pendulum_matches_the_closure_model(numba_double_pendulum, exact_hessians):
    closure = examples.double_pendulum()
    functions = dict(numba_double_pendulum)
    if not exact_hessians:
        del functions["hessians"]
        closure = varmech.Lagrangian(2, closure.lagrangian, dl_dq=closure.dl_dq, dl_dv=closure.dl_dv)
    model = varmech.Lagrangian(2, functions.pop("lagrangian"), **functions)
    assert isinstance(model._core, varmech._core.PointerLagrangian) and not model.separable
    scene = scenes.double_pendulum()
    steps = 1000
    reference = varmech.integrate(closure, scene.q0, scene.p0, dt=0.01, steps=steps, method="midpoint")
    pointer = varmech.integrate(model, scene.q0, scene.p0, dt=0.01, steps=steps, method="midpoint")
    # NumPy's matrix products round differently from the cfuncs' expanded sums; the pendulum's
    # chaos grows that round-off to a few 1e-13 of the state's size over 1000 steps.
    for a, b in [(pointer.q, reference.q), (pointer.p, reference.p)]:
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(b))
    # With exact Hessians Newton takes the same iterations; with differenced Jacobians round-off
    # can add or save one in a few steps (as between closures and native scenes).
    assert abs(pointer.newton_iterations - reference.newton_iterations) <= (0 if exact_hessians else 0.001 * steps)


def test_pointer_functions_are_callable_from_python_and_checked_like_closures(numba_kepler, numba_double_pendulum):
    functions = dict(numba_double_pendulum)
    model = varmech.Lagrangian(2, functions.pop("lagrangian"), **functions)
    closure = examples.double_pendulum()
    q, v = np.array([0.3, -0.7]), np.array([0.4, 1.1])
    assert model.lagrangian(q, v, 0.0) == pytest.approx(closure.lagrangian(q, v, 0.0), rel=1e-15)
    for got, want in zip(model.hessians(q, v, 0.0), closure.hessians(q, v, 0.0)):
        np.testing.assert_allclose(got, want, rtol=1e-15, atol=1e-13)
    check = varmech.check_derivatives(model, q, v)
    assert check.ok and set(check.mismatch) == {"dl_dq", "dl_dv", "L_qq", "L_qv", "L_vv"}
    # A wrong derivative is caught as a closure's would be: ∂L/∂q̇ given for ∂L/∂q.
    wrong = varmech.Lagrangian(2, numba_double_pendulum["lagrangian"], dl_dq=numba_double_pendulum["dl_dv"],
                               dl_dv=numba_double_pendulum["dl_dv"])
    assert varmech.check_derivatives(wrong, q, v).worst[0] == "dl_dq"
    kepler = kepler_model(*numba_kepler)
    assert kepler.potential(np.array([3.0, 4.0])) == -0.2
    assert varmech.check_derivatives(kepler, [0.6, 0.8]).ok


def test_missing_derivatives_of_a_pointer_lagrangian_are_differenced(numba_double_pendulum):
    closure = examples.double_pendulum()
    with pytest.warns(varmech.DerivativeWarning, match="no dl_dq and no dl_dv"):
        model = varmech.Lagrangian(2, numba_double_pendulum["lagrangian"])
    q, v = np.array([0.3, -0.7]), np.array([0.4, 1.1])
    # Central differences: about 1e-10 relative accuracy.
    np.testing.assert_allclose(model.momentum(q, v), closure.dl_dv(q, v, 0.0), rtol=1e-8)
    traj = varmech.integrate(model, q, model.momentum(q, v), dt=0.01, steps=100, method="midpoint")
    reference = varmech.integrate(closure, q, closure.dl_dv(q, v, 0.0), dt=0.01, steps=100, method="midpoint")
    np.testing.assert_allclose(traj.q, reference.q, rtol=0, atol=1e-7)


def test_a_ctypes_callback_works_and_is_kept_alive_by_the_model():
    @pointers.CFUNCTYPE
    def potential(q, v, t, n, out):
        out[0] = -math.cos(q[0])
        return 0

    # The only reference to the gradient's thunk is the model's.
    model = varmech.MechanicalSystem(1, potential, pointers.CFUNCTYPE(lambda q, v, t, n, out: _sine(q, out)))
    gc.collect()
    traj = varmech.integrate(model, [0.0], [1.0], dt=0.01, steps=500, method="verlet")
    reference = varmech.integrate(examples.pendulum(), [0.0], [1.0], dt=0.01, steps=500, method="verlet")
    np.testing.assert_array_equal(traj.q, reference.q)


def _sine(q, out):
    out[0] = math.sin(q[0])
    return 0


def _wrong_signatures():
    numba = pytest.importorskip("numba")

    @numba.cfunc("float64(CPointer(float64), CPointer(float64), float64, int64, CPointer(float64))")
    def float_return(q, v, t, n, out):
        return 0.0

    @numba.cfunc("int32(CPointer(float64), float64, int64, CPointer(float64))")
    def four_arguments(q, t, n, out):
        return 0

    wrong_ctypes = ctypes.CFUNCTYPE(ctypes.c_int32, ctypes.POINTER(ctypes.c_double), ctypes.c_int64)(lambda q, n: 0)
    return {"float64 return": float_return, "four arguments": four_arguments, "raw int": float_return.address,
            "ctypes prototype": wrong_ctypes}


@pytest.mark.parametrize("case", ["float64 return", "four arguments", "raw int", "ctypes prototype"])
def test_a_wrong_signature_is_a_type_error_naming_the_argument_when_the_model_is_built(numba_kepler, case):
    wrong = _wrong_signatures()[case]
    potential, _ = numba_kepler
    with pytest.raises(TypeError, match=r"^gradient: expected a function pointer of signature int32_t f\(const double"):
        varmech.MechanicalSystem(2, potential, wrong)
    with pytest.raises(TypeError, match=r"^dl_dv: expected a function pointer of signature .*int32\(CPointer"):
        varmech.Lagrangian(2, potential, dl_dv=wrong)


def test_a_low_level_callable_or_cffi_pointer_of_another_signature_is_refused():
    scipy = pytest.importorskip("scipy")
    sine = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_double)(math.sin)
    wrong = scipy.LowLevelCallable(sine)
    with pytest.raises(TypeError, match=r"^potential: .*got a LowLevelCallable of signature 'double \(double\)'"):
        varmech.MechanicalSystem(1, wrong, wrong)
    ffi = pytest.importorskip("cffi").FFI()
    # The right parameters but an int64 status.
    wrong = ffi.cast("int64_t(*)(double *, double *, double, int64_t, double *)", ctypes.cast(sine, ctypes.c_void_p).value)
    with pytest.raises(TypeError, match=r"^potential: .*got a cffi object of type 'int64_t\(\*\)\(double \*"):
        varmech.MechanicalSystem(1, wrong, wrong)


def test_pointers_and_closures_do_not_mix(numba_kepler):
    potential, gradient = numba_kepler
    with pytest.raises(TypeError, match="^potential: function pointers cannot be mixed with Python closures \\(gradient\\)"):
        varmech.MechanicalSystem(2, potential, lambda q: q)
    with pytest.raises(TypeError, match="^dl_dq: function pointers cannot be mixed .*\\(lagrangian, dl_dv\\)"):
        varmech.Lagrangian(2, lambda q, v, t: 0.0, dl_dq=gradient, dl_dv=lambda q, v, t: v)
    with pytest.raises(TypeError, match="^gradient: function pointers give the potential and its gradient"):
        varmech.MechanicalSystem(2, potential)
    with pytest.raises(TypeError, match="^mass: function pointers give"):
        varmech.MechanicalSystem(2, potential, gradient, mass=pointers.CFUNCTYPE(gradient.address))
    with pytest.raises(TypeError, match="^rayleigh: not with function pointers"):
        varmech.Lagrangian(2, potential, dl_dq=gradient, rayleigh=0.1)


def test_a_nonzero_status_stops_the_run_with_an_error_naming_the_function():
    # The harmonic oscillator whose gradient fails (status 3) once q < 0.5.
    @pointers.CFUNCTYPE
    def potential(q, v, t, n, out):
        out[0] = 0.5 * q[0] * q[0]
        return 0

    @pointers.CFUNCTYPE
    def gradient(q, v, t, n, out):
        out[0] = q[0]
        return 3 if q[0] < 0.5 else 0

    model = varmech.MechanicalSystem(1, potential, gradient)
    dt = 0.1
    with pytest.raises(varmech.VarmechError, match=r"the function pointer gradient returned status 3") as info:
        varmech.integrate(model, [1.0], [0.0], dt=dt, steps=100, method="verlet")
    err = info.value
    # Störmer–Verlet's kick at the end of step k evaluates ∇V(q_k): the first q_k below 0.5,
    # with q_k = cos(kΔt) to O(Δt²), is at k = 11 (cos(1.0) = 0.54, cos(1.1) = 0.45).
    assert err.step == 11 and err.time == pytest.approx(10 * dt)
    assert f"at step {err.step} " in str(err)
    clean = varmech.integrate(examples.harmonic_oscillator(), [1.0], [0.0], dt=dt, steps=10, method="verlet")
    np.testing.assert_array_equal(err.partial.q, clean.q)
    assert err.partial.steps == 10 and np.all(err.partial.q >= 0.5)


@pytest.mark.parametrize("kind", ["separable", "lagrangian"])
def test_a_pointer_run_releases_the_gil(numba_kepler, numba_double_pendulum, kind):
    if kind == "separable":
        model, q0, p0 = kepler_model(*numba_kepler), scenes.kepler().q0, scenes.kepler().p0
        steps, method = 20_000_000, "verlet"
    else:
        functions = dict(numba_double_pendulum)
        model = varmech.Lagrangian(2, functions.pop("lagrangian"), **functions)
        q0, p0, steps, method = scenes.double_pendulum().q0, scenes.double_pendulum().p0, 1_000_000, "midpoint"
    assert releases_the_gil(
        lambda: varmech.integrate(model, q0, p0, dt=1e-3, steps=steps, save_every=steps, method=method)
    )
