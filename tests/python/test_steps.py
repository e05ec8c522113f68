"""Steps that run (issue 64): the run's energy check stops a run beyond the stability limit
and, within it, an error that grows, not the bounded offset of a symplectic method's modified
energy at a coarse stable step; ``suggest_dt``'s step runs with a "bounded" verdict (in
test_modes.py); :meth:`varmech.Scene.of`'s default step comes from a trial (test_own_model.py).

- every explicit method with a stability limit runs 20 000 steps at 0.9 and 0.99 of it with the
  check on, on the triatomic molecule and on two coupled hardening oscillators at a small
  amplitude, and is stopped just past it with h·ω_max named;
- Verlet's offset at 0.99 of its limit is tens of times the kinetic energy and is let run;
- within the limit at the start, an error that grows (RK4's drift), or one that jumps past the
  scale and leaves a state that grows (the pendulum released with its rod horizontal at h = 3,
  thrown over its top once it swings through its bottom), is stopped while it grows, with its
  partial run, and a run gone on from its checkpoint is judged as one run.
"""

import math
import warnings

import numpy as np
import pytest

import varmech
from varmech import scenes

sp = pytest.importorskip("sympy")

#: Every method of a separable model with a stability limit on the oscillator: the explicit ones.
EXPLICIT = [
    m.name
    for m in varmech.methods()
    if 0 < m.h_omega_max < math.inf and m.implicit is False and not (m.constrained or m.nonholonomic or m.nbody)
]

#: How far past its limit a method is unstable: 1%, or inside the first unstable window of the
#: splittings whose window is narrower (tests/rust/stability.rs; varmech.unstable_intervals).
PAST = {"blanes_moan6": 1 + 1e-4, "blanes_moan4": 1 + 1e-3, "aba864": 1 + 1e-3, "aba1064": 1 + 1e-3}


def molecule_model(compiled: bool = True) -> varmech.Model:
    """The linear triatomic molecule of the small-oscillations guide: masses 1, 3, 1, springs 2."""
    if compiled:
        x = sp.symbols("x0:3")
        return varmech.symbolic.mechanical((x[1] - x[0]) ** 2 + (x[2] - x[1]) ** 2, list(x), sp.diag(1, 3, 1))

    def potential(q):
        return (q[1] - q[0]) ** 2 + (q[2] - q[1]) ** 2

    def gradient(q):
        return 2.0 * np.array([q[0] - q[1], 2 * q[1] - q[0] - q[2], q[2] - q[1]])

    return varmech.MechanicalSystem(3, potential, gradient, mass=[1.0, 3.0, 1.0], symmetries=[varmech.Translation(0, spatial_dim=1)])


@pytest.fixture(scope="module")
def models():
    """The molecule (linear) and two unit oscillators joined by a spring of stiffness 3 with
    hardening quartic terms (ω² = 1 and 7 at rest; a growing mode only stiffens, so that past
    the limit it grows for ever, where a softening pendulum's growth stalls), each with a
    state that excites every mode."""
    y = sp.symbols("y0:2")
    anharmonic = varmech.symbolic.mechanical(
        sum(yi**2 / 2 + yi**4 / 4 for yi in y) + sp.Rational(3, 2) * (y[0] - y[1]) ** 2, list(y), 1
    )
    return {"molecule": (molecule_model(), [0.1, 0.0, -0.2]), "anharmonic": (anharmonic, [1e-3, -2e-3])}


@pytest.mark.parametrize("name", ["molecule", "anharmonic"])
def test_runs_within_the_limit_complete_and_just_past_it_are_stopped_naming_h_omega(models, name):
    model, q0 = models[name]
    p0 = np.zeros(len(q0))
    for method in EXPLICIT:
        limit = varmech.suggest_dt(model, method, np.zeros(len(q0))).stable_dt
        for fraction in (0.9, 0.99):
            traj = varmech.integrate(model, q0, p0, method=method, dt=fraction * limit, steps=20_000)
            # Bounded: the modes' amplitudes stretched by the elongated invariant ellipse at most.
            assert traj.status == 0 and np.max(np.abs(traj.q)) < 10 * np.max(np.abs(q0)), (method, fraction)
        with warnings.catch_warnings(), np.errstate(over="ignore", invalid="ignore"):
            warnings.simplefilter("ignore", varmech.StabilityWarning)
            with pytest.raises(varmech.DivergenceError) as caught:
                varmech.integrate(model, q0, p0, method=method, dt=PAST.get(method, 1.01) * limit, steps=20_000)
        # Stopped with the step's h·ω_max at the start named: an error past the scale at a step
        # beyond the limit, or (the quartic's energy overflowing first) a non-finite energy.
        message, partial = str(caught.value), caught.value.partial
        assert f"at the run's first state (t = 0) is beyond {method}'s stability limit" in message
        assert partial.status == -1 and np.all(np.isfinite(partial.q)), method
        assert len(partial) - 1 in (caught.value.step - 1, caught.value.step), method


def test_the_molecule_of_the_guide_at_the_step_of_issue_64():
    # Closures, the guide's own molecule: the old check stopped the run at 0.9 of the limit at
    # its first step (energy error 1.89 times the kinetic energy); a large offset, but bounded.
    model = molecule_model(compiled=False)
    q0, p0 = [0.1, 0.0, -0.2], np.zeros(3)
    limit = varmech.suggest_dt(model, "verlet", np.zeros(3)).stable_dt
    for fraction in (0.9, 0.99):
        traj = varmech.integrate(model, q0, p0, dt=fraction * limit, steps=20_000)
        report = varmech.check_conservation(traj).energy
        assert report.max_rel_error > 1 and report.verdict == "failed"
        assert np.max(np.abs(traj.q)) < 10 * 0.2
    with pytest.warns(varmech.StabilityWarning), pytest.raises(varmech.DivergenceError) as caught:
        varmech.integrate(model, q0, p0, dt=1.01 * limit, steps=20_000)
    assert "h·ω_max = 2.0200 at the run's first state (t = 0) is beyond verlet's stability limit 2" in str(caught.value)


def test_a_large_bounded_offset_is_let_run():
    # Verlet on q̈ = −q at hω = 1.98: H/H̃ reaches 1/(1 − 0.99²) = 50, the error tens of times
    # the mean kinetic energy, and it stays there for 10⁵ steps.
    traj = varmech.integrate(scenes.harmonic_oscillator(), [1.0], [0.0], dt=1.98, steps=100_000, save_every=1)
    error = np.abs(traj.energy() - traj.energy()[0])
    scale = np.mean(0.5 * traj.p[:, 0] ** 2)
    assert error.max() > 30 * scale
    # Bounded: the largest error of the second half is the first half's.
    assert error[50_000:].max() < 1.001 * error[:50_000].max()


def test_an_error_that_grows_within_the_limit_is_stopped_while_it_grows_with_its_partial_run():
    # Released with its rod horizontal the pendulum has no small oscillation at q0 (ω_max = 0:
    # any step is within the limit there), swings through its bottom at hω = 3, beyond it, and
    # is thrown over its top: its energy error jumps past the scale, and its angle grows from
    # then on, doubling in a doubling of the run.
    pendulum = scenes.pendulum()
    with warnings.catch_warnings():
        warnings.simplefilter("error", varmech.StabilityWarning)  # none: the start is within
        with pytest.raises(varmech.DivergenceError, match="and the state growing: max") as caught:
            varmech.integrate(pendulum, [math.pi / 2], [0.0], dt=3.0, steps=1000)
    step, partial = caught.value.step, caught.value.partial
    angle = np.abs(partial.q[:, 0])
    half = 2 ** (step.bit_length() - 2)
    assert step == 107 and partial.status == -1 and len(partial) == step + 1
    assert angle[-1] >= 2 * angle[: half + 1].max()
    assert abs(partial.energy()[-1] - partial.energy()[0]) > 1
    # Gone on from a checkpoint before the stop, the run is judged as one: stopped at the same step.
    first = varmech.integrate(pendulum, [math.pi / 2], [0.0], dt=3.0, steps=80)
    with pytest.raises(varmech.DivergenceError) as resumed:
        varmech.integrate(first, steps=920)
    assert resumed.value.step == 107
    # Released from its bottom, at a step beyond the limit there, it is stopped at its first step.
    with pytest.warns(varmech.StabilityWarning), pytest.raises(varmech.DivergenceError, match="h·ω_max = 3.0000") as caught:
        varmech.integrate(pendulum, dt=3.0, steps=1000)
    assert caught.value.step == 1
    # RK4's energy drifts within its limit (hω_max = 1.17 of 2.83 at Kepler's pericentre).
    with pytest.raises(varmech.DivergenceError, match="and growing") as caught:
        varmech.integrate(scenes.kepler(), dt=2 * math.pi / 30, steps=6000, method="rk4")
    drift = np.abs(caught.value.partial.energy() + 0.5)
    assert drift[-1] > 2 * drift[: len(drift) // 2].max()
