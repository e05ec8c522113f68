"""The user guide's figure of variable mass (issue 36): the rocket against Tsiolkovsky's law with
gravity up to burn-out, its error against the step for the midpoint rule and Galerkin's order-4
rule, and Cayley's falling chain, whose acceleration tends to g/3.

    PYTHONPATH=$PWD/python python benches/variable_mass.py [--out docs/gallery]

benches/gallery.py draws it too (``--only variable-mass``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import varmech
from varmech.symbolic import examples

G = 9.80665


def rocket_exact(t: np.ndarray, m0: float = 10.0, k: float = 0.4, c: float = 400.0) -> tuple[np.ndarray, np.ndarray]:
    """Height and velocity of the default rocket from rest at 0: Tsiolkovsky with gravity."""
    m = m0 - k * t
    return c * (t + m / k * np.log(m / m0)) - G * t**2 / 2, c * np.log(m0 / m) - G * t


def variable_mass_figure(out: Path, quick: bool = False) -> list[Path]:
    """``out``/variable_mass.png and its data, variable_mass.csv (the rocket's errors)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_rocket, ax_order, ax_chain) = plt.subplots(1, 3, figsize=(13.5, 4.0), layout="constrained")
    rocket = examples.rocket()
    traj = varmech.integrate(rocket, [0.0], v0=[0.0], dt=0.05, t_end=24.0, save_every=10)
    t = np.linspace(0.0, 24.0, 400)
    x, v = rocket_exact(t)
    ax_rocket.plot(t, v, color="0.6", lw=3, label="Tsiolkovsky with gravity")
    ax_rocket.plot(traj.t, traj.v[:, 0], "o", ms=3, color="C0", label="midpoint, h = 0.05")
    ax_rocket.set(xlabel="t", ylabel="v", title="Rocket in gravity, to burn-out at t = 25")
    ax_rocket.legend(loc="upper left")

    steps = [0.4, 0.2, 0.1, 0.05, 0.025] if not quick else [0.4, 0.2, 0.1]
    rows = []
    for method, marker in (("midpoint", "o-"), ("galerkin4", "s-")):
        errors = []
        for dt in steps:
            run = varmech.integrate(rocket, [0.0], v0=[0.0], dt=dt, t_end=16.0, method=method)
            xe, ve = rocket_exact(run.t)
            errors.append(max(abs(run.q[:, 0] - xe).max(), abs(run.v[:, 0] - ve).max()))
            rows.append((method, dt, errors[-1]))
        order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
        ax_order.loglog(steps, errors, marker, label=f"{method}: order {order:.2f}")
    ax_order.set(xlabel="step h", ylabel="max error in x, v to t = 16", title="The rocket: error against step")
    ax_order.set_xticks(steps, [f"{h:g}" for h in steps])
    ax_order.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax_order.legend()

    x0 = 0.1
    chain = varmech.integrate(examples.falling_chain(), [x0], v0=[0.0], dt=0.001, t_end=3.0, save_every=5)
    xs, vs = chain.q[1:, 0], chain.v[1:, 0]
    ax_chain.semilogx(xs / x0, (G - vs**2 / xs) / G, color="C0", lw=2, label="run: ẍ = g − ẋ²/x")
    ax_chain.semilogx(xs / x0, (1 + 2 * (x0 / xs) ** 3) / 3, "--", color="k", lw=1, label="Cayley: (1 + 2(x₀/x)³)/3")
    ax_chain.axhline(1 / 3, color="0.6", lw=1)
    ax_chain.set(xlabel="x / x₀", ylabel="ẍ / g", title="Cayley's falling chain: ẍ → g/3")
    ax_chain.legend()

    png, csv = out / "variable_mass.png", out / "variable_mass.csv"
    fig.savefig(png, dpi=110)
    plt.close(fig)
    with open(csv, "w") as f:
        f.write("method,dt,max_error\n")
        f.writelines(f"{m},{dt},{e:.6e}\n" for m, dt, e in rows)
    return [png, csv]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/gallery"))
    args = parser.parse_args()
    for path in variable_mass_figure(args.out):
        print(path)


if __name__ == "__main__":
    main()
