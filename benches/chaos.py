"""The Chaos guide's figures (docs/gallery/): the damped, driven pendulum's orbit diagram over
Taylor's drive γ ∈ [1.06, 1.09] (one ensemble on every core), its strange attractor strobed at
the drive's period (Baker & Gollub's γ = 1.5), the Lyapunov spectrum's convergence on
Hénon–Heiles' chaotic orbit and on the pendulum at Taylor's chaotic γ = 1.105 (the midpoint
rule's implicit tangent map), with the wall time of each.

    PYTHONPATH=$PWD/python python benches/chaos.py [--values 301]
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

import varmech
from varmech.charts import lyapunov_chart, orbit_diagram_chart, strobe_chart

GALLERY = Path(__file__).resolve().parents[1] / "docs" / "gallery"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--values", type=int, default=301)
    args = parser.parse_args()
    scene = varmech.scenes.get("damped_driven_pendulum")
    values = np.linspace(1.06, 1.09, args.values)
    start = time.perf_counter()
    table = varmech.orbit_diagram(scene, [-math.pi / 2], [0.0], parameter="amplitude", values=values, period=3 * math.pi, periods=64, transient=300)
    print(f"orbit diagram: {args.values} drives in {time.perf_counter() - start:.1f} s ({table.meta['method']}, dt = {table.meta['dt']:.4g})")
    title = "Driven pendulum (Taylor §12.5): φ̇ strobed at the drive's period"
    orbit_diagram_chart(table, GALLERY / "chaos_orbit_diagram.png", title=title)
    hh = varmech.scenes.henon_heiles().model
    start = time.perf_counter()
    spectrum = varmech.lyapunov_spectrum(hh, [0.0, -0.25], [0.42, 0.0], dt=0.05, steps=200_000)
    print(f"spectrum: {time.perf_counter() - start:.2f} s\n{spectrum}")
    lyapunov_chart(spectrum, GALLERY / "chaos_lyapunov.png", title="Hénon–Heiles, H = 0.1247: the spectrum from verlet's tangent map")
    start = time.perf_counter()
    strobe = varmech.stroboscopic_section(scene, [-math.pi / 2], [0.0], period=3 * math.pi, periods=20_000, transient=100)
    print(f"strobe: 20000 periods in {time.perf_counter() - start:.1f} s ({strobe.meta['method']})")
    strobe_chart(strobe, GALLERY / "chaos_strobe.png", wrap=2 * math.pi, title="Driven pendulum, γ = 1.5: the strange attractor at t = kT")
    pendulum = varmech.scenes.get("damped_driven_pendulum", amplitude=1.105).model
    start = time.perf_counter()
    spectrum = varmech.lyapunov_spectrum(pendulum, [-math.pi / 2], [0.0], dt=3 * math.pi / 200, steps=200_000)
    print(f"pendulum's spectrum: {time.perf_counter() - start:.2f} s\n{spectrum}")
    title = "Driven pendulum, γ = 1.105: the midpoint rule's tangent map (Σλ = −2β)"
    lyapunov_chart(spectrum, GALLERY / "chaos_lyapunov_pendulum.png", title=title)


if __name__ == "__main__":
    main()
