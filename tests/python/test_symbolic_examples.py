"""The symbolic examples (varmech.symbolic.examples) as physics: the derived derivatives of each
twin agree with the closure examples' hand-written ones and with central differences
(check_derivatives); the elastic pendulum conserves its energy and swings at the linear
theory's frequencies; the bead on the rotating hoop conserves its Jacobi integral, not its
inertial energy, and rests at its relative equilibrium; the closed-form Routhian of the heavy
top is the textbook one and runs as the numerical Routh reduction. The trajectories of the
twins against their native scenes are in test_symbolic.py. Needs the binding's CompiledModel."""

import math
import pickle

import numpy as np
import pytest

sp = pytest.importorskip("sympy")
_core = pytest.importorskip("varmech._core")
if not hasattr(_core, "CompiledModel"):
    pytest.skip("the binding has no CompiledModel", allow_module_level=True)

import varmech  # noqa: E402
import varmech.symbolic as symbolic  # noqa: E402
from varmech import examples, scenes  # noqa: E402
from varmech._catalogue import DECLARED  # noqa: E402
from varmech.analysis.baselines import Rhs  # noqa: E402
from varmech.symbolic import examples as symbolic_examples  # noqa: E402

# ------------------------------------------------------------------ derivatives


def lambdified(model, name):
    """The model's derived function ``name`` as f(q, v, t) -> array, at its parameters."""
    symbols = {s.name: s for e in model.expressions[name] for s in e.free_symbols}
    parameters = [symbols.get(p, sp.Symbol(p)) for p in model.parameters]
    f = sp.lambdify([*model.q, *model.v, model.t, *parameters], list(model.expressions[name]), "numpy")
    values = list(model.parameters.values())
    return lambda q, v, t: np.array(f(*q, *v, t, *values), dtype=float)


def closure_of(model):
    """The symbolic model's derived expressions as a closure model, for check_derivatives."""
    n = model.dim
    if model.kind_name == "separable":
        potential = lambdified(model, "potential")
        return varmech.MechanicalSystem(
            n, lambda q: float(potential(q, np.zeros(n), 0.0)[0]), lambda q: lambdified(model, "gradient")(q, q, 0.0)
        )
    gradients, hessians = lambdified(model, "gradients"), lambdified(model, "hessians")
    return varmech.Lagrangian(
        n,
        lambda q, v, t: float(lambdified(model, "lagrangian")(q, v, t)[0]),
        dl_dq=lambda q, v, t: gradients(q, v, t)[:n],
        dl_dv=lambda q, v, t: gradients(q, v, t)[n:],
        hessians=lambda q, v, t: tuple(hessians(q, v, t).reshape(3, n, n)),
    )


#: The scenes declared with a symbolic twin (varmech._catalogue).
TWINS = [name for name, declared in DECLARED.items() if declared.symbolic]


def test_the_symbolic_twins_are_those_declared():
    assert len(TWINS) == 9
    for name in scenes.CATALOGUE:
        if name not in TWINS:
            with pytest.raises(ValueError, match=name):
                symbolic_examples.symbolic_of(scenes.get(name))


@pytest.mark.parametrize("name", TWINS)
def test_derivatives_agree_with_the_hand_written_ones_and_with_differences(name):
    scene = scenes.get(name)
    twin, hand = symbolic_examples.symbolic_of(scene), examples.closure_of(scene)
    n = twin.dim
    rng = np.random.default_rng(14)
    # States around the scene's initial one (away from r = 0 and sin θ = 0).
    for _ in range(8):
        q = scene.q0 + rng.uniform(-0.2, 0.2, n)
        v = rng.uniform(-1.5, 1.5, n)
        t = float(rng.uniform(0.0, 10.0))
        if twin.kind_name == "separable":
            gradient = lambdified(twin, "gradient")(q, v, t)
            np.testing.assert_allclose(gradient, hand.gradient(q.copy()), rtol=1e-14, atol=1e-14)
        else:
            gradients = lambdified(twin, "gradients")(q, v, t)
            assert float(lambdified(twin, "lagrangian")(q, v, t)[0]) == pytest.approx(
                hand.lagrangian(q, v, t), rel=1e-14
            )
            np.testing.assert_allclose(gradients[:n], hand.dl_dq(q, v, t), rtol=1e-13, atol=1e-13)
            np.testing.assert_allclose(gradients[n:], hand.dl_dv(q, v, t), rtol=1e-13, atol=1e-13)
            if hand.hessians is not None:
                exact = np.concatenate([h.ravel() for h in hand.hessians(q, v, t)])
                np.testing.assert_allclose(lambdified(twin, "hessians")(q, v, t), exact, rtol=1e-13, atol=1e-13)
            if hand.force is not None:
                np.testing.assert_allclose(lambdified(twin, "force")(q, v, t), hand.force(q, v, t), rtol=1e-14)
            # The core runs the same derivatives: the momentum and ∂L/∂q of the compiled tapes.
            np.testing.assert_allclose(twin.momentum(q, v, t), hand.dl_dv(q, v, t), rtol=1e-13, atol=1e-13)
            np.testing.assert_allclose(twin._derivative("dl_dq", q, v, t), hand.dl_dq(q, v, t), rtol=1e-13, atol=1e-13)
        check = varmech.check_derivatives(closure_of(twin), q, v, t)
        assert check.ok and check.worst[1] <= 1e-8, check


# ------------------------------------------------------------------ the elastic pendulum

M, K, L0, G = 1.0, 10.0, 1.0, 9.80665
L_EQ = L0 + M * G / K


def frequency(t, x):
    """The angular frequency of the oscillation x(t) about 0, from its zero crossings (linearly
    interpolated): π over the mean time between consecutive crossings."""
    i = np.nonzero(np.sign(x[:-1]) * np.sign(x[1:]) < 0)[0]
    crossings = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    return math.pi * (len(crossings) - 1) / (crossings[-1] - crossings[0])


def test_elastic_pendulum_conserves_its_energy():
    model = symbolic_examples.elastic_pendulum()
    assert model.parameters == {"m": M, "k": K, "l0": L0, "g": G}
    assert (model.kind_name, model.cyclic, model.time_dependent) == ("lagrangian", (), False)
    # A large swing, where the radial and angular motions exchange energy.
    traj = varmech.integrate(model, [1.2, 1.0], [0.0, 0.0], dt=0.01, steps=20_000, method="midpoint")
    report = varmech.check_conservation(traj)
    assert report.verdict in ("conserved to round-off", "bounded"), report
    assert report.energy.max_rel_error <= 1e-3, report


def test_elastic_pendulum_small_oscillations_have_the_linear_frequencies():
    h = 0.01
    model = symbolic_examples.elastic_pendulum()
    # Both modes at amplitude 10⁻³ about the hanging rest r = l_eq, θ = 0, for t = 100.
    traj = varmech.integrate(model, [L_EQ * (1 + 1e-3), 1e-3], [0.0, 0.0], dt=h, steps=10_000, method="midpoint")
    for x, omega in [(traj.q[:, 0] - L_EQ, math.sqrt(K / M)), (traj.q[:, 1], math.sqrt(G / L_EQ))]:
        measured = frequency(traj.t, x)
        # The linear theory, to 1e-4: the midpoint rule's own frequency error is −(ωh)²/12
        # (8.3e-5 radially at h = 0.01; measured −8.40e-5 radially, −4.22e-5 angularly) ...
        assert abs(measured / omega - 1) <= 1e-4, (measured, omega)
        # ... and to 1e-5 the rule's frequency of the linear oscillator, (2/h)·atan(ωh/2)
        # (measured within 7e-7 radially, 1e-6 angularly).
        assert abs(measured / (2 / h * math.atan(omega * h / 2)) - 1) <= 1e-5, (measured, omega)


# ------------------------------------------------------------------ the bead on the rotating hoop


def test_rotating_hoop_lagrangian_from_the_inertial_position():
    model = symbolic_examples.rotating_hoop()
    th, om = model.q[0], model.v[0]
    m, R, W, g = sp.symbols("m R Omega g", positive=True)
    expected = m * R**2 * (om**2 + W**2 * sp.sin(th) ** 2) / 2 + m * g * R * sp.cos(th)
    assert sp.simplify(model.L - expected) == 0
    # The explicit t of the rotating position cancels: L is autonomous, separable with the
    # constant mass mR² and the effective potential V_eff = −½mR²Ω² sin²θ − mgR cos θ.
    assert (model.kind_name, model.time_dependent) == ("separable", False)
    assert model.expressions["mass"] == (m * R**2,)
    assert (
        sp.simplify(model.expressions["potential"][0] + m * R**2 * W**2 * sp.sin(th) ** 2 / 2 + m * g * R * sp.cos(th))
        == 0
    )


def test_rotating_hoop_conserves_its_jacobi_integral_not_its_inertial_energy():
    m, R, W, g = 1.0, 1.0, 5.0, G
    model = symbolic_examples.rotating_hoop()
    traj = varmech.integrate(model, [0.3], [0.0], dt=0.001, steps=20_000, method="midpoint")
    theta, omega = traj.q[:, 0], traj.p[:, 0] / (m * R**2)
    # h = pθ̇ − L = ½mR²(θ̇² − Ω² sin²θ) − mgR cos θ, the energy in the rotating frame.
    h = 0.5 * m * R**2 * (omega**2 - W**2 * np.sin(theta) ** 2) - m * g * R * np.cos(theta)
    E, _, _ = _core.energy_terms(model._core, traj.t, traj.q, traj.p)
    np.testing.assert_allclose(E, h, rtol=1e-13, atol=1e-13 * abs(h[0]))
    assert np.max(np.abs(h - h[0])) <= 1e-6 * abs(h[0])  # measured 7.3e-7 (midpoint, h = 0.001)
    # The report names it: the t of the inertial position cancelled (a moving frame).
    report = varmech.check_conservation(traj)
    assert model.energy_name == report.energy.name == "Jacobi integral"
    assert report.verdict in ("conserved to round-off", "bounded") and "Jacobi integral verdict" in str(report)
    assert pickle.loads(pickle.dumps(model)).energy_name == "Jacobi integral"
    # The same bead in L's simplified form, given without t, is an energy like any other.
    simplified = sp.trigsimp(model.L)
    given = {s: model.parameters[s.name] for s in simplified.free_symbols if s.name in model.parameters}
    assert varmech.symbolic.lagrangian(simplified, model.q, model.v, parameters=given).energy_name == "energy"
    # The inertial energy T + V = h + mR²Ω² sin²θ changes by the motor's work: the bead swings
    # from θ = 0.3 through its relative equilibrium and back.
    inertial = 0.5 * m * R**2 * (omega**2 + W**2 * np.sin(theta) ** 2) - m * g * R * np.cos(theta)
    assert np.ptp(inertial) >= 0.5 * m * R**2 * W**2 * (np.sin(theta).max() ** 2 - math.sin(0.3) ** 2) > 1.0


def test_rotating_hoop_rests_at_its_relative_equilibrium():
    R, W, g = 1.0, 5.0, G
    model = symbolic_examples.rotating_hoop()
    rest = math.acos(g / (R * W**2))
    for method in ("midpoint", "verlet"):
        traj = varmech.integrate(model, [rest], [0.0], dt=0.01, steps=1000, method=method)
        assert np.max(np.abs(traj.q[:, 0] - rest)) <= 1e-12
        assert np.max(np.abs(traj.p[:, 0])) <= 1e-12
    # It is stable: about it the bead oscillates at Ω sin θ* (linearizing V_eff) ...
    traj = varmech.integrate(model, [rest + 1e-4], [0.0], dt=0.001, steps=20_000, method="midpoint")
    measured = frequency(traj.t, traj.q[:, 0] - rest)
    assert measured == pytest.approx(W * math.sin(rest), rel=1e-5)  # measured 1.8e-6
    # ... while the bottom, stable for Ω² < g/R, is unstable for Ω² > g/R.
    slow = varmech.integrate(model.with_parameters(Omega=2.0), [1e-4], [0.0], dt=0.01, steps=1000, method="midpoint")
    assert np.max(np.abs(slow.q)) <= 1e-4 * (1 + 1e-9)
    fast = varmech.integrate(model, [1e-4], [0.0], dt=0.01, steps=1000, method="midpoint")
    assert np.max(np.abs(fast.q)) >= 1.0


# ------------------------------------------------------------------ the closed-form Routhian


def test_heavy_top_routhian_is_the_textbook_one_and_runs_as_the_numerical_reduction():
    scene = scenes.heavy_top()
    top = symbolic_examples.heavy_top()
    mu = scene.p0[1:]
    reduced = symbolic.routh(top, [1, 2], mu)
    assert reduced.q == top.q[:1] and reduced.v == top.v[:1]
    assert reduced.parameters == top.parameters | {"mu_phi": mu[0], "mu_psi": mu[1]}
    # varmech's sign convention (Marsden, Ratiu & Scheurle): R = L − μ·ċ, a Lagrangian for θ.
    th, vth = reduced.q[0], reduced.v[0]
    i1, i3 = sp.symbols("I1 I3", positive=True)
    mgl, mu_phi, mu_psi = sp.symbols("Mgl mu_phi mu_psi")
    textbook = (
        i1 * vth**2 / 2
        - (mu_phi - mu_psi * sp.cos(th)) ** 2 / (2 * i1 * sp.sin(th) ** 2)
        - mu_psi**2 / (2 * i3)
        - mgl * sp.cos(th)
    )
    assert sp.simplify(reduced.L - textbook) == 0
    for model in (reduced, reduced.with_parameters(mu_phi=1.5)):
        numerical = varmech.routh(scene.model, [1, 2], [model.parameters["mu_phi"], mu[1]])
        a = varmech.integrate(numerical, scene.q0[:1], scene.p0[:1], dt=scene.dt, steps=1000, method="midpoint")
        b = varmech.integrate(model, scene.q0[:1], scene.p0[:1], dt=scene.dt, steps=1000, method="midpoint")
        scale = max(np.max(np.abs(a.q)), np.max(np.abs(a.p)))
        assert np.max(np.abs(a.q - b.q)) <= 1e-12 * scale and np.max(np.abs(a.p - b.p)) <= 1e-12 * scale


def test_routh_refuses_what_it_cannot_reduce_in_closed_form():
    top = symbolic_examples.heavy_top()
    with pytest.raises(ValueError, match=r"^cyclic: coordinate theta is not cyclic: ∂L/∂theta = "):
        symbolic.routh(top, [0], [1.0])
    with pytest.raises(ValueError, match=r"^cyclic: need distinct indices in \[0, 3\)"):
        symbolic.routh(top, [1, 2, 0], [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="^momenta: "):
        symbolic.routh(top, [1, 2], [1.0])
    # ∂L/∂ẏ = ẏ³ is not linear in ẏ.
    x, y, vx, vy = sp.symbols("x y v_x v_y")
    with pytest.raises(ValueError, match=r"^model: ∂L/∂v_y = v_y\*\*3 is not linear in v_y"):
        symbolic.routh(symbolic.lagrangian(vx**2 / 2 + vy**4 / 4 - x**2, [x, y], [vx, vy]), [1], [1.0])
    damped = symbolic.lagrangian((vx**2 + vy**2) / 2 - x**2, [x, y], [vx, vy], rayleigh=vx**2 / 2)
    with pytest.raises(ValueError, match="^model: .* is forced"):
        symbolic.routh(damped, [1], [1.0])
    with pytest.raises(ValueError, match="^model: .* is constrained"):
        symbolic.routh(symbolic_examples.cartesian_pendulum(), [0], [1.0])
    with pytest.raises(TypeError, match="^model: expected a SymbolicModel"):
        symbolic.routh(examples.heavy_top(), [1, 2], [1.0, 1.0])


def test_the_lambdified_first_order_system_is_the_cores():
    """The SciPy baselines' right-hand side of a symbolic model, lambdified from L, equals the
    core's q̇(q, p) and ∂L/∂q at random states (so both sides of a work–precision comparison
    integrate the same equations)."""
    rng = np.random.default_rng(7)
    for model in (symbolic_examples.elastic_pendulum(), symbolic_examples.elastic_pendulum_cartesian(), symbolic_examples.heavy_top()):
        rhs, core = model.first_order(), Rhs(model)
        for _ in range(5):
            y = rng.uniform(0.3, 1.2, 2 * model.dim)
            np.testing.assert_allclose(rhs(0.0, y), core(0.0, y), rtol=1e-13, atol=1e-13)
    assert symbolic_examples.damped_driven_pendulum().first_order() is None  # forced


def test_the_elastic_pendulum_scene_is_the_separable_cartesian_model():
    scene = scenes.get("elastic_pendulum")
    assert scene.model.kind_name == "separable" and scene.t_end == 1000.0
    polar, cartesian = symbolic_examples.elastic_pendulum(), scene.model
    # The same physics: the Cartesian state mapped to polar coordinates has the same energy.
    x, y = scene.q0
    r, th = np.hypot(x, y), np.arctan2(x, -y)
    e_cartesian = varmech.integrate(cartesian, scene.q0, scene.p0, dt=0.01, steps=1).energy()[0]
    e_polar = varmech.integrate(polar, [r, th], [0.0, 0.0], dt=0.01, steps=1).energy()[0]
    assert e_cartesian == pytest.approx(e_polar, rel=1e-14)
    with pytest.raises(ValueError, match="no_such_scene"):
        symbolic_examples.scene("no_such_scene")
    assert all(scenes.get(name).name == name for name in scenes.SYMBOLIC)
