"""Impulses and ``t_eval`` in the core's step loop (issue 33) against the Python loops around the
core that they replace (commit 5ef2339: ``impulses.run`` restarted the core at each blow,
``dense.at_times`` resumed it at each sample).

Both runs use this build's ``_core`` (the old package is given it), so the ratio is what the loop
around the core costs. The harmonic oscillator (native, verlet, h = 10⁻³, 10⁵ steps):

- K impulses at off-grid times against the same run without, both saving every 100th state:
  the cost of one blow;
- K samples ``t_eval`` at off-grid times against the run saving every 100th state: the cost of
  one sample.

Interleaved (old, new, old, …), best of ``--repeat``, the old timed in a subprocess running the
checkout ``--old`` (``git worktree add /tmp/old5ef2339 5ef2339`` and a copy of the ``_core``
module into its python/varmech/).

    PYTHONPATH=$PWD/python python benches/schedule.py [--repeat 5] [--old /tmp/old5ef2339]
        [--markdown benches/schedule_results.md]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import varmech

DT, STEPS = 1e-3, 100_000

# The timed runs, as source: the same text runs here and in the old checkout's subprocess.
TIMED = f"""
import time, numpy as np, varmech
s = varmech.scenes.harmonic_oscillator()
def timed(kind, k):
    blows = [varmech.Impulse(generalized=[1e-3], t=0.0537 + j * (90.0 / max(k, 1))) for j in range(k)]
    times = np.linspace(0.0137, 99.9, k)
    kw = dict(dt={DT}, steps={STEPS})
    if kind == "t_eval":
        kw["t_eval"] = times
    else:
        kw["save_every"] = 100
    if kind == "impulses":
        kw["impulses"] = blows
    start = time.perf_counter()
    varmech.integrate(s, [0.0], [1.0], **kw)
    return time.perf_counter() - start
"""


def _new(kind: str, k: int) -> float:
    scope: dict = {}
    exec(TIMED, scope)
    return scope["timed"](kind, k)


def _old(old: Path, kind: str, k: int) -> float:
    code = TIMED + f"\nprint(timed({kind!r}, {k}))"
    env = dict(os.environ, PYTHONPATH=str(old / "python"))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.split()[-1])


def measure(old: Path, repeat: int) -> list[dict]:
    rows = []
    for kind, counts in (("impulses", (10, 100, 1000)), ("t_eval", (100, 1000, 10_000))):
        for k in counts:
            best = {"old": np.inf, "new": np.inf, "old_plain": np.inf, "new_plain": np.inf}
            for _ in range(repeat):
                best["old_plain"] = min(best["old_plain"], _old(old, "plain", 0))
                best["old"] = min(best["old"], _old(old, kind, k))
                best["new_plain"] = min(best["new_plain"], _new("plain", 0))
                best["new"] = min(best["new"], _new(kind, k))
            row = {"what": kind, "k": k, **best}
            row["old_each_us"] = max(best["old"] - best["old_plain"], 0.0) / k * 1e6
            row["new_each_us"] = max(best["new"] - best["new_plain"], 0.0) / k * 1e6
            row["ratio"] = best["old"] / best["new"]
            rows.append(row)
            print(json.dumps(row))
    return rows


def markdown(rows: list[dict], repeat: int) -> str:
    lines = [
        "# Impulses and t_eval in the core against the Python loops around it",
        "",
        f"`PYTHONPATH=$PWD/python python benches/schedule.py --repeat {repeat}` on {platform.processor() or platform.machine()},"
        f" {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f} at the end; the harmonic oscillator (native, verlet,"
        f" h = {DT:g}, {STEPS} steps), best of {repeat}, interleaved. Old: commit 5ef2339's Python loops on this build's"
        " core; the plain run saves every 100th state.",
        "",
        "| what | K | old run (s) | new run (s) | old / new | old, each (µs) | new, each (µs) |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r['what']} | {r['k']} | {r['old']:.4f} | {r['new']:.4f} | {r['ratio']:.1f} |"
            f" {r['old_each_us']:.1f} | {r['new_each_us']:.2f} |"
        )
    plain = min(r["new_plain"] for r in rows)
    lines += ["", f"The plain run: {plain:.4f} s ({plain / STEPS * 1e9:.0f} ns a step)."]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--old", type=Path, default=Path("/tmp/old5ef2339"))
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()
    print(f"varmech {varmech.__file__}", file=sys.stderr)
    start = time.perf_counter()
    rows = measure(args.old, args.repeat)
    if args.markdown:
        args.markdown.write_text(markdown(rows, args.repeat))
    print(f"{time.perf_counter() - start:.0f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
