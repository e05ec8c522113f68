"""The command line writes what it says."""

import pytest

import varmech
from varmech import scenes
from varmech.cli import TOUR, TOUR_REDUCED, tour_runs


def test_methods_table(run_cli):
    out = run_cli("methods").stdout
    assert "| `kahan_li8` | 8 | 17 |" in out


def test_tour_prints_reports_and_writes_plots(tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    out = run_cli("tour", "--quick", "--out", tmp_path).stdout
    runs = sum(len(methods) for _, methods, _ in tour_runs()) + sum(len(methods) for _, _, methods in TOUR_REDUCED)
    assert runs == 52 and out.count("Conservation report") == runs
    assert "max |G M⁻¹ p|" in out
    assert "verdict: secular drift" in out and "verdict: bounded" in out
    # The summary: every symplectic or variational run conserves its energy (or its balance),
    # and every RK4 run drifts.
    lines = out.splitlines()
    start = lines.index(next(line for line in lines if line.startswith("Tour: energy error")))
    rows = [line.split(" | ") for line in lines[start + 2 : start + 2 + runs]]
    assert len(rows) == runs and all(len(r) == 6 for r in rows)
    info = {m.name: m for m in varmech.methods()}
    rolling = {name for name in scenes.CATALOGUE if scenes.get(name).model.velocity_constraints}
    for scene, method, _, _, _, verdict in rows:
        # The discrete Lagrange–d'Alembert step is not symplectic (nonholonomic flows are not):
        # the ball on the incline accelerates (its energy error grows with it over its t_end)
        # and the turntable's energy is not conserved.
        if info[method].symplectic and scene.strip("| `") not in rolling:
            assert verdict.removeprefix("balance E − W ") in ("conserved to round-off", "bounded"), (scene, method, verdict)
        if method == "rk4":
            assert verdict == "secular drift", scene
    written = sorted(p.name for p in tmp_path.glob("*_energy.png"))
    assert written == sorted(f"{name}_energy.png" for name in scenes.CATALOGUE)
    # The charts, each with its data.
    for stem in ["work_precision_kepler", "energy_growth_kepler", "stability", "implicit_regions_pendulum", "phase_portrait_pendulum"]:
        assert (tmp_path / f"{stem}.png").exists() and (tmp_path / f"{stem}.csv").exists()
    # The reduced runs, reconstructed: the ignored momenta are exact by construction.
    assert sum(line.startswith("=== ") and "Routh-reduced" in line for line in out.splitlines()) == len(TOUR_REDUCED)
    assert out.count("max |ΔJ| = 0.000e+00") >= sum(len(c) * len(m) for _, c, m in TOUR_REDUCED)
    named = {line.split(" ", 1)[1] for line in out.splitlines() if line.startswith("wrote ")}
    assert named == {str(p) for p in tmp_path.iterdir()}


def test_the_tour_runs_every_scene_with_its_showcase_or_its_kinds_methods():
    runs = {scene.name: (methods, horizon) for scene, methods, horizon in tour_runs()}
    assert list(runs) == list(scenes.CATALOGUE)
    for name, (methods, horizon) in TOUR.items():
        assert runs[name] == (methods, horizon if horizon is not None else scenes.get(name).t_end)
    kind = scenes.damped_driven_pendulum().model.kind
    assert runs["damped_driven_pendulum"] == ((kind.default_method, kind.accurate_method), 100.0)


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
