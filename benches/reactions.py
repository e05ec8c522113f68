"""The forces of constraint (``Trajectory.reactions``, issue 34): their cost against the run that
saved the states, and the gallery's figure.

The multipliers are computed from the saved states after the run (``model::reactions`` in the
core), so a run pays nothing for them and a caller pays per saved state. Timed here, interleaved
(run, reactions, run, …), best of ``--repeat``: 10⁵ steps of

- the Cartesian pendulum (rattle, one constraint),
- a planar chain of 8 links (rattle, 8 constraints),
- the rolling disk (midpoint, two velocity constraints),

saving every 1st, 10th and 100th state, as the ratio reactions / run.

    PYTHONPATH=$PWD/python python benches/reactions.py [--repeat 5]
        [--markdown benches/reactions_results.md] [--figure docs/gallery]
"""

from __future__ import annotations

import argparse
import platform
import time
from pathlib import Path

import numpy as np

import varmech

STEPS = 100_000
SCENES = {
    "Cartesian pendulum, rattle": (lambda: varmech.scenes.cartesian_pendulum(), 0.01),
    "planar chain of 8 links, rattle": (lambda: varmech.scenes.planar_chain(8), 0.002),
    "rolling disk, midpoint": (lambda: varmech.scenes.rolling_disk(), 0.01),
}


def timings(repeat: int) -> list[tuple[str, int, float, float]]:
    rows = []
    for name, (make, dt) in SCENES.items():
        scene = make()
        for save_every in (1, 10, 100):
            run = reactions = np.inf
            for _ in range(repeat):
                start = time.perf_counter()
                traj = varmech.integrate(scene, dt=dt, steps=STEPS, save_every=save_every)
                middle = time.perf_counter()
                traj.reactions()
                end = time.perf_counter()
                run, reactions = min(run, middle - start), min(reactions, end - middle)
            rows.append((name, save_every, run, reactions))
            print(f"{name:34} save_every {save_every:4}: run {run * 1e3:7.2f} ms, reactions {reactions * 1e3:7.2f} ms, ratio {reactions / run:.3f}")
    return rows


def tension_chart(out: Path, quick: bool = False) -> list[Path]:
    """The gallery's figure ``<out>/reactions_pendulum.png``: the Cartesian pendulum's tension
    over a run, and the multipliers' convergence at the methods' orders (``quick`` is as fast)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scene = varmech.scenes.cartesian_pendulum()
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.8))
    fine = varmech.integrate(scene, dt=1e-3, t_end=6.0, method="rattle4")
    coarse = varmech.integrate(scene, dt=0.1, t_end=6.0)
    a.plot(fine.t, -fine.reactions().multipliers[:, 0], "k-", lw=1, label="rattle4, h = 0.001")
    a.plot(coarse.t, -coarse.reactions().multipliers[:, 0], "o", ms=3, label="rattle, h = 0.1")
    a.axhline(0.0, color="grey", lw=0.5)
    a.set(xlabel="t", ylabel="tension T = −λ", title="Cartesian pendulum from θ = 2: a rod pushes where T < 0")
    a.legend(fontsize=8)
    reference = varmech.integrate(scene, dt=1e-4, t_end=1.0, method="rattle4").reactions().multipliers[-1, 0]
    for method, marker in (("rattle", "o-"), ("rattle4", "s-")):
        hs = 0.1 / 2.0 ** np.arange(6)
        errors = [abs(varmech.integrate(scene, dt=h, t_end=1.0, method=method).reactions().multipliers[-1, 0] - reference) for h in hs]
        b.loglog(hs, errors, marker, label=f"{method} (slope {np.polyfit(np.log(hs[1:4]), np.log(errors[1:4]), 1)[0]:.2f})")
    b.set(xlabel="h", ylabel="|λ − λ_ref| at t = 1", title="multipliers converge at the method's order")
    b.legend(fontsize=8)
    fig.tight_layout()
    path = out / "reactions_pendulum.png"
    fig.savefig(path, dpi=110)
    return [path]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--markdown", type=Path)
    parser.add_argument("--figure", type=Path)
    args = parser.parse_args()
    rows = timings(args.repeat)
    if args.markdown:
        lines = [
            "# Forces of constraint: cost against the run",
            "",
            f"`PYTHONPATH=$PWD/python python benches/reactions.py --repeat {args.repeat} --markdown benches/reactions_results.md`"
            f" ({platform.machine()}, {STEPS} steps, best of {args.repeat}, interleaved). The run pays nothing; "
            "`traj.reactions()` pays per saved state.",
            "",
            "| scene | save_every | run (ms) | reactions (ms) | reactions / run |",
            "|---|---:|---:|---:|---:|",
        ]
        lines += [f"| {name} | {k} | {run * 1e3:.2f} | {r * 1e3:.2f} | {r / run:.3f} |" for name, k, run, r in rows]
        args.markdown.write_text("\n".join(lines) + "\n")
    if args.figure:
        print("wrote", *tension_chart(args.figure))


if __name__ == "__main__":
    main()
