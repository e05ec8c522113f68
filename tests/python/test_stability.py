"""Linear stability measured from the integrators: the scans find the limits of
reference/compositions.json, the growth factors follow the closed forms, and the implicit
methods' failure map has its failures where they belong (varmech.stability)."""

import json
import math

import numpy as np
import pytest

import varmech
from conftest import REFERENCE_DIR
from varmech import stability
from varmech.analysis.implicit import implicit_regions
from varmech.analysis.stability import (
    COMPOSITION_NAMES,
    REFERENCE_LIMITS,
    growth_factor,
    growth_table,
    stability_scan,
    stability_table,
    step_matrix,
    unstable_intervals,
)

REFERENCE = REFERENCE_DIR / "compositions.json"
DATA = json.loads(REFERENCE.read_text())
INFO = {m.name: m for m in varmech.methods()}
# Every finite limit lies below 3.4: scanning to 4 finds them all, and keeps the file fast.
SCAN_MAX = 4.0


@pytest.fixture(scope="module")
def table():
    return stability_table(h_omega_max=SCAN_MAX, progress=False)


def limit(table, name):
    return table.where(method=name).column("h_omega_max")[0]


def gammas(entry):
    half = entry["half"]
    middle = entry["middle"] if not isinstance(entry["middle"], str) else 1 - 2 * sum(half)
    return half + [middle] + half[::-1]


def numpy_step_matrix(entry, y):
    """The composition of Verlet steps g·y on q'' = -q, as a matrix product."""
    psi = np.eye(2)
    for g in gammas(entry):
        h = g * y
        psi = np.array([[1 - h * h / 2, h], [-h * (1 - h * h / 4), 1 - h * h / 2]]) @ psi
    return psi


# ------------------------------------------------------------------------ reference data


def test_embedded_limits_match_the_reference_file():
    for key, entry in DATA["methods"].items():
        assert REFERENCE_LIMITS[COMPOSITION_NAMES[key]] == entry["h_omega_max"], key
    facts = DATA["other_linear_stability_facts"]
    assert "2*sqrt(2)" in facts["rk4"] and REFERENCE_LIMITS["rk4"] == 2 * math.sqrt(2)
    assert "always unstable" in facts["explicit_euler"] and REFERENCE_LIMITS["explicit_euler"] == 0.0
    assert "h*omega < 2" in facts["symplectic_euler"] and REFERENCE_LIMITS["symplectic_euler"] == 2.0
    assert "for all h" in facts["implicit_midpoint"] and REFERENCE_LIMITS["midpoint"] == math.inf


def test_composition_names_map_to_the_same_methods():
    """Every composition of the file is a varmech method with its order and stages, and one step
    of it is the file's composition of Verlet steps (so the name map is right)."""
    assert set(COMPOSITION_NAMES) == set(DATA["methods"])
    for key, entry in DATA["methods"].items():
        info = INFO[COMPOSITION_NAMES[key]]
        assert (info.order, info.stages) == (entry["order"], entry["stages"]), key
        assert info.symplectic and info.symmetric and not info.implicit
        for y in (0.7, 1.9):
            np.testing.assert_allclose(step_matrix(info.name, y), numpy_step_matrix(entry, y), rtol=0, atol=1e-13)


# ---------------------------------------------------------------------------------- scans


@pytest.mark.parametrize("key", sorted(DATA["methods"]))
def test_composition_scans_within_one_percent_of_reference(table, key):
    name = COMPOSITION_NAMES[key]
    ref = DATA["methods"][key]["h_omega_max"]
    measured = limit(table, name)
    assert abs(measured / ref - 1) < 0.01, (name, measured, ref)
    # The reference values are rounded to 4–5 digits, and the scan agrees to that rounding.
    assert abs(measured / ref - 1) < 5e-5, (name, measured, ref)


def test_baselines_and_first_order_methods(table):
    assert abs(limit(table, "rk4") / (2 * math.sqrt(2)) - 1) < 0.01
    assert abs(limit(table, "rk4") - 2 * math.sqrt(2)) < 1e-8
    assert abs(limit(table, "symplectic_euler") - 2) < 1e-9
    assert limit(table, "explicit_euler") == 0.0
    assert limit(table, "trapezoid") == pytest.approx(2.0, abs=1e-9)  # Verlet, solved implicitly


def test_midpoint_and_galerkin_are_unbounded(table):
    for name in ("midpoint", "galerkin4", "galerkin6"):
        assert limit(table, name) == math.inf
    assert stability_scan("midpoint", h_omega_max=100.0, resolution=0.05, progress=False) == math.inf


def test_table_agrees_with_the_documented_limits(table):
    for row in table:
        doc, measured = row["documented"], row["h_omega_max"]
        if math.isinf(doc) or doc == 0:
            assert measured == doc, row
        else:
            assert abs(measured / doc - 1) < 0.01, row
        if not math.isnan(row["reference"]):
            assert abs(row["relative_difference"]) < 0.01, row
    assert set(table.column("method")) == {m.name for m in varmech.methods() if not m.constrained and not m.nonholonomic and not m.nbody}


# -------------------------------------------------------------------------- growth factors


def test_midpoint_growth_is_one_to_round_off_at_large_steps():
    for y in (10.0, 1e3):
        assert abs(growth_factor("midpoint", y) - 1) < 1e-14
    # A rotation by 2·arctan(hω/2): the trace of the step matrix is 2·cos of it.
    psi = step_matrix("midpoint", 10.0)
    assert np.trace(psi) == pytest.approx(2 * math.cos(2 * math.atan(5.0)), abs=1e-14)


def test_rk4_growth_follows_its_stability_polynomial():
    y = np.linspace(0.05, 3.5, 70)
    expected = np.sqrt(1 - y**6 / 72 + y**8 / 576)
    assert np.max(np.abs(growth_factor("rk4", y) - expected)) < 1e-12


def test_closed_forms_of_euler_and_verlet():
    y = np.array([0.5, 1.0, 1.99, 2.5, 3.0])
    assert np.max(np.abs(growth_factor("explicit_euler", y) - np.sqrt(1 + y**2))) < 1e-13
    tau = 2 - y**2  # cos(θ) = 1 − (hω)²/2
    expected = np.where(np.abs(tau) <= 2, 1.0, np.abs(tau) / 2 + np.sqrt(np.maximum(tau**2 / 4 - 1, 0)))
    assert np.max(np.abs(growth_factor("verlet", y) - expected)) < 1e-13


def test_symplectic_methods_have_unit_growth_inside_their_interval():
    for name in ("verlet", "yoshida4", "kahan_li8", "trapezoid", "galerkin4", "galerkin6"):
        lim = min(INFO[name].h_omega_max, 4.0)
        y = np.linspace(0.01, 0.99 * lim, 25)
        assert np.max(np.abs(growth_factor(name, y) - 1)) < 1e-12, name
        assert abs(np.linalg.det(step_matrix(name, 0.5 * lim)) - 1) < 1e-13, name


def test_resonance_windows_beyond_the_first_instability():
    """Kahan–Li 8 turns stable again after a short unstable window past its limit."""
    windows = unstable_intervals("kahan_li8", 6.0, resolution=0.002, progress=False)
    assert len(windows) >= 2
    first, second = windows[0], windows[1]
    assert abs(first[0] / REFERENCE_LIMITS["kahan_li8"] - 1) < 1e-4
    assert first[1] < 3.2 and second[0] > 5.5
    # Inside the gap it is stable, as an independent matrix product confirms.
    entry = DATA["methods"]["kahan_li_8_17stage"]
    assert abs(np.trace(numpy_step_matrix(entry, 4.0))) < 2
    assert abs(growth_factor("kahan_li8", 4.0) - 1) < 1e-12
    assert unstable_intervals("midpoint", 5.0, resolution=0.01, progress=False) == []
    assert unstable_intervals("explicit_euler", 1.0, resolution=0.01, progress=False) == [(0.0, 1.0)]


def test_growth_table_carries_the_limits():
    t = growth_table(["verlet", "rk4", "midpoint"], np.linspace(0.1, 3.0, 30), progress=False)
    assert t.columns == ("method", "h_omega", "growth") and len(t) == 90
    assert t.meta["limits"]["verlet"] == pytest.approx(2.0, abs=1e-9)
    assert t.meta["limits"]["midpoint"] == math.inf


def test_arguments_are_checked():
    with pytest.raises(ValueError, match="method"):
        growth_factor("nonsense", 1.0)
    with pytest.raises(ValueError, match="constrained"):
        growth_factor("rattle", 1.0)
    with pytest.raises(ValueError, match="h_omega"):
        growth_factor("verlet", -1.0)
    with pytest.raises(ValueError, match="resolution"):
        stability_scan("verlet", h_omega_max=1.0, resolution=2.0)


# ------------------------------------------------------------------------ implicit methods


@pytest.fixture(scope="module")
def regions():
    return implicit_regions(progress=False)


def test_implicit_regions_fail_near_the_top_at_large_steps(regions):
    assert set(regions.unique("method")) == set(stability.IMPLICIT_METHODS)
    assert set(regions.unique("outcome")) <= set(stability.OUTCOMES)
    # Near the top the midpoint rule's DEL map has a fold once h ≥ 2 (h²/4 > 1/|cos q|): none of
    # these runs may pass, and at least one is refused by Newton or the fold test.
    top = [r for r in regions if r["method"] == "midpoint" and r["q0"] >= 3.0 and r["h"] >= 3.0]
    assert top and all(r["outcome"] != "ok" for r in top)
    assert any(r["outcome"] in ("newton failure", "spurious branch") for r in top)
    failures = [r for r in regions if r["q0"] >= 2.75 and r["h"] >= 3.0 and r["outcome"] in ("newton failure", "spurious branch")]
    assert failures
    small = [r for r in regions if r["h"] <= 0.25 and r["q0"] <= 1.0]
    assert small and all(r["outcome"] == "ok" and r["steps_done"] == 20 for r in small)
    for r in regions:
        if r["outcome"] == "ok":
            assert r["energy_error"] <= 0.05 and r["steps_done"] == 20
        else:
            assert r["steps_done"] < 20 or r["outcome"] == "energy"


def test_implicit_regions_on_a_chosen_grid():
    t = implicit_regions("midpoint", h_values=[0.1, 3.0], q0_values=[0.5, 3.0], steps=10, progress=False)
    outcome = {(r["h"], r["q0"]): r["outcome"] for r in t}
    assert outcome[(0.1, 0.5)] == "ok" and outcome[(0.1, 3.0)] == "ok"
    assert outcome[(3.0, 3.0)] in ("newton failure", "spurious branch")


# ---------------------------------------------------------------------------------- charts


def test_charts_write_their_files(tmp_path, regions):
    pytest.importorskip("matplotlib")
    from varmech.charts.stability import implicit_regions_chart, stability_chart

    t = growth_table(["verlet", "yoshida4", "rk4", "midpoint"], np.linspace(0.05, 3.5, 70), progress=False)
    stability_chart(t, tmp_path / "growth.png")
    stability_chart(t, tmp_path / "growth.svg", limits=REFERENCE_LIMITS)
    implicit_regions_chart(regions, tmp_path / "regions.png")
    assert all((tmp_path / name).stat().st_size > 10_000 for name in ("growth.png", "growth.svg", "regions.png"))
    with pytest.raises(ValueError, match="path"):
        stability_chart(t, tmp_path / "growth.pdf")
