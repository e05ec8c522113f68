"""The command line writes what it says."""

import subprocess
import sys

import pytest


def test_methods_table():
    out = subprocess.run([sys.executable, "-m", "varmech", "methods"], capture_output=True, text=True, check=True).stdout
    assert "| `kahan_li8` | 8 | 17 |" in out


def test_tour_prints_reports_and_writes_plots(tmp_path):
    pytest.importorskip("matplotlib")
    out = subprocess.run(
        [sys.executable, "-m", "varmech", "tour", "--quick", "--out", str(tmp_path)], capture_output=True, text=True, check=True
    ).stdout
    assert out.count("Conservation report") == 32
    assert "max |G M⁻¹ p|" in out
    assert "verdict: secular drift" in out and "verdict: bounded" in out
    written = sorted(p.name for p in tmp_path.glob("*.png"))
    assert written == sorted(f"{n}_energy.png" for n in ["harmonic_oscillator", "pendulum", "kepler", "henon_heiles", "fermi_pasta_ulam", "outer_solar_system", "double_pendulum", "spherical_pendulum", "charged_particle", "charged_particle_nonuniform", "cartesian_pendulum", "planar_chain", "rigid_body"])
    for line in out.splitlines():
        if line.startswith("wrote "):
            assert line.split(" ", 1)[1].endswith("_energy.png")
