"""The nonholonomic scenes of the core's catalogue (reference/impulses_and_rolling.md, "Rolling
without slipping"): each is its closure twin of varmech.examples to the bit; the conservation
report claims only the momenta each conserves and judges its constraint residuals; the ball on
the turntable's affine constraints A(q)q̇ + b(q) = 0 (``velocity_constraint_offset``) keep its
Jacobi integral and not its energy, and their bad input is named."""

import math

import numpy as np
import pytest

import varmech
from varmech import conservation, examples, scenes

NONHOLONOMIC = ["rolling_disk", "chaplygin_sleigh", "rolling_sphere", "ball_on_turntable"]


@pytest.mark.parametrize("name", NONHOLONOMIC)
def test_the_native_scene_is_its_closure_twin_to_the_bit(name):
    # The twin evaluates the native formulas in the same order (math.sin and math.cos, the C
    # library's, as Rust's), and both take ∂A/∂q (and ∂b/∂q) by the core's differences: the
    # same Newton iterations on the same numbers.
    scene = scenes.get(name)
    twin = examples.closure_of(scene)
    assert twin.velocity_constraints == scene.model.velocity_constraints and twin.affine == scene.model.affine
    native = varmech.integrate(scene, dt=scene.dt, steps=300)
    python = varmech.integrate(twin, scene.q0, scene.p0, dt=scene.dt, steps=300)
    assert native.method == python.method == "midpoint"
    for a, b in [(native.t, python.t), (native.q, python.q), (native.p, python.p)]:
        np.testing.assert_array_equal(a, b)
    assert native.nfev == python.nfev and native.newton_iterations == python.newton_iterations


@pytest.mark.parametrize(
    "name, momenta, energy",
    [
        ("rolling_disk", ["p_theta", "p_phi"], "conserved to round-off"),
        ("chaplygin_sleigh", [], "bounded"),
        ("rolling_sphere", ["p_phi"], None),
        ("ball_on_turntable", ["p_phi"], conservation.NOT_JUDGED),
    ],
)
def test_the_report_claims_only_the_conserved_momenta_and_judges_the_residuals(name, momenta, energy):
    scene = scenes.get(name)
    traj = varmech.integrate(scene, dt=scene.dt, t_end=scene.t_end)
    report = varmech.check_conservation(traj)
    assert [m.name for m in report.momenta] == momenta
    assert all(m.verdict == "conserved to round-off" for m in report.momenta), report
    assert report.constraints is not None and report.constraints[0].verdict == "conserved to round-off"
    if energy is not None:  # the incline's run is a fraction of one oscillation of its error
        assert report.verdict == energy, report
    assert ("A q̇ + b" in str(report)) == scene.model.affine
    for invariant, value in scene.invariants.items():
        if invariant.startswith("p["):
            assert traj.p[-1, int(invariant[2])] == pytest.approx(value, abs=1e-12)


def test_the_turntable_ball_keeps_its_jacobi_integral_and_circles_at_two_sevenths_of_the_rate():
    # ν = 2Ω/7 turns the centre's velocity by 4π over T = 14π/Ω: back at its start, to O(h²).
    scene = scenes.ball_on_turntable(omega=1.3)
    assert scene.model.affine and scene.model.velocity_constraints == 2
    omega = 1.3
    errors = []
    for steps in (400, 800):
        traj = varmech.integrate(scene, dt=scene.t_end / steps, steps=steps)
        angle = np.unwrap(np.arctan2(traj.p[:, 1], traj.p[:, 0]))
        errors.append(abs((angle[-1] - angle[0]) / scene.t_end - 2 * omega / 7))
        energy = traj.energy()
        jacobi = energy - omega * (traj.q[:, 0] * traj.p[:, 1] - traj.q[:, 1] * traj.p[:, 0])
        assert np.max(np.abs(jacobi - scene.invariants["J"])) < 1e-3 * (400 / steps) ** 2 * abs(scene.invariants["J"])
        assert np.ptp(energy) > 0.25 * energy[0]  # the table does work (0.52 E₀ here)
        assert np.max(traj.constraint_residuals()[1]) < 1e-14
    assert abs(math.log2(errors[0] / errors[1]) - 2.0) < 0.1, errors


def _ball(offset, count=2):
    """The turntable ball's twin with the affine term ``offset``."""
    twin = examples.ball_on_turntable()
    return varmech.Lagrangian(
        5,
        twin.lagrangian,
        dl_dq=twin.dl_dq,
        dl_dv=twin.dl_dv,
        velocity_constraints=twin._arguments["velocity_constraints"],
        velocity_constraint_count=count,
        velocity_constraint_offset=offset,
    )


def test_bad_affine_terms_are_named():
    scene = scenes.ball_on_turntable()
    with pytest.raises(ValueError, match="^velocity_constraint_offset: only with velocity_constraints"):
        varmech.MechanicalSystem(
            2, lambda q: 0.0, lambda q: np.zeros(2), velocity_constraint_offset=lambda q: np.zeros(1)
        )
    with pytest.raises(TypeError, match="^velocity_constraint_offset: must be callable"):
        _ball(np.zeros(2))
    with pytest.raises(
        ValueError, match=r"velocity_constraint_offset\(q\) returned an array of shape \[3\], expected \[2\]"
    ):
        varmech.integrate(_ball(lambda q: np.zeros(3)), scene.q0, scene.p0, dt=0.1, steps=3)
    with pytest.raises(ValueError, match=r"velocity_constraint_offset\(q\) returned non-finite values"):
        varmech.integrate(_ball(lambda q: np.array([0.0, np.nan])), scene.q0, scene.p0, dt=0.1, steps=3)
    # Initial data off the affine constraints is refused naming p0, and project() repairs it.
    off = _ball(lambda q: np.array([q[1], -q[0]]) * 2.0)
    with pytest.raises(ValueError, match="^p0: is off the velocity constraints"):
        varmech.integrate(off, scene.q0, scene.p0, dt=0.1, steps=3)
    q, p = varmech.project(off, scene.q0, p0=scene.p0)
    traj = varmech.integrate(off, q, p, dt=0.1, steps=3)
    assert np.max(traj.constraint_residuals()[1]) < 1e-15
