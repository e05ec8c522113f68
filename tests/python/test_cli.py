"""The command line writes what it says."""

import pytest

from varmech.cli import TOUR, TOUR_REDUCED


def test_methods_table(run_cli):
    out = run_cli("methods").stdout
    assert "| `kahan_li8` | 8 | 17 |" in out


def test_tour_prints_reports_and_writes_plots(tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    out = run_cli("tour", "--quick", "--out", tmp_path).stdout
    runs = sum(len(methods) for _, methods, _ in TOUR) + sum(len(methods) for _, _, methods in TOUR_REDUCED)
    assert runs == 40 and out.count("Conservation report") == runs
    assert "max |G M⁻¹ p|" in out
    assert "verdict: secular drift" in out and "verdict: bounded" in out
    written = sorted(p.name for p in tmp_path.glob("*_energy.png"))
    assert written == sorted(f"{name}_energy.png" for name, _, _ in TOUR)
    # The charts, each with its data.
    for stem in ["work_precision_kepler", "energy_growth_kepler", "stability", "implicit_regions_pendulum", "phase_portrait_pendulum"]:
        assert (tmp_path / f"{stem}.png").exists() and (tmp_path / f"{stem}.csv").exists()
    # The reduced runs, reconstructed: the ignored momenta are exact by construction.
    assert out.count("Routh-reduced") == len(TOUR_REDUCED)
    assert out.count("max |ΔJ| = 0.000e+00") >= sum(len(c) * len(m) for _, c, m in TOUR_REDUCED)
    named = {line.split(" ", 1)[1] for line in out.splitlines() if line.startswith("wrote ")}
    assert named == {str(p) for p in tmp_path.iterdir()}


@pytest.mark.parametrize("kind", ["stability", "phase"])
def test_chart_writes_the_files_it_names(tmp_path, kind, run_cli):
    pytest.importorskip("matplotlib")
    out = run_cli("chart", kind, "--quick", "--format", "svg", "--out", tmp_path).stdout
    named = [line.split(" ", 1)[1] for line in out.splitlines() if line.startswith("wrote ")]
    assert {p.rsplit(".", 1)[1] for p in named} == {"csv", "svg"}
    assert sorted(named) == sorted(str(p) for p in tmp_path.iterdir())
    header = next(line for line in open(next(p for p in named if p.endswith(".csv"))) if not line.startswith("#"))
    assert header.startswith("method," if kind == "stability" else "orbit,")


def test_chart_refuses_an_unknown_scene(run_cli):
    result = run_cli("chart", "phase", "nowhere", check=False)
    assert result.returncode != 0 and "scene:" in result.stderr
