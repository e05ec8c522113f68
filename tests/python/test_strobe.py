"""Stroboscopic sections and orbit diagrams (issue 37) on the damped, driven pendulum at Taylor's
parameters (Classical Mechanics §12.5: ω = 2π, ω₀ = 1.5ω, β = ω₀/4, φ(0) = −π/2; the scene in
the time unit 1/ω₀, damping 2β/ω₀ = 0.5, drive frequency ω/ω₀ = 2/3, period 3π): the period
doublings at γ = 1.0663, 1.0793 and 1.0821 located from the strobe's own splits and confirmed by SciPy,
the cascade's periods 1, 2, 4, 8, and bad requests refused by name."""

import math

import numpy as np
import pytest

import varmech
from varmech.analysis.strobe import orbit_diagram, strobe_period, stroboscopic_section

PERIOD = 3 * math.pi
START = ([-math.pi / 2], [0.0])


def splits(values, lag, transient=300):
    """|φ̇ₖ − φ̇ₖ₋ₗₐ₉| at the strobe's end for each drive γ: the period-2 orbit's split (lag 1) or
    the period-4 orbit's (lag 2), 0 below the doubling."""
    scene = varmech.scenes.get("damped_driven_pendulum")
    table = orbit_diagram(scene, *START, parameter="amplitude", values=values, period=PERIOD, periods=8, transient=transient)
    return np.array([abs(np.diff(table.where(value=float(v)).column("p0")[-1 - lag :: lag])[-1]) for v in values])


def onset(values, d):
    """Where d² (linear in γ past a flip bifurcation, d ∝ √(γ − γc)) extrapolates to 0."""
    slope, intercept = np.polyfit(values, np.asarray(d) ** 2, 1)
    return -intercept / slope


def test_the_period_doubling_cascade_has_periods_one_two_four_eight_then_chaos():
    scene = varmech.scenes.get("damped_driven_pendulum")
    values = [1.060, 1.070, 1.078, 1.080, 1.0815, 1.0825, 1.085]
    table = orbit_diagram(scene, *START, parameter="amplitude", values=values, period=PERIOD, periods=64, transient=300)
    assert [table.meta["periods"][v] for v in values] == [1, 2, 2, 4, 4, 8, None]
    # Every strobe point is a row: 65 a value (k = 300 … 364).
    assert len(table) == 65 * len(values) and table.columns == ("value", "k", "q0", "p0")


def scipy_split(gamma, lag, k=300):
    """|φ̇ₖ − φ̇ₖ₋ₗₐ₉| at the strobe k from SciPy's DOP853 on the same equation (tolerance 1e-11)."""
    scipy = pytest.importorskip("scipy.integrate")

    def rhs(t, y):
        return [y[1], -0.5 * y[1] - math.sin(y[0]) + gamma * math.cos(2.0 / 3.0 * t)]

    strobes = PERIOD * np.array([k - lag, k])
    sol = scipy.solve_ivp(rhs, (0.0, strobes[-1]), [-math.pi / 2, 0.0], method="DOP853", rtol=1e-11, atol=1e-12, t_eval=strobes)
    return abs(sol.y[1, -1] - sol.y[1, 0])


def test_the_three_doublings_are_taylors_and_scipys():
    # Past γc the split grows as √(γ − γc): its square, extrapolated to 0 from three drives, is
    # the onset, to about 1e-4 (Taylor gives four digits): period 2 (lag 1), 4 (lag 2), 8 (lag 4).
    first, second, third = [1.068, 1.070, 1.072], [1.0800, 1.0805, 1.0810], [1.0822, 1.0823, 1.0824]
    d2, d4, d8 = splits(first, 1), splits(second, 2), splits(third, 4)
    assert onset(first, d2) == pytest.approx(1.0663, abs=2e-4)
    assert onset(second, d4) == pytest.approx(1.0793, abs=2e-4)
    assert onset(third, d8) == pytest.approx(1.0821, abs=2e-4)
    # SciPy's DOP853 on the same equation finds the same splits at the strobe k = 308 (its
    # transient 300 periods and 8 more): the period-2 orbit's at γ = 1.070, the period-8 one's
    # at γ = 1.0823.
    assert scipy_split(1.070, 1, k=308) == pytest.approx(d2[1], rel=1e-6)
    assert scipy_split(1.0823, 4, k=308) == pytest.approx(d8[1], rel=1e-6)


def test_the_strobe_is_the_runs_own_states():
    scene = varmech.scenes.get("damped_driven_pendulum", amplitude=1.075)
    table = stroboscopic_section(scene, *START, period=PERIOD, periods=4, transient=10, steps_per_period=100)
    traj = varmech.integrate(scene.model, *START, dt=PERIOD / 100, steps=1400, method=table.meta["method"], progress=False)
    np.testing.assert_array_equal(table.column("p0"), traj.p[1000::100, 0])
    np.testing.assert_array_equal(table.column("k"), np.arange(10, 15))


def test_strobe_period():
    assert strobe_period([1.0, 2.0, 1.0, 2.0, 1.0]) == 2
    assert strobe_period([3.0] * 5) == 1
    assert strobe_period(np.sin(np.arange(50.0))) is None


def test_a_model_without_the_period_is_refused_naming_why():
    pendulum = varmech.scenes.pendulum().model
    with pytest.raises(ValueError, match="^model: .*does not depend on t"):
        stroboscopic_section(pendulum, [0.1], [0.0], period=1.0, periods=3)
    driven = varmech.scenes.get("damped_driven_pendulum")
    with pytest.raises(ValueError, match="^period: .*not periodic with period 1"):
        stroboscopic_section(driven, *START, period=1.0, periods=3)
    with pytest.raises(ValueError, match="^periods:"):
        stroboscopic_section(driven, *START, period=PERIOD, periods=0)
    with pytest.raises(ValueError, match="^coordinate:"):
        orbit_diagram(driven, *START, parameter="amplitude", values=[1.07], period=PERIOD, coordinate="z")


def test_the_strobe_chart_draws_the_attractor_with_its_angle_wrapped(tmp_path):
    # Baker & Gollub's chaotic drive (the scene's default): hundreds of distinct points, φ taken
    # into [−π, π); its axes say so.
    pytest.importorskip("matplotlib")
    from varmech.charts import strobe_chart

    scene = varmech.scenes.get("damped_driven_pendulum")
    table = stroboscopic_section(scene, *START, period=PERIOD, periods=400, transient=50)
    assert len(np.unique(np.round(table.column("p0"), 6))) > 300
    path = tmp_path / "attractor.svg"
    strobe_chart(table, path, wrap=2 * math.pi)
    text = path.read_text()
    # The axes in the model's own names: φ, and its momentum.
    assert "phi at t₀ + kT (mod 6.283)" in text and "p_phi at t₀ + kT" in text
    with pytest.raises(ValueError, match="^coordinate:"):
        strobe_chart(table, tmp_path / "bad.svg", coordinate=1)
    with pytest.raises(ValueError, match="^wrap:"):
        strobe_chart(table, tmp_path / "bad.svg", wrap=0.0)
