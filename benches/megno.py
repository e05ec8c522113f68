"""MEGNO of the outer solar system from varmech's tangent map (verlet, h = 50 days) against
REBOUND's own (its variational equations under WHFast, h = 50 days, and IAS15), at growing
horizons: a quasi-periodic system's ⟨Y⟩ tends to 2 in every one, at the rate its transients
allow. Needs the ``bench`` extra (rebound).

    PYTHONPATH=$PWD/python python benches/megno.py
"""

from __future__ import annotations

import time

import numpy as np
import rebound

import varmech

H = 50.0
HORIZONS = (1e5, 1e6, 1e7)


def rebound_megno(integrator: str, horizon: float) -> tuple[float, float]:
    scene = varmech.scenes.outer_solar_system()
    G, masses = scene.model._core.gravity
    sim = rebound.Simulation()
    sim.G = G
    for m, x, p in zip(masses, scene.q0.reshape(-1, 3), scene.p0.reshape(-1, 3)):
        v = p / m
        sim.add(m=m, x=x[0], y=x[1], z=x[2], vx=v[0], vy=v[1], vz=v[2])
    sim.integrator = integrator
    if integrator == "whfast":
        sim.dt = H
    sim.init_megno()
    start = time.perf_counter()
    sim.integrate(horizon, exact_finish_time=0)
    return sim.megno(), time.perf_counter() - start


def main() -> None:
    scene = varmech.scenes.outer_solar_system()
    start = time.perf_counter()
    m = varmech.megno(scene.model, scene.q0, scene.p0, dt=H, steps=round(HORIZONS[-1] / H))
    seconds = time.perf_counter() - start
    elapsed = m.t - m.t[0] + H
    print(f"varmech verlet, h = {H:g} days, to {HORIZONS[-1]:g} days in {seconds:.1f} s (one run, read at each horizon)")
    print("| horizon (days) | varmech verlet ⟨Y⟩ | REBOUND WHFast ⟨Y⟩ (s) | REBOUND IAS15 ⟨Y⟩ (s) |")
    print("|---:|---:|---:|---:|")
    for horizon in HORIZONS:
        mine = m.mean[min(np.searchsorted(elapsed, horizon), len(elapsed) - 1)]
        wh, ias = rebound_megno("whfast", horizon), rebound_megno("ias15", horizon)
        print(f"| {horizon:g} | {mine:.4f} | {wh[0]:.4f} ({wh[1]:.2f}) | {ias[0]:.4f} ({ias[1]:.2f}) |")


if __name__ == "__main__":
    main()
