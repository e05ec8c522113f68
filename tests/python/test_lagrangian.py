"""General Lagrangians from Python closures with the implicit variational integrators."""

import math

import numpy as np
import pytest

import varmech
from conftest import Boom, raising_when
from varmech import examples, scenes


def charged_particle(B: float) -> varmech.Lagrangian:
    """A unit charge of unit mass in the uniform field B ẑ: L = ½|v|² + A(q)·v, A = (B/2)(−y, x)."""

    def lagrangian(q, v, t):
        return 0.5 * float(v @ v) + 0.5 * B * (q[0] * v[1] - q[1] * v[0])

    def dl_dq(q, v, t):
        return 0.5 * B * np.array([v[1], -v[0]])

    def dl_dv(q, v, t):
        return v + 0.5 * B * np.array([-q[1], q[0]])

    return varmech.Lagrangian(2, lagrangian, dl_dq=dl_dq, dl_dv=dl_dv, name="charged particle")


@pytest.mark.parametrize("native", [False, True])
@pytest.mark.parametrize("h", [0.1, 1.0, 3.0])
def test_midpoint_gyration_phase_is_two_arctan_half_h_omega(h, native):
    # From (1, 0) with velocity (0, −B) the exact orbit is q(t) = (cos Ωt, −sin Ωt), Ω = B; the
    # midpoint rule turns by exactly 2·arctan(hΩ/2) a step, at every step size.
    B, steps = 2.0, 200
    model = scenes.charged_particle(B).model if native else charged_particle(B)
    traj = varmech.integrate(model, [1.0, 0.0], v0=[0.0, -B], dt=h, steps=steps, method="midpoint")
    theta = 2 * math.atan(h * B / 2) * np.arange(steps + 1)
    np.testing.assert_allclose(traj.q, np.column_stack([np.cos(theta), -np.sin(theta)]), atol=1e-12)
    np.testing.assert_allclose(traj.v[:, 1], -B * np.cos(theta), atol=1e-12)
    report = varmech.check_conservation(traj)
    # The midpoint rule keeps this quadratic L's energy exactly: what is left is round-off.
    assert report.verdict == "conserved to round-off" and report.energy.max_abs_error / abs(report.energy.initial) < 1e-13


def test_double_pendulum_closure_reaches_the_reference_at_order_two():
    scene = scenes.double_pendulum()
    model = examples.double_pendulum()
    errors = []
    for steps in (1000, 2000, 4000):
        traj = varmech.integrate(model, scene.q0, scene.p0, dt=scene.reference.t / steps, steps=steps, method="midpoint", save_every=steps)
        errors.append(np.hypot(np.linalg.norm(traj.q[-1] - scene.reference.q), np.linalg.norm(traj.p[-1] - scene.reference.p)))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 2) < 0.3), orders
    e0 = varmech.integrate(scene, dt=0.01, steps=1).energy()[0]
    assert e0 == pytest.approx(-40.218179175435154, rel=1e-13)


def test_time_dependent_lagrangian_is_judged_on_its_energy_balance():
    # A parametrically driven oscillator: E = p·q̇ − L changes by −∫∂L/∂t dt, which the run
    # tracks (traj.work); the balance E − W is judged, and checked during the run.
    omega = lambda t: 1.0 + 0.5 * math.sin(t)  # noqa: E731
    model = varmech.Lagrangian(
        1,
        lambda q, v, t: 0.5 * v[0] ** 2 - 0.5 * omega(t) ** 2 * q[0] ** 2,
        dl_dq=lambda q, v, t: np.array([-omega(t) ** 2 * q[0]]),
        dl_dv=lambda q, v, t: v.copy(),
        dl_dt=lambda q, v, t: -omega(t) * 0.5 * math.cos(t) * q[0] ** 2,
        time_dependent=True,
    )
    traj = varmech.integrate(model, [1.0], [0.0], dt=0.05, steps=400, method="midpoint")
    report = varmech.check_conservation(traj)
    assert report.time_dependent and report.energy.name == "energy balance"
    assert report.verdict == "bounded" and "(E − W)0" in str(report)
    assert np.ptp(traj.energy()) > 0.1 and np.ptp(traj.energy() - traj.work) < 1e-2
    varmech.integrate(model, [1.0], [0.0], dt=0.05, steps=10, method="midpoint", max_energy_error=1.0)
    with pytest.raises(ValueError, match="^dl_dt: given for an L declared independent of t"):
        varmech.Lagrangian(1, model.lagrangian, dl_dq=model.dl_dq, dl_dv=model.dl_dv, dl_dt=model.dl_dt)
    with pytest.warns(varmech.DerivativeWarning, match="no dl_dt given"):
        varmech.Lagrangian(1, model.lagrangian, dl_dq=model.dl_dq, dl_dv=model.dl_dv, time_dependent=True)


def test_check_derivatives_catches_a_wrong_derivative():
    good = examples.double_pendulum()
    report = varmech.check_derivatives(good, [0.3, -1.2], [0.7, 2.5])
    assert report.ok and report.worst[1] < 1e-8
    wrong = varmech.Lagrangian(2, good.lagrangian, dl_dq=lambda q, v, t: -good.dl_dq(q, v, t), dl_dv=good.dl_dv)
    report = varmech.check_derivatives(wrong, [0.3, -1.2], [0.7, 2.5])
    assert not report.ok and report.worst[0] == "dl_dq" and "MISMATCH" in str(report)
    kepler = examples.kepler()
    assert varmech.check_derivatives(kepler, [0.4, 0.3]).ok
    bad = varmech.MechanicalSystem(2, kepler.potential, lambda q: 2 * kepler.gradient(q))
    assert not varmech.check_derivatives(bad, [0.4, 0.3]).ok


def test_check_derivatives_checks_second_derivatives_and_mass_derivatives():
    good = examples.double_pendulum()
    q, v = [0.3, -1.2], [0.7, 2.5]
    report = varmech.check_derivatives(good, q, v)
    assert set(report.mismatch) == {"dl_dq", "dl_dv", "L_qq", "L_qv", "L_vv"} and report.worst[1] < 1e-8

    def transposed(q, v, t):  # a classic slip: L_qv given as ∂²L/∂q̇∂q
        lqq, lqv, lvv = good.hessians(q, v, t)
        return lqq, lqv.T, lvv

    wrong = varmech.Lagrangian(2, good.lagrangian, dl_dq=good.dl_dq, dl_dv=good.dl_dv, hessians=transposed)
    report = varmech.check_derivatives(wrong, q, v)
    assert not report.ok and report.worst[0] == "L_qv"

    def mass(q):
        return np.diag([1.0, np.sin(q[0]) ** 2])

    natural = [
        varmech.MechanicalSystem(2, lambda q: -np.cos(q[0]), lambda q: np.array([np.sin(q[0]), 0.0]), mass=mass, mass_derivative=dm)
        for dm in (
            lambda q: np.array([np.diag([0.0, np.sin(2 * q[0])]), np.zeros((2, 2))]),
            lambda q: np.array([np.zeros((2, 2)), np.diag([0.0, np.sin(2 * q[0])])]),  # on the wrong axis
        )
    ]
    assert varmech.check_derivatives(natural[0], [1.0, 0.0]).ok
    assert varmech.check_derivatives(natural[1], [1.0, 0.0]).worst[0] == "mass_derivative"


def test_lagrangian_without_derivatives_warns_and_uses_differences():
    exact = examples.double_pendulum()
    with pytest.warns(varmech.DerivativeWarning, match="no dl_dq and no dl_dv"):
        fd = varmech.Lagrangian(2, exact.lagrangian)
    scene = scenes.double_pendulum()
    a = varmech.integrate(exact, scene.q0, scene.p0, dt=0.01, steps=100, method="midpoint")
    b = varmech.integrate(fd, scene.q0, scene.p0, dt=0.01, steps=100, method="midpoint")
    assert np.max(np.abs(a.q - b.q)) < 1e-8


def test_general_lagrangians_refuse_explicit_methods_and_name_bad_closures():
    model = charged_particle(1.0)
    with pytest.raises(ValueError, match="^method: verlet needs a separable mechanical system"):
        varmech.integrate(model, [1.0, 0.0], [0.0, 1.0], dt=0.1, steps=1, method="verlet")
    broken = varmech.Lagrangian(2, model.lagrangian, dl_dq=lambda q, v, t: np.zeros(3), dl_dv=model.dl_dv)
    with pytest.raises(ValueError, match=r"dl_dq\(q, v, t\) returned 3 values, expected 2"):
        varmech.integrate(broken, [1.0, 0.0], [0.0, 1.0], dt=0.1, steps=1, method="midpoint")
    with pytest.raises(ValueError, match=r"^symmetries\[0\]: Rotation\(axis=2, spatial_dim=2\) does not apply to a model of 3"):
        varmech.Lagrangian(3, model.lagrangian, dl_dq=model.dl_dq, dl_dv=model.dl_dv, symmetries=[varmech.Rotation(spatial_dim=2)])
    with pytest.raises(TypeError, match="^symmetries:"):
        varmech.Lagrangian(2, model.lagrangian, dl_dq=model.dl_dq, dl_dv=model.dl_dv, symmetries=["L"])
    with pytest.raises(TypeError, match="^lagrangian: must be callable"):
        varmech.Lagrangian(2, 1.0, dl_dq=model.dl_dq, dl_dv=model.dl_dv)


def test_forced_system_keeps_its_energy_balance_with_the_tracked_work(damped_oscillator):
    # A damped oscillator with Rayleigh dissipation R = ½cq̇²: for the midpoint rule on this
    # quadratic L, E changes by exactly the tracked work of the force each step.
    model = damped_oscillator(0.1)
    assert model.forced
    traj = varmech.integrate(model, [1.0], [0.0], dt=0.1, steps=2000, method="midpoint", save_every=10)
    e = traj.energy()
    np.testing.assert_allclose(e - e[0], traj.work, atol=1e-14)
    assert e[-1] < 0.01 * e[0]
    report = varmech.check_conservation(traj)
    balance = report.energy
    assert balance.name == "energy balance" and balance.max_abs_error / abs(balance.initial) < 1e-13
    assert report.verdict == balance.verdict == "conserved to round-off" and "(E − W)0" in str(report)
    with pytest.raises(ValueError, match="^rayleigh:"):
        varmech.Lagrangian(1, model.lagrangian, dl_dq=model.dl_dq, dl_dv=model.dl_dv, rayleigh=[1.0, 2.0])


def test_a_force_closure_that_raises_propagates_unchanged():
    force = raising_when(lambda q, v, t: t > 0.5, lambda q, v, t: np.zeros(1), "stalled")
    model = varmech.Lagrangian(
        1, lambda q, v, t: 0.5 * v[0] ** 2 - 0.5 * q[0] ** 2, dl_dq=lambda q, v, t: -q.copy(), dl_dv=lambda q, v, t: v.copy(), force=force
    )
    with pytest.raises(Boom, match="stalled") as info:
        varmech.integrate(model, [1.0], [0.0], dt=0.1, steps=100, method="midpoint")
    assert info.value.partial.steps == 5 and len(info.value.partial.work) == 6


def test_spherical_pendulum_declares_its_cyclic_azimuth():
    scene = scenes.spherical_pendulum()
    assert scene.model.symmetries == (varmech.Cyclic(1),)
    traj = varmech.integrate(scene, dt=0.01, t_end=50.0, save_every=100)
    report = varmech.check_conservation(traj)
    assert report.momenta[0].name == "p_phi" and report.momenta[0].max_rel_error < 1e-13
    assert report.verdict == "bounded"
    assert abs(traj.q[-1, 0] - scene.reference.q[0]) < 1e-3


def test_native_charged_particle_in_a_non_uniform_field_is_the_readme_closure():
    # The README's closure: the same Lagrangian in the same gauge, with difference derivatives.
    def A(q):
        return 0.5 * (1 + q @ q / 8) * np.array([-q[1], q[0]])

    with pytest.warns(varmech.DerivativeWarning, match="central differences"):
        readme = varmech.Lagrangian(2, lambda q, v, t: 0.5 * v @ v + A(q) @ v, symmetries=[varmech.Rotation(spatial_dim=2)])
    scene = scenes.charged_particle_nonuniform()
    assert scene.model.symmetries == readme.symmetries
    rng = np.random.default_rng(1)
    q, v = rng.normal(size=(20, 2)), rng.normal(size=(20, 2))
    np.testing.assert_allclose(scene.model.momentum(q, v), v + np.array([A(x) for x in q]), rtol=1e-15, atol=1e-15)
    assert list(scene.q0) == [1.0, 0.0]
    np.testing.assert_allclose(scene.model.velocity(scene.q0, scene.p0), [0.0, -1.0], atol=1e-16)
    # The closure twin with exact derivatives follows the native run to the Newton tolerance,
    # the README closure to the accuracy of its difference derivatives.
    native = varmech.integrate(scene, dt=0.05, steps=400, method="midpoint")
    twin = varmech.integrate(examples.closure_of(scene), scene.q0, scene.p0, dt=0.05, steps=400, method="midpoint")
    fd = varmech.integrate(readme, scene.q0, scene.p0, dt=0.05, steps=400, method="midpoint")
    assert np.max(np.abs(native.q - twin.q)) <= 1e-10 and np.max(np.abs(native.p - twin.p)) <= 1e-10
    assert np.max(np.abs(native.q - fd.q)) <= 1e-8
    report = varmech.check_conservation(native)
    assert report.momenta[0].name == "L" and report.momenta[0].initial == pytest.approx(-0.4375, abs=1e-15)
    assert report.momenta[0].max_rel_error < 1e-13 and report.verdict == "bounded"


@pytest.mark.parametrize("name", ["charged_particle", "charged_particle_nonuniform", "damped_driven_pendulum"])
@pytest.mark.parametrize("method", ["midpoint", "trapezoid"])
def test_new_scenes_are_in_the_catalogue_and_integrate(name, method):
    scene = scenes.get(name)
    assert name in scenes.CATALOGUE and not scene.model.separable
    traj = varmech.integrate(scene, dt=scene.dt, steps=1000, method=method)
    assert traj.status == 0 and np.all(np.isfinite(traj.q))
    e = traj.energy()
    if name == "damped_driven_pendulum":
        # The energy changes by the tracked work, up to the method's own O(h²) energy error.
        assert np.ptp(e) > 0.5 and np.max(np.abs(e - e[0] - traj.work)) < 1e-4
    else:
        assert e[0] == pytest.approx(scene.invariants["E"], rel=1e-15)
        report = varmech.check_conservation(traj)
        assert report.momenta[0].initial == pytest.approx(scene.invariants["L"], rel=1e-15)
        assert report.momenta[0].max_rel_error < 1e-13


def test_uniform_field_scene_reaches_its_exact_reference_and_validates_its_field():
    scene = scenes.charged_particle(2.0)
    ref = scene.reference
    assert ref.source.startswith("exact")
    traj = varmech.integrate(scene, dt=scene.t_end / 4000, t_end=scene.t_end, method="galerkin6", save_every=4000)
    np.testing.assert_allclose(traj.q[-1], ref.q, atol=1e-11)
    np.testing.assert_allclose(traj.p[-1], ref.p, atol=1e-11)
    with pytest.raises(ValueError, match="^B:"):
        scenes.charged_particle(float("nan"))
    with pytest.raises(ValueError, match="^gamma:"):
        scenes.damped_driven_pendulum(gamma=-1.0)


@pytest.mark.parametrize("method", ["midpoint", "trapezoid"])
def test_a_forced_two_point_step_takes_its_solutions_force_from_newtons_last_evaluation(method):
    # One force call an evaluation of the step's equations, none more for the momentum change
    # (nfev counts that change as one evaluation a step), and the same run as evaluating again.
    calls = []

    def force(q, v, t):
        calls.append(t)
        return -0.1 * v

    model = varmech.Lagrangian(1, lambda q, v, t: 0.5 * v @ v - 0.5 * q @ q, dl_dq=lambda q, v, t: -q, dl_dv=lambda q, v, t: v, force=force)
    counts = []
    for steps in (1000, 2000):
        calls.clear()
        traj = varmech.integrate(model, [1.0], v0=[0.0], dt=0.01, steps=steps, method=method)
        counts.append((len(calls), traj.nfev - traj.steps))
    (short_calls, short_evaluations), (long_calls, long_evaluations) = counts
    assert long_calls - short_calls == long_evaluations - short_evaluations > 0
    # Damped at the exact rate to the method's order: E ∝ e^(−0.1 t) on average.
    assert abs(traj.energy()[-1] / traj.energy()[0] / np.exp(-0.1 * 20.0) - 1) < 0.05
