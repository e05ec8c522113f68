"""Delayed forces (issue 36): a force of the state τ ago (``varmech.symbolic.Delayed``), read
from the run's own history:

- the delayed feedback oscillator q̈ + ω²q = −k q̇(t − τ): its stability boundary in k against
  the exact Hopf crossing of s² + ω² + k s e^(−sτ) = 0 (s = iΩ, Ωτ = π/2, k = (Ω² − ω²)/Ω),
  runs at 0.5% either side decaying and growing, for τ a whole number of steps (the method's own
  past) and not (the interpolant);
- the term acts only once its past exists (t ≥ τ): before, the run is the undelayed model's;
- the past read is the method's own force nodes where τ is a whole number of steps, their cubic
  Hermite interpolant otherwise: each step's momentum change against the force recomputed from
  the run's midpoints, to round-off;
- with the state before the run given (``history=``), q̈ = −k q(t − τ) from a constant past:
  exact (round-off) over [0, τ], where it reads the history alone, and at order 2 over
  [τ, 2τ], against the method of steps' closed form;
- the acceleration τ ago: each step's momentum change against the derivative of the parabola
  through the run's three velocities nearest t − τ, recomputed in NumPy, to round-off; and
  q̈ + q = −k q̈(t − τ), whose exact solution from the past cos ωs is cos ωt where ωτ = π and
  ω²(1 − k) = 1, at order 2;
- a stream resumed from its checkpoint, a Stepper in pieces and an ensemble: bit for bit the
  whole run (the history is part of the state);
- bad input named: τ ≤ 0, τ shorter than the step (1.5 steps for the acceleration), a method
  without a history, constraints, a delay as long as the run, a stored model of the earlier slots.
"""

import math

import numpy as np
import pytest
import sympy as sp

import varmech
from varmech.symbolic import Delayed

q, w, w_past, k = sp.symbols("q w w_past k")


def _oscillator(tau: float) -> varmech.Model:
    return varmech.symbolic.lagrangian(
        (w**2 - q**2) / 2, [q], [w], parameters={k: 0.5}, delayed=Delayed(tau, [-k * w_past], v_past=[w_past])
    )


def _critical_gain(tau: float, omega: float = 1.0) -> float:
    big_omega = math.pi / (2 * tau)
    return (big_omega**2 - omega**2) / big_omega


def _growth_rate(model, gain, dt=0.01, t_end=600.0):
    traj = varmech.integrate(model, [1.0], v0=[0.0], dt=dt, t_end=t_end, parameters={"k": gain})
    x, quarter = traj.q[:, 0], len(traj) // 4
    early, late = abs(x[quarter : 2 * quarter]).max(), abs(x[3 * quarter :]).max()
    return math.log(late / early) / (traj.t[3 * quarter] - traj.t[quarter])


@pytest.mark.parametrize("tau", [1.0, 1.0037])
def test_the_delayed_oscillators_stability_boundary_is_the_hopf_crossing(tau):
    model, critical = _oscillator(tau), _critical_gain(tau)
    assert _growth_rate(model, 0.995 * critical) < 0 < _growth_rate(model, 1.005 * critical)
    # far from it, the rates have the size the linearized roots give (decay, growth)
    assert _growth_rate(model, 0.5 * critical) < -0.05 and _growth_rate(model, 1.5 * critical) > 0.05


def test_the_delayed_term_acts_only_once_its_past_exists():
    tau, dt = 0.5, 0.01
    delayed = varmech.integrate(_oscillator(tau), [1.0], v0=[0.0], dt=dt, t_end=2.0)
    free = varmech.integrate(varmech.symbolic.lagrangian((w**2 - q**2) / 2, [q], [w], force=[0 * w]),
                             [1.0], v0=[0.0], dt=dt, t_end=2.0)
    before = int(round(tau / dt))
    # Steps 0 … τ/h − 1 have force nodes before τ: no past, no force; then the term acts.
    assert np.array_equal(delayed.q[: before + 1], free.q[: before + 1])
    assert abs(delayed.q[before + 2 :] - free.q[before + 2 :]).max() > 1e-4


x, x_past, t = sp.symbols("x x_past t")


def _retarded(tau: float, history=None, **kw) -> varmech.Model:
    """q̈ = −k q(t − τ) (L = ½q̇²), from the past q(s) = ``history`` (none: no past)."""
    return varmech.symbolic.lagrangian(
        w**2 / 2, [x], [w], t=t, parameters={k: 2.0}, delayed=Delayed(tau, [-k * x_past], q_past=[x_past]),
        history=history, **kw,
    )


def _steps_solution(t, tau, gain=2.0):
    """q̈ = −k q(t − τ) with q = 1 for t ≤ 0, by the method of steps over [0, 2τ]."""
    u = t - tau
    first = 1 - gain * t**2 / 2
    second = 1 - gain * tau**2 / 2 - gain * tau * u - gain * u**2 / 2 + gain**2 * u**4 / 24
    return np.where(t <= tau, first, second)


@pytest.mark.parametrize("tau", [0.5, 0.5037])
def test_the_past_is_the_methods_own_midpoints_or_their_hermite_interpolant(tau):
    # q̈ = −k q(t − τ), L = ½q̇²: the midpoint rule's p₊ − p = h f(t + h/2), f = −k q(t + h/2 − τ)
    # read from the force nodes (q̄ₘ, v̄ₘ) = ((qₘ + qₘ₊₁)/2, (qₘ₊₁ − qₘ)/h) at tₘ + h/2.
    h, gain = 0.01, 2.0
    traj = varmech.integrate(_retarded(tau), [1.0], v0=[0.3], dt=h, steps=300)
    qs, ps = traj.q[:, 0], traj.p[:, 0]
    mid, vel = (qs[:-1] + qs[1:]) / 2, np.diff(qs) / h
    force = np.diff(ps) / h
    for n in range(len(force)):
        s = n * h + h / 2 - tau
        older = math.floor(s / h - 0.5 + 1e-9)
        if older < 0:
            assert force[n] == pytest.approx(0.0, abs=1e-11), n
            continue
        x_ = (s - (older * h + h / 2)) / h
        if abs(x_) < 1e-9:
            past = mid[older]
        else:
            basis = ((1 + 2 * x_) * (1 - x_) ** 2, x_ * (1 - x_) ** 2 * h, x_**2 * (3 - 2 * x_), x_**2 * (x_ - 1) * h)
            past = np.dot(basis, (mid[older], vel[older], mid[older + 1], vel[older + 1]))
        assert force[n] == pytest.approx(-gain * past, rel=1e-10, abs=1e-11), n


@pytest.mark.parametrize("tau", [0.5, 0.5037])
def test_a_given_history_makes_the_delayed_term_act_from_the_start(tau):
    model = _retarded(tau, history=[sp.Integer(1)])
    assert model.has_history and not _retarded(tau).has_history
    errors = []
    for dt in (0.01, 0.005, 0.0025):
        traj = varmech.integrate(model, [1.0], v0=[0.0], dt=dt, steps=int(2 * tau / dt))
        error = np.abs(traj.q[:, 0] - _steps_solution(traj.t, tau))
        early = traj.t <= tau - dt
        # Over [0, τ] the past is the history's, constant: the midpoint rule is exact for the
        # parabola, to round-off, where τ is a whole number of steps (else the interpolant's
        # first steps between the history and the first node cost O(h²)).
        if tau == 0.5:
            assert error[early].max() < 1e-13, (dt, error[early].max())
        errors.append(error.max())
    orders = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
    assert all(abs(p - 2) < 0.2 for p in orders), (errors, orders)
    # Without a history nothing acts before τ: the state stays at rest.
    untold = varmech.integrate(_retarded(tau), [1.0], v0=[0.0], dt=0.01, steps=int(2 * tau / 0.01))
    assert np.all(untold.q[untold.t <= tau - 0.01, 0] == 1.0)


def test_a_history_with_a_delay_longer_than_the_run_is_taken():
    # The term reads the history throughout, q(s) = cos s: q̈ = −k cos(t − τ).
    tau, gain = 3.0, 2.0
    model = _retarded(tau, history=[sp.cos(t)])
    traj = varmech.integrate(model, [1.0], v0=[0.0], dt=0.01, t_end=2.0)
    exact = 1 + gain * (np.cos(traj.t - tau) - math.cos(tau) - traj.t * math.sin(tau))
    assert np.abs(traj.q[:, 0] - exact).max() < 1e-4


@pytest.mark.parametrize(
    ("history", "delayed", "match"),
    [
        ([sp.Integer(1)], False, r"^history: the state before the run, which only delayed forces read"),
        ([1, 2], True, r"^history: must give q\(t\) for each coordinate \(1\)"),
        ([x], True, r"^history\[0\]: the state before the run is a function of t alone"),
    ],
)
def test_a_bad_history_is_refused_naming_it(history, delayed, match):
    with pytest.raises(ValueError, match=match):
        if delayed:
            _retarded(0.5, history=history)
        else:
            varmech.symbolic.lagrangian(w**2 / 2, [x], [w], t=t, history=history)


a_past = sp.Symbol("a_past")


def _neutral(tau: float, gain: float, history=None) -> varmech.Model:
    """q̈ + q = −k q̈(t − τ), from the past ``history`` (none: no past)."""
    return varmech.symbolic.lagrangian(
        (w**2 - x**2) / 2, [x], [w], t=t, parameters={k: gain}, history=history,
        delayed=Delayed(tau, [-k * a_past], a_past=[a_past]),
    )


@pytest.mark.parametrize("tau", [0.5, 0.5037, 0.015])
def test_the_past_acceleration_is_the_parabola_through_the_three_nearest_velocities(tau):
    # The midpoint rule's p₊ − p = h(−q̄ + f), f = −k a(t + h/2 − τ), where a is the derivative of
    # the parabola through the velocities v̄ of the three force nodes nearest t − τ. τ = 1.5h is
    # the shortest delay it takes: the newest of them is the previous step's.
    h, gain = 0.01, 0.4
    traj = varmech.integrate(_neutral(tau, gain), [1.0], v0=[0.3], dt=h, steps=300)
    qs, ps = traj.q[:, 0], traj.p[:, 0]
    mid, vel = (qs[:-1] + qs[1:]) / 2, np.diff(qs) / h
    force = np.diff(ps) / h + mid
    acted = 0
    for n in range(len(force)):
        u = (n * h + h / 2 - tau - h / 2) / h          # t − τ in steps from the first node
        older = math.floor(u + 1e-9)
        c = older if u - older <= 0.5 + 1e-9 else older + 1
        y = u - c
        if c - 1 < 0:
            assert force[n] == pytest.approx(0.0, abs=1e-10), n
            continue
        assert c + 1 < n, n
        past = ((y - 0.5) * vel[c - 1] - 2 * y * vel[c] + (y + 0.5) * vel[c + 1]) / h
        assert force[n] == pytest.approx(-gain * past, rel=1e-9, abs=1e-10), n
        acted += 1
    assert acted > 200


def _neutral_cosine(tau: float) -> tuple[float, float]:
    """ω and k for which cos ωt solves q̈ + q = −k q̈(t − τ): ωτ = π, ω²(1 − k) = 1."""
    omega = math.pi / tau
    return omega, 1 - 1 / omega**2


@pytest.mark.parametrize("tau", [2.5, 2.5037])
def test_a_delayed_acceleration_converges_at_order_2_to_the_exact_periodic_solution(tau):
    omega, gain = _neutral_cosine(tau)
    model = _neutral(tau, gain, history=[sp.cos(omega * t)])
    errors = []
    for dt in (0.02, 0.01, 0.005):
        traj = varmech.integrate(model, [1.0], v0=[0.0], dt=dt, steps=math.ceil(3 * tau / dt))
        window = traj.t <= 2.9 * tau              # the same times at each step
        errors.append(np.abs(traj.q[window, 0] - np.cos(omega * traj.t[window])).max())
    # (Where τ is no whole number of steps, where t − τ falls between nodes varies with h, and
    # the error's constant with it: the orders scatter about 2 by 0.1.)
    orders = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
    assert errors[-1] < 1e-4 and all(abs(p - 2) < 0.15 for p in orders), (errors, orders)


def test_a_term_of_the_acceleration_acts_a_step_after_its_position_would():
    # Its past needs the velocities a step either side of t − τ: without a history it acts from
    # the step whose t − τ has a node before it, one step after a term of q(t − τ).
    tau, dt = 0.5, 0.01
    neutral = varmech.integrate(_neutral(tau, 0.4), [1.0], v0=[0.0], dt=dt, t_end=2.0)
    free = varmech.integrate(varmech.symbolic.lagrangian((w**2 - x**2) / 2, [x], [w], force=[0 * w]),
                             [1.0], v0=[0.0], dt=dt, t_end=2.0)
    before = int(round(tau / dt)) + 1
    assert np.array_equal(neutral.q[: before + 1], free.q[: before + 1])
    assert neutral.q[before + 1, 0] != free.q[before + 1, 0]


@pytest.mark.parametrize("acceleration", [False, True])
def test_a_delayed_run_resumes_from_its_checkpoint_bit_for_bit(tmp_path, acceleration):
    pytest.importorskip("h5py")
    model = _neutral(0.73, 0.4) if acceleration else _oscillator(0.73)
    whole = varmech.integrate(model, [1.0], v0=[0.0], dt=0.01, t_end=20.0)
    path = tmp_path / "delayed.h5"
    varmech.integrate(model, [1.0], v0=[0.0], dt=0.01, t_end=10.0, output=path)
    resumed = varmech.resume(path, t_end=20.0)
    assert np.array_equal(resumed.q[-1], whole.q[-1]) and np.array_equal(resumed.p[-1], whole.p[-1])


def test_a_stepper_in_pieces_and_an_ensemble_are_the_whole_run_bit_for_bit():
    model = _oscillator(0.5)
    whole = varmech.integrate(model, [1.0], v0=[0.0], dt=0.01, steps=2000)
    stepper = varmech.Stepper(model, [1.0], whole.p[0], dt=0.01)
    stepper.advance(700)
    stepper.step()
    stepper.advance(1299)
    assert np.array_equal(stepper.q, whole.q[-1]) and np.array_equal(stepper.p, whole.p[-1])
    runs = varmech.ensemble(model, np.ones((3, 1)), np.zeros((3, 1)), dt=0.01, steps=2000,
                            parameters={"k": [0.3, 0.5, 0.7]}, workers=2)
    assert np.array_equal(runs.q[1, -1], whole.q[-1])
    assert not np.array_equal(runs.q[0, -1], whole.q[-1])


@pytest.mark.parametrize(
    ("build", "run", "error", "match"),
    [
        (dict(tau=0.0), {}, ValueError, r"^delayed\[0\].tau: must be positive and finite"),
        (dict(tau="1"), {}, TypeError, r"^delayed\[0\].tau: expected a number"),
        (dict(v_past=[q]), {}, ValueError, r"^delayed\[0\].v_past: .* must be new symbols"),
        (dict(tau=0.005), {}, ValueError, r"^delays: τ = 0.005 is shorter than the step dt = 0.01"),
        (dict(tau=0.0149, a_past=[a_past]), {}, ValueError,
         r"^delays: τ = 0.0149 reads q̈\(t − τ\) and is shorter than 1.5 steps dt = 0.01.*take dt ≤ τ/1.5"),
        (dict(a_past=[w]), {}, ValueError, r"^delayed\[0\].a_past: .* must be new symbols"),
        ({}, dict(method="galerkin4"), ValueError, r"^method: galerkin4 does not take delayed forces"),
        ({}, dict(t_end=0.4), ValueError, r"^delayed: τ = 0.5 is as long as the run"),
    ],
)
def test_bad_delays_are_refused_naming_them(build, run, error, match):
    args = dict(tau=0.5, v_past=[w_past], a_past=None) | build
    force = [-k * w_past - (k * a_past if args["a_past"] else 0)]
    with pytest.raises(error, match=match):
        model = varmech.symbolic.lagrangian((w**2 - q**2) / 2, [q], [w], parameters={k: 0.5},
                                            delayed=Delayed(force=force, **args))
        varmech.integrate(model, [1.0], v0=[0.0], **({"dt": 0.01, "t_end": 2.0} | run))


def test_the_methods_that_take_delayed_forces_are_those_whose_features_say_so():
    # Every method that integrates the model runs it exactly where MethodInfo.features has
    # "delayed_forces"; the others are refused, naming the ones that do.
    model, taking = _oscillator(0.5), []
    for m in varmech.methods():
        try:
            varmech.integrate(model, [1.0], v0=[0.0], dt=0.01, steps=100, method=m.name)
        except ValueError as err:
            assert "delayed_forces" not in m.features, str(err)
            if "does not take delayed forces" in str(err):
                assert str(err).startswith(f"method: {m.name} does not take delayed forces; use midpoint or trapezoid")
            continue
        assert "delayed_forces" in m.features, m.name
        taking.append(m.name)
    assert taking == ["midpoint", "trapezoid"]


def test_a_model_stored_in_the_earlier_slots_is_refused_naming_delays():
    recipe = _oscillator(0.5)._recipe()
    assert varmech.model.from_recipe(recipe).delays == (0.5,)
    del recipe["delayed_layout"]
    with pytest.raises(ValueError, match=r"delays: its delayed forces were stored in the slots of an earlier varmech"):
        varmech.model.from_recipe(recipe)


def test_delays_with_constraints_are_refused():
    x, y, vx, vy = sp.symbols("x y vx vy")
    with pytest.raises(ValueError, match=r"^delayed: delayed forces are not taken with constraints"):
        varmech.symbolic.lagrangian((vx**2 + vy**2) / 2 - y, [x, y], [vx, vy], constraints=[x**2 + y**2 - 1],
                                    delayed=Delayed(0.5, [-vx, -vy]))
