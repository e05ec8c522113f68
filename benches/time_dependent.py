"""The cost of tracking the energy balance of a Lagrangian that depends on t (issue 36): a run
that tracks −Σ∂L_d/∂t against the same run of the same functions declared independent of t
(built on the binding directly, past the Python check that would refuse it), side by side,
interleaved, best of ``--repeat``.

Three models: a pendulum on a vertically driven support compiled from SymPy (∂L/∂t compiled, the
gradients' last output, so that a step keeps it from Newton's last evaluation of them) under
the midpoint rule and Galerkin's fourth-order rule, a double pendulum on the same support, and
the parametric oscillator from closures with its ∂L/∂t closure (midpoint).

    PYTHONPATH=$PWD/python python benches/time_dependent.py [--repeat 7] [--markdown benches/time_dependent_results.md]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import platform
import time
from pathlib import Path

import numpy as np
import sympy as sp

import varmech
from varmech import _core
from varmech.symbolic._lower import lower
from varmech.symbolic._model import _compile

G = 9.81


def pendulum() -> tuple[object, object]:
    """The driven pendulum's compiled model, tracked and untracked."""
    theta, w, t = sp.symbols("theta w t")
    y = 0.05 * sp.cos(7.0 * t)
    ydot = sp.diff(y, t)
    L = (0.64 * w**2 + ydot**2 + 2 * ydot * 0.8 * sp.sin(theta) * w) / 2 - G * (y - 0.8 * sp.cos(theta))
    return compiled(varmech.symbolic.lagrangian(L, [theta], [w], t=t))


def double_pendulum() -> tuple[object, object]:
    """A double pendulum (unit masses and lengths) on the same driven support, compiled."""
    q1, q2, w1, w2, t = sp.symbols("q1 q2 w1 w2 t")
    y = 0.05 * sp.cos(7.0 * t)
    x1, y1 = sp.sin(q1), y - sp.cos(q1)
    x2, y2 = x1 + sp.sin(q2), y1 - sp.cos(q2)
    rate = {q1: w1, q2: w2}

    def d(e):
        return sum(sp.diff(e, q) * rate[q] for q in (q1, q2)) + sp.diff(e, t)

    L = (d(x1) ** 2 + d(y1) ** 2 + d(x2) ** 2 + d(y2) ** 2) / 2 - G * (y1 + y2)
    return compiled(varmech.symbolic.lagrangian(L, [q1, q2], [w1, w2], t=t))


def compiled(model: varmech.Model) -> tuple[object, object]:
    """A compiled L of t, tracked, and its functions declared independent of t (untracked)."""
    spec, symbols = model._spec, model._symbolic
    # Untracked: the gradients' tape without ∂L/∂t, its last output, lowered afresh.
    slots = {s: i for i, s in enumerate((*symbols.q, *symbols.v, symbols.t))}
    gradients = lower(symbols.expressions["gradients"][: 2 * spec.dim], slots, {})
    functions = {k: v for k, v in spec.functions.items() if k != "dl_dt"} | {"gradients": gradients}
    untracked = _compile(dataclasses.replace(spec, functions=functions, time_dependent=False))
    return model._core, untracked


def oscillator() -> tuple[object, object]:
    """The parametric oscillator's closures, tracked and untracked."""

    def omega(t):
        return 1.0 + 0.5 * math.sin(t)

    def lagrangian(q, v, t):
        return 0.5 * v[0] ** 2 - 0.5 * omega(t) ** 2 * q[0] ** 2

    def dl_dq(q, v, t):
        return np.array([-omega(t) ** 2 * q[0]])

    def dl_dv(q, v, t):
        return v.copy()

    def dl_dt(q, v, t):
        return -omega(t) * 0.5 * math.cos(t) * q[0] ** 2

    def build(tracked):
        return _core.ClosureLagrangian(1, lagrangian, dl_dq, dl_dv, None, None, tracked, [], dl_dt if tracked else None)

    return build(True), build(False)


def run(core, method: str, steps: int) -> float:
    start = time.perf_counter()
    n = core.dim
    spec = _core.RunSpec(dt=0.005, steps=steps, method=method, save_every=steps, max_energy_error=None)
    _core.integrate(core, np.full(n, 0.6), np.zeros(n), spec)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()
    cases = [
        ("driven pendulum, compiled", "midpoint", *pendulum(), 200_000),
        ("driven pendulum, compiled", "galerkin4", *pendulum(), 50_000),
        ("driven double pendulum, compiled", "midpoint", *double_pendulum(), 50_000),
        ("parametric oscillator, closures", "midpoint", *oscillator(), 20_000),
    ]
    rows = []
    for name, method, tracked, untracked, steps in cases:
        times: dict[str, list[float]] = {"tracked": [], "untracked": []}
        for _ in range(args.repeat):
            times["tracked"].append(run(tracked, method, steps))
            times["untracked"].append(run(untracked, method, steps))
        a, b = min(times["tracked"]), min(times["untracked"])
        rows.append((name, method, steps, a, b))
        print(f"{name:32} {method:10} {steps:7d} steps: tracked {a * 1e3:8.2f} ms, untracked {b * 1e3:8.2f} ms, ratio {a / b:.3f}")
    if args.markdown:
        load = " ".join(Path("/proc/loadavg").read_text().split()[:3]) if Path("/proc/loadavg").exists() else "n/a"
        table = "\n".join(f"| {n} | {m} | {s} | {a * 1e3:.2f} | {b * 1e3:.2f} | {a / b:.3f} |" for n, m, s, a, b in rows)
        args.markdown.write_text(
            f"""# Tracking the energy balance of a time-dependent L: cost

Command: `PYTHONPATH=$PWD/python python benches/time_dependent.py --repeat {args.repeat} --markdown benches/time_dependent_results.md`
Machine: {platform.processor() or platform.machine()}, {platform.system()}; load average {load} before.

Each run against the same functions declared independent of t (no ∂L/∂t evaluated, no work
kept), h = 0.005, one state saved; interleaved, best of {args.repeat}.

| model | method | steps | tracked (ms) | untracked (ms) | tracked / untracked |
|---|---|---:|---:|---:|---:|
{table}

Target (issue 36): tracking the balance costs ≤ 5% of a run.
"""
        )


if __name__ == "__main__":
    main()
