"""MEGNO of the outer solar system from varmech's tangent map (verlet, h = 50 days) against
REBOUND's own (its variational equations under WHFast, h = 50 days, and IAS15), at growing
horizons: a quasi-periodic system's ⟨Y⟩ tends to 2 in every one, at the rate its transients
allow. Each side once from its own default start, and varmech again from REBOUND's start
(``init_megno(seed=1)``'s random (δx, δv), δp = mδv), where the two should agree to their
integrators' differences. Needs the ``bench`` extra (rebound).

    PYTHONPATH=$PWD/python python benches/megno.py [--markdown benches/megno_results.md]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import rebound
from _common import publish, rebound_simulation

import varmech

H = 50.0
HORIZONS = (1e5, 1e6, 1e7)


def simulation(integrator: str) -> rebound.Simulation:
    """REBOUND's copy of the scene, with its MEGNO variational particles (seed 1)."""
    scene = varmech.scenes.outer_solar_system()
    G, masses = scene.model._core.gravity
    sim = rebound_simulation(G, masses, scene.q0, scene.p0, integrator)
    if integrator == "whfast":
        sim.dt = H
    sim.init_megno(seed=1)
    return sim


def rebound_start() -> np.ndarray:
    """REBOUND's start of the tangent vector as (δq, δq̇): the bodies' δx, then their δv."""
    particles = simulation("whfast").var_config[0].particles
    dx = [c for p in particles for c in (p.x, p.y, p.z)]
    dv = [c for p in particles for c in (p.vx, p.vy, p.vz)]
    return np.array(dx + dv)


def rebound_megno(integrator: str, horizon: float) -> tuple[float, float]:
    sim = simulation(integrator)
    start = time.perf_counter()
    sim.integrate(horizon, exact_finish_time=0)
    return sim.megno(), time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()
    scene = varmech.scenes.outer_solar_system()
    steps = round(HORIZONS[-1] / H)
    runs, seconds = {}, {}
    for label, tangent0 in (("own", None), ("rebound", rebound_start())):
        start = time.perf_counter()
        runs[label] = varmech.megno(scene.model, scene.q0, scene.p0, dt=H, steps=steps, method="verlet", tangent0=tangent0)
        seconds[label] = time.perf_counter() - start
    lines = [
        "# MEGNO: varmech's tangent map beside REBOUND's variational equations",
        "",
        f"Command: `PYTHONPATH=$PWD/python python benches/megno.py` (REBOUND {rebound.__version__}).",
        "",
        "The outer solar system (the Sun and the four giant planets and Pluto, AU, days, solar masses),",
        "from the scene's initial state. varmech: verlet, h = 50 days, one tangent vector normalized",
        f"every step (`varmech.megno`), one run of {steps} steps read at each horizon, from its own",
        "default start and from REBOUND's. REBOUND: `init_megno(seed=1)`, its variational particles",
        "under WHFast (h = 50 days) and IAS15, one run a horizon.",
        "",
        "| horizon (days) | varmech ⟨Y⟩, own start | varmech ⟨Y⟩, REBOUND's start | REBOUND WHFast ⟨Y⟩ (s) | REBOUND IAS15 ⟨Y⟩ (s) |",
        "|---:|---:|---:|---:|---:|",
    ]
    for horizon in HORIZONS:
        at = {label: m.mean[min(np.searchsorted(m.t - m.t[0] + H, horizon), len(m.t) - 1)] for label, m in runs.items()}
        wh, ias = rebound_megno("whfast", horizon), rebound_megno("ias15", horizon)
        lines.append(f"| {horizon:g} | {at['own']:.4f} | {at['rebound']:.4f} | {wh[0]:.4f} ({wh[1]:.2f}) | {ias[0]:.4f} ({ias[1]:.2f}) |")
    lines += [
        "",
        f"varmech's run to {HORIZONS[-1]:g} days took {seconds['own']:.1f} s (its Hessian differenced: 36 gradients a kick).",
    ]
    publish("\n".join(lines), args.markdown)


if __name__ == "__main__":
    main()
