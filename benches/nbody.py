"""N-body steps per unique pair: varmech's native Verlet against REBOUND's ``leapfrog`` with
``gravity="basic"`` (direct summation), on the same random Plummer cluster, in one run.

    python benches/nbody.py [--sizes 64 256 1024] [--repeat 5] [--markdown FILE]

Both integrators take one force evaluation a step (Verlet kick–drift–kick with the last force
reused; REBOUND's leapfrog drift–kick–drift), so time per step over N(N − 1)/2 is the cost of
a unique pair, the pair loop plus the step's O(N) work spread over the pairs. Each run keeps
only its final state; the two are interleaved and the best of ``--repeat`` rounds is reported,
so that the noise of a shared machine falls on both alike. Ratios carry over between machines;
nanoseconds do not.
"""

from __future__ import annotations

import os

# OpenBLAS's idle worker threads spin on a core of their own; nothing here uses BLAS.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import math
from pathlib import Path

import numpy as np
from compare import best_times_interleaved

import varmech
from varmech import scenes

#: Steps per run at N bodies: about 4·10⁷ pairs, some tens of milliseconds a run.
PAIRS_PER_RUN = 4e7
DT = 1e-4


def plummer(n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Masses (total 1), positions and velocities of a Plummer-like cluster (G = 1): radii
    from the Plummer cumulative mass, uniform directions, isotropic velocities of the local
    circular speed's size."""
    rng = np.random.default_rng(seed)
    m = rng.uniform(0.5, 1.5, n)
    m /= m.sum()
    u = rng.uniform(0.01, 0.99, n)
    r = (u ** (-2.0 / 3.0) - 1.0) ** -0.5
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    x = r[:, None] * direction
    speed = (r * r / (1.0 + r * r) ** 1.5) ** 0.5
    v = rng.normal(size=(n, 3)) * (speed / math.sqrt(3.0))[:, None]
    return m, x - m @ x, v - m @ v


def rebound_run(rebound, m: np.ndarray, x: np.ndarray, v: np.ndarray, steps: int):
    def run() -> None:
        sim = rebound.Simulation()
        sim.G = 1.0
        for mi, xi, vi in zip(m, x, v):
            sim.add(m=mi, x=xi[0], y=xi[1], z=xi[2], vx=vi[0], vy=vi[1], vz=vi[2])
        sim.integrator = "leapfrog"
        sim.gravity = "basic"
        sim.dt = DT
        sim.steps(steps)

    return run


def varmech_run(scene, steps: int):
    def run() -> None:
        varmech.integrate(scene, dt=DT, steps=steps, save_every=steps, max_energy_error=None)

    return run


def measure(sizes: list[int], repeat: int) -> list[dict]:
    import rebound

    rows = []
    for n in sizes:
        m, x, v = plummer(n)
        pairs = n * (n - 1) // 2
        steps = max(20, round(PAIRS_PER_RUN / pairs))
        scene = scenes.nbody(m, x, v, G=1.0, dt=DT)
        runs = {"varmech": varmech_run(scene, steps), "rebound": rebound_run(rebound, m, x, v, steps)}
        best = best_times_interleaved(runs, repeat)
        ns = {name: 1e9 * t / (steps * pairs) for name, t in best.items()}
        rows.append({"N": n, "steps": steps, **ns, "ratio": ns["rebound"] / ns["varmech"]})
    return rows


def markdown(rows: list[dict]) -> str:
    lines = [
        "| N | steps | varmech verlet, ns/pair | REBOUND leapfrog (basic), ns/pair | REBOUND / varmech |",
        "|---:|---:|---:|---:|---:|",
    ]
    lines += [f"| {r['N']} | {r['steps']} | {r['varmech']:.2f} | {r['rebound']:.2f} | {r['ratio']:.2f} |" for r in rows]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 256, 1024])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()
    table = markdown(measure(args.sizes, args.repeat))
    print(table)
    if args.markdown:
        args.markdown.write_text(table)


if __name__ == "__main__":
    main()
