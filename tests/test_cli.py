"""The command line writes what it says."""

import subprocess
import sys

import pytest

from varmech.cli import TOUR, TOUR_REDUCED


def test_methods_table():
    out = subprocess.run([sys.executable, "-m", "varmech", "methods"], capture_output=True, text=True, check=True).stdout
    assert "| `kahan_li8` | 8 | 17 |" in out


def test_tour_prints_reports_and_writes_plots(tmp_path):
    pytest.importorskip("matplotlib")
    out = subprocess.run(
        [sys.executable, "-m", "varmech", "tour", "--quick", "--out", str(tmp_path)], capture_output=True, text=True, check=True
    ).stdout
    runs = sum(len(methods) for _, methods, _ in TOUR) + sum(len(methods) for _, _, methods in TOUR_REDUCED)
    assert runs == 40 and out.count("Conservation report") == runs
    assert "max |G M⁻¹ p|" in out
    assert "verdict: secular drift" in out and "verdict: bounded" in out
    written = sorted(p.name for p in tmp_path.glob("*.png"))
    assert written == sorted(f"{name}_energy.png" for name, _, _ in TOUR)
    # The reduced runs, reconstructed: the ignored momenta are exact by construction.
    assert out.count("Routh-reduced") == len(TOUR_REDUCED)
    assert out.count("max |ΔJ| = 0.000e+00") >= sum(len(c) * len(m) for _, c, m in TOUR_REDUCED)
    for line in out.splitlines():
        if line.startswith("wrote "):
            assert line.split(" ", 1)[1].endswith("_energy.png")
