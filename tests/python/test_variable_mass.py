"""Variable mass (issue 36): Meshchersky's reactive force from a declared mass flow
(``varmech.symbolic.MassFlow``), against the closed forms of the lecture and the source:

- the rocket in uniform gravity (Tsiolkovsky with gravity) at the method's order, its discrete
  momentum balance p₁ − p₀ = h(∂L/∂x + Q)(x̄, δx/h, t̄) at round-off for the midpoint rule, and
  a typed error at the step where its mass burns out, the run before it kept;
- Cayley's falling chain, ẋ² = (2g/3)(x³ − x₀³)/x², its acceleration → g/3, its energy lost to
  the pickup as the balance E − E₀ = W says;
- the snowplough (coasting: P = (m₀ + ρx)ẋ conserved to round-off; pushed: its closed form),
  the same plough in another coordinate (``at``), and the conveyor belt (kept at its speed by
  F = kv₀, half the power lost);
- the closure form (``varmech.reactive_force``) the symbolic model's motion;
- bad mass flows refused, naming ``mass_flow``.
"""

import math

import numpy as np
import pytest
import sympy as sp

import varmech
from varmech.symbolic import MassFlow, examples

G = 9.80665


def _order(errors, steps):
    return math.log(errors[0] / errors[1]) / math.log(steps[0] / steps[1])


def _rocket_exact(t, m0=10.0, k=0.4, c=400.0):
    m = m0 - k * t
    return c * (t + m / k * np.log(m / m0)) - G * t**2 / 2, c * np.log(m0 / m) - G * t


@pytest.mark.parametrize(("method", "order"), [("midpoint", 2), ("galerkin4", 4)])
def test_the_rocket_rises_as_tsiolkovsky_says_at_the_methods_order(method, order):
    errors, steps = [], [0.2, 0.1]
    for dt in steps:
        traj = varmech.integrate(examples.rocket(), [0.0], v0=[0.0], dt=dt, t_end=16.0, method=method)
        x, v = _rocket_exact(traj.t)
        errors.append(max(abs(traj.q[:, 0] - x).max(), abs(traj.v[:, 0] - v).max()))
    assert abs(_order(errors, steps) - order) < 0.15, errors


def test_the_rockets_discrete_momentum_balance_holds_to_round_off():
    # The midpoint rule's DEL: p₁ − p₀ = h(∂L/∂x + Q)(x̄, v̄, t̄) = h(−m(t̄)g − k(v̄ − c)), v̄ = δx/h.
    dt, m0, k, c = 0.01, 10.0, 0.4, 400.0
    traj = varmech.integrate(examples.rocket(), [0.0], v0=[0.0], dt=dt, t_end=15.0)
    x, p, t = traj.q[:, 0], traj.p[:, 0], traj.t
    mid = (t[1:] + t[:-1]) / 2
    impulse = dt * (-(m0 - k * mid) * G - k * (np.diff(x) / dt - c))
    balance = np.cumsum(np.diff(p) - impulse)
    assert abs(balance).max() < 1e-11 * abs(p).max()
    # and p is the rocket's momentum m(t)ẋ
    assert np.allclose(p, (m0 - k * t) * traj.v[:, 0], rtol=1e-12, atol=1e-12)


def test_a_burnt_out_rocket_stops_with_a_typed_error_at_that_step():
    with pytest.raises(varmech.VarmechError, match=r"mass_flow\[0\]: the mass is 0 at t = 25") as err:
        varmech.integrate(examples.rocket(), [0.0], v0=[0.0], dt=0.01, t_end=30.0)
    e = err.value
    assert e.step == 2500 and e.time == pytest.approx(25.0)
    assert e.partial.status == -1 and e.partial.t[-1] == pytest.approx(25.0)


def test_cayleys_chain_falls_as_he_found():
    x0, errors, steps = 0.1, [], [0.004, 0.002]
    for dt in steps:
        traj = varmech.integrate(examples.falling_chain(), [x0], v0=[0.0], dt=dt, t_end=3.0)
        x, v = traj.q[:, 0], traj.v[:, 0]
        errors.append(abs(v**2 - 2 * G / 3 * (x**3 - x0**3) / x**2).max())
    assert errors[1] < 1e-4 and abs(_order(errors, steps) - 2) < 0.15, errors
    # ẍ = g − ẋ²/x → g/3: at x = 40 x₀ the exact one is g/3 (1 + 2(x₀/x)³), 2 parts in 10⁵ above.
    a = G - v[-1] ** 2 / x[-1]
    assert abs(a / (G / 3) - 1) < 1e-4 and x[-1] > 40 * x0


def test_cayleys_chain_loses_to_the_pickup_what_the_balance_says():
    x0, dt = 0.1, 0.002
    traj = varmech.integrate(examples.falling_chain(), [x0], v0=[0.0], dt=dt, t_end=3.0, save_every=10)
    x = traj.q[:, 0]
    # E on the exact motion: ½ρxẋ² − ½ρgx² with ẋ² of Cayley's law.
    exact = G * ((x**3 - x0**3) / (3 * x) - x**2 / 2)
    energy = traj.energy()
    assert abs(energy - exact).max() < 1e-4 * abs(exact).max()
    # The pickup's loss: E − E₀ = W, the reactive force's work −∫½ρẋ³ dt, balanced to O(h²)
    # (h² = 4e-6), a tenth of the energy by the end.
    assert abs((energy - energy[0]) - traj.work).max() < 1e-6 * abs(energy).max()
    assert traj.work[-1] < -0.1 * abs(energy[-1])


def test_a_coasting_snowplough_keeps_its_momentum_to_round_off():
    traj = varmech.integrate(examples.snowplough(), [0.0], v0=[2.0], dt=0.01, t_end=20.0)
    P = (1.0 + 0.5 * traj.q[:, 0]) * traj.v[:, 0]
    assert abs(P - 2.0).max() < 1e-12
    assert abs(traj.p[:, 0] - 2.0).max() < 1e-12


@pytest.mark.parametrize("in_s", [False, True])
def test_a_pushed_snowplough_follows_its_closed_form(in_s):
    m0, rho, F, v0 = 1.0, 0.5, 0.3, 1.0
    if in_s:
        # The plough's position x = 2s: the body is at r(s) = 2s, J = 2 (``at``).
        s, w = sp.symbols("s w")
        m = m0 + rho * 2 * s
        model = varmech.symbolic.lagrangian(m * (2 * w) ** 2 / 2 + F * 2 * s, [s], [w],
                                            mass_flow=MassFlow(m, 0, at=[2 * s]))
        scale, start = 2.0, [0.0, v0 / 2]
    else:
        model, scale, start = examples.snowplough(push=F), 1.0, [0.0, v0]
    traj = varmech.integrate(model, [start[0]], v0=[start[1]], dt=0.05, t_end=10.0)
    t = traj.t
    exact = (np.sqrt(m0**2 + 2 * rho * (m0 * v0 * t + F * t**2 / 2)) - m0) / rho
    # The midpoint rule's momentum P = P₀ + Ft is exact (dP/dt = F), and so is its m₀x + ½ρx²,
    # whose increment P̄δt it integrates exactly: x to round-off, at any step.
    assert abs(scale * traj.q[:, 0] - exact).max() < 1e-12 * exact.max()


def test_the_conveyor_belt_kept_at_speed_loses_half_the_power():
    m0, k, v0, t_end = 1.0, 0.2, 1.0, 10.0
    traj = varmech.integrate(examples.conveyor_belt(m0, k, k * v0), [0.0], v0=[v0], dt=0.01, t_end=t_end)
    assert abs(traj.v[:, 0] - v0).max() < 1e-12
    # E = ½m(t)ẋ² − Fx changes by −∫∂L/∂t = −½kv₀²t: of the force's work kv₀²t, half goes into
    # the kinetic energy (½kv₀²t) and half is lost bringing the sand up to speed.
    kinetic_gain = 0.5 * (m0 + k * t_end) * v0**2 - 0.5 * m0 * v0**2
    force_work = k * v0 * traj.q[-1, 0]
    assert kinetic_gain == pytest.approx(force_work / 2, rel=1e-12)
    assert traj.work[-1] == pytest.approx(-0.5 * k * v0**2 * t_end, rel=1e-12)


def test_the_conveyor_belt_under_another_force_follows_its_closed_form():
    m0, k, F, v0 = 1.0, 0.2, 0.5, 0.3
    traj = varmech.integrate(examples.conveyor_belt(m0, k, F), [0.0], v0=[v0], dt=0.05, t_end=10.0)
    exact = (m0 * v0 + F * traj.t) / (m0 + k * traj.t)
    # d(mẋ)/dt = F is linear: the midpoint rule's momentum is exact at the steps.
    assert abs(traj.p[:, 0] - (m0 * v0 + F * traj.t)).max() < 1e-12
    assert abs(traj.v[:, 0] - exact).max() < 1e-12


def test_the_reactive_force_is_meshcherskys():
    x, w, t = sp.symbols("x w t")
    rho, c = sp.symbols("rho c")
    model = varmech.symbolic.lagrangian(rho * x * w**2 / 2, [x], [w], t=t, parameters={rho: 1.0, c: 2.0},
                                        mass_flow=MassFlow(rho * x, w - c))
    # Q_r = ṁu − ½ẋ²∂m/∂x, ṁ = ρẋ
    assert sp.simplify(model.expressions["force"][0] - (rho * w * (w - c) - rho * w**2 / 2)) == 0
    assert model.expressions["masses"] == (rho * x,)


@pytest.mark.parametrize(
    ("flow", "error", "match"),
    [
        ("not a flow", TypeError, r"^mass_flow: expected a varmech.symbolic.MassFlow"),
        (MassFlow(sp.Symbol("w"), 0), ValueError, r"^mass_flow\[0\].mass: must depend on the coordinates and t alone"),
        (MassFlow(1 + sp.Symbol("x"), [0, 0]), ValueError, r"^mass_flow\[0\].velocity: needs one component per component"),
        (MassFlow(1.0, 0, at=[sp.Symbol("x") * sp.Symbol("t")]), ValueError, r"^mass_flow\[0\].at: must depend on the coordinates alone"),
        (MassFlow(sp.Function("f")(sp.Symbol("x")), 0), ValueError, r"^mass_flow\[0\].mass"),
    ],
)
def test_bad_mass_flows_are_refused_naming_them(flow, error, match):
    x, w, t = sp.symbols("x w t")
    with pytest.raises(error, match=match):
        varmech.symbolic.lagrangian((1 + x) * w**2 / 2, [x], [w], t=t, mass_flow=flow)


def test_the_closure_form_is_the_symbolic_models_motion():
    m = lambda q, t: 10.0 - 0.4 * t  # noqa: E731
    rocket = varmech.Lagrangian(
        1, lambda q, v, t: m(q, t) * (v[0] ** 2 / 2 - G * q[0]), time_dependent=True,
        dl_dq=lambda q, v, t: np.array([-G * m(q, t)]), dl_dv=lambda q, v, t: m(q, t) * v,
        dl_dt=lambda q, v, t: -0.4 * (v[0] ** 2 / 2 - G * q[0]),
        force=varmech.reactive_force(m, lambda q, v, t: v - 400.0, mass_rate=lambda q, t: -0.4))
    closure = varmech.integrate(rocket, [0.0], v0=[0.0], dt=0.05, t_end=15.0)
    compiled = varmech.integrate(examples.rocket(), [0.0], v0=[0.0], dt=0.05, t_end=15.0)
    assert abs(closure.q - compiled.q).max() < 1e-9 and abs(closure.work - compiled.work).max() < 1e-8
    # Cayley's chain: m = ρx, ∂m/∂x = ρ, links joining at rest.
    chain = varmech.Lagrangian(
        1, lambda q, v, t: q[0] * v[0] ** 2 / 2 + G * q[0] ** 2 / 2,
        dl_dq=lambda q, v, t: np.array([v[0] ** 2 / 2 + G * q[0]]), dl_dv=lambda q, v, t: q[0] * v,
        force=varmech.reactive_force(lambda q, t: q[0], lambda q, v, t: np.zeros(1), mass_rate=lambda q, t: 0.0,
                                     mass_gradient=lambda q, t: np.ones(1)))
    a = varmech.integrate(chain, [0.1], v0=[0.0], dt=0.01, t_end=2.0)
    b = varmech.integrate(examples.falling_chain(), [0.1], v0=[0.0], dt=0.01, t_end=2.0)
    assert abs(a.q - b.q).max() < 1e-9 * abs(b.q).max()


def test_a_closure_mass_that_runs_out_stops_the_run_naming_mass():
    force = varmech.reactive_force(lambda q, t: 1.0 - q[0], lambda q, v, t: np.zeros(1), mass_rate=lambda q, t: 0.0)
    with pytest.raises(ValueError, match=r"^mass: the mass is -0.5 at t = 1"):
        force(np.array([1.5]), np.array([0.0]), 1.0)
    with pytest.raises(TypeError, match=r"^mass_rate: must be callable as mass_rate\(q, t\), got float"):
        varmech.reactive_force(lambda q, t: 1.0, lambda q, v, t: np.zeros(1), mass_rate=0.5)


def test_a_rocket_streamed_to_a_file_resumes_bit_for_bit(tmp_path):
    pytest.importorskip("h5py")
    whole = varmech.integrate(examples.rocket(), [0.0], v0=[0.0], dt=0.01, t_end=15.0)
    path = tmp_path / "rocket.h5"
    varmech.integrate(examples.rocket(), [0.0], v0=[0.0], dt=0.01, t_end=7.5, output=path)
    resumed = varmech.resume(path, t_end=15.0)
    assert np.array_equal(resumed.q[-1], whole.q[-1]) and np.array_equal(resumed.work[-1:], whole.work[-1:])
    # and the stored model is the rocket, burning out where it does
    with pytest.raises(varmech.VarmechError, match=r"mass_flow\[0\]"):
        varmech.resume(path, t_end=30.0)
