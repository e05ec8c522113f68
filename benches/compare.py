"""Side by side, in one run, on the same problems: varmech (native and Python-closure models),
REBOUND (leapfrog, WHFast), scipy.integrate.solve_ivp (DOP853, RK45) and a plain-Python Verlet
loop with the same closure.

    python benches/compare.py [--quick] [--markdown FILE]

Needs the ``bench`` extra (scipy, rebound). Every timing is the best of several repeats of a run
with nothing saved but the final state; accuracy comes from a separate run that samples the
energy. Ratios, not absolute figures, are what carries over between machines.
"""

from __future__ import annotations

import os

# OpenBLAS's idle worker threads spin on a core of their own; nothing here uses BLAS, and on a
# two-core machine they would distort every timing.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import math
import time
import timeit
from dataclasses import dataclass
from functools import partial

import numpy as np
from _common import publish, quick_arguments, rebound_simulation

import varmech
from varmech import examples, scenes


@dataclass
class Row:
    problem: str
    method: str
    steps: int
    seconds: float
    energy_error: float
    final_error: float

    @property
    def steps_per_second(self) -> float:
        return self.steps / self.seconds


def best_time(run, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return best


def best_times_interleaved(runs: dict, repeat: int) -> dict:
    """Best time of each run, the runs alternating so that machine noise hits them alike."""
    best = {k: math.inf for k in runs}
    for _ in range(repeat):
        for k, run in runs.items():
            start = time.perf_counter()
            run()
            best[k] = min(best[k], time.perf_counter() - start)
    return best


def max_rel(values: np.ndarray) -> float:
    return float(np.max(np.abs(values - values[0])) / abs(values[0]))


def verlet_loop(gradient, q, p, inv_mass, h, steps):
    """Störmer–Verlet written directly in Python, calling the same closure once a step."""
    g = gradient(q)
    for _ in range(steps):
        p = p - 0.5 * h * g
        q = q + h * inv_mass * p
        g = gradient(q)
        p = p - 0.5 * h * g
    return q, p


# --------------------------------------------------------------------------- outer solar system


def solar_system(quick: bool, repeat: int) -> list[Row]:
    from scipy.integrate import solve_ivp

    scene = scenes.outer_solar_system()
    G, masses = scene.model._core.gravity
    m3 = np.repeat(masses, 3)
    ref = scene.reference
    v_ref = ref.p / m3
    t_end = ref.t / (10 if quick else 1)
    compare_ref = not quick
    h = 50.0
    steps = round(t_end / h)
    closure = examples.closure_of(scene)
    rows = []
    name = f"outer solar system, {t_end:g} days"

    def error(q, v):
        return float(np.sqrt(np.sum((q - ref.q) ** 2) + np.sum((v - v_ref) ** 2))) if compare_ref else math.nan

    def varmech_row(model, label, method, dt):
        n = round(t_end / dt)
        seconds = best_time(
            lambda: varmech.integrate(model, scene.q0, scene.p0, dt=dt, steps=n, method=method, save_every=n, max_energy_error=None), repeat
        )
        traj = varmech.integrate(model, scene.q0, scene.p0, dt=dt, steps=n, method=method, save_every=max(1, n // 500), max_energy_error=None)
        rows.append(Row(name, label, n, seconds, max_rel(traj.energy()), error(traj.q[-1], traj.v[-1])))

    varmech_row(scene.model, "varmech verlet (native)", "verlet", h)
    varmech_row(scene.model, "varmech kahan_li8 (native), h = 200", "kahan_li8", 200.0)
    varmech_row(closure, "varmech verlet (NumPy closure)", "verlet", h)

    def make_sim(integrator):
        sim = rebound_simulation(G, masses, scene.q0, scene.p0, integrator)
        sim.dt = h
        return sim

    # Head to head: the native Verlet and REBOUND's integrators over ten times the horizon,
    # interleaved, so that each timing is tens of milliseconds.
    long_steps = 10 * steps
    head_to_head = best_times_interleaved(
        {
            "varmech verlet (native)": lambda: varmech.integrate(scene, dt=h, steps=long_steps, save_every=long_steps),
            "leapfrog": lambda: make_sim("leapfrog").integrate(10 * t_end, exact_finish_time=0),
            "whfast": lambda: make_sim("whfast").integrate(10 * t_end, exact_finish_time=0),
        },
        repeat,
    )
    rows[0].seconds = head_to_head["varmech verlet (native)"] / 10
    for integrator in ("leapfrog", "whfast"):
        seconds = head_to_head[integrator] / 10
        sim = make_sim(integrator)
        energies = [sim.energy()]
        for t in np.linspace(0, t_end, 501)[1:]:
            sim.integrate(t, exact_finish_time=0)
            energies.append(sim.energy())
        q = np.array([[pt.x, pt.y, pt.z] for pt in sim.particles]).ravel()
        v = np.array([[pt.vx, pt.vy, pt.vz] for pt in sim.particles]).ravel()
        # REBOUND stops at the first step past t_end; with h dividing t_end that is t_end.
        rows.append(Row(name, f"REBOUND {integrator}", steps, seconds, max_rel(np.array(energies)), error(q, v)))

    def rhs(_t, y):
        q, v = y[: len(m3)], y[len(m3) :]
        return np.concatenate([v, -closure.gradient(q) / m3])

    y0 = np.concatenate([scene.q0, scene.p0 / m3])
    h_scene = scene.model
    for method, tol in (("DOP853", 1e-10), ("RK45", 1e-8)):
        seconds = best_time(lambda: solve_ivp(rhs, (0, t_end), y0, method=method, rtol=tol, atol=tol * 1e-3), 1)  # noqa: B023 (timed at once, in this iteration)
        sol = solve_ivp(rhs, (0, t_end), y0, method=method, rtol=tol, atol=tol * 1e-3, dense_output=False)
        q, v = sol.y[: len(m3)].T, sol.y[len(m3) :].T
        energies = np.array([float(h) for h in _energies(h_scene, q[:: max(1, len(q) // 500)], (v * m3)[:: max(1, len(q) // 500)])])
        rows.append(Row(name, f"solve_ivp {method} (rtol {tol:g})", sol.t.size - 1, seconds, max_rel(energies), error(q[-1], v[-1])))

    q0, p0 = scene.q0.copy(), scene.p0.copy()
    loop_steps = steps // 10
    seconds = best_time(lambda: verlet_loop(closure.gradient, q0, p0, 1 / m3, h, loop_steps), 1)
    rows.append(Row(f"{name} (first {loop_steps} steps)", "plain-Python Verlet loop (same closure)", loop_steps, seconds, math.nan, math.nan))
    return rows


def _energies(model, q, p, t=None):
    from varmech import _core

    t = np.zeros(len(q)) if t is None else np.ascontiguousarray(t, dtype=float)
    return _core.energy_terms(model._core, t, np.ascontiguousarray(q), np.ascontiguousarray(p))[0]


# ---------------------------------------------------------------------------------- Kepler


def kepler(quick: bool, repeat: int) -> tuple[list[Row], dict[str, float]]:
    from scipy.integrate import solve_ivp

    scene = scenes.kepler(0.6)
    closure = examples.kepler()
    periods = 20 if quick else 200
    t_end = periods * 2 * math.pi
    h = 2 * math.pi / 200
    steps = round(t_end / h)
    name = f"Kepler e = 0.6, {periods} periods"
    rows = []

    def error(q, p):
        return float(np.hypot(np.linalg.norm(q - scene.q0), np.linalg.norm(p - scene.p0)))

    for model, label in ((scene.model, "native"), (closure, "Python closure")):
        seconds = best_time(lambda: varmech.integrate(model, scene.q0, scene.p0, dt=h, steps=steps, save_every=steps), repeat)  # noqa: B023 (timed at once, in this iteration)
        traj = varmech.integrate(model, scene.q0, scene.p0, dt=h, steps=steps, save_every=max(1, steps // 1000))
        rows.append(Row(name, f"varmech verlet ({label})", steps, seconds, max_rel(traj.energy()), error(traj.q[-1], traj.p[-1])))

    seconds = best_time(lambda: verlet_loop(closure.gradient, scene.q0, scene.p0, 1.0, h, steps), repeat)
    q, p = verlet_loop(closure.gradient, scene.q0, scene.p0, 1.0, h, steps)
    rows.append(Row(name, "plain-Python Verlet loop (same closure)", steps, seconds, math.nan, error(q, p)))

    def rhs(_t, y):
        return np.concatenate([y[2:], -closure.gradient(y[:2])])

    y0 = np.concatenate([scene.q0, scene.p0])
    for method, tol in (("DOP853", 1e-10), ("RK45", 1e-8)):
        seconds = best_time(lambda: solve_ivp(rhs, (0, t_end), y0, method=method, rtol=tol, atol=tol), 1)  # noqa: B023 (timed at once, in this iteration)
        sol = solve_ivp(rhs, (0, t_end), y0, method=method, rtol=tol, atol=tol)
        qs, ps = sol.y[:2].T, sol.y[2:].T
        energies = 0.5 * np.sum(ps**2, 1) - 1 / np.hypot(qs[:, 0], qs[:, 1])
        rows.append(Row(name, f"solve_ivp {method} (rtol {tol:g})", sol.t.size - 1, seconds, max_rel(energies), error(qs[-1], ps[-1])))

    # The closure's own cost, called from Python as the plain loop calls it.
    calls = 200_000
    timer = timeit.Timer("gradient(q)", globals={"gradient": closure.gradient, "q": scene.q0.copy()})
    call_cost = min(timer.repeat(repeat, calls)) / calls
    per_step = {r.method: r.seconds / r.steps for r in rows}
    varmech_step = per_step["varmech verlet (Python closure)"]
    facts = {
        "closure call (s)": call_cost,
        "varmech closure step (s)": varmech_step,
        "overhead per step / closure call": (varmech_step - call_cost) / call_cost,
        "speed-up over plain-Python loop": per_step["plain-Python Verlet loop (same closure)"] / varmech_step,
    }
    return rows, facts


# ------------------------------------------------------------------------------- double pendulum


def coarsest_reaching(target: float, settings, error_of):
    """The coarsest of ``settings`` (ordered coarse to fine) whose error and the next finer one's
    are both at most ``target``: on this chaotic problem the error is not monotone in the step or
    the tolerance, and a lucky dip would flatter the method."""
    candidate = None
    for setting in settings:
        if error_of(setting) <= target:
            if candidate is not None:
                return candidate
            candidate = setting
        else:
            candidate = None
    raise RuntimeError(f"no setting reaches {target:.2e}")


def double_pendulum(quick: bool, repeat: int) -> tuple[list[Row], dict[str, float]]:
    """varmech's midpoint rule and Galerkin integrators (native and closure) against solve_ivp
    (DOP853, Radau) at matched accuracy: the midpoint run's final error is the target, every other
    method gets the coarsest setting of a sweep that reaches it, and the ratios of wall times,
    measured interleaved, are reported."""
    from scipy.integrate import solve_ivp

    scene = scenes.double_pendulum()
    closure = examples.double_pendulum()
    ref = scene.reference
    m1, m2, l1, l2, g = 1.0, 2.0, 2.0, 3.0, 9.80665
    v_ref = scene.model.velocity(ref.q, ref.p)
    name = "double pendulum, T = 10"

    def error(q, v):
        return float(np.sqrt(np.sum((q - ref.q) ** 2) + np.sum((v - v_ref) ** 2)))

    def rhs(_t, y):
        th, w = y[:2], y[2:]
        c, s = math.cos(th[0] - th[1]), math.sin(th[0] - th[1])
        m = np.array([[(m1 + m2) * l1 * l1, m2 * l1 * l2 * c], [m2 * l1 * l2 * c, m2 * l2 * l2]])
        k = m2 * l1 * l2 * s
        dl_dq = np.array([-k * w[0] * w[1] - (m1 + m2) * g * l1 * math.sin(th[0]), k * w[0] * w[1] - m2 * g * l2 * math.sin(th[1])])
        m_dot_w = np.array([-k * (w[0] - w[1]) * w[1], -k * (w[0] - w[1]) * w[0]])
        return np.concatenate([w, np.linalg.solve(m, dl_dq - m_dot_w)])

    y0 = np.concatenate([scene.q0, scene.model.velocity(scene.q0, scene.p0)])

    def varmech_run(model, method, steps, save_every):
        return varmech.integrate(model, scene.q0, scene.p0, dt=ref.t / steps, steps=steps, method=method, save_every=save_every)

    def varmech_error(method, steps):
        try:
            traj = varmech_run(scene.model, method, steps, steps)
        except (varmech.ConvergenceError, varmech.DivergenceError):
            return math.inf  # too coarse a step
        return error(traj.q[-1], traj.v[-1])

    def scipy_run(method, tol):
        return solve_ivp(rhs, (0, ref.t), y0, method=method, rtol=tol, atol=tol)

    def scipy_error(method, tol):
        sol = scipy_run(method, tol)
        return error(sol.y[:2, -1], sol.y[2:, -1])

    # Every sweep refines the error by about a quarter of a decade a setting: the step by 10^(1/4p)
    # for order p (100 to 10 000 steps), the tolerance by 10^(1/4) (1e-3 to 1e-12).
    steps = {"midpoint": 2000 if quick else 8000}
    target = varmech_error("midpoint", steps["midpoint"])
    for method, order in (("galerkin4", 4), ("galerkin6", 6)):
        grid = (round(100 * 10 ** (k / (4 * order))) for k in range(8 * order + 1))
        steps[method] = coarsest_reaching(target, grid, partial(varmech_error, method))
    tolerances = {
        method: coarsest_reaching(target, (10 ** (-3 - k / 4) for k in range(37)), partial(scipy_error, method))
        for method in ("DOP853", "Radau")
    }

    models = ((scene.model, "native"), (closure, "Lagrangian closure"))
    runs = {}
    for method, n in steps.items():
        for model, label in models:
            runs[method, label] = lambda model=model, method=method, n=n: varmech_run(model, method, n, n)
    for method, tol in tolerances.items():
        runs[method] = lambda method=method, tol=tol: scipy_run(method, tol)
    seconds = best_times_interleaved(runs, repeat)

    rows = []
    for method, n in steps.items():
        for model, label in models:
            traj = varmech_run(model, method, n, max(1, n // 500))
            row_label = f"varmech {method} ({label}), h = {ref.t / n:.3g}"
            rows.append(Row(name, row_label, n, seconds[method, label], max_rel(traj.energy()), error(traj.q[-1], traj.v[-1])))
    for method, tol in tolerances.items():
        sol = scipy_run(method, tol)
        th, w = sol.y[:2].T, sol.y[2:].T
        energies = _energies(scene.model, th, scene.model.momentum(th, w), sol.t)
        label = f"solve_ivp {method} (rtol {tol:.3g}), nfev {sol.nfev}"
        rows.append(Row(name, label, sol.t.size - 1, seconds[method], max_rel(energies), error(th[-1], w[-1])))
    ratios = {}
    for scipy_method in tolerances:
        for method in steps:
            for _, label in models:
                key = f"double pendulum: solve_ivp {scipy_method} / varmech {method} ({label}), time at matched accuracy"
                ratios[key] = seconds[scipy_method] / seconds[method, label]
    return rows, ratios


def table(rows: list[Row]) -> str:
    out = ["| problem | method | steps | steps/s | max rel. energy error | final error |", "|---|---|---:|---:|---:|---:|"]
    cell = lambda x: "–" if math.isnan(x) else f"{x:.2e}"  # noqa: E731 (not measured: –)
    for r in rows:
        out.append(
            f"| {r.problem} | {r.method} | {r.steps} | {r.steps_per_second:,.0f} | {cell(r.energy_error)} | {cell(r.final_error)} |"
        )
    return "\n".join(out)


def main() -> None:
    args = quick_arguments(__doc__, "a tenth of each horizon, fewer repeats", "also write the tables to this file")
    repeat = 2 if args.quick else 5

    sun = solar_system(args.quick, repeat)
    kep, facts = kepler(args.quick, repeat)
    dp, dp_ratios = double_pendulum(args.quick, repeat)
    by = {r.method: r for r in sun}
    ratios = {
        "varmech verlet (native) / REBOUND leapfrog, steps/s": by["varmech verlet (native)"].steps_per_second
        / by["REBOUND leapfrog"].steps_per_second,
        "varmech verlet (native) / REBOUND whfast, steps/s": by["varmech verlet (native)"].steps_per_second
        / by["REBOUND whfast"].steps_per_second,
        "varmech verlet (NumPy closure) / plain-Python loop, steps/s": by["varmech verlet (NumPy closure)"].steps_per_second
        / sun[-1].steps_per_second,
        "Kepler: varmech verlet (closure) / plain-Python loop, steps/s": facts["speed-up over plain-Python loop"],
        "Kepler: integrator overhead per step / closure call cost": facts["overhead per step / closure call"],
    }
    ratios.update(dp_ratios)
    text = [table(sun + kep + dp), "", "| ratio | value |", "|---|---:|"]
    text += [f"| {k} | {v:.2f} |" for k, v in ratios.items()]
    call, step = facts["closure call (s)"] * 1e9, facts["varmech closure step (s)"] * 1e9
    text += ["", f"Kepler closure call: {call:.0f} ns; varmech step with it: {step:.0f} ns."]
    publish("\n".join(text), args.markdown)


if __name__ == "__main__":
    main()
