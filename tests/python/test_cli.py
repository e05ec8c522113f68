"""The command line writes what it says."""

import subprocess
import sys

import pytest

import varmech
from varmech import scenes
from varmech._catalogue import DECLARED
from varmech.charts.recipes import KINDS, chart, fitting_methods, scenes_for
from varmech.cli import TOUR_REDUCED, tour_runs


def test_methods_table(run_cli):
    out = run_cli("methods").stdout
    assert "| `kahan_li8` | 8 | 17 |" in out


def test_a_pipe_closed_early_ends_quietly():
    # `varmech methods | head -1`: the reader closes the pipe (here before the table is written,
    # which its import takes long enough for); no BrokenPipeError traceback, status 141
    # (128 + SIGPIPE) as Unix tools end.
    reader = subprocess.Popen([sys.executable, "-m", "varmech", "methods"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert reader.stdout is not None
    reader.stdout.close()
    _, err = reader.communicate()
    assert reader.returncode == 141 and b"Traceback" not in err and b"BrokenPipe" not in err, err


def test_version_and_plain_help(run_cli):
    assert run_cli("--version").stdout == f"python -m varmech {varmech.__version__}\n"
    out = run_cli("--help").stdout
    assert out.startswith("usage: python -m varmech") and "``" not in out


def test_tour_prints_reports_and_writes_plots(tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    out = run_cli("tour", "--quick", "--out", tmp_path).stdout
    runs = sum(len(methods) for _, methods, _ in tour_runs()) + sum(len(methods) for _, _, methods in TOUR_REDUCED)
    assert runs == 56 and out.count("Conservation report") == runs  # the rolling scenes: midpoint and dla4
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
            assert verdict.removeprefix("energy balance ") in ("conserved to round-off", "bounded"), (scene, method, verdict)
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
    for name, declared in DECLARED.items():
        if declared.tour is not None:
            methods, horizon = declared.tour
            assert runs[name] == (methods, horizon if horizon is not None else scenes.get(name).t_end)
    kind = scenes.damped_driven_pendulum().model.kind
    assert runs["damped_driven_pendulum"] == ((kind.default_method, kind.accurate_method), 100.0)


def test_the_tour_exits_1_naming_what_failed_and_goes_on_past_it(tmp_path, monkeypatch, capsys):
    import dataclasses

    from varmech import cli

    pendulum = scenes.pendulum()
    # A step of half the period blows up at once; the run after it is the tour's own.
    blowing_up = dataclasses.replace(pendulum, dt=3.0)
    monkeypatch.setattr(cli, "tour_runs", lambda: [(blowing_up, ("verlet",), 30.0), (pendulum, ("verlet",), 10.0)])
    monkeypatch.setattr(cli, "TOUR_REDUCED", [])
    monkeypatch.setattr(cli, "TOUR_CHARTS", ())
    assert cli.tour(tmp_path, quick=False) == 1
    out, err = capsys.readouterr()
    assert "tour: pendulum, verlet: DivergenceError" in err and out.count("Conservation report") == 1
    monkeypatch.setattr(cli, "tour_runs", lambda: [(pendulum, ("verlet",), 10.0)])
    assert cli.tour(tmp_path, quick=False) == 0


def chart_from_the_command_line(run_cli, kind, out):
    """Runs ``chart <kind> --quick --format svg`` and checks that it wrote the files it names,
    figures and their data, with the CSV header of the kind."""
    printed = run_cli("chart", kind, "--quick", "--format", "svg", "--out", out).stdout
    named = [line.split(" ", 1)[1] for line in printed.splitlines() if line.startswith("wrote ")]
    assert {p.rsplit(".", 1)[1] for p in named} == {"csv", "svg"}
    assert sorted(named) == sorted(str(p) for p in out.iterdir())
    header = next(line for line in open(next(p for p in named if p.endswith(".csv"))) if not line.startswith("#"))
    assert header.startswith("method," if kind == "stability" else "orbit,")


def test_chart_writes_the_files_it_names(tmp_path, run_cli):
    """The phase portrait; the stability chart's are checked with its labels, below."""
    pytest.importorskip("matplotlib")
    chart_from_the_command_line(run_cli, "phase", tmp_path)


def test_chart_refuses_an_unknown_scene(run_cli):
    result = run_cli("chart", "phase", "nowhere", check=False)
    assert result.returncode != 0 and "scene:" in result.stderr


def svg_texts(path):
    """The texts of a matplotlib SVG (each drawn text is preceded by a comment holding it)."""
    import re

    return re.findall(r"<!-- (.*?) -->", path.read_text(), flags=re.S)


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(kind for kind in KINDS if scenes_for(kind)))
def test_every_chart_runs_with_its_defaults_on_every_scene_it_lists(tmp_path, kind):
    """Every scene the kind applies to, with the default methods (from the scene's kind):
    none is refused for its method. The sweeps are the quick ones. The charts of no scene
    (stability, nonholonomic) are drawn with their defaults by their own tests, which check more."""
    pytest.importorskip("matplotlib")
    for name in scenes_for(kind):
        scene = scenes.get(name)
        assert all(scene.model.kind.admits(m) for m in fitting_methods(KINDS[kind].methods, scene)), name
        # The rest by their methods alone (their sweeps take minutes), and these drawn by other
        # tests: kepler's by the tour, outer_solar_system's work-precision chart by
        # test_work_precision_titles_and_units_in_days, double_pendulum's energy chart by
        # test_energy_and_work_precision_default_to_the_scenes_kind.
        drawn = {"work-precision": ("double_pendulum",), "energy": ("outer_solar_system",)}
        if name not in drawn.get(kind, (name,)):
            continue
        written = chart(kind, name, out=tmp_path, quick=True, fmt="svg", progress=False)
        assert written and all(p.exists() for p in written), (kind, name)


def test_the_refused_scenes_are_those_a_chart_cannot_show():
    assert "kepler" not in scenes_for("phase") and "pendulum" in scenes_for("phase")
    assert set(scenes_for("poincare")) >= {"henon_heiles", "kepler", "double_pendulum"}
    assert not {"cartesian_pendulum", "elliptic_billiard", "damped_driven_pendulum"} & set(scenes_for("poincare"))
    assert fitting_methods(KINDS["energy"].methods, scenes.get("double_pendulum")) == ("galerkin6", "midpoint")
    assert fitting_methods(KINDS["energy"].methods, scenes.get("kepler")) == KINDS["energy"].methods


def test_energy_and_work_precision_default_to_the_scenes_kind(tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    out = run_cli("chart", "energy", "double_pendulum", "--quick", "--format", "svg", "--out", tmp_path).stderr
    texts = svg_texts(tmp_path / "energy_growth_double_pendulum.svg")
    assert "double_pendulum: max energy error up to t, over t = 0 … 50 time units" in texts
    assert "t (time units)" in texts and any(t.startswith("galerkin6: ") for t in texts), texts
    # SciPy's baselines ran to a shorter horizon: said on screen (standard error, with the notes).
    assert "note: solve_ivp baselines run to t = 5" in out


def test_work_precision_titles_and_units_in_days(tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    run_cli("chart", "work-precision", "outer_solar_system", "--quick", "--format", "svg", "--out", tmp_path)
    energy = svg_texts(tmp_path / "work_precision_energy_outer_solar_system.svg")
    assert any(t.startswith("outer_solar_system: max energy error over t = 0 … ") and t.endswith(" days against cost") for t in energy), energy
    assert "max relative energy error |ΔH/H₀|" in energy and "wall time (s)" in energy
    error = svg_texts(tmp_path / "work_precision_outer_solar_system.svg")
    assert any(t.startswith("outer_solar_system: error in (q, p) at t = ") and t.endswith(" days against cost") for t in error)


def test_skipped_baselines_are_said_on_screen_and_drawn_on_the_chart(tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    out = run_cli("chart", "energy", "cartesian_pendulum", "--quick", "--format", "svg", "--out", tmp_path).stderr
    # solve_ivp does not integrate a constrained scene (a DAE).
    note = "solve_ivp baselines skipped: the scene is constrained (a DAE; solve_ivp baselines do not apply)"
    assert f"note: {note}" in out.splitlines()
    texts = svg_texts(tmp_path / "energy_growth_cartesian_pendulum.svg")
    # Drawn wrapped, a text per line.
    assert f"note: {note}" in " ".join(" ".join(t.split()) for t in texts) and "t (time units)" in texts, texts


def test_the_stability_chart_labels_its_limits_and_its_coincident_curves(tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    # Drawn once (its sweeps take a while): from the command line, which writes the files it names.
    chart_from_the_command_line(run_cli, "stability", tmp_path)
    texts = svg_texts(tmp_path / "stability.svg")
    assert "verlet (the same ρ as symplectic_euler)" in texts and "midpoint: stable for every hω" in texts
    assert "symplectic_euler, verlet 2" in texts and "yoshida4 1.5734" in texts
    assert "hω (step × angular frequency, dimensionless)" in texts and "growth factor ρ(Ψ) per step" in texts


def test_poincare_takes_its_energy_and_box_on_the_command_line(tmp_path, run_cli):
    pytest.importorskip("matplotlib")
    # A box that starts below 0 takes "=" (argparse reads "-1,…" as an option).
    run_cli("chart", "poincare", "kepler", "--quick", "--energy", "-0.5", "--box=-0.1,0.1,1.5,2", "--out", tmp_path)
    assert (tmp_path / "poincare_H-0_5_kepler.png").exists()
    bad = run_cli("chart", "poincare", "kepler", "--box", "1,2", check=False)
    assert bad.returncode != 0 and "QMIN,QMAX,PMIN,PMAX" in bad.stderr
