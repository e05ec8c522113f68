"""The energy balance of a Lagrangian that depends on t (issue 36): E = p·q̇ − L changes by
−∫∂L/∂t dt (with the forces' work), which the run tracks on its method's own quadrature
(−Σ∂L_d/∂t, ``traj.work``), so that E − W is judged as a conserved quantity is:

- a parametrically driven oscillator (closures): the balance error falls at the method's order
  (2 for the midpoint and trapezoidal rules, 4 for Galerkin's), to the differences' floor
  where ∂L/∂t is differenced;
- a pendulum whose support is driven up and down (SymPy, ∂L/∂t compiled): the balance
  bounded at order 2, the compiled ∂L/∂t and the closures' differenced one alike;
- the driven Duffing oscillator, its drive written as a force and as a term of L: the same
  motion, and both balances bounded at order 2 (the method's error, not a drift);
- a run streamed to a file keeps its work, and goes on from it bit for bit.
"""

import dataclasses
import math

import numpy as np
import pytest
import sympy as sp

import varmech
from varmech.symbolic._lower import lower
from varmech.symbolic._model import _compile

G = 9.81


def _parametric(dl_dt: bool = True) -> varmech.Lagrangian:
    """q̈ = −ω(t)²q, ω = 1 + ½ sin t."""

    def omega(t):
        return 1.0 + 0.5 * math.sin(t)

    with pytest.warns(UserWarning) if not dl_dt else _nothing():
        return varmech.Lagrangian(
            1,
            lambda q, v, t: 0.5 * v[0] ** 2 - 0.5 * omega(t) ** 2 * q[0] ** 2,
            dl_dq=lambda q, v, t: np.array([-omega(t) ** 2 * q[0]]),
            dl_dv=lambda q, v, t: v.copy(),
            dl_dt=(lambda q, v, t: -omega(t) * 0.5 * math.cos(t) * q[0] ** 2) if dl_dt else None,
            time_dependent=True,
        )


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *_):
        return False


def _balance_error(traj: varmech.Trajectory) -> float:
    e = traj.energy()
    return float(np.max(np.abs(e - e[0] - traj.work)))


def _orders(errors):
    return [math.log2(a / b) for a, b in zip(errors, errors[1:])]


@pytest.mark.parametrize(("method", "order"), [("midpoint", 2), ("trapezoid", 2), ("galerkin4", 4)])
def test_a_parametric_oscillators_balance_falls_at_the_methods_order(method, order):
    model = _parametric()
    errors = [_balance_error(varmech.integrate(model, [1.0], [0.0], dt=dt, t_end=20.0, method=method)) for dt in (0.05, 0.025, 0.0125)]
    assert all(abs(p - order) < 0.1 for p in _orders(errors)), errors
    traj = varmech.integrate(model, [1.0], [0.0], dt=0.025, t_end=200.0, method=method, save_every=10)
    report = varmech.check_conservation(traj)
    assert report.energy.name == "energy balance" and report.verdict == "bounded", str(report)
    # The energy itself is far from conserved: the balance carries it.
    assert np.ptp(traj.energy()) > 10 * report.energy.max_abs_error


def test_a_differenced_dl_dt_is_the_exact_ones_to_its_floor():
    exact, differenced = _parametric(), _parametric(dl_dt=False)
    a, b = (varmech.integrate(m, [1.0], [0.0], dt=0.025, t_end=20.0, method="galerkin4") for m in (exact, differenced))
    np.testing.assert_array_equal(a.q, b.q)
    # A central difference in t steps by ε^{1/3}·|t|: 1e-8 of the work at t = 20.
    assert np.max(np.abs(a.work - b.work)) < 1e-7 * np.max(np.abs(a.work))


def _driven_pendulum(length=0.8, lift=0.05, drive=7.0):
    """A pendulum whose support moves as y = a cos ωt (SymPy: ∂L/∂t compiled)."""
    theta, w, t = sp.symbols("theta w t")
    y = lift * sp.cos(drive * t)
    ydot = sp.diff(y, t)
    L = (length**2 * w**2 + ydot**2 + 2 * ydot * length * sp.sin(theta) * w) / 2 - G * (y - length * sp.cos(theta))
    return varmech.symbolic.lagrangian(L, [theta], [w], t=t), L, (theta, w, t)


def test_a_pendulum_on_a_driven_support_keeps_its_balance_bounded_with_a_compiled_dl_dt():
    model, L, (theta, w, t) = _driven_pendulum()
    assert model.time_dependent and "dl_dt" in model._spec.functions
    errors = [
        _balance_error(varmech.integrate(model, [0.6], v0=[0.0], dt=dt, t_end=10.0, method="midpoint"))
        for dt in (0.01, 0.005, 0.0025)
    ]
    assert all(abs(p - 2) < 0.1 for p in _orders(errors)), errors
    traj = varmech.integrate(model, [0.6], v0=[0.0], dt=0.005, t_end=100.0, method="midpoint", save_every=20)
    report = varmech.check_conservation(traj)
    assert report.energy.name == "energy balance" and report.verdict == "bounded", str(report)
    # The same L from closures, ∂L/∂t differenced: the same motion and, to the floor, the same work.
    f = sp.lambdify((theta, w, t), L)
    fq = sp.lambdify((theta, w, t), sp.diff(L, theta))
    fv = sp.lambdify((theta, w, t), sp.diff(L, w))
    with pytest.warns(varmech.DerivativeWarning, match="no dl_dt"):
        closures = varmech.Lagrangian(
            1,
            lambda q, v, s: f(q[0], v[0], s),
            dl_dq=lambda q, v, s: np.array([fq(q[0], v[0], s)]),
            dl_dv=lambda q, v, s: np.array([fv(q[0], v[0], s)]),
            time_dependent=True,
        )
    a = varmech.integrate(model, [0.6], v0=[0.0], dt=0.005, t_end=5.0, method="midpoint")
    b = varmech.integrate(closures, [0.6], v0=[0.0], dt=0.005, t_end=5.0, method="midpoint")
    np.testing.assert_allclose(b.q, a.q, rtol=0, atol=1e-11)
    np.testing.assert_allclose(b.work, a.work, rtol=0, atol=1e-8 * np.max(np.abs(a.work)))


@pytest.mark.parametrize("method", ["midpoint", "galerkin4", "galerkin6"])
def test_dl_dt_kept_from_the_gradients_gives_the_evaluated_ones_balance(method):
    # A compiled L of t has ∂L/∂t as its gradients' last output, kept from Newton's last
    # evaluation at the solution; the same model with 2n gradients evaluates ∂L/∂t at the
    # solution instead (a model stored before). One motion to the bit, one work to round-off.
    model, _, _ = _driven_pendulum()
    spec, symbols = model._spec, model._symbolic
    assert len(symbols.expressions["gradients"]) == 2 * spec.dim + 1
    slots = {s: i for i, s in enumerate((*symbols.q, *symbols.v, symbols.t))}
    gradients = lower(symbols.expressions["gradients"][: 2 * spec.dim], slots, {})
    evaluated = _compile(dataclasses.replace(spec, functions={**spec.functions, "gradients": gradients}))
    runs = [
        varmech._core.integrate(
            core, np.array([0.6]), np.array([0.0]), varmech._core.RunSpec(dt=0.01, steps=2000, method=method, max_energy_error=None)
        )
        for core in (model._core, evaluated)
    ]
    kept, other = runs
    np.testing.assert_array_equal(kept.q, other.q)
    np.testing.assert_array_equal(kept.p, other.p)
    assert np.max(np.abs(other.work)) > 1e-3
    # 2000 steps' sums, each term alike to a few ulps.
    np.testing.assert_allclose(kept.work, other.work, rtol=0, atol=1e-12 * np.max(np.abs(other.work)))


def test_the_driven_duffing_oscillator_as_a_force_and_as_a_term_of_l_has_one_motion_and_a_bounded_balance():
    # q̈ + q + q³ = F cos Ωt: the drive as a force, and as +qF cos Ωt in L.
    q, v, t = sp.symbols("q v t")
    amplitude, frequency = 0.3, 1.3
    autonomous = v**2 / 2 - q**2 / 2 - q**4 / 4
    forced = varmech.symbolic.lagrangian(autonomous, [q], [v], t=t, force=[amplitude * sp.cos(frequency * t)])
    driven = varmech.symbolic.lagrangian(autonomous + q * amplitude * sp.cos(frequency * t), [q], [v], t=t)
    assert forced.forced and not forced.time_dependent and driven.time_dependent and not driven.forced
    runs = {}
    for name, model in (("force", forced), ("term of L", driven)):
        errors = []
        for dt in (0.02, 0.01, 0.005):
            traj = varmech.integrate(model, [0.1], [0.0], dt=dt, t_end=40.0, method="midpoint")
            errors.append(_balance_error(traj))
            runs.setdefault(name, traj)
        assert all(abs(p - 2) < 0.15 for p in _orders(errors)), (name, errors)
        long = varmech.integrate(model, [0.1], [0.0], dt=0.01, t_end=400.0, method="midpoint", save_every=10)
        assert varmech.check_conservation(long).verdict == "bounded", name
    # The midpoint rule evaluates the force and L's driving term at the same t + h/2.
    np.testing.assert_allclose(runs["term of L"].q, runs["force"].q, rtol=0, atol=1e-12)


def test_a_streamed_time_dependent_run_keeps_its_work_and_goes_on_bit_for_bit(tmp_path):
    model = _parametric()
    whole = varmech.integrate(model, [1.0], [0.0], dt=0.05, steps=400, method="midpoint", save_every=10)
    first = varmech.integrate(model, [1.0], [0.0], dt=0.05, steps=200, method="midpoint", save_every=10, output=tmp_path / "run.h5")
    rest = varmech.resume(tmp_path / "run.h5", steps=200, model=model)
    assert first.work is not None and np.array_equal(rest.work[-1:], whole.work[-1:])
    assert np.array_equal(rest.q[-1], whole.q[-1])


def test_a_lagrangian_whose_t_cancels_is_autonomous_and_conserves_its_jacobi_integral():
    # A bead on a hoop spinning at Ω, written from inertial coordinates: t enters x and y, and
    # cancels from L (sin² + cos²). It is accepted as the separable model it is, its rest off
    # the axis at cos θ = g/(RΩ²), and Verlet keeps its energy function (the Jacobi integral).
    theta, w, t = sp.symbols("theta w t")
    radius, spin = 0.7, 6.0
    x, y, z = radius * sp.sin(theta) * sp.cos(spin * t), radius * sp.sin(theta) * sp.sin(spin * t), -radius * sp.cos(theta)
    vx, vy, vz = (sp.diff(e, theta) * w + sp.diff(e, t) for e in (x, y, z))
    bead = varmech.symbolic.lagrangian((vx**2 + vy**2 + vz**2) / 2 - G * z, [theta], [w], t=t)
    assert not bead.time_dependent and bead.separable
    (rest,) = varmech.equilibria(bead, [1.0])
    assert abs(math.cos(rest.q[0]) - G / (radius * spin**2)) < 1e-14 and rest.kind == "minimum"
    traj = varmech.integrate(bead, rest.q + 0.3, [0.0], dt=0.005, t_end=50.0, method="verlet", save_every=10)
    assert varmech.check_conservation(traj).verdict == "bounded"
