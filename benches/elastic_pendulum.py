"""The elastic pendulum to t = 1000 at matched energy error: the compiled symbolic model with
varmech's compositions against SciPy's DOP853 on the lambdified first-order system, in one run
(issue 14's target: varmech at least 10× faster).

    python benches/elastic_pendulum.py [--quick] [--markdown FILE]

Both sides run the same physics from the same state: the scene ``elastic_pendulum`` (Cartesian
coordinates, so separable). varmech's steps and SciPy's tolerances are swept by
:func:`varmech.work_precision`; each side's wall time at an energy error is interpolated
log–log between the settings around it, and the ratio is reported at errors that both sweeps
reach.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


import numpy as np
from _common import publish, quick_arguments

import varmech
from varmech import scenes

METHODS = ("verlet", "kahan_li6", "kahan_li8")
#: Steps per unit time swept by each method: from a step of about a third of the fastest
#: period (radial, 2π/√10 ≈ 2) down to round-off.
RATES = {"verlet": range(3, 12), "kahan_li6": range(1, 8), "kahan_li8": range(0, 7)}
ERRORS = (1e-4, 1e-6, 1e-8, 1e-10)


def seconds_at(rows: list, error: float) -> float:
    """Wall time at ``error``, interpolated log–log over a sweep's (error, seconds) points; NaN
    outside them."""
    points = sorted((r["max_energy_error"], r["seconds"]) for r in rows if r["max_energy_error"] > 0)
    e = np.log([p[0] for p in points])
    s = np.log([p[1] for p in points])
    if not (e.min() <= np.log(error) <= e.max()):
        return float("nan")
    return float(np.exp(np.interp(np.log(error), e, s)))


def main() -> None:
    args = quick_arguments(__doc__, "t = 100 and fewer repeats")
    scene = scenes.get("elastic_pendulum")
    t_end = 100.0 if args.quick else scene.t_end
    steps = {m: [int(t_end) * 2**k for k in RATES[m]] for m in METHODS}
    table = varmech.work_precision(
        scene,
        METHODS,
        steps=steps,
        baselines=("DOP853",),
        rtols=tuple(10.0**-k for k in range(4, 14)),
        t_end=t_end,
        repeat=2 if args.quick else 5,
        max_seconds=None,
    )
    rows = [dict(zip(table.columns, row)) for row in table.rows]
    lines = [
        f"Elastic pendulum, t = 0 … {table.meta['t_end']:g}: wall time at matched max |ΔH|/|H₀|",
        "",
        "| energy error | varmech best | method | DOP853 (lambdified) | DOP853 / varmech |",
        "|---:|---:|---|---:|---:|",
    ]
    dop = [r for r in rows if r["method"] == "DOP853"]
    for error in ERRORS:
        ours = {m: seconds_at([r for r in rows if r["method"] == m], error) for m in METHODS}
        best = min((t, m) for m, t in ours.items() if not np.isnan(t)) if any(not np.isnan(t) for t in ours.values()) else None
        theirs = seconds_at(dop, error)
        if best is None or np.isnan(theirs):
            continue
        lines.append(f"| {error:.0e} | {best[0] * 1e3:.2f} ms | {best[1]} | {theirs * 1e3:.1f} ms | {theirs / best[0]:.0f} |")
    publish("\n".join(lines), args.markdown)


if __name__ == "__main__":
    main()
