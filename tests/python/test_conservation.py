"""Conservation checks from Python: verdicts, Noether momenta, symplecticity."""

import math

import numpy as np
import pytest

import varmech
from varmech import examples, scenes


def test_kepler_verdicts_tell_symplectic_from_rk4():
    scene = scenes.kepler(0.6)
    dt = 2 * math.pi / 100
    bounded = varmech.check_conservation(varmech.integrate(scene, dt=dt, t_end=scene.t_end, method="mclachlan4", save_every=10))
    drift = varmech.check_conservation(varmech.integrate(scene, dt=dt, t_end=scene.t_end, method="rk4", save_every=10))
    assert bounded.verdict == "bounded"
    assert bounded.momenta[0].name == "L" and bounded.momenta[0].max_rel_error <= 1e-13
    assert drift.verdict == "secular drift"
    assert "verdict: secular drift" in str(drift)
    # HLW: RK4 at h = 2π/100 loses 1.05e-4 of energy per period.
    assert drift.energy.drift_rate * 2 * math.pi == pytest.approx(-1.05e-4, rel=0.2)
    assert drift.momenta[0].max_rel_error > 1e-6


def test_closure_generator_gives_the_same_momentum_as_the_built_in_one():
    scene = scenes.kepler()
    traj = varmech.integrate(scene, dt=0.01, steps=1000, method="verlet")
    built_in = varmech.momentum(traj, varmech.Rotation(spatial_dim=2))
    closure = varmech.momentum(traj, lambda q: np.array([-q[1], q[0]]))
    np.testing.assert_allclose(closure, built_in, rtol=1e-15)
    assert np.max(np.abs(built_in - 0.8)) < 1e-14
    report = varmech.check_conservation(traj, generators=[lambda q: np.array([-q[1], q[0]])])
    assert report.momenta[0].name == "xi[0]"


def test_cyclic_coordinate_momentum_is_conserved():
    # A free particle in x with a potential in y only: p_x is the momentum of a cyclic x.
    model = varmech.MechanicalSystem(2, lambda q: 0.5 * q[1] ** 2, lambda q: np.array([0.0, q[1]]), symmetries=[varmech.Cyclic(0)])
    traj = varmech.integrate(model, [0.0, 1.0], [0.3, 0.0], dt=0.1, steps=1000, method="kahan_li6")
    report = varmech.check_conservation(traj)
    assert report.momenta[0].max_abs_error == 0.0


def _cart(**generator):
    """A pendulum on a cart, q = (x, θ): M = 2, m = l = 1, g = 9.81; x is cyclic."""
    M, m, l, g = 2.0, 1.0, 1.0, 9.81

    def mass(q):
        c = m * l * np.cos(q[1])
        return np.array([[M + m, c], [c, m * l**2]])

    return varmech.MechanicalSystem(
        2, lambda q: -m * g * l * np.cos(q[1]), lambda q: np.array([0.0, m * g * l * np.sin(q[1])]), mass=mass, **generator
    )


@pytest.mark.parametrize("generator", ["cyclic", "closure"])
def test_a_momentum_at_rest_under_a_moving_system_is_conserved_to_round_off_not_failed(generator):
    # Released at rest with the bob out, the cart's momentum p_x = (M + m)ẋ + ml cos θ θ̇ stays 0
    # while the bob swings. Its rounding error is that of the whole motion, O(ε‖p‖); against
    # its own terms, all ≈ 0, it read "failed" (an error of 5.5e-14 against a scale of 2.6e-14).
    if generator == "cyclic":
        model, generators = _cart(symmetries=[varmech.Cyclic(0)]), None
    else:
        model, generators = _cart(), [lambda q: np.array([1.0, 0.0])]
    traj = varmech.integrate(model, [0.0, 1.0], [0.0, 0.0], dt=0.01, steps=5000, method="midpoint", save_every=10)
    report = varmech.check_conservation(traj, generators=generators)
    momentum = report.momenta[0]
    assert 0.0 < momentum.max_abs_error < 1e-12 and abs(momentum.initial) == 0.0
    assert momentum.scale > 1.0  # ‖p‖∞: the bob's p_θ
    assert momentum.verdict == "conserved to round-off", str(report)


# The constrained methods are symplectic on the constraint manifold, which Hénon–Heiles has not.
@pytest.mark.parametrize("method", [m.name for m in varmech.methods() if not m.constrained and not m.nonholonomic and not m.nbody])
def test_symplecticity_defect(method):
    info = {m.name: m for m in varmech.methods()}[method]
    scene = scenes.henon_heiles()
    for model in (scene.model, examples.henon_heiles()):
        defect = varmech.symplecticity_defect(model, method, scene.q0, scene.p0, dt=0.5)
        if info.symplectic:
            assert defect <= 1e-9
        else:
            assert defect >= 1e-6


def test_velocity_and_momentum_round_trip():
    scene = scenes.outer_solar_system()
    traj = varmech.integrate(scene, dt=100.0, steps=10)
    masses = np.repeat(scene.model._core.gravity[1], 3)
    np.testing.assert_allclose(traj.v, traj.p / masses, rtol=1e-15)
    via_v0 = varmech.integrate(scene.model, scene.q0, v0=scene.p0 / masses, dt=100.0, steps=10)
    np.testing.assert_allclose(via_v0.q, traj.q, rtol=1e-15)


def test_methods_table():
    table = {m.name: m for m in varmech.methods()}
    assert table["verlet"].order == 2 and table["verlet"].h_omega_max == 2.0
    assert table["kahan_li8"].force_evaluations == 17 and table["kahan_li8"].order == 8
    assert table["rk4"].h_omega_max == pytest.approx(2 * math.sqrt(2))
    assert not table["rk4"].symplectic and not table["explicit_euler"].symplectic


def test_saving_every_kth_state_keeps_the_final_state():
    scene = scenes.pendulum()
    full = varmech.integrate(scene, dt=0.01, steps=1001)
    thin = varmech.integrate(scene, dt=0.01, steps=1001, save_every=100)
    assert len(thin) == 12
    np.testing.assert_array_equal(thin.q, full.q[[*range(0, 1001, 100), 1001]])
    assert thin.t[-1] == pytest.approx(10.01)


def test_published_pendulum_reference_is_reached():
    scene = scenes.pendulum()
    traj = varmech.integrate(scene, dt=scene.t_end / 64, t_end=scene.t_end, method="kahan_li8")
    ref = scene.reference
    assert traj.t[-1] == pytest.approx(ref.t)
    assert abs(traj.q[-1, 0] - ref.q[0]) < 1e-9 and abs(traj.p[-1, 0] - ref.p[0]) < 1e-9


def test_a_native_forced_scene_reports_its_energy_balance_as_its_energy():
    scene = scenes.damped_driven_pendulum()
    assert scene.model.forced and not scene.model.time_dependent
    coarse, fine = (varmech.integrate(scene, dt=dt, t_end=20.0, method="midpoint") for dt in (0.02, 0.01))
    reports = [varmech.check_conservation(t) for t in (coarse, fine)]
    assert all(r.energy.name == "energy balance" for r in reports)
    # The balance E − E0 − W is the midpoint rule's O(h²) energy error on a non-quadratic L.
    balances = [r.energy.max_abs_error for r in reports]
    assert balances[1] < 1e-3 * abs(reports[1].energy.initial)
    assert 3.5 < balances[0] / balances[1] < 4.5
    assert reports[1].verdict == "bounded"


def test_velocity_and_momentum_name_the_argument_of_the_wrong_shape():
    # The Legendre transform and its inverse check their inputs, naming the one that does not fit
    # rather than failing in NumPy's broadcasting or blaming the core's (t, q).
    model = scenes.kepler().model
    with pytest.raises(ValueError, match=r"^p: expected shape \(2,\) or \(N, 2\), got \(3,\)"):
        model.velocity([1.0, 0.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=r"^v: expected shape"):
        model.momentum([1.0, 0.0], [[1.0], [2.0]])
    with pytest.raises(ValueError, match=r"^q: shape \(3,\) does not fit"):
        model.momentum([1.0, 0.0, 0.0], [1.0, 2.0])
    with pytest.raises(ValueError, match=r"^t: shape \(2,\) does not fit"):
        model.velocity(np.zeros((3, 2)), np.ones((3, 2)), t=[0.0, 1.0])
    # What fits still works: one q for many rows, one t for all.
    np.testing.assert_array_equal(model.momentum([1.0, 0.0], np.ones((3, 2))), np.ones((3, 2)))


def test_a_closure_generator_is_called_once_a_saved_state_where_a_force_acts():
    # Its J and the test of whether the force pushes along ξ share one evaluation of ξ(q).
    model = varmech.Lagrangian(
        2, lambda q, v, t: 0.5 * (v @ v) - 0.5 * (q @ q),
        dl_dq=lambda q, v, t: -q, dl_dv=lambda q, v, t: v.copy(), force=lambda q, v, t: -0.1 * v,
    )  # fmt: skip
    traj = varmech.integrate(model, [1.0, 0.0], v0=[0.0, 1.0], dt=0.05, steps=100, method="midpoint")
    calls = []

    def xi(q):
        calls.append(1)
        return np.array([-q[1], q[0]])

    report = varmech.check_conservation(traj, [xi])
    assert len(calls) == len(traj.t)
    assert report.momenta[0].verdict == "not judged" and "force" in report.momenta[0].advice
