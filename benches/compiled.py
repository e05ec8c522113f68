"""Compiled symbolic models against the hand-written native scenes and the closure path, side by
side in one run (issue 14's targets).

    python benches/compiled.py [--quick] [--markdown FILE]

For each case, the same scene is integrated by four models of it: the native scene (Rust written
by hand), its symbolic twin (``varmech.symbolic.examples``) with its tapes compiled to machine
code, the same twin run by the tape interpreter, and the NumPy closure model of
``varmech.examples`` (hand-derived derivatives). The runs alternate, each figure is the best of
several, and the closure path runs fewer steps; the figures are times per step, and the ratios
are what carries over between machines. The one-off cost from SymPy expression to a ready model
is timed too, in a fresh process.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import subprocess
import sys
from functools import partial

from _common import publish, quick_arguments
from compare import best_times_interleaved

import varmech
from varmech import examples, scenes
from varmech.symbolic import examples as symbolic_examples

#: (scene, method): the cases of issue 14's table.
CASES = [
    ("double_pendulum", "midpoint"),
    ("double_pendulum", "galerkin4"),
    ("kepler", "verlet"),
    ("kepler", "kahan_li8"),
    ("heavy_top", "midpoint"),
    ("cartesian_pendulum", "rattle"),
]


def seconds_per_step(runs: dict[str, tuple[object, int]], scene: scenes.Scene, method: str, repeat: int) -> dict[str, float]:
    """Best time per step of each model, the runs alternating."""
    timed = {
        label: partial(varmech.integrate, model, scene.q0, scene.p0, dt=scene.dt, steps=steps, method=method, save_every=steps)
        for label, (model, steps) in runs.items()
    }
    best = best_times_interleaved(timed, repeat)
    return {label: best[label] / steps for label, (_, steps) in runs.items()}


def build_seconds(name: str) -> float:
    """Wall time from SymPy expression to a ready model (derivation, lowering, machine code), in
    a fresh process: SymPy caches what it derived, so only a first build is the user's cost."""
    code = (
        "import time, varmech; from varmech import scenes; from varmech.symbolic import examples; "
        f"s = scenes.get({name!r}); t = time.perf_counter(); examples.symbolic_of(s); "
        "print(time.perf_counter() - t)"
    )
    return float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout)


def main() -> None:
    args = quick_arguments(__doc__, "fewer steps and repeats")
    repeat = 3 if args.quick else 7
    steps = 2_000 if args.quick else 20_000
    lines = [
        "| case | native µs/step | compiled (JIT) | compiled (tape) | closure | JIT / native | tape / native "
        "| closure / JIT | build s |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, method in CASES:
        scene = scenes.get(name)
        twin = symbolic_examples.symbolic_of(scene)
        runs = {
            "native": (scene.model, steps),
            "jit": (twin, steps),
            "tape": (twin.with_jit(False), steps),
            "closure": (examples.closure_of(scene), max(steps // 20, 100)),
        }
        t = seconds_per_step(runs, scene, method, repeat)
        build = build_seconds(name)
        lines.append(
            f"| {name} {method} | {t['native'] * 1e6:.3f} | {t['jit'] * 1e6:.3f} | {t['tape'] * 1e6:.3f} "
            f"| {t['closure'] * 1e6:.2f} | {t['jit'] / t['native']:.2f} | {t['tape'] / t['native']:.2f} "
            f"| {t['closure'] / t['jit']:.1f} | {build:.3f} |"
        )
        print(lines[-1], flush=True)
    print()
    publish("\n".join(lines), args.markdown)


if __name__ == "__main__":
    main()
