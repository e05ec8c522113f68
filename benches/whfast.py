"""varmech's Wisdom–Holman methods against REBOUND's WHFast on the outer solar system over
500 000 days, at matched final error, in one run.

    python benches/whfast.py [--quick] [--markdown FILE]

Each method runs over a half-octave sweep of steps; its error is the final-position error
‖q(500 000 d) − q_ref‖₂ in AU (all six bodies) against a converged reference: REBOUND's IAS15,
checked against the finest varmech run (their distance is printed, and HLW's published state's
distance too). The final state, not the energy, is the measure: the correctors and kernels
are chosen for the state (WHFast's energy error with correctors is ~ε times the state's), and
over 500 000 days the phase error dominates. Timing: best of 5 of the whole run (stepping and
the final synchronisation, nothing saved on the way), every configuration run once per round,
the rounds interleaved so that the machine's noise hits all alike. The cost of each method at
each error level 1e-3 … 1e-10 is interpolated log-log along its sweep; the table gives the
ratios. Needs REBOUND (the ``bench`` extra).
"""

from __future__ import annotations

import os

# Idle OpenBLAS threads would spin on the second core of a two-core machine.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from _common import publish

import varmech
from varmech import scenes
from varmech.analysis.baselines import import_rebound, rebound_sim, rebound_state, restore_sigint

T_END = 500_000.0
LEVELS = [10.0**-k for k in range(3, 11)]
#: varmech methods and REBOUND WHFast configurations (corrector, kernel).
VARMECH = ("wh", "whc", "whckl")
REBOUND = {
    "WHFast corrector=11": (11, "default"),
    "WHFast": (0, "default"),
    "WHFast corrector=17 kernel=lazy": (17, "lazy"),
}


def varmech_run(scene: scenes.Scene, method: str, steps: int) -> Callable[[], np.ndarray]:
    dt = T_END / steps

    def run() -> np.ndarray:
        traj = varmech.integrate(scene, method=method, dt=dt, steps=steps, save_every=steps, max_energy_error=None)
        return np.asarray(traj.q[-1])

    return run


def whfast_run(rebound, scene: scenes.Scene, corrector: int, kernel: str, steps: int) -> Callable[[], np.ndarray]:
    dt = T_END / steps

    def run() -> np.ndarray:
        sim = rebound_sim(rebound, scene, "WHFast", dt=dt)
        sim.integrator.corrector = corrector
        sim.integrator.kernel = kernel
        sim.integrator.safe_mode = 0
        try:
            sim.steps(steps)
            sim.synchronize()
        finally:
            restore_sigint()
        return rebound_state(sim, scene)[0]

    return run


def timed(run: Callable[[], np.ndarray]) -> tuple[np.ndarray, float]:
    start = time.perf_counter()
    q = run()
    return q, time.perf_counter() - start


def reference(rebound, scene: scenes.Scene) -> np.ndarray:
    """IAS15 at its default precision to t = 500 000 days exactly."""
    sim = rebound_sim(rebound, scene, "IAS15", dt=1.0)
    try:
        sim.integrate(T_END, exact_finish_time=1)
    finally:
        restore_sigint()
    return rebound_state(sim, scene)[0]


def cost_at(level: float, points: list[tuple[float, float]]) -> float | None:
    """The time at error `level` along the sweep's front (the points no cheaper point beats in
    error: round-off plateaus make the sweep non-monotone), interpolated log-log between the
    front's points that bracket it; None when the front does not reach `level`."""
    front: list[tuple[float, float]] = []
    for e, t in sorted(points, key=lambda p: p[1]):
        if not front or e < front[-1][0]:
            front.append((e, t))
    for (e1, t1), (e2, t2) in zip(front, front[1:]):
        if e2 <= level <= e1:
            w = math.log(e1 / level) / math.log(e1 / e2)
            return math.exp((1 - w) * math.log(t1) + w * math.log(t2))
    return None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="best of 2, errors down to 1e-7")
    parser.add_argument("--markdown", type=Path, help="write the tables to this file")
    args = parser.parse_args()
    rebound = import_rebound()
    if rebound is None:
        raise SystemExit("REBOUND is not installed (pip install rebound)")
    repeat = 2 if args.quick else 5
    floor = 1e-7 if args.quick else LEVELS[-1]
    scene = scenes.get("outer_solar_system")
    q_ref = reference(rebound, scene)

    makers: dict[str, Callable[[int], Callable[[], np.ndarray]]] = {
        **{f"varmech {m}": (lambda n, m=m: varmech_run(scene, m, n)) for m in VARMECH},
        **{
            f"REBOUND {name}": (lambda n, c=c, k=k: whfast_run(rebound, scene, c, k, n))
            for name, (c, k) in REBOUND.items()
        },
    }
    # The accuracy pass: each method's sweep of whole numbers of steps to 500 000 days, from
    # dt ≈ 800 days down by √2 until the error is below the floor (one step beyond, to bracket
    # it) or 4e6 steps.
    configs: list[tuple[str, float]] = []
    errors: dict[tuple[str, float], float] = {}
    finest: dict[str, np.ndarray] = {}
    for name, make in makers.items():
        for k in range(64):
            steps = round(T_END / 800.0 * 2.0 ** (k / 2))
            dt = T_END / steps
            q, _ = timed(make(steps))
            err = float(np.linalg.norm(q - q_ref)) if np.all(np.isfinite(q)) else math.inf
            errors[(name, dt)] = err
            print(f"{name:40s} dt = {dt:9.4f}: error {err:.3e}", flush=True)
            if math.isfinite(err) and err < 1e-2:
                configs.append((name, dt))
                finest[name] = q
            if err < 0.3 * floor or steps > 4e6:
                break
    best = {c: math.inf for c in configs}
    for _ in range(repeat):
        for c in configs:
            best[c] = min(best[c], timed(makers[c[0]](round(T_END / c[1])))[1])

    hlw = np.asarray(scene.reference.q) if scene.reference is not None else None
    lines = [
        "# varmech Wisdom–Holman against REBOUND WHFast (outer solar system, 500 000 days)",
        "",
        "Command: `python benches/whfast.py`. Error: ‖q − q_ref‖₂ in AU at t = 500 000 days, q_ref from",
        f"REBOUND IAS15; its distance to the finest varmech whckl run: "
        f"{np.linalg.norm(finest.get('varmech whckl', q_ref) - q_ref):.1e} AU.",
    ]
    if hlw is not None:
        lines.append(f"HLW's published reference state is {np.linalg.norm(hlw - q_ref):.1e} AU from it.")
    lines += [
        "",
        f"Time: best of {repeat}, interleaved. Cost at each error, interpolated log-log along each sweep:",
        "",
    ]
    names = list(makers)
    lines.append("| error | " + " | ".join(names) + " | varmech best | WHFast c11 / varmech best |")
    lines.append("|---" * (len(names) + 3) + "|")
    for level in [x for x in LEVELS if x >= floor]:
        costs = {n: cost_at(level, [(errors[c], best[c]) for c in configs if c[0] == n]) for n in names}
        ours = {n: t for n, t in costs.items() if n.startswith("varmech") and t is not None}
        winner = min(ours, key=ours.get) if ours else None  # type: ignore[arg-type]
        theirs = costs["REBOUND WHFast corrector=11"]
        ratio = f"{theirs / ours[winner]:.2f}" if winner and theirs else "—"
        cells = [f"{costs[n] * 1e3:.1f} ms" if costs[n] else "—" for n in names]
        lines.append(f"| {level:.0e} | " + " | ".join(cells) + f" | {winner or '—'} | {ratio} |")
    lines += [
        "",
        "Sweep (dt in days, error in AU, best time):",
        "",
        "| method | dt | error | time |",
        "|---|---|---|---|",
    ]
    lines += [f"| {n} | {dt:.4g} | {errors[(n, dt)]:.2e} | {best[(n, dt)] * 1e3:.2f} ms |" for n, dt in configs]
    publish("\n".join(lines) + "\n", args.markdown)


if __name__ == "__main__":
    main()
