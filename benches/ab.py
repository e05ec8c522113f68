"""Two builds of varmech side by side: the same workloads in two Python interpreters, interleaved,
best of several rounds, reported as ratios.

    python benches/ab.py --before /path/to/other/python [--rounds 7]

Use it to check that a change keeps the speed: build the old commit into a virtual environment
(``pip install`` of its wheel), then compare that interpreter (``--before``) with this one. Each
round runs every workload once in each interpreter, alternating, so that the noise of a shared
machine falls on both alike; a workload's figure is its best time over the rounds.
"""

from __future__ import annotations

import argparse
import subprocess
import sys

# Each workload prints the seconds of its timed part. The set-up (scene building, first calls)
# is outside the timing; the loop is what users pay for.
WORKLOADS = {
    "kepler verlet, native, 2e5 steps": """
s = varmech.scenes.kepler()
run = lambda: varmech.integrate(s, dt=2*np.pi/200, steps=200_000, method="verlet", save_every=200_000)
""",
    "kepler kahan_li8, native, 2e4 steps": """
s = varmech.scenes.kepler()
run = lambda: varmech.integrate(s, dt=2*np.pi/200, steps=20_000, method="kahan_li8", save_every=20_000)
""",
    "kepler verlet, closure, 2e4 steps": """
m = varmech.MechanicalSystem(2, potential=lambda q: -1/np.hypot(q[0], q[1]),
                             gradient=lambda q: q/np.hypot(q[0], q[1])**3)
s = varmech.scenes.kepler()
run = lambda: varmech.integrate(m, s.q0, s.p0, dt=2*np.pi/200, steps=20_000, method="verlet", save_every=20_000)
""",
    "double pendulum midpoint, native, 2e4 steps": """
s = varmech.scenes.double_pendulum()
run = lambda: varmech.integrate(s, dt=0.01, steps=20_000, method="midpoint", save_every=20_000)
""",
    "double pendulum galerkin4, native, 5e3 steps": """
s = varmech.scenes.double_pendulum()
run = lambda: varmech.integrate(s, dt=0.01, steps=5_000, method="galerkin4", save_every=5_000)
""",
    "cartesian pendulum rattle, native, 2e4 steps": """
s = varmech.scenes.cartesian_pendulum()
run = lambda: varmech.integrate(s, dt=0.01, steps=20_000, method="rattle", save_every=20_000)
""",
}

PROLOGUE = """
import time, warnings
import numpy as np
import varmech
warnings.simplefilter("ignore")
"""

EPILOGUE = """
run()
best = float("inf")
for _ in range(3):
    start = time.perf_counter()
    run()
    best = min(best, time.perf_counter() - start)
print(best)
"""


def seconds(python: str, workload: str) -> float:
    out = subprocess.run([python, "-c", PROLOGUE + workload + EPILOGUE], capture_output=True, text=True, check=True)
    return float(out.stdout.split()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--before", required=True, help="the Python interpreter of the other build")
    parser.add_argument("--after", default=sys.executable, help="the Python interpreter of this build")
    parser.add_argument("--rounds", type=int, default=7)
    args = parser.parse_args()
    best = {(name, side): float("inf") for name in WORKLOADS for side in ("before", "after")}
    for _ in range(args.rounds):
        for name, code in WORKLOADS.items():
            for side in ("before", "after"):
                python = args.before if side == "before" else args.after
                best[name, side] = min(best[name, side], seconds(python, code))
    print("| workload | before (ms) | after (ms) | speed after / before |")
    print("|---|---:|---:|---:|")
    for name in WORKLOADS:
        before, after = best[name, "before"], best[name, "after"]
        print(f"| {name} | {before * 1e3:.2f} | {after * 1e3:.2f} | {before / after:.3f} |")


if __name__ == "__main__":
    main()
