"""Impacts: the cost of resolving them in the core's step loop (issue 33) side by side with the
old Python loop around the core (commit 88600cf), and the accuracy of the variational collision
integrator (``law="variational"``, Fetecau, Marsden, Ortiz & West 2003) and of the exact
reflection (``law="reflect"``) against the naive scheme every simple simulation starts with.

The naive scheme (the rival, not library code): plain steps of the method; when a step ends
with φ(q) < 0 while the normal velocity points out (∇φ·q̇ < 0), the normal momentum is
reflected there in the metric of the kinetic energy (:func:`reflect`) and **the position is left
where it is**, outside the table: the textbook "if y < 0: v = −v". (Mirroring the position as
well is the other common version; on a curved wall it needs the nearest point.)

- Cost, all on native scenes with verlet, interleaved, best of ``--repeat``, as ratios:
  per impact, old (a subprocess running the checkout ``--old``, timed there) against new (the
  ball on ``Contact.wall(0)``, h = 10⁻³, 10³ bounces; the elliptic billiard on
  ``Contact.ellipsoid``, h = 0.05); a circular billiard to 10⁶ impacts; a run with a contact
  never hit against the same run without; an ensemble of 256 billiards on 1 and 2 workers, each
  member asserted equal to its single run bit for bit. Each for both laws; a law this build
  refuses is reported as skipped, with the core's reason.
- Accuracy: the billiard's focal invariant L₁L₂ over 10³ impacts against wall time, the VCI
  against the naive scheme over a sweep of steps, and the error at matched cost; the ball's
  energy and bounce times over 10³ bounces.
- :func:`billiard_chart` draws the gallery's figure (``python benches/gallery.py --only
  impacts``): the trajectory with its impacts, and the invariant's error over 10⁴ impacts.

    PYTHONPATH=$PWD/python python benches/impacts.py [--repeat 5] [--quick] [--old /tmp/old88600cf]
        [--markdown benches/impacts_results.md | --only "never hit"]

``--quick`` shrinks every size (10² bounces and impacts, 10⁴ for the million, 32 ensemble
members) to check that the bench runs; its numbers are not the results.
"""

from __future__ import annotations

import argparse
import inspect
import json
import math
import os
import platform
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np

import varmech

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


def reflect(model: varmech.Model, contact: varmech.Contact, q: np.ndarray, p: np.ndarray, t: float) -> np.ndarray:
    """The naive scheme's reflection: p⁺ = p − (1 + e)(n·q̇)/(nᵀM⁻¹n) n with n = ∇φ(q), the normal
    velocity reversed and scaled by e in the kinetic metric; q̇ and M⁻¹n from the model's
    velocity map (affine in p, hence M⁻¹n = q̇(n) − q̇(0))."""
    normal = np.asarray(contact.gradient(q.copy()), dtype=float).reshape(-1)

    def velocity(x: np.ndarray) -> np.ndarray:
        return varmech._core.derivative(model._core, "velocity", np.array([t]), q[None, :], np.asarray(x, dtype=float)[None, :])[0]

    metric = velocity(normal) - velocity(np.zeros_like(p))
    return np.asarray(p - (1.0 + contact.restitution) * float(normal @ velocity(p)) / float(normal @ metric) * normal)


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


#: The old implementation (impacts as a Python loop around the core, commit 88600cf), for the
#: side-by-side costs: a checkout whose python/ holds its package and its own built core.
OLD = Path("/tmp/old88600cf")
LAWS = ("variational", "reflect")
#: The circular billiard's start (impact parameter 0.18: a chord of 1.967 between impacts).
CIRCLE_Q0, CIRCLE_P0 = [0.3, 0.1], [0.6, 0.8]


def timed_run(vm, scene: str, law: str | None, steps: int, dt: float, far: bool = False, method: str = "verlet"):
    """One run of the cost tables, built with the varmech module ``vm`` (this one, or the old
    one in its subprocess, which gets this function's source): the native ``scene`` ("ball" on
    ``Contact.wall(0)``, "billiard" the elliptic table A = 2, B = 1, "circle" the unit circle)
    with its contact under ``law`` (none if None; with ``far`` one never hit, the wall moved to
    10³⁰), stepped by ``method``; returns the seconds of the ``integrate`` call and its impacts."""
    if scene == "ball":
        model, q0, p0 = vm.scenes.bouncing_ball().model, [1.0], [0.0]
        contact = lambda: vm.Contact.wall(0, -1e30 if far else 0.0, law=law)  # noqa: E731
    else:
        axes = [1.0, 1.0] if scene == "circle" else [2.0, 1.0]
        model, q0, p0 = vm.scenes.elliptic_billiard(A=axes[0], B=axes[1]).model, [0.3, 0.1], [0.6, 0.8]
        contact = lambda: vm.Contact.ellipsoid([1e30 * a for a in axes] if far else axes, law=law)  # noqa: E731
    contacts = {} if law is None else {"contacts": [contact()]}
    start = time.perf_counter()
    traj = vm.integrate(model, q0, p0, dt=dt, steps=steps, save_every=10**9, method=method, **contacts)
    return time.perf_counter() - start, (len(traj.events[0]) if contacts else 0)


#: The old checkout's side: reads one JSON list of ``timed_run``'s arguments a line, answers
#: [seconds, impacts], timed inside the subprocess.
OLD_SERVER = """
import json, sys
import varmech
for line in sys.stdin:
    print(json.dumps(timed_run(varmech, *json.loads(line))), flush=True)
"""


class OldCore:
    """The old implementation in a subprocess (its own varmech and core), run on request."""

    def __init__(self, root: Path) -> None:
        source = "import time\n" + textwrap.dedent(inspect.getsource(timed_run)) + OLD_SERVER
        env = {**os.environ, "PYTHONPATH": str(root / "python")}
        self.process = subprocess.Popen([sys.executable, "-c", source], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env)

    def __call__(self, *args) -> tuple[float, int]:
        assert self.process.stdin is not None and self.process.stdout is not None
        self.process.stdin.write(json.dumps(args) + "\n")
        self.process.stdin.flush()
        answer = self.process.stdout.readline()
        if not answer:
            raise RuntimeError(f"the old implementation's subprocess ended (exit {self.process.wait()})")
        seconds, impacts = json.loads(answer)
        return seconds, impacts

    def close(self) -> None:
        if self.process.stdin is not None:
            self.process.stdin.close()
        self.process.wait()


def law_available(law: str) -> str | None:
    """None where this build resolves impacts under ``law``, else why not (the core's refusal)."""
    try:
        varmech.integrate(ball(), [1.0], [0.0], dt=1e-3, steps=10, contacts=[varmech.Contact.wall(0, law=law)])  # type: ignore[arg-type]
    except ValueError as error:
        return str(error)
    return None


def best_interleaved(runs: dict, repeat: int) -> dict:
    """Best of ``repeat`` of each run, the runs alternating; each run returns (seconds, impacts),
    timed where it ran (the old implementation's in its subprocess)."""
    best = {k: (math.inf, 0) for k in runs}
    for _ in range(repeat):
        for k, run in runs.items():
            seconds, impacts = run()
            best[k] = (min(best[k][0], seconds), impacts)
    return best


def per_impact(repeat: int, quick: bool, old: OldCore | None, skipped: dict[str, str]) -> list[str]:
    """µs per impact, old (a Python loop around the core) and new (in the core's step loop): the
    same runs with and without contacts, interleaved."""
    bounces, billiard_impacts = (100, 100) if quick else (1000, 1000)
    sizes = {
        "ball": (1e-3, round(2 * math.sqrt(2 / G) * bounces / 1e-3)),
        "billiard": (0.05, round(T_BILLIARD * billiard_impacts / 0.05)),
    }
    runs = {}
    for scene, (dt, steps) in sizes.items():
        for law in (None, *LAWS):
            runs[("new", scene, law)] = lambda s=scene, law=law, dt=dt, n=steps: timed_run(varmech, s, law, n, dt)
            if old is not None:
                runs[("old", scene, law)] = lambda s=scene, law=law, dt=dt, n=steps, o=old: o(s, law, n, dt)
        runs[("new", scene, "far")] = lambda s=scene, dt=dt, n=steps: timed_run(varmech, s, "reflect", n, dt, True)
    runs = {k: run for k, run in runs.items() if not (k[0] == "new" and k[2] in skipped)}
    best = best_interleaved(runs, repeat)
    lines = [
        f"Native scenes, verlet, `save_every` = 10⁹: the ball dropped from 1 on `Contact.wall(0)`, h = {sizes['ball'][0]:g}, "
        f"{sizes['ball'][1]} steps ({bounces} bounces); the elliptic billiard (A = 2, B = 1) on `Contact.ellipsoid([2, 1])`, "
        f"h = {sizes['billiard'][0]:g}, {sizes['billiard'][1]} steps. µs per impact = (seconds with contacts − seconds "
        f"without) / impacts; the last column, new only, subtracts instead the same run with its contact never hit (the "
        f"wall moved to 10³⁰): the resolution of the impacts alone, without the watching of the wall at every step (see "
        f"below). Old: commit 88600cf (impacts in a Python loop around the core), in a subprocess, timed there; "
        f"new: this commit. Best of {repeat}, all interleaved.",
        "",
        "| scene | law | impacts | old s, no contacts | old s | old µs/impact | new s, no contacts | new s | new µs/impact | "
        "old ÷ new | new µs/impact, resolution |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for scene in sizes:
        for law in LAWS:
            cells, costs, n = [], {}, 0
            for side in ("old", "new"):
                if (side, scene, law) not in best:
                    cells += ["–", "–", "skipped" if side == "new" else "–"]
                    continue
                plain, (seconds, n) = best[(side, scene, None)][0], best[(side, scene, law)]
                costs[side] = 1e6 * (seconds - plain) / n
                cells += [f"{plain:.4f}", f"{seconds:.4f}", f"{costs[side]:.2f}"]
            ratio = f"{costs['old'] / costs['new']:.0f}" if len(costs) == 2 and costs["new"] > 0 else "–"
            key = ("new", scene, law)
            alone = f"{1e6 * (best[key][0] - best[('new', scene, 'far')][0]) / n:.2f}" if key in best else "skipped"
            lines.append(f"| {scene} | {law} | {n} | {' | '.join(cells)} | {ratio} | {alone} |")
    lines += ["", "Target (issue 33): ≤ 2 µs per impact, native scene, verlet."]
    return lines


def million(repeat: int, quick: bool, skipped: dict[str, str]) -> list[str]:
    """The circular billiard to 10⁶ impacts (10⁴ with ``quick``): its wall-clock time."""
    target, dt = (10**4 if quick else 10**6), 0.5
    chord = 2 * math.sqrt(1 - (CIRCLE_Q0[0] * CIRCLE_P0[1] - CIRCLE_Q0[1] * CIRCLE_P0[0]) ** 2)
    steps = math.ceil(target * chord / dt)
    laws = [law for law in LAWS if law not in skipped]
    runs = {law: lambda law=law: timed_run(varmech, "circle", law, steps, dt) for law in laws}
    runs[None] = lambda: timed_run(varmech, "circle", None, steps, dt)
    best = best_interleaved(runs, repeat)
    lines = [
        f"The unit circle (`Contact.ellipsoid([1, 1])`, native free particle), from q = {CIRCLE_Q0}, p = {CIRCLE_P0} (a chord of "
        f"{chord:.3f} between impacts), verlet, h = {dt:g} (about {chord / dt:.1f} steps an impact: Verlet is exact on the "
        f"straight lines, so the step only sets how often the wall is checked), {steps} steps, `save_every` = 10⁹ (the two "
        f"rows saved at each impact remain). Best of {repeat}, interleaved.",
        "",
        "| law | impacts | seconds | seconds without contacts | µs per impact (all in) |",
        "|---|---:|---:|---:|---:|",
    ]
    for law in LAWS:
        if law not in best:
            lines.append(f"| {law} | – | skipped | – | – |")
            continue
        seconds, n = best[law]
        lines.append(f"| {law} | {n} | {seconds:.3f} | {best[None][0]:.3f} | {1e6 * seconds / n:.2f} |")
    lines += ["", "Target (issue 33): about a second for 10⁶ impacts."]
    return lines


def idle_contact(repeat: int, quick: bool, old: OldCore | None, skipped: dict[str, str]) -> list[str]:
    """A run with a contact never hit (the ball's floor at −10³⁰) against the same run without,
    old and new, for verlet and yoshida4, and the new one against the same wall as a native event
    (no contact)."""
    dt, steps, least = 1e-3, 10**6, (0.05 if quick else 0.3)
    seconds, _ = timed_run(varmech, "ball", None, steps, dt)
    steps = max(steps, math.ceil(steps * 1.3 * least / seconds))  # long enough to time
    sides = {"new": lambda *a: timed_run(varmech, *a), **({"old": old} if old is not None else {})}
    methods = ("verlet", "yoshida4")
    runs = {}
    for side, run in sides.items():
        for method in methods:
            runs[(side, method, None)] = lambda run=run, m=method: run("ball", None, steps, dt, False, m)
            for law in LAWS:
                if not (side == "new" and law in skipped):
                    runs[(side, method, law)] = lambda run=run, law=law, m=method: run("ball", law, steps, dt, True, m)
    model = varmech.scenes.bouncing_ball().model
    runs[("new", "verlet", "event")] = lambda: (
        _seconds(varmech.integrate, model, [1.0], [0.0], dt=dt, steps=steps, save_every=10**9, events=[varmech.events.crossing(0, -1e30)]),
        0,
    )
    best = best_interleaved(runs, repeat)
    lines = [
        f"The native ball, h = {dt:g}, {steps} steps, `save_every` = 10⁹, with `Contact.wall(0, -1e30)` (never hit) "
        f"and without contacts; and (new only, verlet) the same wall as a native event `events.crossing(0, -1e30)`, no "
        f"contact. Best of {repeat}, interleaved.",
        "",
        "| method | run | old s | old ÷ no contacts | new s | new ÷ no contacts |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for method in methods:
        for what in (None, *LAWS, *(("event",) if method == "verlet" else ())):
            cells = []
            for side in ("old", "new"):
                if (side, method, what) in best:
                    seconds = best[(side, method, what)][0]
                    cells += [f"{seconds:.3f}", f"{seconds / best[(side, method, None)][0]:.3f}"]
                else:
                    cells += ["skipped" if side == "new" else "–", "–"]
            name = {None: "no contacts", "event": "crossing event, no contact"}.get(what, f"contact, law {what}")
            lines.append(f"| {method} | {name} | {' | '.join(cells)} |")
    lines += ["", "Target (issue 33): ≤ 1.05× (a contact, native scene, verlet)."]
    return lines


def ensemble_speedup(repeat: int, quick: bool, skipped: dict[str, str]) -> list[str]:
    """256 elliptic billiards (native ellipsoid) on 1 and 2 workers: the speed-up, and each member
    its single run's bit for bit."""
    (members, steps), dt = ((32, 2000) if quick else (256, 20_000)), 0.05
    model = varmech.scenes.elliptic_billiard(A=2.0, B=1.0).model
    rng = np.random.default_rng(33)
    q0 = rng.uniform(-0.5, 0.5, (members, 2))
    p0 = rng.normal(size=(members, 2))
    run = dict(dt=dt, steps=steps, save_every=100, method="verlet")
    lines = [
        f"{members} elliptic billiards (A = 2, B = 1, `Contact.ellipsoid([2, 1])`, native), q₀ uniform in [−0.5, 0.5]², "
        f"p₀ standard normal (seed 33), verlet, h = {dt:g}, {steps} steps, `save_every` = 100; `varmech.ensemble(..., "
        f"contacts=[table], workers=w)`. Every member of both is asserted equal, bit for bit (t, q, p and the impacts), "
        f"to its single `varmech.integrate` run. Best of {repeat}, interleaved.",
        "",
        "| law | impacts (all members) | 1 worker s | 2 workers s | speed-up |",
        "|---|---:|---:|---:|---:|",
    ]
    for law in LAWS:
        if law in skipped:
            lines.append(f"| {law} | – | skipped | skipped | – |")
            continue
        table = varmech.Contact.ellipsoid([2.0, 1.0], name="table", law=law)  # type: ignore[arg-type]
        out: dict[int, varmech.Ensemble] = {}

        def go(workers: int, table=table, out=out) -> tuple[float, int]:
            start = time.perf_counter()
            out[workers] = varmech.ensemble(model, q0, p0, contacts=[table], workers=workers, progress=False, **run)
            return time.perf_counter() - start, 0

        best = best_interleaved({w: lambda w=w: go(w) for w in (1, 2)}, repeat)
        impacts = 0
        for i in range(members):
            single = varmech.integrate(model, q0[i], p0[i], contacts=[table], **run)
            impacts += len(single.events[0])
            for workers, runs in out.items():
                got = runs[i]
                same = all(np.array_equal(getattr(got, a), getattr(single, a)) for a in ("t", "q", "p")) and all(
                    np.array_equal(getattr(got.events[0], a), getattr(single.events[0], a)) for a in ("t", "q", "p")
                )
                assert same, f"member {i} on {workers} workers differs from its single run ({law})"
        one, two = best[1][0], best[2][0]
        lines.append(f"| {law} | {impacts} | {one:.3f} | {two:.3f} | {one / two:.2f} |")
    lines += ["", "Target (issue 33): ≥ 1.8× on 2 workers."]
    return lines


# --------------------------------------------------------------------------- accuracy


def matched_cost(repeat: int, quick: bool, skipped: dict[str, str]) -> list[str]:
    """The billiard's invariant over 10³ impacts (10² with ``quick``) against wall time: the VCI
    and the naive scheme over a sweep of steps, and the naive scheme's error at the VCI's cost."""
    impacts = 100 if quick else 1000
    vci = [] if "variational" in skipped else [("variational", 0.2), ("variational", 0.05)]
    sweep = [*vci, *[("naive", h) for h in (0.2, 0.05, 0.0125, 0.003125)]]
    errors = {(law, h): float(billiard_errors(h, impacts, law).max()) for law, h in sweep}
    best = best_interleaved({(law, h): lambda law=law, h=h: (_seconds(billiard_errors, h, impacts, law), 0) for law, h in sweep}, repeat)
    lines = [
        f"Elliptic billiard (A = {A:g}, B = {B:g}, the wall from Python closures), max |L₁L₂ − L₁L₂(0)| / |L₁L₂(0)| over "
        f"{impacts} impacts; verlet; best of {repeat}, interleaved.",
        "",
        "| scheme | h | steps | seconds | max invariant error |",
        "|---|---:|---:|---:|---:|",
    ]
    for (law, h), (seconds, _) in best.items():
        name = 'VCI (law="variational")' if law == "variational" else "naive (reflect at the step's end)"
        lines.append(f"| {name} | {h:g} | {round(T_BILLIARD * impacts / h)} | {seconds:.3f} | {errors[(law, h)]:.2e} |")
    naive_runs = sorted((best[k][0], errors[k]) for k in best if k[0] == "naive")
    seconds, errs = np.log([s for s, _ in naive_runs]), np.log([e for _, e in naive_runs])
    lines.append("")
    for law, h in vci:
        cost = best[(law, h)][0]
        at = math.exp(float(np.interp(math.log(cost), seconds, errs)))
        lines.append(
            f"- At the VCI's cost with h = {h:g} ({cost:.2f} s, error {errors[(law, h)]:.1e}) the naive scheme's "
            f"error is {at:.1e} (log-interpolated in its sweep)."
        )
    if not vci:
        lines.append(f"- The VCI rows are skipped: {skipped['variational']}")
    return lines


def _seconds(run, *args, **kwargs) -> float:
    """The wall-clock seconds of ``run(*args, **kwargs)``."""
    start = time.perf_counter()
    run(*args, **kwargs)
    return time.perf_counter() - start


def ball_accuracy(quick: bool, skipped: dict[str, str]) -> list[str]:
    """The ball over 10³ bounces (10² with ``quick``) at h = 10⁻³: energy at the impacts and the
    last bounce's time."""
    t1, dt, bounces = math.sqrt(2 / G), 1e-3, (100 if quick else 1000)
    exact = t1 * (2 * bounces - 1)
    lines = [
        f"Ball dropped from h₀ = 1 (g = {G}), verlet, h = {dt:g}, {bounces} bounces: max |H − gh₀| / gh₀ at the impacts "
        "and the error of the last bounce's time.",
        "",
        "| scheme | max energy error | bounce-time error |",
        "|---|---:|---:|",
    ]
    steps = round((exact + t1) / dt)
    for law in LAWS:
        if law in skipped:
            lines.append(f"| {law} | skipped | skipped |")
            continue
        hits = varmech.integrate(ball(), [1.0], [0.0], dt=dt, steps=steps, save_every=10**9, contacts=[varmech.Contact.wall(0, law=law)]).events[0]  # type: ignore[arg-type]
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

    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 4.4), layout="constrained")
    left, right = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.25]})
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
    fig.savefig(out / "impacts_billiard.png", dpi=120)
    written.append(out / "impacts_billiard.png")
    return written


def machine() -> str:
    """The CPU, its cores and the load average (1, 5 and 15 minutes), for the results' header."""
    model = platform.processor() or platform.machine()
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.exists():
        names = [line.split(":", 1)[1].strip() for line in cpuinfo.read_text().splitlines() if line.startswith("model name")]
        model = names[0] if names else model
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return f"{model}, {os.cpu_count()} logical cores, {platform.system()} {platform.release()}; load average {load}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="small sizes, to check that the bench runs")
    parser.add_argument("--old", type=Path, default=OLD, help="a checkout of the old implementation (commit 88600cf), built")
    parser.add_argument("--markdown", type=Path)
    parser.add_argument("--only", help="run only the sections whose title contains this (printed; not with --markdown)")
    args = parser.parse_args()
    if args.only is not None and args.markdown is not None:
        parser.error("--only prints some sections; --markdown writes the whole file: give one of them")
    start = time.perf_counter()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=Path(__file__).parent).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain"], capture_output=True, text=True, cwd=Path(__file__).parent).stdout.strip()
    before = machine()
    skipped = {law: why for law in LAWS if (why := law_available(law)) is not None}
    old = OldCore(args.old) if (args.old / "python" / "varmech").is_dir() else None
    try:
        every = {
            "Cost per impact: old (Python loop around the core) and new (in the core's step loop)": lambda: per_impact(
                args.repeat, args.quick, old, skipped
            ),
            "A circular billiard to 10⁶ impacts": lambda: million(args.repeat, args.quick, skipped),
            "A contact never hit": lambda: idle_contact(args.repeat, args.quick, old, skipped),
            "An ensemble of billiards on 1 and 2 workers": lambda: ensemble_speedup(args.repeat, args.quick, skipped),
            "Accuracy at matched cost: the billiard's focal invariant": lambda: matched_cost(args.repeat, args.quick, skipped),
            "The ball: energy and bounce times": lambda: ball_accuracy(args.quick, skipped),
        }
        wanted = {title: section for title, section in every.items() if (args.only or "").lower() in title.lower()}
        if not wanted:
            parser.error(f"--only {args.only!r} names no section; they are: {', '.join(every)}")
        sections = {title: section() for title, section in wanted.items()}
    finally:
        if old is not None:
            old.close()
    notes = [f"- `{law}` skipped: this build refuses it ({why})" for law, why in skipped.items()]
    if old is None:
        notes.append(f"- the old implementation's columns are empty: no checkout at {args.old}")
    command = "PYTHONPATH=$PWD/python python benches/impacts.py " + " ".join(sys.argv[1:])
    head = [
        f"Command: `{command}`",
        f"Commit: {commit}{' (with uncommitted changes)' if dirty else ''}; old: commit 88600cf at {args.old}.",
        f"Machine: {before} before the run; {machine().split('; ')[-1]} after.",
        *(["", "**`--quick`: small sizes, a check that the bench runs; not the results.**"] if args.quick else []),
        *([""] + notes if notes else []),
    ]
    text = "\n".join(head) + "\n\n" + "\n\n".join(f"### {title}\n\n" + "\n".join(lines) for title, lines in sections.items())
    print(text)
    print(f"\n({time.perf_counter() - start:.0f} s)")
    if args.markdown:
        args.markdown.write_text(f"# Impacts: cost and accuracy\n\n{text}\n")


if __name__ == "__main__":
    main()
