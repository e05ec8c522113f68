"""Contacts that hold (issue 34): a held contact's cost per step against the equivalent
bilateral constraint, with and without friction, and the gallery's figures of the particle
leaving the sphere and of Byerly's billiard ball starting to roll.

The pendulum x² + y² = 1 (g = 1, released from rest 1 rad from the bottom, never slack), both
models compiled from the same SymPy L = ½(ẋ² + ẏ²) − y:

- held: the free particle with the contact |q| ≤ 1 (e = 0), held closed by RATTLE from the first
  step (the bob presses on the string throughout), its λ checked after every step;
- bilateral: the particle with the constraint x² + y² − 1 = 0, ``rattle``;
- held with friction: the held contact with Coulomb friction μ = 10⁻⁴ (the bob slides along
  the string's circle throughout: the friction's fixed point and multipliers at every step);

10⁵ steps of h = 0.01 each, interleaved, best of ``--repeat``, as µs a step and their ratio.

    PYTHONPATH=$PWD/python python benches/holds.py [--repeat 5]
        [--markdown benches/holds_results.md] [--figure docs/gallery]
"""

from __future__ import annotations

import argparse
import math
import platform
import time
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp

import varmech

STEPS = 100_000
DT = 0.01


def models() -> tuple[varmech.Model, varmech.Model]:
    x, y = sp.symbols("x y")
    vx, vy = sp.symbols("vx vy")
    L = (vx**2 + vy**2) / 2 - y
    free = varmech.symbolic.lagrangian(L, [x, y], [vx, vy])
    bilateral = varmech.symbolic.lagrangian(L, [x, y], [vx, vy], constraints=[x**2 + y**2 - 1])
    return free, bilateral


def timings(repeat: int) -> dict[str, float]:
    free, bilateral = models()
    string = varmech.Contact.ellipsoid([1.0, 1.0], restitution=0.0, law="reflect", name="string")
    q0 = np.array([math.sin(1.0), -math.cos(1.0)])
    q0 /= np.hypot(*q0)
    rough = varmech.Contact.ellipsoid([1.0, 1.0], restitution=0.0, law="reflect", name="string", friction=varmech.Friction(1e-4))
    runs = {
        "held contact, verlet": lambda: varmech.integrate(free, q0, [0.0, 0.0], dt=DT, steps=STEPS, save_every=STEPS, contacts=[string]),
        "bilateral constraint, rattle": lambda: varmech.integrate(bilateral, q0, [0.0, 0.0], dt=DT, steps=STEPS, save_every=STEPS, method="rattle"),
        "held contact with friction, verlet": lambda: varmech.integrate(free, q0, [0.0, 0.0], dt=DT, steps=STEPS, save_every=STEPS, contacts=[rough]),
    }
    # The two runs are one motion: the held one never leaves the circle.
    held, both = runs["held contact, verlet"](), runs["bilateral constraint, rattle"]()
    assert len(held.events[2]) == 0 and abs(np.hypot(*held.q[-1]) - 1) < 1e-12
    assert np.max(np.abs(held.q[-1] - both.q[-1])) < 1e-9, (held.q[-1], both.q[-1])
    slid = runs["held contact with friction, verlet"]()
    assert len(slid.events[3]) == 0 and slid.work[-1] < 0, "slides throughout"
    best = dict.fromkeys(runs, np.inf)
    for _ in range(repeat):
        for name, run in runs.items():
            start = time.perf_counter()
            run()
            best[name] = min(best[name], time.perf_counter() - start)
    for name, seconds in best.items():
        print(f"{name:30} {seconds * 1e6 / STEPS:6.3f} µs a step")
    return best


def saved(plt: Any, fig: Any, path: Path) -> Path:
    """``path``, where ``fig`` is written laid out (its folder made if needed), then closed."""
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def lift_off_chart(out: Path) -> Path:
    """The gallery's figure ``<out>/sphere_lift_off.png``: the particle sliding from rest at
    θ₀ = 0.3 on the unit sphere (held), its λ falling to 0 where cos θ = (2/3)cos θ₀, and the
    projectile after."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    particle = varmech.MechanicalSystem(2, lambda q: 9.81 * q[1], lambda q: np.array([0.0, 9.81]), name="particle")
    sphere = varmech.Contact.ellipsoid([1.0, 1.0], inside=False, restitution=0.0, law="reflect", name="sphere")
    q0 = np.array([math.sin(0.3), math.cos(0.3)]) * (1 + 2 * np.finfo(float).eps)
    traj = varmech.integrate(particle, q0, [0.0, 0.0], dt=0.005, t_end=1.0, contacts=[sphere])
    released = traj.events[2]
    t_off = released.t[0]
    held = traj.t <= t_off
    # λ of the held states: m(g cos θ − v²), the sphere's push.
    radius = np.hypot(traj.q[:, 0], traj.q[:, 1])
    lam = 9.81 * traj.q[:, 1] / radius - np.sum(traj.p**2, axis=1)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4.2))
    angle = np.linspace(0, 2 * np.pi, 400)
    ax.plot(np.cos(angle), np.sin(angle), color="0.6", lw=1)
    ax.plot(traj.q[held, 0], traj.q[held, 1], color="C0", lw=2, label="held on the sphere")
    ax.plot(traj.q[~held, 0], traj.q[~held, 1], color="C1", lw=2, label="projectile")
    ax.plot(*released.q[0], "ko", label=f"lift-off: cos θ = {released.q[0][1]:.5f}\n(exact (2/3)cos θ₀ = {2 / 3 * math.cos(0.3):.5f})")
    ax.set_aspect("equal")
    ax.set_xlim(-0.2, 2.2)
    ax.set_ylim(-1.3, 1.3)
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title("A particle sliding from rest at θ₀ = 0.3 (verlet, h = 0.005)")
    bx.plot(traj.t[held], lam[held] / 9.81, color="C0")
    bx.axvline(t_off, color="k", ls=":", lw=1)
    bx.axhline(0, color="0.6", lw=1)
    bx.set_xlabel("t")
    bx.set_ylabel("λ / mg")
    bx.set_title("The sphere's push, held until it reaches 0")
    return saved(plt, fig, out / "sphere_lift_off.png")


def billiard_chart(out: Path) -> Path:
    """The gallery's figure ``<out>/billiard_ball_rolls.png``: Byerly's billiard ball (Art. 10(b)),
    struck to slide without spin on a table with μ = 0.2, its speed v and its rim's speed rω
    meeting at 5v₀/7 at t = 2v₀/(7μg), where it sticks (rolls), and the work of friction."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    g, r, v0, mu = 9.81, 0.1, 2.0, 0.2
    inertia = 0.4 * r**2
    ball = varmech.MechanicalSystem(3, lambda q: g * q[1], lambda q: np.array([0.0, g, 0.0]), mass=[1.0, 1.0, inertia], name="ball")
    floor = varmech.Contact.wall(1, r, restitution=0.0, law="reflect", name="table", friction=varmech.Friction(mu, slip=[[1.0, 0.0, -r]]))
    traj = varmech.integrate(ball, [0.0, r, 0.0], [v0, 0.0, 0.0], dt=0.01, t_end=2.0, contacts=[floor])
    rolls = traj.events[3].t[0]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4.2))
    ax.plot(traj.t, traj.p[:, 0], color="C0", lw=2, label="v, the centre's speed")
    ax.plot(traj.t, r * traj.p[:, 2] / inertia, color="C1", lw=2, label="rω, the rim's speed")
    ax.axhline(5 * v0 / 7, color="0.6", lw=1, ls="--", label="5v₀/7")
    ax.axvline(rolls, color="k", ls=":", lw=1, label=f"stuck at t = {rolls:.6f}\n(exact 2v₀/(7μg) = {2 * v0 / (7 * mu * g):.6f})")
    ax.set_xlabel("t")
    ax.legend(loc="center right", fontsize=8)
    ax.set_title("Byerly's billiard ball: slides, then rolls (verlet, h = 0.01)")
    bx.plot(traj.t, -traj.work / (v0**2 / 2), color="C3", lw=2)
    bx.axhline(2 / 7, color="0.6", lw=1, ls="--")
    bx.set_xlabel("t")
    bx.set_ylabel("−W / E₀")
    bx.set_title("The work of friction: 2/7 of the energy, then none")
    return saved(plt, fig, out / "billiard_ball_rolls.png")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--markdown", type=Path)
    parser.add_argument("--figure", type=Path)
    args = parser.parse_args()
    if args.figure:
        print(lift_off_chart(args.figure))
        print(billiard_chart(args.figure))
    load = " ".join(Path("/proc/loadavg").read_text().split()[:3]) if Path("/proc/loadavg").exists() else "n/a"
    best = timings(args.repeat)
    if args.markdown:
        held, bilateral = best["held contact, verlet"], best["bilateral constraint, rattle"]
        rough = best["held contact with friction, verlet"]
        rows = "\n".join(f"| {name} | {seconds * 1e6 / STEPS:.3f} |" for name, seconds in best.items())
        args.markdown.write_text(
            f"""# Contacts that hold: cost per step

Command: `PYTHONPATH=$PWD/python python benches/holds.py --repeat {args.repeat} --markdown benches/holds_results.md`
Machine: {platform.processor() or platform.machine()}, {platform.system()}; load average {load} before.

The pendulum x² + y² = 1 (g = 1, from rest 1 rad from the bottom), both models compiled from
L = ½(ẋ² + ẏ²) − y: the free particle with the contact |q| ≤ 1 held closed (verlet: RATTLE on the
contact, λ checked after every step), the particle with the bilateral constraint (rattle), and the
held contact with Coulomb friction μ = 1e-4 (sliding throughout). {STEPS} steps of h = {DT},
interleaved, best of {args.repeat}; the frictionless end states agree to 1e-9.

| run | µs a step |
|---|---:|
{rows}

Held ÷ bilateral: {held / bilateral:.2f}; with friction ÷ without: {rough / held:.2f}. Target (issue 34): a
contact that holds costs no more than the equivalent bilateral constraint per step.
"""
        )


if __name__ == "__main__":
    main()
