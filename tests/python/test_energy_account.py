"""One energy account (issue 64): everything that puts energy into a run or takes it out enters
its work W (``traj.work``), and the report judges the balance E − W.

- each impact with e < 1 takes the reflect law's own loss, −(1 − e²)/2 (n·q̇⁻)²/(nᵀM⁻¹n): the
  bouncing ball's W after its k-th impact is −gh₀(1 − e^{2k}) to 1e-13, just before it the
  loss of the ones before, and E − W is round-off;
- an elastic impact puts in nothing, exactly: an elastic run records no work, and its energy
  (not a balance) is judged, the variational law's O(h²) jumps included;
- an impulse puts in its energy change E(q, p⁺) − E(q, p⁻), at the grid and between grid points,
  in the rows just after it and not before;
- samples (``t_eval``) inside a step carry the work up to them;
- a momentum is judged only where nothing pushes along its ξ: a rough floor's friction breaks
  a rolling ball's p_x and p_θ (not judged, naming it), a smooth floor breaks neither; a
  circular table keeps the angular momentum, an elliptic one does not; a damping force breaks
  the momentum of its coordinate.
"""

import math

import numpy as np
import pytest

import varmech
from varmech import scenes
from varmech.conservation import NOT_JUDGED

G = 9.81


def _balance(traj: varmech.Trajectory) -> float:
    e = traj.energy()
    return float(np.max(np.abs(e - e[0] - traj.work)))


@pytest.mark.parametrize("law", ["variational", "reflect"])
@pytest.mark.parametrize("e", [0.3, 0.8])
def test_each_impact_takes_the_laws_own_loss_and_the_balance_closes_to_round_off(e, law):
    scene = scenes.bouncing_ball(restitution=e)
    floor = varmech.Contact.wall(0, restitution=e, law=law, name="floor")
    traj = varmech.integrate(scene.model, scene.q0, scene.p0, dt=scene.dt, t_end=scene.t_end, save_every=1000, contacts=[floor])
    impacts = traj.events[0]
    # The scene follows ten bounces, or those whose flights last 10⁻⁴ of the first (seven at 0.3).
    assert len(impacts) == min(10, int(math.log(1e-4) / math.log(e)))
    after = np.searchsorted(traj.t, impacts.t, side="right") - 1
    k = np.arange(1, len(impacts) + 1)
    # The normal velocity √(2gh₀)eᵏ⁻¹ just before the k-th: the loss (1 − e²)gh₀e^{2(k−1)}.
    np.testing.assert_allclose(traj.work[after], -G * (1 - e ** (2 * k)), rtol=1e-13)
    np.testing.assert_allclose(traj.work[after - 1], -G * (1 - e ** (2 * k - 2)), rtol=1e-13, atol=1e-15)
    report = varmech.check_conservation(traj)
    assert report.energy.name == "energy balance" and report.verdict == "conserved to round-off", report
    assert _balance(traj) <= 1e-14 * G


def test_a_ball_coming_to_rest_loses_all_its_energy_to_its_impacts_and_the_closure():
    # e = 0.5 under verlet: the contact closes at the limit of the Zeno series, the impact
    # that closes it taking the whole normal kinetic energy; at rest on the floor, E = 0 = E₀ + W.
    scene = scenes.bouncing_ball(restitution=0.5)
    traj = varmech.integrate(scene.model, scene.q0, scene.p0, dt=0.01, t_end=3.0, contacts=scene.contacts)
    assert len(traj.events[1]) == 1
    np.testing.assert_allclose(traj.work[-1], -G, rtol=1e-14)
    assert _balance(traj) <= 1e-14 * G
    assert varmech.check_conservation(traj).verdict == "conserved to round-off"


@pytest.mark.parametrize("law", ["variational", "reflect"])
def test_an_elastic_impact_puts_in_nothing_so_the_methods_own_error_is_judged(law):
    scene = scenes.bouncing_ball()
    floor = varmech.Contact.wall(0, restitution=1.0, law=law, name="floor")
    traj = varmech.integrate(scene.model, scene.q0, scene.p0, dt=scene.dt, t_end=scene.t_end, contacts=[floor])
    assert not np.any(traj.work)
    energy = varmech.check_conservation(traj).energy
    assert energy.name == "energy"
    if law == "reflect":
        # Verlet is exact on the parabolas, the reflection exact at the impacts.
        assert energy.verdict == "conserved to round-off", energy
    else:
        # The variational law keeps E_d, not E: E jumps by O(h²) at each impact, in the report.
        assert energy.verdict == "bounded" and energy.max_abs_error > 1e3 * energy.round_off, energy


@pytest.mark.parametrize("t_blow", [2.0, 1.234])
def test_an_impulse_puts_in_its_energy_change_in_the_rows_after_it(t_blow):
    # On the grid (2.0) and between grid points (1.234): W jumps by E(p⁺) − E(p⁻) = P·q̇ + P²/2.
    osc = scenes.harmonic_oscillator()
    blow = varmech.Impulse(generalized=[0.7], t=t_blow)
    traj = varmech.integrate(osc, dt=0.1, steps=40, method="midpoint", impulses=[blow])
    before, after = np.flatnonzero(traj.t == t_blow)
    e = traj.energy()
    np.testing.assert_allclose(traj.work[after] - traj.work[before], e[after] - e[before], rtol=1e-14)
    assert traj.work[before] == 0.0 and np.all(traj.work[after:] == traj.work[after])
    # The midpoint rule keeps the oscillator's quadratic energy: the balance is round-off.
    report = varmech.check_conservation(traj)
    assert report.energy.name == "energy balance" and report.verdict == "conserved to round-off", report


def test_samples_inside_a_step_carry_the_work_up_to_them():
    scene = scenes.bouncing_ball(restitution=0.8)
    t_end = 3.6
    times = np.linspace(0.0, t_end, 777)
    traj = varmech.integrate(scene.model, scene.q0, scene.p0, dt=0.01, t_end=t_end, t_eval=times, contacts=scene.contacts)
    np.testing.assert_array_equal(traj.t, times)
    assert _balance(traj) <= 1e-14 * G


R, M = 0.1, 1.0
INERTIA = 0.4 * M * R**2
BALL = varmech.MechanicalSystem(
    3, lambda q: M * G * q[1], lambda q: np.array([0.0, M * G, 0.0]), mass=[M, M, INERTIA], name="ball",
    symmetries=[varmech.Cyclic(0), varmech.Cyclic(2)],
)


def test_a_rough_floors_friction_breaks_the_balls_momenta_and_a_smooth_floor_breaks_neither():
    rough = varmech.Contact.wall(1, R, restitution=0.6, law="reflect", name="floor", friction=varmech.Friction(0.3, slip=[[1.0, 0.0, -R]]))
    smooth = varmech.Contact.wall(1, R, restitution=0.6, law="reflect", name="floor")
    start = ([2.5, R + 0.05, 0.0], [2.0, 0.0, 0.0])
    traj = varmech.integrate(BALL, *start, dt=1e-3, t_end=1.0, contacts=[rough])
    report = varmech.check_conservation(traj)
    assert report.energy.name == "energy balance" and report.verdict == "conserved to round-off", report
    for m in report.momenta:
        assert m.verdict == NOT_JUDGED and "the friction of contact 'floor'" in m.advice, m
    assert report.momenta[0] not in report.quantities
    # Without friction the floor pushes along y alone: p_x and p_θ are kept, and judged.
    report = varmech.check_conservation(varmech.integrate(BALL, *start, dt=1e-3, t_end=1.0, contacts=[smooth]))
    assert [m.verdict for m in report.momenta] == ["conserved to round-off"] * 2, report


def test_a_circular_table_keeps_the_angular_momentum_and_an_elliptic_one_breaks_it():
    free = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2), name="free", symmetries=[varmech.Rotation(spatial_dim=2)])
    for axes, kept in (((1.0, 1.0), True), ((2.0, 1.0), False)):
        table = varmech.Contact.ellipsoid(axes, name="table")
        traj = varmech.integrate(free, [0.3, 0.1], [0.6, 0.8], dt=0.01, steps=2000, contacts=[table])
        (angular,) = varmech.check_conservation(traj).momenta
        if kept:
            assert angular.verdict == "conserved to round-off", angular
        else:
            assert angular.verdict == NOT_JUDGED and "contact 'table' (its normal ∇φ·ξ ≠ 0)" in angular.advice, angular


def test_a_damping_force_breaks_the_momentum_of_its_coordinate():
    damped = varmech.Lagrangian(
        1,
        lambda q, v, t: 0.5 * v @ v,
        dl_dq=lambda q, v, t: np.zeros(1),
        dl_dv=lambda q, v, t: v.copy(),
        force=lambda q, v, t: -0.5 * v,
        name="damped",
        symmetries=[varmech.Cyclic(0)],
    )
    traj = varmech.integrate(damped, [0.0], [1.0], dt=0.01, steps=500, method="midpoint")
    report = varmech.check_conservation(traj)
    assert report.energy.name == "energy balance"
    (p,) = report.momenta
    assert p.verdict == NOT_JUDGED and "the model's force (Q·ξ ≠ 0)" in p.advice, p
