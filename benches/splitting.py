"""varmech's splitting methods against REBOUND's ``leapfrog`` with ``order=8`` (McLachlan's
17-stage composition SS17, Blanes & Casas 2016, p. 91) at matched final error, in one run.

    python benches/splitting.py [--quick] [--markdown FILE]

Two problems: Kepler e = 0.6 over 1 000 periods (error ‖(q, p) − (q₀, p₀)‖ against the exact
periodic orbit) and the outer solar system over 500 000 days (error ‖(q, v) − reference‖ against
HLW's reference state, whose own accuracy is checked against converged runs of both codes).
Each method runs a geometric sweep of step counts; every run is timed best of ``--repeat``
(default 5), all runs interleaved so that machine noise hits them alike. For each target error
10⁻², …, 10⁻¹⁰ the cost of a method is interpolated on its work–precision curve (log time
against log error, between the two runs that bracket the target), varmech's best method at that
error is picked, and the ratio REBOUND time / varmech time is printed. Needs REBOUND (the
``bench`` extra).
"""

from __future__ import annotations

import os

# OpenBLAS's idle worker threads spin on a core of their own; nothing here uses BLAS.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from compare import best_times_interleaved

import varmech
from varmech import scenes
from varmech.analysis.baselines import import_rebound, rebound_advance, rebound_sim, rebound_state

#: The REBOUND baseline (a method of varmech.analysis.baselines) and its label; the other methods
#: of a problem's sweeps are varmech's candidates (the best at each error is compared).
BASELINE = "leapfrog order=8"
REBOUND = f"REBOUND {BASELINE}"
TARGETS = [10.0**-k for k in range(2, 11)]


@dataclass
class Problem:
    name: str
    #: (method, step count) → a run that returns its final error.
    run: Callable[[str, int], Callable[[], float]]
    #: The step counts of each method's sweep.
    sweeps: dict[str, list[int]]


def geometric(lo: int, hi: int, count: int) -> list[int]:
    return sorted({round(lo * (hi / lo) ** (k / (count - 1))) for k in range(count)})


def order_sweeps(n: int, order8: tuple[int, int], lower: dict[str, tuple[int, int]]) -> dict[str, list[int]]:
    """``n`` step counts, geometric over ``order8`` for REBOUND and varmech's order-8 methods and
    over each range of ``lower`` for its method."""
    ranges = dict.fromkeys((REBOUND, "mclachlan8_dkd", "mclachlan8", "kahan_li8"), order8) | lower
    return {method: geometric(lo, hi, n) for method, (lo, hi) in ranges.items()}


def runner(
    scene: scenes.Scene,
    steps_and_h: Callable[[int], tuple[int, float]],
    sim_state: Callable[[Any], tuple[np.ndarray, np.ndarray]],
    varmech_state: Callable[[str, float, int], tuple[np.ndarray, np.ndarray]],
    error: Callable[[np.ndarray, np.ndarray], float],
) -> Callable[[str, int], Callable[[], float]]:
    """(method, sweep value) → a run returning its final error: REBOUND's leapfrog with order=8 on
    ``scene``, or varmech's ``method``."""
    rebound = import_rebound()

    def run(method: str, n: int) -> Callable[[], float]:
        steps, h = steps_and_h(n)
        if method != REBOUND:
            return lambda: error(*varmech_state(method, h, steps))

        def go() -> float:
            sim = rebound_sim(rebound, scene, BASELINE, dt=h)
            rebound_advance(sim, BASELINE, steps, math.nan)
            return error(*sim_state(sim))

        return go

    return run


def kepler(quick: bool) -> Problem:
    scene = scenes.kepler(0.6)
    periods = 100 if quick else 1000
    q0, p0 = scene.q0, scene.p0

    def varmech_state(method: str, h: float, steps: int) -> tuple[np.ndarray, np.ndarray]:
        traj = varmech.integrate(scene.model, q0, p0, dt=h, steps=steps, method=method, save_every=steps, max_energy_error=None)
        return traj.q[-1], traj.p[-1]

    def error(q: np.ndarray, p: np.ndarray) -> float:
        return float(np.hypot(np.linalg.norm(q - q0), np.linalg.norm(p - p0)))

    def steps_and_h(per_period: int) -> tuple[int, float]:
        return periods * per_period, 2 * math.pi / per_period

    sweeps = order_sweeps(7 if quick else 13, (24, 800), {"blanes_moan6": (24, 1600), "blanes_moan4": (40, 4000)})
    run = runner(scene, steps_and_h, lambda sim: rebound_state(sim, scene), varmech_state, error)
    return Problem(f"Kepler e = 0.6, {periods} periods (steps per period)", run, sweeps)


def outer_solar_system(quick: bool) -> Problem:
    scene = scenes.outer_solar_system()
    _, masses = scene.model._core.gravity
    m3 = np.repeat(masses, 3)
    ref = scene.reference
    v_ref = ref.p / m3

    def sim_state(sim: Any) -> tuple[np.ndarray, np.ndarray]:
        q, p = rebound_state(sim, scene)
        return q, p / m3

    def varmech_state(method: str, h: float, steps: int) -> tuple[np.ndarray, np.ndarray]:
        traj = varmech.integrate(scene.model, scene.q0, scene.p0, dt=h, steps=steps, method=method, save_every=steps, max_energy_error=None)
        return traj.q[-1], traj.v[-1]

    def error(q: np.ndarray, v: np.ndarray) -> float:
        return float(np.sqrt(np.sum((q - ref.q) ** 2) + np.sum((v - v_ref) ** 2)))

    # 500 000 days in 500 steps (h = 1 000 days, a quarter of Jupiter's period) to 40 000
    # (h = 12.5 days); the lower orders further.
    lower = {"blanes_moan6": (500, 60_000), "aba1064": (1000, 200_000), "blanes_moan4": (1000, 200_000)}
    sweeps = order_sweeps(7 if quick else 11, (500, 40_000), lower)
    if quick:
        sweeps = {k: v[: len(v) - 2] for k, v in sweeps.items()}
    run = runner(scene, lambda steps: (steps, ref.t / steps), sim_state, varmech_state, error)
    return Problem("outer solar system, 500 000 days (steps)", run, sweeps)


def measure(problem: Problem, repeat: int) -> dict[str, list[tuple[int, float, float]]]:
    """(steps, error, best seconds) of every run of every method, timed interleaved."""
    runs = {(m, n): problem.run(m, n) for m, ns in problem.sweeps.items() for n in ns}
    errors = {key: run() for key, run in runs.items()}
    best = best_times_interleaved(runs, repeat)
    return {m: [(n, errors[m, n], best[m, n]) for n in ns] for m, ns in problem.sweeps.items()}


def cost_at(curve: list[tuple[int, float, float]], target: float) -> float:
    """Seconds to reach final error ``target``, interpolated log–log between the coarsest run at
    or below it and the run before; NaN when no run of the sweep brackets it (or the curve is
    past its round-off floor there)."""
    for (_, e0, t0), (_, e1, t1) in zip(curve, curve[1:]):
        if e1 <= target <= e0 and e1 < e0:
            w = math.log(target / e0) / math.log(e1 / e0)
            return math.exp(math.log(t0) + w * math.log(t1 / t0))
    return math.nan


def report(problem: Problem, curves: dict[str, list[tuple[int, float, float]]]) -> str:
    lines = [f"### {problem.name}", "", "| method | steps | final error | seconds (best) |", "|---|---:|---:|---:|"]
    for method, curve in curves.items():
        for n, e, t in curve:
            lines.append(f"| {method} | {n} | {e:.2e} | {t:.4g} |")
    lines += ["", "| target error | REBOUND order=8 (s) | varmech best (s) | method | ratio REBOUND / varmech |", "|---:|---:|---:|---|---:|"]
    for target in TARGETS:
        rb = cost_at(curves[REBOUND], target)
        costs = {m: cost_at(c, target) for m, c in curves.items() if m != REBOUND}
        finite = {m: c for m, c in costs.items() if not math.isnan(c)}
        if not finite:
            lines.append(f"| {target:.0e} | {rb:.4g} | not reached | – | – |")
            continue
        best = min(finite, key=finite.__getitem__)
        if math.isnan(rb):
            floor = min(e for _, e, _ in curves[REBOUND])
            rb_cell = f"not reached (least error {floor:.1e})" if floor > target else "not bracketed"
            lines.append(f"| {target:.0e} | {rb_cell} | {finite[best]:.4g} | {best} | – |")
            continue
        lines.append(f"| {target:.0e} | {rb:.4g} | {finite[best]:.4g} | {best} | {rb / finite[best]:.2f} |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="a tenth of the Kepler horizon, shorter sweeps, 2 repeats")
    parser.add_argument("--repeat", type=int, default=None, help="timing repeats (default 5; 2 with --quick)")
    parser.add_argument("--markdown", type=Path, help="also write the tables to this file")
    args = parser.parse_args()
    if import_rebound() is None:
        raise SystemExit("needs REBOUND (pip install rebound)")
    repeat = args.repeat or (2 if args.quick else 5)
    parts = []
    for make in (kepler, outer_solar_system):
        problem = make(args.quick)
        parts.append(report(problem, measure(problem, repeat)))
        print(parts[-1], flush=True)
    if args.markdown:
        args.markdown.write_text("\n\n".join(parts) + "\n")


if __name__ == "__main__":
    main()
