"""Impacts (issue 17): the cost of the variational collision integrator (``law="variational"``,
Fetecau, Marsden, Ortiz & West 2003) and of the exact reflection (``law="reflect"``), and their
accuracy against the naive scheme every simple simulation starts with.

The naive scheme (the rival, not library code): plain steps of the method; when a step ends
with φ(q) < 0 while the normal velocity points out (∇φ·q̇ < 0), the normal momentum is
reflected there in the metric of the kinetic energy (:func:`varmech.impacts.reflect`) and **the
position is left where it is**, outside the table: the textbook "if y < 0: v = −v". (Mirroring
the position as well is the other common version; on a curved wall it needs the nearest point.)

- Cost: runs with impacts against the same runs without contacts (the same steps, no impacts),
  as ratios and as the cost per impact, for verlet and yoshida4, on the bouncing ball (the floor
  a native wall, ``Contact.wall``) and the elliptic billiard (the wall φ from Python closures,
  called once a step). Interleaved, best of ``--repeat``.
- Accuracy: the billiard's focal invariant L₁L₂ over 10³ impacts against wall time, the VCI
  against the naive scheme over a sweep of steps, and the error at matched cost; the ball's
  energy and bounce times over 10³ bounces.
- :func:`billiard_chart` draws the gallery's figure (``python benches/gallery.py --only
  impacts``): the trajectory with its impacts, and the invariant's error over 10⁴ impacts.

    python benches/impacts.py [--repeat 5] [--markdown benches/impacts_results.md]
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
from compare import best_times_interleaved

import varmech
from varmech.charts._figure import pyplot, save
from varmech.impacts import reflect

G = 9.81
#: The elliptic billiard x²/A² + y²/B² ≤ 1 of tests/python/test_impacts.py, foci (±c, 0).
A, B = 2.0, 1.0
C = math.sqrt(A * A - B * B)
Q0, P0 = np.array([0.3, 0.1]), np.array([0.6, 0.8])
#: Time for 10⁴ impacts of the billiard's orbit (about 2.08 per impact).
T_BILLIARD = 2.1


def ball() -> varmech.MechanicalSystem:
    """A unit mass under gravity, height q₀ (the floor is ``Contact.wall(0)``)."""
    return varmech.MechanicalSystem(1, lambda q: G * q[0], lambda q: np.array([G]), name="ball")


def billiard(law: str = "variational") -> tuple[varmech.MechanicalSystem, varmech.Contact]:
    """A free unit mass in the plane, and the wall φ = 1 − x²/A² − y²/B² ≥ 0."""
    free = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2), name="billiard")
    wall = varmech.Contact(
        lambda q: 1 - (q[0] / A) ** 2 - (q[1] / B) ** 2, lambda q: [-2 * q[0] / A**2, -2 * q[1] / B**2], name="wall", law=law
    )
    return free, wall


def focal(q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """L₁L₂ with Lᵢ = (x ∓ c)ẏ − yẋ, the angular momenta about the foci (rows of q and p)."""
    return ((q[..., 0] - C) * p[..., 1] - q[..., 1] * p[..., 0]) * ((q[..., 0] + C) * p[..., 1] - q[..., 1] * p[..., 0])


def naive(
    model: varmech.Model, contact: varmech.Contact, q0: np.ndarray, p0: np.ndarray, dt: float, impacts: int, method: str = "verlet"
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The naive scheme (module docstring) until ``impacts`` reflections: their times, and the
    positions and momenta just after each."""
    stepper = varmech.Stepper(model, q0, p0, dt=dt, method=method)
    ts, qs, ps = [], [], []
    while len(ts) < impacts:
        stepper.step()
        q = stepper.q
        if contact.phi(q) < 0:
            p = stepper.p
            after = reflect(model, contact, q, p, stepper.t)
            # The reflection adds a multiple of ∇φ: a positive one where q̇ points out.
            if np.dot(after - p, contact.gradient(q)) > 0:
                stepper.reset(q, after)
                ts.append(stepper.t)
                qs.append(q)
                ps.append(after)
    return np.array(ts), np.array(qs), np.array(ps)


def after_impacts(traj: varmech.Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """The states just after each impact of a run with contacts: the second of the two saved
    rows at an impact's time."""
    rows = np.flatnonzero(np.diff(traj.t) == 0) + 1
    return traj.q[rows], traj.p[rows]


def billiard_errors(dt: float, impacts: int, law: str) -> np.ndarray:
    """|L₁L₂ − L₁L₂(0)| / |L₁L₂(0)| just after each of the first ``impacts`` impacts of the
    billiard, by ``integrate`` (``law``) or the naive scheme (``law="naive"``)."""
    model, wall = billiard("variational" if law == "naive" else law)
    if law == "naive":
        _, q, p = naive(model, wall, Q0, P0, dt, impacts)
    else:
        traj = varmech.integrate(model, Q0, P0, dt=dt, steps=round(T_BILLIARD * impacts / dt), save_every=10**9, contacts=[wall])
        q, p = after_impacts(traj)
    start = focal(Q0, P0)
    return np.abs(focal(q[:impacts], p[:impacts]) - start) / abs(start)


# --------------------------------------------------------------------------- cost


def cost(repeat: int) -> list[str]:
    """Runs with impacts against the same runs without contacts: ratios and µs per impact."""
    t1 = math.sqrt(2 / G)
    bounces = 1000
    dt_ball, dt_billiard = 1e-3, 0.05
    ball_steps = round(2 * t1 * bounces / dt_ball)
    billiard_steps = round(T_BILLIARD * 1000 / dt_billiard)
    runs, impacts = {}, {}
    for method in ("verlet", "yoshida4"):
        runs[("ball", method, "none")] = lambda m=method: varmech.integrate(
            ball(), [1.0], [0.0], dt=dt_ball, steps=ball_steps, save_every=10**9, method=m
        )
        runs[("billiard", method, "none")] = lambda m=method: varmech.integrate(
            billiard()[0], Q0, P0, dt=dt_billiard, steps=billiard_steps, save_every=10**9, method=m
        )
        for law in ("variational", "reflect"):
            floor = varmech.Contact.wall(0, law=law)
            runs[("ball", method, law)] = lambda m=method, c=floor: varmech.integrate(
                ball(), [1.0], [0.0], dt=dt_ball, steps=ball_steps, save_every=10**9, method=m, contacts=[c]
            )
            model, wall = billiard(law)
            runs[("billiard", method, law)] = lambda m=method, s=model, c=wall: varmech.integrate(
                s, Q0, P0, dt=dt_billiard, steps=billiard_steps, save_every=10**9, method=m, contacts=[c]
            )
    for key in runs:
        if key[2] != "none":
            impacts[key] = len(runs[key]().events[0])
    best = best_times_interleaved(runs, repeat)
    lines = [
        f"Ball: {ball_steps} steps of h = {dt_ball:g} (the floor a native wall); billiard: {billiard_steps} steps of "
        f"h = {dt_billiard:g} (the wall from Python closures). Best of {repeat}, interleaved.",
        "",
        "| scene | method | law | impacts | seconds | ÷ no contacts | µs per impact |",
        "|---|---|---|---:|---:|---:|---:|",
    ]
    for (scene, method, law), seconds in best.items():
        plain = best[(scene, method, "none")]
        if law == "none":
            lines.append(f"| {scene} | {method} | no contacts | 0 | {seconds:.3f} | 1 | |")
            continue
        n = impacts[(scene, method, law)]
        lines.append(f"| {scene} | {method} | {law} | {n} | {seconds:.3f} | {seconds / plain:.1f} | {1e6 * (seconds - plain) / n:.0f} |")
    return lines


# --------------------------------------------------------------------------- accuracy


def matched_cost(repeat: int) -> list[str]:
    """The billiard's invariant over 10³ impacts against wall time: the VCI and the naive scheme
    over a sweep of steps, and the naive scheme's error at the VCI's cost."""
    impacts = 1000
    sweep = [("variational", 0.2), ("variational", 0.05), *[("naive", h) for h in (0.2, 0.05, 0.0125, 0.003125)]]
    errors = {(law, h): float(billiard_errors(h, impacts, law).max()) for law, h in sweep}
    best = best_times_interleaved({(law, h): lambda law=law, h=h: billiard_errors(h, impacts, law) for law, h in sweep}, repeat)
    lines = [
        f"Elliptic billiard (A = {A:g}, B = {B:g}), max |L₁L₂ − L₁L₂(0)| / |L₁L₂(0)| over {impacts} impacts; verlet; "
        f"best of {repeat}, interleaved.",
        "",
        "| scheme | h | steps | seconds | max invariant error |",
        "|---|---:|---:|---:|---:|",
    ]
    for (law, h), seconds in best.items():
        name = 'VCI (law="variational")' if law == "variational" else "naive (reflect at the step's end)"
        lines.append(f"| {name} | {h:g} | {round(T_BILLIARD * impacts / h)} | {seconds:.3f} | {errors[(law, h)]:.2e} |")
    naive_runs = sorted((best[k], errors[k]) for k in best if k[0] == "naive")
    seconds, errs = np.log([s for s, _ in naive_runs]), np.log([e for _, e in naive_runs])
    lines.append("")
    for h in (0.2, 0.05):
        vci = best[("variational", h)]
        at = math.exp(float(np.interp(math.log(vci), seconds, errs)))
        lines.append(
            f"- At the VCI's cost with h = {h:g} ({vci:.2f} s, error {errors[('variational', h)]:.1e}) the naive scheme's "
            f"error is {at:.1e} (log-interpolated in its sweep)."
        )
    return lines


def ball_accuracy() -> list[str]:
    """The ball over 10³ bounces at h = 10⁻³: energy at the impacts and the last bounce's time."""
    t1, dt, bounces = math.sqrt(2 / G), 1e-3, 1000
    exact = t1 * (2 * bounces - 1)
    lines = [
        f"Ball dropped from h₀ = 1 (g = {G}), verlet, h = {dt:g}, {bounces} bounces: max |H − gh₀| / gh₀ at the impacts "
        "and the error of the last bounce's time.",
        "",
        "| scheme | max energy error | bounce-time error |",
        "|---|---:|---:|",
    ]
    steps = round((exact + t1) / dt)
    for law in ("variational", "reflect"):
        hits = varmech.integrate(ball(), [1.0], [0.0], dt=dt, steps=steps, save_every=10**9, contacts=[varmech.Contact.wall(0, law=law)]).events[0]
        energy = np.abs(0.5 * hits.p[:bounces, 0] ** 2 + G * hits.q[:bounces, 0] - G) / G
        lines.append(f"| {law} | {energy.max():.1e} | {abs(hits.t[bounces - 1] - exact):.1e} |")
    t, q, p = naive(ball(), varmech.Contact.wall(0), np.array([1.0]), np.array([0.0]), dt, bounces)
    energy = np.abs(0.5 * p[:, 0] ** 2 + G * q[:, 0] - G) / G
    lines.append(f"| naive | {energy.max():.1e} | {abs(t[-1] - exact):.1e} |")
    return lines


# --------------------------------------------------------------------------- the gallery's chart


def billiard_chart(out: Path, quick: bool = False) -> list[Path]:
    """The gallery's impact figure, ``<out>/impacts_billiard.png`` and its data (CSV): the
    elliptic billiard at h = 0.05 under the VCI, the exact reflection and the naive scheme
    (also at h/4); left, the orbit's first 30 impacts under the VCI and the naive scheme's last
    30; right, the focal invariant's error after each of 10⁴ impacts (10³ with ``quick``)."""
    impacts, dt, shown = (1000 if quick else 10_000), 0.05, 30
    model, wall = billiard()
    traj = varmech.integrate(model, Q0, P0, dt=dt, steps=round(T_BILLIARD * impacts / dt), save_every=10**9, contacts=[wall])
    vci_path = np.vstack([Q0, traj.events[0].q[:shown]])
    _, naive_q, _ = naive(model, wall, Q0, P0, dt, impacts)
    errors = {
        f'VCI (law="variational"), h = {dt:g}': billiard_errors(dt, impacts, "variational"),
        f'law="reflect", h = {dt:g}': billiard_errors(dt, impacts, "reflect"),
        f"naive, h = {dt:g}": billiard_errors(dt, impacts, "naive"),
        f"naive, h = {dt / 4:g}": billiard_errors(dt / 4, impacts, "naive"),
    }
    table = varmech.Table(("scheme", "impact", "invariant_error"), title="elliptic billiard: focal invariant error after each impact")
    for name, err in errors.items():
        for k, e in enumerate(err, 1):
            table.append(name, k, float(e))
    written = [table.to_csv(out / "impacts_billiard.csv")]

    plt = pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.4), layout="constrained", gridspec_kw={"width_ratios": [1, 1.25]})
    angle = np.linspace(0, 2 * np.pi, 400)
    left.plot(A * np.cos(angle), B * np.sin(angle), color="k", lw=1)
    left.plot([-C, C], [0, 0], "k+", ms=8)
    left.plot(vci_path[:, 0], vci_path[:, 1], color="C0", lw=0.7, marker="o", ms=3, label=f"VCI: impacts 1–{shown}")
    left.plot(
        naive_q[-shown:, 0], naive_q[-shown:, 1], color="C3", lw=0.7, marker="o", ms=3,
        label=f"naive: impacts {impacts - shown + 1}–{impacts}",
    )  # fmt: skip
    left.set_aspect("equal")
    left.set_title(f"elliptic billiard, h = {dt:g}: orbits and impacts (+: foci)")
    left.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.05), ncol=2)
    left.axis("off")
    k = np.arange(1, impacts + 1)
    for (name, err), style in zip(errors.items(), ("-", "--", "-", "-")):
        keep = err > 0
        right.loglog(k[keep], err[keep], style, lw=0.8, label=name)
    right.set_xlabel("impact")
    right.set_ylabel("|L₁L₂ − L₁L₂(0)| / |L₁L₂(0)|")
    right.set_title("focal invariant L₁L₂ after each impact")
    right.grid(True, which="major", alpha=0.3)
    right.legend(fontsize=8)
    written.append(save(fig, out / "impacts_billiard.png"))
    return written


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()
    start = time.perf_counter()
    sections = {
        "Cost of impacts": cost(args.repeat),
        "Accuracy at matched cost: the billiard's focal invariant": matched_cost(args.repeat),
        "The ball: energy and bounce times": ball_accuracy(),
    }
    text = "\n\n".join(f"### {title}\n\n" + "\n".join(lines) for title, lines in sections.items())
    print(text)
    print(f"\n({time.perf_counter() - start:.0f} s)")
    if args.markdown:
        args.markdown.write_text(f"# Impacts: cost and accuracy\n\n`python benches/impacts.py --repeat {args.repeat}`\n\n{text}\n")


if __name__ == "__main__":
    main()
