"""Delayed forces (issue 36): what a delay costs, and the user guide's figure of the delayed
feedback oscillator q̈ + q = −k q̇(t − τ) about its Hopf boundary.

The cost: the oscillator damped by its velocity τ = m·h ago against the same force of the
velocity now, −k q̇(t) (no history kept or read), side by side, interleaved, best of
``--repeat``; τ a whole number of steps (the method's own past, the issue's case) and not (the
Hermite interpolant); the pendulum in a controlled wind, θ̈ + sin θ = −k θ̇(t − τ) cos θ,
against −k θ̇ cos θ; and the oscillator pushed by its acceleration τ ago, q̈ + q = −k q̈(t − τ), against the same
oscillator pushed by its velocity τ ago (what reading the acceleration adds; the same force now,
−k q̈(t), is added mass, a model with no force to evaluate at all, not a like run).

    PYTHONPATH=$PWD/python python benches/delays.py [--repeat 25] [--steps 50000] [--markdown benches/delays_results.md] [--figure docs/gallery]

benches/gallery.py draws the figure too (``--only delays``).
"""

from __future__ import annotations

import argparse
import gc
import math
import platform
import time
from pathlib import Path

import numpy as np
import sympy as sp

import varmech
from varmech.symbolic import Delayed

q, w, w_past, a_past, k = sp.symbols("q w w_past a_past k")
L = (w**2 - q**2) / 2


def delayed(tau: float) -> varmech.Model:
    """q̈ + q = −k q̇(t − τ)."""
    return varmech.symbolic.lagrangian(L, [q], [w], parameters={k: 0.5}, delayed=Delayed(tau, [-k * w_past], v_past=[w_past]))


def critical_gain(tau: float) -> float:
    """The gain of the Hopf crossing: s = iΩ with Ωτ = π/2, k = (Ω² − 1)/Ω."""
    big_omega = math.pi / (2 * tau)
    return (big_omega**2 - 1) / big_omega


def growth_rate(model: varmech.Model, gain: float, dt: float = 0.01, t_end: float = 600.0) -> float:
    """The amplitude's growth rate, from the run's second and fourth quarters."""
    traj = varmech.integrate(model, [1.0], v0=[0.0], dt=dt, t_end=t_end, parameters={"k": gain})
    x, quarter = traj.q[:, 0], len(traj) // 4
    early, late = abs(x[quarter : 2 * quarter]).max(), abs(x[3 * quarter :]).max()
    return math.log(late / early) / (traj.t[3 * quarter] - traj.t[quarter])


def delays_figure(out: Path, quick: bool = False) -> list[Path]:
    """``out``/delays.png and its data, delays.csv (the growth rate against the gain)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tau = 1.0
    model, kc = delayed(tau), critical_gain(tau)
    fig, (ax_runs, ax_rate) = plt.subplots(1, 2, figsize=(11.0, 4.0), layout="constrained")
    for factor, color in ((0.9, "C0"), (1.1, "C3")):
        traj = varmech.integrate(model, [1.0], v0=[0.0], dt=0.01, t_end=150.0, parameters={"k": factor * kc})
        ax_runs.semilogy(traj.t, abs(traj.q[:, 0]), color=color, lw=0.6, label=f"k = {factor:g} k_c")
    ax_runs.set(xlabel="t", ylabel="|q|", title=f"q̈ + q = −k q̇(t − τ), τ = {tau:g}: either side of k_c = {kc:.4f}")
    ax_runs.set_ylim(1e-4, 1e2)
    ax_runs.legend(loc="lower left")

    factors = np.linspace(0.6, 1.4, 5 if quick else 17)
    rates = [growth_rate(model, f * kc, t_end=300.0 if quick else 600.0) for f in factors]
    ax_rate.axhline(0.0, color="0.6", lw=1)
    ax_rate.axvline(1.0, color="0.6", lw=3, label="exact Hopf crossing")
    ax_rate.plot(factors, rates, "o-", color="C0", label="measured growth rate, midpoint h = 0.01")
    ax_rate.set(xlabel="k / k_c", ylabel="growth rate of the amplitude", title="The stability boundary")
    ax_rate.legend(loc="upper left")
    png, csv = out / "delays.png", out / "delays.csv"
    fig.savefig(png, dpi=120)
    plt.close(fig)
    np.savetxt(csv, np.column_stack([factors, rates]), delimiter=",", header="k_over_kc,growth_rate", comments="")
    return [png, csv]


def undelayed() -> varmech.Model:
    """q̈ + q = −k q̇(t): the same force of the velocity now."""
    return varmech.symbolic.lagrangian(L, [q], [w], parameters={k: 0.5}, force=[-k * w])


def neutral(tau: float) -> varmech.Model:
    """q̈ + q = −k q̈(t − τ)."""
    return varmech.symbolic.lagrangian(L, [q], [w], parameters={k: 0.5}, delayed=Delayed(tau, [-k * a_past], a_past=[a_past]))


def wind(tau: float | None) -> varmech.Model:
    """The pendulum in a controlled wind, θ̈ + sin θ = −k θ̇(t − τ) cos θ (τ None: θ̇(t))."""
    pendulum = w**2 / 2 + sp.cos(q)
    if tau is None:
        return varmech.symbolic.lagrangian(pendulum, [q], [w], parameters={k: 0.5}, force=[-k * w * sp.cos(q)])
    feedback = Delayed(tau, [-k * w_past * sp.cos(q)], v_past=[w_past])
    return varmech.symbolic.lagrangian(pendulum, [q], [w], parameters={k: 0.5}, delayed=feedback)


def run(model: varmech.Model, steps: int) -> float:
    # As timeit does: SymPy's heap makes a collection in the timed call cost milliseconds.
    gc.collect()
    gc.disable()
    try:
        start = time.perf_counter()
        varmech.integrate(model, [1.0], v0=[0.0], dt=0.01, steps=steps, save_every=steps, max_energy_error=None)
        return time.perf_counter() - start
    finally:
        gc.enable()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=25)
    parser.add_argument("--steps", type=int, default=50_000)
    parser.add_argument("--markdown", type=Path)
    parser.add_argument("--figure", type=Path)
    args = parser.parse_args()
    cases = [
        ("oscillator, τ = 50 h (the method's own past)", delayed(0.5), undelayed()),
        ("oscillator, τ = 50.37 h (interpolated)", delayed(0.5037), undelayed()),
        ("pendulum in a controlled wind, τ = 50 h", wind(0.5), wind(None)),
        ("oscillator, −k q̈(t − τ) against −k q̇(t − τ), τ = 50 h", neutral(0.5), delayed(0.5)),
    ]
    rows = []
    for name, model, baseline in cases:
        times: dict[str, list[float]] = {"delayed": [], "undelayed": []}
        for _ in range(args.repeat):
            times["delayed"].append(run(model, args.steps))
            times["undelayed"].append(run(baseline, args.steps))
        a, b = min(times["delayed"]), min(times["undelayed"])
        rows.append((name, a, b))
        print(f"{name:46} delayed {a * 1e3:8.2f} ms, undelayed {b * 1e3:8.2f} ms, ratio {a / b:.3f}")
    if args.markdown:
        load = " ".join(Path("/proc/loadavg").read_text().split()[:3]) if Path("/proc/loadavg").exists() else "n/a"
        table = "\n".join(f"| {n} | {a * 1e3:.2f} | {b * 1e3:.2f} | {a / b:.3f} |" for n, a, b in rows)
        args.markdown.write_text(
            f"""# A delayed force: cost

Command: `PYTHONPATH=$PWD/python python benches/delays.py --repeat {args.repeat} --steps {args.steps} --markdown benches/delays_results.md`
Machine: {platform.processor() or platform.machine()}, {platform.system()}; load average {load} before.

q̈ + q = −k q̇(t − τ) against q̈ + q = −k q̇(t), θ̈ + sin θ = −k θ̇(t − τ) cos θ against
−k θ̇ cos θ, and q̈ + q = −k q̈(t − τ) against q̈ + q = −k q̇(t − τ) (what reading the
acceleration adds to reading the velocity), each pair compiled from SymPy, midpoint rule, h = 0.01, {args.steps} steps, one
state saved; interleaved, best of {args.repeat}, the garbage collector off in the timed calls.

| model, delay | delayed (ms) | undelayed (ms) | delayed / undelayed |
|---|---:|---:|---:|
{table}

Target (issue 36): a delayed force with τ = k·h costs ≤ 10% over the same force without delay.
"""
        )
    if args.figure:
        print(*delays_figure(args.figure), sep="\n")


if __name__ == "__main__":
    main()
