"""Work–precision sweeps and long-run energy growth: the tables' numbers, the verdicts, the
baselines (SciPy and REBOUND, optional) and the charts. Kept to a few seconds in all."""

import math

import numpy as np
import pytest

import varmech
from varmech import scenes
from varmech.analysis import baselines
from varmech.analysis import work_precision as wp
from varmech.analysis.energy_growth import ENERGY_GROWTH_COLUMNS, energy_growth, verdicts
from varmech.analysis.work_precision import work_precision
from varmech.scenes import Reference

PERIOD = 2 * math.pi


def kepler_periods(periods):
    """Kepler (e = 0.6) with its exact reference after ``periods`` whole periods: the start."""
    scene = scenes.kepler()
    return scene, Reference(periods * PERIOD, scene.q0.copy(), scene.p0.copy(), f"exact: {periods} whole periods")


def ratios(table, method):
    rows = table.where(method=method)
    err = rows.column("final_error")
    return err[:-1] / err[1:]


@pytest.fixture(scope="module")
def kepler_sweep():
    scene, ref = kepler_periods(10)
    steps = {"verlet": [2**13, 2**14, 2**15], "yoshida4": [2**11, 2**12, 2**13], "kahan_li8": [2**10, 2**11, 2**12]}
    return work_precision(scene, ["verlet", "yoshida4", "kahan_li8"], steps=steps, baselines=(), reference=ref, repeat=1, progress=False)


def test_table_has_one_row_per_method_and_setting(kepler_sweep):
    t = kepler_sweep
    assert t.columns == wp.WORK_PRECISION_COLUMNS
    assert {(r["method"], r["value"]) for r in t} == {
        *(("verlet", n) for n in (2**13, 2**14, 2**15)),
        *(("yoshida4", n) for n in (2**11, 2**12, 2**13)),
        *(("kahan_li8", n) for n in (2**10, 2**11, 2**12)),
    }
    assert len(t) == 9 and set(t.column("tool")) == {"varmech"} and set(t.column("parameter")) == {"steps"}
    assert np.all(t.column("seconds") > 0)
    for r in t:
        # Force evaluations: first same as last, so (stages) × steps + 1.
        stages = {"verlet": 1, "yoshida4": 3, "kahan_li8": 17}[r["method"]]
        assert r["evaluations"] == stages * r["steps"] + 1
        assert 0 < r["max_energy_error"] < 1e-2
    assert t.meta["t_end"] == pytest.approx(10 * PERIOD) and t.meta["notes"] == []


def test_final_error_falls_at_each_methods_order(kepler_sweep):
    # Halving the step divides the error by 2^order: 4, 16, 256.
    np.testing.assert_allclose(ratios(kepler_sweep, "verlet"), 4.0, rtol=0.1)
    np.testing.assert_allclose(ratios(kepler_sweep, "yoshida4"), 16.0, rtol=0.15)
    assert np.all((ratios(kepler_sweep, "kahan_li8")[:1] > 150) & (ratios(kepler_sweep, "kahan_li8")[:1] < 400))


def test_default_sweep_is_powers_of_two_and_stops_at_round_off():
    scene, ref = kepler_periods(10)
    t = work_precision(scene, ["kahan_li8"], baselines=(), reference=ref, repeat=1, progress=False)
    steps = t.column("value")
    assert np.all(steps[1:] / steps[:-1] == 2)
    assert steps[0] == 2 ** math.floor(math.log2(10 * PERIOD / scene.dt / 4))
    # Round-off comes within a few doublings: the sweep stops there, well short of 11 settings.
    assert 3 <= len(t) < 11 and t.column("final_error").min() < 1e-11


def test_final_error_skips_unknown_reference_components():
    # The spherical pendulum's reference gives the angles only (p_θ is NaN).
    scene = scenes.spherical_pendulum()
    assert np.isnan(scene.reference.p).any()
    t = work_precision(scene, ["midpoint"], steps=[2500, 5000], baselines=(), repeat=1, progress=False)
    err = t.column("final_error")
    assert np.all(np.isfinite(err)) and err[0] / err[1] == pytest.approx(4.0, rel=0.2)


def test_a_reference_at_another_horizon_is_computed_there_and_none_gives_nan():
    scene = scenes.kepler()
    kwargs = dict(steps=[1000], baselines=(), t_end=100 * scene.dt, repeat=1, progress=False)
    computed = work_precision(scene, ["verlet"], **kwargs)
    assert computed.meta["notes"][0].startswith("reference computed: kahan_li6 at ") and computed.meta["reference_tolerance"] < 1e-9
    exact = work_precision(scene, ["verlet"], reference=scene.reference, **kwargs)
    assert math.isnan(exact.rows[0][7]) and exact.meta["notes"][0].startswith("no reference at t = 3.14159 (the reference given is at t = 1256.64)")
    none = work_precision(scene, ["verlet"], reference=None, **kwargs)
    assert math.isnan(none.rows[0][7]) and none.meta["notes"] == ["no reference (reference=None): final_error is NaN"]
    assert computed.rows[0][8] == none.rows[0][8]  # the energy error is measured all the same


def test_scipy_baselines_sweep_tolerances():
    pytest.importorskip("scipy")
    scene, ref = kepler_periods(10)
    t = work_precision(
        scene, ["kahan_li8"], steps=[2**11], baselines=("RK45", "DOP853", "Radau"), rtols=(1e-4, 1e-7), reference=ref, repeat=1, progress=False
    )
    assert {(r["tool"], r["method"], r["value"]) for r in t if r["tool"] == "scipy"} == {
        ("scipy", m, r) for m in ("RK45", "DOP853", "Radau") for r in (1e-4, 1e-7)
    }
    for method in ("RK45", "DOP853", "Radau"):
        rows = t.where(method=method)
        assert set(rows.column("parameter")) == {"rtol"}
        # A tighter tolerance: more work, smaller errors.
        assert np.all(np.diff(rows.column("evaluations")) > 0)
        assert np.all(np.diff(rows.column("final_error")) < 0) and np.all(np.diff(rows.column("max_energy_error")) < 0)
        # Every step costs several evaluations (DOP853 12, RK45 6, Radau's Newton iterations).
        assert np.all(rows.column("evaluations") > 4 * rows.column("steps"))
    # DOP853 at rtol 1e-7 has the final error of a tolerance-driven run: about 1e-3 here.
    assert 1e-5 < t.where(method="DOP853").rows[-1][7] < 1e-2


def test_missing_scipy_is_skipped_with_a_note(monkeypatch):
    monkeypatch.setattr(baselines, "import_scipy", lambda: None)
    scene, ref = kepler_periods(1)
    t = work_precision(scene, ["verlet"], steps=[1000], reference=ref, repeat=1, progress=False)
    assert set(t.column("tool")) == {"varmech"}
    assert any("SciPy is not installed" in n for n in t.meta["notes"])
    g = energy_growth(scene, ["verlet"], t_end=10 * PERIOD, samples=100, progress=False)
    assert set(g.column("tool")) == {"varmech"} and any("SciPy is not installed" in n for n in g.meta["notes"])


def two_body():
    """A planet of 10⁻³ solar masses on a circular orbit of radius 1 (G = 1), barycentric."""
    m = np.array([1.0, 1e-3])
    mu = m.sum()
    x = np.array([[-1e-3 / mu, 0, 0], [1 / mu, 0, 0]])
    w = math.sqrt(mu)
    v = np.array([[0, -w * 1e-3 / mu, 0], [0, w / mu, 0]])
    scene = scenes.nbody(m, x, v, G=1.0, t_end=10.0, dt=0.01)
    period = 2 * math.pi / w
    return scene, period, Reference(5 * period, scene.q0.copy(), scene.p0.copy(), "5 whole periods")


def test_rebound_baselines_on_an_nbody_scene():
    pytest.importorskip("rebound")
    scene, _, ref = two_body()
    t = work_precision(scene, ["verlet"], steps=[256, 512], baselines=(), epsilons=(1e-4, 1e-9), reference=ref, repeat=1, progress=False)
    rows = t.where(tool="rebound")
    assert {(r["method"], r["parameter"], r["value"]) for r in rows} == {
        ("WHFast", "steps", 256),
        ("WHFast", "steps", 512),
        ("IAS15", "epsilon", 1e-4),
        ("IAS15", "epsilon", 1e-9),
    }
    # WHFast solves the two-body problem exactly (Kepler drift), IAS15 to round-off.
    assert np.all(rows.column("final_error") < 1e-10) and np.all(rows.column("max_energy_error") < 1e-12)
    assert np.all(rows.where(method="WHFast").column("evaluations") == [256, 512])
    assert np.all(rows.where(method="IAS15").column("evaluations") > rows.where(method="IAS15").column("steps"))
    # Kepler is not an N-body scene: no REBOUND rows there.
    k, kref = kepler_periods(1)
    assert "rebound" not in work_precision(k, ["verlet"], steps=[500], baselines=(), reference=kref, repeat=1, progress=False).unique("tool")


@pytest.fixture(scope="module")
def long_kepler():
    """500 periods of Kepler (e = 0.6) at h = 2π/200, DOP853 at rtol 1e-7 over the same horizon."""
    pytest.importorskip("scipy")
    scene = scenes.kepler()
    return energy_growth(
        scene, ["verlet", "kahan_li8", "rk4"], t_end=500 * PERIOD, samples=400, baselines=("DOP853",), rtol=1e-7,
        baseline_t_end=500 * PERIOD, progress=False,
    )


def test_long_kepler_verdicts(long_kepler):
    v = long_kepler.meta["verdicts"]
    assert v["verlet"]["verdict"] == "bounded"
    # Eighth order at h = 2π/200: its truncation error is below round-off over 10⁵ steps.
    assert v["kahan_li8"]["verdict"] == "conserved to round-off"
    assert v["rk4"]["verdict"] == "secular drift"
    assert v["DOP853"]["verdict"] == "secular drift" and v["DOP853"]["tool"] == "scipy"
    # Both drifts are many standard errors from zero and lose energy; the symplectic errors are
    # no larger at the end than at the start.
    for m in ("rk4", "DOP853"):
        assert v[m]["drift_rate"] < 0 and abs(v[m]["drift_rate"]) > 100 * v[m]["drift_rate_stderr"]
        assert v[m]["max_error_last_tenth"] > 5 * v[m]["max_error_first_tenth"]
    for m in ("verlet", "kahan_li8"):
        assert v[m]["max_error_last_tenth"] < 1.5 * v[m]["max_error_first_tenth"]
    # RK4's fitted drift is the energy it loses in a plain run: 3.3e-6 a period at h = 2π/200
    # (HLW report 1.05e-4 at h = 2π/100; halving h divides it by 33, not 16, at e = 0.6).
    scene = scenes.kepler()
    run = varmech.integrate(scene, dt=PERIOD / 200, steps=500 * 200, method="rk4", save_every=200)
    energy = run.energy()
    per_period = (energy[-1] - energy[0]) / 500
    assert v["rk4"]["drift_rate"] * PERIOD == pytest.approx(per_period, rel=0.05)
    small = verdicts(long_kepler)
    assert small.unique("method") == ["verlet", "kahan_li8", "rk4", "DOP853"]


def test_energy_growth_rows_are_log_spaced_with_a_running_maximum(long_kepler):
    t = long_kepler
    assert t.columns == ENERGY_GROWTH_COLUMNS
    for method in ("verlet", "kahan_li8", "rk4", "DOP853"):
        rows = t.where(method=method)
        times, err, top = rows.column("t"), rows.column("energy_error"), rows.column("max_energy_error")
        assert np.all(np.diff(times) > 0) and np.all(np.diff(top) >= 0) and np.all(err <= top)
        # Spread over five decades: from the first step to the horizon.
        # (each row is the worst sample of its log-spaced bin, so the last one lies in the last bin)
        assert times[0] <= scenes.kepler().dt and 0.95 * 500 * PERIOD <= times[-1] <= (1 + 1e-12) * 500 * PERIOD
        assert np.sum(times < 10) > 50 and len(rows) > 150
    # The drifting curve climbs by orders of magnitude over the last two decades; the bounded
    # ones do not move.
    top = lambda m, at: np.interp(at, t.where(method=m).column("t"), t.where(method=m).column("max_energy_error"))  # noqa: E731
    assert top("rk4", 500 * PERIOD) > 50 * top("rk4", 5 * PERIOD)
    assert top("verlet", 500 * PERIOD) < 1.01 * top("verlet", 5 * PERIOD)


def test_energy_growth_defaults_to_ten_thousand_kepler_periods():
    # Only the horizon arithmetic: 50 × the scene's 200 periods, in whole steps of scene.dt.
    scene = scenes.kepler()
    assert round(50 * scene.t_end / scene.dt) * scene.dt == pytest.approx(1e4 * PERIOD)


def test_ctrl_c_stops_a_sweep_and_keeps_the_rows_so_far(interrupt_after):
    scene, ref = kepler_periods(1)
    with pytest.raises(KeyboardInterrupt) as info:
        timer, _ = interrupt_after(0.5)
        # The second setting would take minutes.
        work_precision(scene, ["verlet"], steps=[200, 2**34], baselines=(), reference=ref, repeat=1, progress=False)
    timer.join()
    partial = info.value.partial
    assert len(partial) == 1 and partial.rows[0][3] == 200


def test_charts_write_files(tmp_path, kepler_sweep, long_kepler):
    pytest.importorskip("matplotlib")
    from varmech.charts.work_precision import energy_growth_chart, work_precision_chart

    for x, y in (("seconds", "final_error"), ("evaluations", "max_energy_error")):
        work_precision_chart(kepler_sweep, tmp_path / f"wp_{x}_{y}.png", x=x, y=y)
        assert (tmp_path / f"wp_{x}_{y}.png").stat().st_size > 10_000
    energy_growth_chart(long_kepler, tmp_path / "growth.svg")
    assert (tmp_path / "growth.svg").stat().st_size > 10_000
    with pytest.raises(ValueError, match="no column"):
        work_precision_chart(kepler_sweep, tmp_path / "bad.png", x="wall")


def test_rebound_leapfrog_order8_falls_at_order_8_on_kepler_and_is_mclachlan8_dkd():
    """REBOUND's leapfrog with order=8 on Kepler e = 0.3 over 10 periods, at 24 and 48 steps a
    period: final errors 1.34e-6 and 5.33e-9 (measured), a slope of 7.97, the same as varmech's
    mclachlan8_dkd (the same SS17 of drift–kick–drift Verlet) to round-off, at 17 forces a step."""
    pytest.importorskip("rebound")
    scene = scenes.kepler(0.3)
    ref = Reference(10 * PERIOD, scene.q0.copy(), scene.p0.copy(), "exact: 10 whole periods")
    steps = [240, 480]
    t = work_precision(
        scene, ["mclachlan8_dkd"], steps={"mclachlan8_dkd": steps, "leapfrog order=8": steps}, baselines=(),
        rebound=("leapfrog order=8",), reference=ref, repeat=1, progress=False,
    )
    rows = t.where(tool="rebound")
    assert list(rows.column("method")) == ["leapfrog order=8"] * 2 and list(rows.column("steps")) == steps
    err = rows.column("final_error")
    assert math.log2(err[0] / err[1]) == pytest.approx(8.0, abs=0.25)
    # Round-off apart (REBOUND sums uncompensated): 2.7e-12 at 480 steps.
    np.testing.assert_allclose(err, t.where(tool="varmech").column("final_error"), rtol=0, atol=1e-11)
    assert list(rows.column("evaluations")) == [17 * n for n in steps]
    # Bounded energy error, at the scale of the state's error.
    assert np.all(rows.column("max_energy_error") < 10 * err)


def test_rebound_baselines_run_where_they_apply():
    """On Kepler only leapfrog order=8 runs (the others skipped with a note when asked for); on
    an N-body scene every one, leapfrog order=8 agreeing with mclachlan8_dkd."""
    pytest.importorskip("rebound")
    notes: list[str] = []
    _, names = baselines.rebound_baselines(scenes.kepler(), baselines.REBOUND_METHODS, notes, asked=True)
    assert names == ["leapfrog order=8"]
    assert notes == [
        "REBOUND baselines ['WHFast', 'IAS15', 'WHFast corrector=11'] skipped: kepler is not an N-body scene; only the Kepler ones run"
    ]
    scene, _, ref = two_body()
    t = work_precision(
        scene, ["mclachlan8_dkd"], steps=[64], baselines=(), rebound=baselines.REBOUND_METHODS, epsilons=(1e-9,),
        reference=ref, repeat=1, progress=False,
    )
    assert set(t.where(tool="rebound").column("method")) == set(baselines.REBOUND_METHODS)
    np.testing.assert_allclose(
        t.where(method="leapfrog order=8").column("final_error"), t.where(method="mclachlan8_dkd").column("final_error"), rtol=1e-6
    )


def test_rebound_whfast_corrector_11_is_whc_on_the_outer_solar_system():
    """WHFast with corrector=11 (safe_mode=0) over 500 000 days at h = 100 days ends where
    varmech's whc does (5.02e-6 from HLW's reference, measured), 60 times closer than WHFast
    without the corrector (3.04e-4, as wh), with an energy error bounded at 8e-10."""
    pytest.importorskip("rebound")
    scene = scenes.outer_solar_system()
    names = ("WHFast", "WHFast corrector=11")
    t = work_precision(
        scene, ["whc", "wh"], steps=[5000], baselines=(), rebound=names, reference=scene.reference, repeat=1, progress=False
    )
    error = {m: t.where(method=m).column("final_error")[0] for m in ("whc", "wh", *names)}
    assert error["WHFast corrector=11"] == pytest.approx(error["whc"], rel=1e-4)
    assert error["WHFast"] == pytest.approx(error["wh"], rel=1e-4)
    assert error["WHFast"] > 50 * error["WHFast corrector=11"]
    assert t.where(method="WHFast corrector=11").column("max_energy_error")[0] < 1e-9
