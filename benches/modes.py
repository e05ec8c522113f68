"""Small oscillations (issue 35): the cost of an equilibrium and the normal modes of a
100-coordinate chain once its model is built, of ``suggest_dt``, and of the check that
``integrate`` makes before stepping (ω_max by Lanczos, ``varmech.fastest_frequency``), each
against the 10⁴-step run it is for.

The chain: 100 unit masses between fixed walls, joined by FPU-β springs
V = Σ ½(qᵢ₊₁ − qᵢ)² + ¼β(qᵢ₊₁ − qᵢ)⁴ (β = 1), compiled from SymPy (``varmech.symbolic``) and as
NumPy closures. Its modes at rest are the closed form ωₖ = 2 sin(kπ/2(N + 1)), checked.
``varmech.equilibria`` from a guess 1e-2 off (Newton, then the modes) and ``varmech.normal_modes``
at rest, best of ``--repeat``; ``suggest_dt`` and the pre-run check (``modes.warn_if_unstable``,
what ``integrate`` calls, at the run's first state) against a 10⁴-step verlet run, interleaved;
the check's ω_max against the dense modes' at that state.

    PYTHONPATH=$PWD/python python benches/modes.py [--repeat 7] [--markdown benches/modes_results.md]

benches/gallery.py draws the user guide's spectrum chart from here (``spectrum_figure``): the
linear triatomic molecule's modes at dt = 0.9 against each method's stability interval.
"""

from __future__ import annotations

import argparse
import math
import platform
import time
from pathlib import Path

import numpy as np
import sympy as sp

import varmech
from varmech import _core
from varmech.modes import warn_if_unstable

N = 100
BETA = 1.0


def chains() -> dict[str, varmech.Model]:
    q = sp.symbols(f"q0:{N}")
    v = sp.symbols(f"v0:{N}")
    walls = [0, *q, 0]
    bonds = [walls[i + 1] - walls[i] for i in range(N + 1)]
    potential = sum(b**2 / 2 + BETA * b**4 / 4 for b in bonds)
    compiled = varmech.symbolic.lagrangian(sum(x**2 for x in v) / 2 - potential, list(q), list(v))

    def V(x: np.ndarray) -> float:
        b = np.diff(np.concatenate([[0.0], x, [0.0]]))
        return float(np.sum(b**2 / 2 + BETA * b**4 / 4))

    def dV(x: np.ndarray) -> np.ndarray:
        b = np.diff(np.concatenate([[0.0], x, [0.0]]))
        f = b + BETA * b**3
        return f[:-1] - f[1:]

    return {"compiled (SymPy)": compiled, "closures (NumPy)": varmech.MechanicalSystem(N, V, dV, name="FPU chain")}


HEADER = (
    "| model | normal_modes (ms) | equilibria: Newton + modes (ms) | suggest_dt (ms) | pre-run check (µs) "
    "| Lanczos iterations | its ω_max, relative error | 10⁴ verlet steps (ms) | check / run |"
)


def triatomic() -> varmech.MechanicalSystem:
    """The linear triatomic molecule of the user guide: masses 1, 3, 1, springs 2."""
    k = 2.0

    def V(q: np.ndarray) -> float:
        return 0.5 * k * ((q[1] - q[0]) ** 2 + (q[2] - q[1]) ** 2)

    def dV(q: np.ndarray) -> np.ndarray:
        return k * np.array([q[0] - q[1], 2 * q[1] - q[0] - q[2], q[2] - q[1]])

    return varmech.MechanicalSystem(3, V, dV, mass=[1.0, 3.0, 1.0], symmetries=[varmech.Translation(0, spatial_dim=1)], name="triatomic")


def spectrum_figure(out: Path, quick: bool = False) -> list[Path]:
    """The triatomic molecule's spectrum at dt = 0.9 against the stability intervals, with its
    data: ``out``/spectrum_triatomic.png and .csv."""
    methods = ["verlet", "yoshida4", "mclachlan4", "kahan_li8", "rk4", "midpoint"]
    table = varmech.analysis.stability.spectrum(triatomic(), methods, q=np.zeros(3), dt=0.9)
    table.to_csv(out / "spectrum_triatomic.csv")
    varmech.charts.spectrum_chart(table, out / "spectrum_triatomic.png")
    return [out / "spectrum_triatomic.png", out / "spectrum_triatomic.csv"]


def best(call, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()
    exact = 2 * np.sin(np.arange(1, N + 1) * math.pi / (2 * (N + 1)))
    guess = 1e-2 * np.sin(np.arange(N))
    rows = []
    for name, model in chains().items():
        (rest,) = varmech.equilibria(model, guess)
        assert np.max(np.abs(rest.q)) < 1e-12 and np.max(np.abs(rest.modes.frequencies - exact)) < 1e-8
        t_modes = best(lambda model=model: varmech.normal_modes(model, np.zeros(N)), args.repeat)
        t_equilibrium = best(lambda model=model: varmech.equilibria(model, guess), args.repeat)
        t_suggest = best(lambda model=model: varmech.suggest_dt(model, "verlet", np.zeros(N)), args.repeat)
        dt = varmech.suggest_dt(model, "verlet", np.zeros(N)).dt
        # The check and the run, interleaved: best of each over the same rounds.
        checks, runs = [], []
        for _ in range(max(3, args.repeat)):
            checks.append(best(lambda model=model, dt=dt: warn_if_unstable(model, "verlet", guess, dt, 0.0), 1))
            runs.append(best(lambda model=model, dt=dt: varmech.integrate(model, guess, np.zeros(N), dt=dt, steps=10_000, save_every=10_000), 1))
        t_check, t_run = min(checks), min(runs)
        omega, iterations, converged = _core.fastest_frequency(model._core, guess, 0.0)
        dense = varmech.normal_modes(model, guess).omega_max
        # The chain's top is the densest spectrum there is (its highest modes 7e-4 apart):
        # the iteration cap is reached, within 1e-3 from below.
        assert omega <= dense * (1 + 1e-9) and abs(omega / dense - 1) < 1e-3, (omega, dense)
        rows.append((name, t_modes, t_equilibrium, t_suggest, t_check, iterations, abs(omega / dense - 1), t_run))
        print(f"{name:18} modes {t_modes * 1e3:7.2f} ms  equilibrium + modes {t_equilibrium * 1e3:7.2f} ms  "
              f"suggest_dt {t_suggest * 1e3:7.2f} ms  pre-run check {t_check * 1e6:7.1f} µs ({iterations} Lanczos "
              f"iterations, ω_max to {abs(omega / dense - 1):.1e}) = {t_check / t_run:.2%} of a 10⁴-step run ({t_run * 1e3:.0f} ms)")
    if args.markdown:
        load = " ".join(Path("/proc/loadavg").read_text().split()[:3]) if Path("/proc/loadavg").exists() else "n/a"
        table = "\n".join(
            f"| {name} | {a * 1e3:.2f} | {b * 1e3:.2f} | {c * 1e3:.2f} | {e * 1e6:.0f} | {k} | {err:.1e} | {d * 1e3:.0f} | {e / d:.2%} |"
            for name, a, b, c, e, k, err, d in rows
        )
        args.markdown.write_text(
            f"""# Small oscillations: cost

Command: `PYTHONPATH=$PWD/python python benches/modes.py --repeat {args.repeat} --markdown benches/modes_results.md`
Machine: {platform.processor() or platform.machine()}, {platform.system()}; load average {load} before.

An FPU-β chain of {N} unit masses between walls, its model built once; the modes at rest are the
closed form ωₖ = 2 sin(kπ/2(N + 1)) (checked to 1e-8). Best of {args.repeat}. The pre-run check
is what `integrate` calls before stepping (`modes.warn_if_unstable`: ω_max by Lanczos at the first
state, 1e-2 off rest), interleaved with the 10⁴-step verlet run it precedes, best of each; its ω_max
against the dense modes' at that state.

{HEADER}
|---|---:|---:|---:|---:|---:|---:|---:|---:|
{table}

Targets (issue 35): equilibrium and modes ≤ 10 ms with exact derivatives; the pre-run check
≤ 1% of a 10⁴-step run.
"""
        )


if __name__ == "__main__":
    main()
