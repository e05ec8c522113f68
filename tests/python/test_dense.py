"""Dense output (Trajectory.sol): the cubic Hermite interpolant's error falls as the fourth power
of the saved states' spacing, measured against the run's own states between them."""

import numpy as np
import pytest

import varmech

#: A method and step whose own error between the saved states is far below the interpolant's,
#: so that the differences measure the interpolant alone.
METHOD, DT = "kahan_li8", 0.005


def interpolation_errors(scene, steps, spacings):
    """max |q_sol − q| and |p_sol − p| at every step strictly between saved states, per spacing."""
    fine = varmech.integrate(scene, dt=DT, steps=steps, save_every=1, method=METHOD)
    errors = []
    for every in spacings:
        coarse = varmech.integrate(scene, dt=DT, steps=steps, save_every=every, method=METHOD)
        np.testing.assert_array_equal(coarse.q, fine.q[::every])
        between = np.arange(len(fine.t)) % every != 0
        q, p = coarse.sol(fine.t[between])
        errors.append((np.max(np.abs(q - fine.q[between])), np.max(np.abs(p - fine.p[between]))))
    return np.array(errors)


@pytest.mark.parametrize(
    ("scene", "steps"),
    [(varmech.scenes.harmonic_oscillator(), 2560), (varmech.scenes.kepler(0.3), 2560)],
    ids=["harmonic_oscillator", "kepler"],
)
def test_the_hermite_interpolant_is_of_order_four(scene, steps):
    spacings = [32, 16, 8]
    errors = interpolation_errors(scene, steps, spacings)
    orders = np.log2(errors[:-1] / errors[1:])
    # Cubic Hermite: local error Δ⁴/384·max|x⁗|; measured orders 3.99–4.00 for q and p on both.
    assert np.all(np.abs(orders - 4.0) < 0.25), orders


def test_the_interpolant_passes_through_the_saved_states_and_their_harmonic_values():
    s = varmech.scenes.harmonic_oscillator()
    traj = varmech.integrate(s, dt=0.01, steps=1000, save_every=10, method=METHOD)
    q, p = traj.sol(traj.t)
    np.testing.assert_array_equal(q, traj.q)
    np.testing.assert_array_equal(p, traj.p)
    t = np.linspace(0.0, 10.0, 77)
    q, p = traj.sol(t)
    assert q.shape == p.shape == (77, 1)
    # From q = 0, p = 1 (ω = 1): q = sin t, p = cos t. Δ = 0.1: error Δ⁴/384 ≈ 2.6e-7 at most.
    assert (s.q0[0], s.p0[0]) == (0.0, 1.0)
    assert np.max(np.abs(q[:, 0] - np.sin(t))) < 3e-7 and np.max(np.abs(p[:, 0] - np.cos(t))) < 3e-7


def test_forced_models_interpolate_with_the_force_in_p_dot(damped_oscillator):
    """The damped oscillator q̈ = −q − cq̇: ṗ = ∂L/∂q + f, and the interpolant keeps order 4."""
    model = damped_oscillator(0.3)
    fine = varmech.integrate(model, [1.0], [0.0], dt=0.002, steps=2000, method="galerkin6")
    errors = []
    for every in (40, 20):
        coarse = varmech.integrate(model, [1.0], [0.0], dt=0.002, steps=2000, method="galerkin6", save_every=every)
        between = np.arange(len(fine.t)) % every != 0
        _, p = coarse.sol(fine.t[between])
        errors.append(np.max(np.abs(p - fine.p[between])))
    assert abs(np.log2(errors[0] / errors[1]) - 4.0) < 0.3, errors


def test_bad_times_and_constrained_models_are_refused():
    s = varmech.scenes.harmonic_oscillator()
    traj = varmech.integrate(s, dt=0.1, steps=10)
    with pytest.raises(ValueError, match="^t: must lie within"):
        traj.sol(1.5)
    with pytest.raises(ValueError, match="^t: must be finite"):
        traj.sol([0.5, np.nan])
    pendulum = varmech.scenes.cartesian_pendulum()
    assert pendulum.model.constraints
    run = varmech.integrate(pendulum, dt=pendulum.dt, steps=4)
    with pytest.raises(ValueError, match="constraint forces"):
        run.sol(pendulum.dt)


def test_t_eval_on_the_grid_gives_the_runs_own_states_to_the_bit():
    s = varmech.scenes.double_pendulum()
    run = varmech.integrate(s, dt=0.01, steps=300, save_every=1)
    picked = [0, 7, 8, 150, 300]
    at = varmech.integrate(s, dt=0.01, steps=300, t_eval=run.t[picked])
    np.testing.assert_array_equal(at.q, run.q[picked])
    np.testing.assert_array_equal(at.p, run.p[picked])
    np.testing.assert_array_equal(at.newton, run.newton[picked])
    # The run itself goes on to its end: the same stepper state as without t_eval (the energy
    # check, which saw other states, aside).
    def state(traj):
        return varmech.Stepper.from_checkpoint(s, traj.checkpoint).checkpoint()

    assert at.steps == run.steps and state(at) == state(run)


@pytest.mark.parametrize(("method", "order", "h"), [("verlet", 2, 0.02), ("kahan_li6", 6, 0.2), ("midpoint", 2, 0.02)])
def test_t_eval_between_steps_has_the_methods_own_order(method, order, h):
    # The harmonic oscillator from q = 0, p = 1: q = sin t, p = cos t. Times off every grid.
    s = varmech.scenes.harmonic_oscillator()
    times = np.linspace(0.0137, 9.9, 25)
    errors = []
    for dt in (h, h / 2):
        steps = int(np.ceil(10.0 / dt))
        traj = varmech.integrate(s, [0.0], [1.0], dt=dt, steps=steps, method=method, t_eval=times)
        np.testing.assert_array_equal(traj.t, times)
        errors.append(max(np.max(np.abs(traj.q[:, 0] - np.sin(times))), np.max(np.abs(traj.p[:, 0] - np.cos(times)))))
    measured = np.log2(errors[0] / errors[1])
    assert abs(measured - order) < 0.3, (errors, measured)


def test_bad_t_eval_is_named():
    s = varmech.scenes.harmonic_oscillator()
    for bad, match in [
        ([0.5, 0.2], "sorted"),
        ([0.5, 20.0], "within the run's span"),
        ([np.nan], "finite"),
        ([], "non-empty"),
    ]:
        with pytest.raises(ValueError, match=f"^t_eval: .*{match}"):
            varmech.integrate(s, dt=0.1, steps=100, t_eval=bad)
    with pytest.raises(ValueError, match="^save_every: not with t_eval"):
        varmech.integrate(s, dt=0.1, steps=100, save_every=10, t_eval=[0.5])


def test_a_run_of_t_eval_times_goes_on_from_its_checkpoint_with_more_of_them():
    # The trajectory ends at its last sample; the run at its last step, where it goes on from.
    s = varmech.scenes.pendulum()
    first, second = np.linspace(0.013, 2.9, 17), np.linspace(5.013, 9.9, 23)
    whole = varmech.integrate(s, dt=0.01, steps=1000, t_eval=np.concatenate([first, second]))
    half = varmech.integrate(s, dt=0.01, steps=500, t_eval=first)
    more = varmech.integrate(half, t_end=10.0, t_eval=second)
    np.testing.assert_array_equal(more.t, second)
    np.testing.assert_array_equal(more.q, whole.q[len(first) :])
    np.testing.assert_array_equal(more.p, whole.p[len(first) :])
    assert more.steps == 1000
    with pytest.raises(ValueError, match=r"^t_eval: must lie within the run's span \[5.0"):
        varmech.integrate(half, t_end=10.0, t_eval=[4.0])
