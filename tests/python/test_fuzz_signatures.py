"""The fuzz signatures of issue 32, one case per cause: each bad argument raises a ValueError or
TypeError whose message starts with the argument the user passed (or names the closure whose
result is wrong), never an OverflowError or a message naming nothing; strings are never read
as numbers; a closure's own exception propagates unchanged."""

import warnings

import numpy as np
import pytest

import varmech
from varmech import scenes

HUGE = 10**400


def _oscillator(**kwargs):
    return varmech.MechanicalSystem(2, lambda q: 0.5 * float(q @ q), lambda q: np.asarray(q, dtype=float), **kwargs)


def _lagrangian(dim=1, **kwargs):
    functions = dict(dl_dq=lambda q, v, t: -q, dl_dv=lambda q, v, t: np.asarray(v, dtype=float))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return varmech.Lagrangian(dim, lambda q, v, t: 0.5 * float(v @ v) - 0.5 * float(q @ q), **(functions | kwargs))


def _kepler_run():
    return varmech.integrate(scenes.kepler(), dt=0.1, steps=5)


# (what, the call, the exception, the start of its message)
CASES = [
    # Array arguments: an int beyond the float range, or strings, in the shared conversion.
    ("q0 huge (project)", lambda: varmech.project(scenes.rigid_body().model, [HUGE] * 4, []), ValueError, "q0: must be finite"),
    ("p0 huge (project)", lambda: varmech.project(scenes.rigid_body().model, scenes.rigid_body().q0, [HUGE] * 4),
     ValueError, "p0: must be finite"),
    ("q0 huge (integrate)", lambda: varmech.integrate(scenes.kepler().model, [HUGE] * 2, [0.0, 1.0], dt=0.1, steps=3),
     ValueError, "q0: must be finite"),
    ("v0 huge", lambda: varmech.integrate(scenes.kepler().model, [1.0, 0.0], v0=[HUGE, 0.0], dt=0.1, steps=3),
     ValueError, "v0: must be finite"),
    ("q strings", lambda: varmech.integrate(scenes.kepler().model, ["1.0", "0.0"], [0.0, 1.0], dt=0.1, steps=3),
     TypeError, "q0: must be numbers"),
    ("q bytes", lambda: varmech.integrate(scenes.kepler().model, [b"1", 0.0], [0.0, 1.0], dt=0.1, steps=3),
     TypeError, "q0: must be numbers"),
    ("check_derivatives q huge", lambda: varmech.check_derivatives(_oscillator(), [HUGE] * 2), ValueError, "q: must be finite"),
    ("symplecticity_defect q huge", lambda: varmech.symplecticity_defect(scenes.kepler().model, "verlet", [HUGE] * 2, [0.0, 1.0], 0.1),
     ValueError, "q: must be finite"),
    ("momentum v huge", lambda: scenes.kepler().model.momentum(1.0, [HUGE] * 2), ValueError, "v: must be finite"),
    ("momentum v strings", lambda: scenes.kepler().model.momentum(None, ["a"] * 2), TypeError, "v: must be numbers"),
    ("momentum q strings", lambda: scenes.kepler().model.momentum(["a"] * 2, [True] * 2), TypeError, "q: must be numbers"),
    ("mass a string", lambda: _oscillator(mass="heavy"), TypeError, "mass: must be numbers"),
    ("rayleigh a string", lambda: _lagrangian(rayleigh="x"), TypeError, "rayleigh: must be numbers"),
    # Scalar arguments.
    ("dt huge", lambda: varmech.integrate(scenes.kepler(), dt=HUGE, steps=3), ValueError, "dt: must be finite"),
    ("dt a string", lambda: varmech.integrate(scenes.kepler(), dt="0.1", steps=3), TypeError, "dt: must be a number"),
    ("symplecticity_defect dt huge", lambda: varmech.symplecticity_defect(scenes.kepler().model, "verlet", [1.0, 0.0], [0.0, 1.0], HUGE),
     ValueError, "dt: must be finite"),
    ("t_end a string", lambda: varmech.integrate(scenes.kepler(), dt=0.1, t_end="1.0"), TypeError, "t_end: must be a number"),
    ("t_end 1e308", lambda: varmech.integrate(scenes.kepler(), dt=0.1, t_end=1e308), ValueError, "t_end: 1e\\+308 is more than 2\\*\\*63 - 1 steps"),
    ("check_derivatives t a string", lambda: varmech.check_derivatives(_lagrangian(), [0.1], t="0"), TypeError, "t: must be a number"),
    # Integer arguments: negative, a float, or beyond the core's unsigned integers.
    ("Cyclic(-1)", lambda: varmech.momentum(_kepler_run(), varmech.Cyclic(-1)), ValueError, "index: must be an integer ≥ 0"),
    ("Cyclic(1.5)", lambda: varmech.momentum(_kepler_run(), varmech.Cyclic(1.5)), ValueError, "index: must be an integer"),
    ("Translation(-1, 2)", lambda: varmech.Translation(-1, 2), ValueError, "axis: must be an integer ≥ 0"),
    ("Rotation(spatial_dim=-2)", lambda: varmech.Rotation(spatial_dim=-2), ValueError, "spatial_dim: must be a positive integer"),
    ("Cyclic(2**64)", lambda: varmech.Cyclic(2**64), ValueError, "index: must be at most 2\\*\\*63 - 1"),
    ("dim 2**64", lambda: varmech.MechanicalSystem(2**64, lambda q: 0.0, lambda q: q),
     ValueError, "dim: must be at most"),
    ("Lagrangian dim 2**64", lambda: varmech.Lagrangian(2**64, lambda q, v, t: 0.0), ValueError, "dim: must be at most"),
    ("constraint_count -1", lambda: _oscillator(constraints=lambda q: q[:1], constraint_count=-1),
     ValueError, "constraint_count: must be a positive integer"),
    ("velocity_constraint_count -1", lambda: _oscillator(velocity_constraints=lambda q: np.ones((1, 2)), velocity_constraint_count=-1),
     ValueError, "velocity_constraint_count: must be a positive integer"),
    # method: a name (str), whatever else is given; the binding names it for every entry point.
    ("method an int", lambda: varmech.integrate(scenes.pendulum(), dt=0.05, steps=10, method=1), TypeError, "method: must be a method's name"),
    ("method bytes", lambda: varmech.integrate(scenes.pendulum(), dt=0.05, steps=10, method=b"verlet"), TypeError, "method: must be"),
    ("method a list", lambda: varmech.integrate(scenes.pendulum(), dt=0.05, steps=10, method=["verlet"]), TypeError, "method: must be"),
    ("Stepper method bytes", lambda: varmech.Stepper(scenes.pendulum(), dt=0.05, method=b"verlet"), TypeError, "method: must be"),
    ("symplecticity_defect method", lambda: varmech.symplecticity_defect(scenes.kepler().model, 2, [1.0, 0.0], [0.0, 1.0], 0.1),
     TypeError, "method: must be"),
    ("kind.admits method", lambda: scenes.kepler().model.kind.admits(None), TypeError, "method: must be"),
    # A closure's result read in Python is read as the core reads one, naming the closure.
    ("generator returns a string", lambda: varmech.momentum(_kepler_run(), lambda q: "x"), TypeError, "generator: xi\\(q\\) must return numbers"),
    ("gradient returns a string", lambda: varmech.check_derivatives(
        varmech.MechanicalSystem(2, lambda q: 0.5 * float(q @ q), lambda q: "abc"), [True] * 2), TypeError, "gradient\\(q\\) must return"),
    ("gradient returns bytes", lambda: varmech.check_derivatives(
        varmech.MechanicalSystem(2, lambda q: 0.5 * float(q @ q), lambda q: b"abc"), [0.0] * 2), TypeError, "gradient\\(q\\) must return"),
    ("gradient returns huge ints", lambda: varmech.check_derivatives(
        varmech.MechanicalSystem(2, lambda q: 0.5 * float(q @ q), lambda q: [HUGE] * 2), [0.0] * 2), TypeError, "gradient\\(q\\) must return"),
    ("L returns an array", lambda: varmech.integrate(
        varmech.Lagrangian(2, lambda q, v, t: 0.5 * v * v, dl_dq=lambda q, v, t: np.zeros(2), dl_dv=lambda q, v, t: np.asarray(v, dtype=float)),
        [-0.7, 2.0], [0.3, 1.1], dt=0.3, steps=3, method="midpoint"), TypeError, "lagrangian\\(q, v, t\\) must return a float"),
    ("force with rayleigh, wrong shape", lambda: varmech.integrate(
        _lagrangian(2, force=lambda q, v, t: np.zeros(0), rayleigh=np.eye(2) * 0.1), [-0.7, 1.1], v0=[0.0, -1.5], dt=0.3, steps=2,
        method="trapezoid"), ValueError, "force\\(q, v, t\\) returned an array of shape \\(0,\\)"),
    # Found by the fuzz of the newer features (test_fuzz.py): events, t_eval, checkpoints, ensembles.
    ("crossing k 2**64", lambda: varmech.events.crossing(2**64), ValueError, "k: must be at most 2\\*\\*63 - 1"),
    ("crossing k 1.5", lambda: varmech.events.crossing(1.5), ValueError, "k: must be an integer ≥ 0"),
    ("crossing value None", lambda: varmech.events.crossing(0, None), TypeError, "value: must be a number"),
    ("escape radius a string", lambda: varmech.events.escape("1"), TypeError, "radius: must be a number"),
    ("t_eval strings", lambda: varmech.integrate(scenes.kepler(), dt=0.05, steps=10, t_eval=["x"]), TypeError, "t_eval: must be numbers"),
    ("t_eval complex", lambda: varmech.integrate(scenes.kepler(), dt=0.05, steps=10, t_eval=1j), ValueError, "t_eval: must be numbers"),
    ("checkpoint a str", lambda: varmech.Stepper.from_checkpoint(scenes.kepler(), "x"), TypeError, "checkpoint: expected the bytes"),
    ("checkpoint an int", lambda: varmech.Stepper.from_checkpoint(scenes.kepler(), 5), TypeError, "checkpoint: expected the bytes"),
    ("ensemble q0 strings", lambda: varmech.ensemble(scenes.kepler(), [["x", "y"]], [[0.0, 1.0]], dt=0.1, steps=2, progress=False),
     TypeError, "q0: must be numbers"),
    ("ensemble q0 NaN", lambda: varmech.ensemble(scenes.kepler(), [[1.0, 0.0], [np.nan, 0.0]], [[0.0, 1.0]] * 2, dt=0.1, steps=2,
                                                 progress=False), ValueError, "q0: must be finite, got non-finite values for members \\[1\\]"),
    ("ensemble p0 inf", lambda: varmech.ensemble(scenes.kepler(), [[1.0, 0.0]], [[np.inf, 1.0]], dt=0.1, steps=2, progress=False),
     ValueError, "p0: must be finite"),
    ("nbody masses strings", lambda: scenes.nbody(["1", "1"], np.eye(2, 3), np.zeros((2, 3))), TypeError, "masses: must be numbers"),
    ("at_times t strings", lambda: varmech.integrate(scenes.harmonic_oscillator(), dt=0.1, steps=10).sol(["0.5"]),
     TypeError, "t: must be numbers"),
    ("routh cyclic_velocity x strings", lambda: varmech.routh(scenes.heavy_top(), [1, 2]).cyclic_velocity(["0.3"], [0.0]),
     TypeError, "x: must be numbers"),
    # The inverse Legendre transform at the initial state names the state's arguments.
    ("singular Hessian at q0, p0", lambda: varmech.integrate(
        _lagrangian(1, dl_dv=lambda q, v, t: np.ones(1)), [2.0], [2.0], dt=1.0, steps=0, method="midpoint"),
     ValueError, "q0, p0: the Hessian ∂²L/∂q̇² is singular"),
    ("singular Hessian at q0, v0", lambda: varmech.integrate(
        _lagrangian(1, dl_dv=lambda q, v, t: np.asarray(q, dtype=float)), [1.1], v0=[-0.7], dt=0.1, steps=1),
     ValueError, "q0, v0: the Hessian ∂²L/∂q̇² is singular"),
    ("singular Hessian at q, p (velocity)", lambda: _lagrangian(1, dl_dv=lambda q, v, t: np.ones(1)).velocity([1.0], [1.0]),
     ValueError, "q, p: the Hessian"),
]


@pytest.mark.parametrize("call, exception, message", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_bad_argument_is_named(call, exception, message):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(exception, match=f"^{message}"):
            call()


def test_bools_and_numpy_ints_stay_numbers():
    kepler = scenes.kepler()
    traj = varmech.integrate(kepler.model, np.array([1, 0], dtype=np.uint8), [True, False], dt=0.1, steps=np.uint8(3))
    assert traj.q.shape == (4, 2) and traj.q.dtype == np.float64
    assert varmech.Cyclic(np.int64(1)).spec().index == 1


class Mine(Exception):
    pass


def test_a_closures_own_exception_propagates_unchanged():
    def dl_dv(q, v, t):
        raise ValueError("mine, unchanged")

    # The start's Legendre transform names the state only for the core's own errors.
    model = _lagrangian(1, dl_dv=dl_dv)
    with pytest.raises(ValueError, match="^mine, unchanged$"):
        varmech.integrate(model, [1.0], [1.0], dt=0.1, steps=1)
    with pytest.raises(ValueError, match="^mine, unchanged$"):
        model.velocity([1.0], [1.0])

    def gradient(q):
        raise Mine("in check_derivatives")

    with pytest.raises(Mine, match="^in check_derivatives$"):
        varmech.check_derivatives(varmech.MechanicalSystem(1, lambda q: 0.0, gradient), [0.0])
