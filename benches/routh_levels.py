"""One scene at three levels of modelling, side by side in one run: the spherical pendulum
(m = l = g = 1, θ₀ = 1, φ̇₀ = 1.2, T = 50; reference/scenes.json) as

1. a point in Cartesian coordinates on the constraint |x| = 1 (RATTLE, 3 coordinates and 1
   multiplier),
2. the angles (θ, φ), a general Lagrangian (midpoint, Galerkin-4),
3. θ alone, Routh-reduced at the conserved p_φ, with φ reconstructed afterwards (midpoint,
   Galerkin-4).

    python benches/routh_levels.py [--repeat 5] [--markdown FILE]

Every model is native (no Python per step). Times are the best of interleaved repeats of runs
that save only the final state (the reduced runs save every state, which reconstruction
needs, and include the reconstruction); errors are |(θ, φ) − reference| at T = 50.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

import varmech
from varmech import scenes

T = 50.0


def angles_of(q: np.ndarray, phi_reference: float) -> tuple[float, float]:
    """(θ, φ) of a Cartesian point, φ unwrapped to the turn nearest the reference."""
    theta, phi = math.acos(-q[2]), math.atan2(q[1], q[0])
    return theta, phi + round((phi_reference - phi) / math.tau) * math.tau


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--steps", type=int, nargs="+", default=[1000, 4000])
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()

    angles = scenes.spherical_pendulum()
    cartesian = scenes.cartesian_spherical_pendulum()
    theta_ref, phi_ref = angles.reference.q
    reduced = varmech.routh(angles, [1])
    x0, px0 = reduced.reduce(angles.q0, angles.p0)

    def cartesian_run(steps: int, method: str):
        traj = varmech.integrate(cartesian, dt=T / steps, steps=steps, method=method, save_every=steps)
        return angles_of(traj.q[-1], phi_ref)

    def angles_run(steps: int, method: str):
        traj = varmech.integrate(angles, dt=T / steps, steps=steps, method=method, save_every=steps)
        return tuple(traj.q[-1])

    def reduced_run(steps: int, method: str):
        traj = varmech.integrate(reduced, x0, px0, dt=T / steps, steps=steps, method=method)
        full = reduced.reconstruct(traj, c0=angles.q0[[1]])
        return tuple(full.q[-1])

    levels = [
        ("Cartesian + constraint", 3, "rattle", cartesian_run),
        ("angles (θ, φ)", 2, "midpoint", angles_run),
        ("angles (θ, φ)", 2, "galerkin4", angles_run),
        ("Routh-reduced θ, φ rebuilt", 1, "midpoint", reduced_run),
        ("Routh-reduced θ, φ rebuilt", 1, "galerkin4", reduced_run),
    ]
    rows = []
    for steps in args.steps:
        best = [math.inf] * len(levels)
        result = [None] * len(levels)
        for _ in range(args.repeat):
            for i, (_, _, method, run) in enumerate(levels):
                start = time.perf_counter()
                result[i] = run(steps, method)
                best[i] = min(best[i], time.perf_counter() - start)
        for (name, n, method, _), seconds, (theta, phi) in zip(levels, best, result):
            error = math.hypot(theta - theta_ref, phi - phi_ref)
            rows.append((steps, name, n, method, 1e6 * seconds / steps, seconds / best[1], error))

    lines = [
        "| steps | model | coordinates | method | µs/step | time vs (θ, φ) midpoint | error at T = 50 |",
        "|---:|---|---:|---|---:|---:|---:|",
    ]
    lines += [f"| {s} | {name} | {n} | {m} | {us:.2f} | {ratio:.2f} | {err:.2e} |" for s, name, n, m, us, ratio, err in rows]
    table = "\n".join(lines)
    print(table)
    if args.markdown:
        args.markdown.write_text(
            "# Three levels of modelling: the spherical pendulum\n\n`python benches/routh_levels.py`\n\n" + table + "\n"
        )


if __name__ == "__main__":
    main()
