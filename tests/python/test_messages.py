"""Messages that lead to the fix (issue 38): each provoked as a new user met it, the error naming
what the user passed and the next step that helps."""

import numpy as np
import pytest
import sympy as sp

import varmech


def test_a_closure_of_the_wrong_signature_is_named_when_the_model_is_made():
    with pytest.raises(TypeError, match=r"^potential: must be callable as potential\(q\), but it takes \(q, t\)"):
        varmech.MechanicalSystem(1, lambda q, t: 0.5 * q[0] ** 2, lambda q: q)
    with pytest.raises(TypeError, match=r"^gradient: must be callable as gradient\(q\)"):
        varmech.MechanicalSystem(1, lambda q: 0.5 * q[0] ** 2, lambda: 0.0)
    with pytest.raises(TypeError, match=r"^dl_dv: must be callable as dl_dv\(q, v, t\), but it takes \(q, v\)"):
        varmech.Lagrangian(1, lambda q, v, t: 0.5 * v[0] ** 2, dl_dv=lambda q, v: v)
    with pytest.raises(TypeError, match=r"^force: must be callable as force\(q, v, t\), got float"):
        varmech.Lagrangian(1, lambda q, v, t: 0.5 * v[0] ** 2, force=1.0)
    # Defaults, *args and builtins' unreadable signatures are taken as they are.
    varmech.MechanicalSystem(1, lambda q, scale=1.0: scale * q[0] ** 2, lambda *a: 2.0 * a[0])


def test_a_symbolic_l_whose_kinetic_energy_is_not_positive_definite_names_l_not_mass():
    x, y, v, w = sp.symbols("x y v w")
    with pytest.raises(ValueError, match=r"^L: ∂²L/∂q̇², the constant mass matrix derived from L, must be positive definite"):
        varmech.symbolic.lagrangian((v + w) ** 2 / 2 - x**2 / 2 - y**2 / 2, [x, y], [v, w])
    with pytest.raises(ValueError, match=r"^L: .*a negative one is that of −L"):
        varmech.symbolic.lagrangian(-(v**2) / 2 - x**2 / 2, [x], [v])
    # mechanical's mass is the user's own argument, and keeps its name.
    with pytest.raises(ValueError, match="^mass:"):
        varmech.symbolic.mechanical(x**2 / 2, [x], mass=-1)


def test_a_divergence_from_a_wrong_gradient_blames_the_gradient_not_dt():
    # ∇V with a curl, q + Jq for V = ½|q|²: a force that is no gradient pumps energy in, the
    # error grows within the stability limit, and a smaller dt cannot help. (A wrong gradient
    # that is the gradient of another potential, 40q, conserves that one: its error is a bounded
    # offset, which the run's check lets run, and the verdict judges.)
    turn = np.array([[0.0, 1.0], [-1.0, 0.0]])
    wrong = varmech.MechanicalSystem(2, lambda q: 0.5 * q @ q, lambda q: q + turn @ q)
    with pytest.raises(varmech.DivergenceError, match="and growing") as err:
        varmech.integrate(wrong, [1.0, 0.0], [0.0, 1.0], dt=0.1, steps=200)
    message = str(err.value)
    assert "the model's gradient disagrees with central differences" in message
    assert "reducing dt cannot help" in message and "; reduce dt" not in message
    assert err.value.partial.status == -1
    # A right gradient at too large a step is told to reduce dt, as before.
    right = varmech.MechanicalSystem(1, lambda q: 800.0 * q[0] ** 2, lambda q: 1600.0 * q)
    with pytest.raises(varmech.DivergenceError, match="; reduce dt") as err, pytest.warns(varmech.StabilityWarning):
        varmech.integrate(right, [1.0], [0.0], dt=0.1, steps=100)
    assert "disagrees" not in str(err.value)


def test_a_verdict_from_a_wrong_gradient_blames_the_gradient_not_dt():
    # The gradient of another potential (twice the pendulum's) runs bounded, conserving that
    # potential's energy: the pendulum's errs by its own size at every step, 0.01 as 0.001.
    pendulum = lambda q: float(9.81 * (1.0 - np.cos(q[0])))  # noqa: E731
    wrong = varmech.MechanicalSystem(1, pendulum, lambda q: 2.0 * 9.81 * np.sin(q))
    for dt in (0.01, 0.001):
        traj = varmech.integrate(wrong, [1.0], [0.0], dt=dt, steps=round(50 / dt), max_energy_error=None)
        energy = varmech.check_conservation(traj).energy
        assert energy.verdict == "failed" and energy.max_rel_error > 0.9
        assert energy.advice.startswith("the model's gradient disagrees with central differences at the first state")
        assert "reducing dt cannot help" in energy.advice and "reduce dt;" not in energy.advice
    right = varmech.MechanicalSystem(1, pendulum, lambda q: 9.81 * np.sin(q))
    energy = varmech.check_conservation(varmech.integrate(right, [1.0], [0.0], dt=0.01, steps=5000)).energy
    assert energy.verdict == "bounded" and energy.max_rel_error < 1e-3


def test_shake_on_a_linkage_asks_for_more_sweeps_not_a_smaller_step():
    # Four links: SHAKE's sweeps converge linearly, about 90 a step here; a tenth of the step
    # does not bring them under the default 50, more sweeps do.
    chain = varmech.scenes.planar_chain(4)
    for dt in (0.01, 0.001):
        with pytest.raises(varmech.ConvergenceError, match="more sweeps help .newton_max_iterations., or rattle") as err:
            varmech.integrate(chain, dt=dt, steps=20, method="shake")
        # The reported residual is the one that failed the tolerance, never one within it.
        assert err.value.residual > 1e-14 and err.value.iterations == 50
    traj = varmech.integrate(chain, dt=0.01, steps=20, method="shake", newton_max_iterations=500)
    assert np.all(np.isfinite(traj.q))


def test_shake_past_its_linearization_asks_for_a_smaller_step_not_more_sweeps():
    # A pendulum (a particle on the unit circle, g = 9.81) at hω = 0.94, inside Verlet's limit 2: the
    # step moves q₁ so far from SHAKE's linearization at q₀ that the sweeps no longer bring the
    # residual down, and 10⁴ of them fail as 50 do; a quarter of the step runs.
    pendulum = varmech.MechanicalSystem(
        2, lambda q: 9.81 * q[1], lambda q: np.array([0.0, 9.81]), mass=[1.0, 1.0],
        constraints=lambda q: np.array([0.5 * (q @ q - 1)]), constraint_jacobian=lambda q: q.reshape(1, 2),
        constraint_count=1,
    )
    for sweeps in (50, 10_000):
        with pytest.raises(varmech.ConvergenceError, match=r"a smaller step \(dt\) helps, or rattle") as err:
            varmech.integrate(pendulum, [1.0, 0.0], [0.0, 0.0], dt=0.3, steps=20, method="shake", newton_max_iterations=sweeps)
        assert "more sweeps" not in str(err.value)
    traj = varmech.integrate(pendulum, [1.0, 0.0], [0.0, 0.0], dt=0.075, steps=80, method="shake")
    assert np.abs(np.hypot(*np.asarray(traj.q).T) - 1).max() < 1e-12


def test_a_graze_verlet_once_reflected_into_the_floor_now_runs_and_is_judged_coarse():
    # A particle in a 3-d trap under gravity, bouncing on a floor (e = 0.38, reflected): at
    # hω = 1.4 under Verlet a graze whose momentum already left the floor was reflected into
    # it at t = 74, and the run ended advising the methods that hold a contact, Verlet first,
    # the method running (found by tests/python/test_properties.py). The graze takes no
    # impulse now: the run completes above the floor, "failed" with "reduce dt", and a quarter
    # of the step is bounded.
    k, m, g = np.array([4.392042690043614, 3.994136860012241, 2.802714012430567]), 0.6150760536066074, 2.328391456885223
    trap = varmech.MechanicalSystem(
        3, lambda q: float(0.5 * np.sum(k * q**2) + g * m * q[2]), lambda q: k * q + np.array([0.0, 0.0, g * m]), mass=[m] * 3
    )
    floor = varmech.Contact.wall(2, -1.3496865674122844, restitution=0.3845122916678635, law="reflect", name="floor")
    q0, v0 = [0.41795310749637893, -1.0, 1.5], np.array([-1.6522023387366032, -1.0784000949861097, 1.7152379765926584])
    dt = 0.5239129969430322
    verdicts = []
    for r in (1, 4):
        traj = varmech.integrate(trap, q0, m * v0, dt=dt / r, steps=188 * r, contacts=[floor])
        assert traj.status == 0 and np.asarray(traj.q)[:, 2].min() >= -1.3496865674122844 - 1e-12
        verdicts.append(varmech.check_conservation(traj).energy)
    assert verdicts[0].verdict == "failed" and "reduce dt" in verdicts[0].advice
    assert verdicts[1].verdict == "bounded"


def test_a_resting_contact_a_method_cannot_hold_names_the_methods_that_can():
    # A ball dropped on a floor with e = 0 under the implicit midpoint rule, which holds no
    # contact: after the impact gravity presses it through the floor at once.
    ball = varmech.MechanicalSystem(1, lambda q: 9.81 * q[0], lambda q: np.array([9.81]), name="ball")
    wall = varmech.Contact.wall(0, restitution=0.0)
    with pytest.raises(varmech.ContactError, match="crosses it again at once") as err:
        varmech.integrate(ball, [1.0], [0.0], dt=0.01, steps=300, method="midpoint", contacts=[wall])
    assert "verlet and its compositions" in str(err.value) and "hold such a contact closed" in str(err.value)
