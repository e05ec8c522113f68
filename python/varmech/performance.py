"""Work–precision and long-run energy growth, measured in one run against the baselines.

:func:`work_precision` sweeps the step of varmech's fixed-step methods, and the tolerance of
``scipy.integrate.solve_ivp`` (RK45, DOP853, Radau), and REBOUND's WHFast and IAS15 on N-body
scenes, and measures for each setting the wall time, the force evaluations, the error at the final
time and the largest energy error. :func:`energy_growth` follows the energy error over a long
horizon, sampled log-spaced in time, with the verdict of each method ("bounded" or "secular
drift"). Both return a :class:`~varmech.Table`; :mod:`varmech.charts.work_precision` plots them.

SciPy and REBOUND are optional: they are imported when a baseline needs them, and a baseline whose
package is missing is skipped with a note in ``table.meta["notes"]``. Long sweeps show a progress
bar (tqdm) on a terminal. Ctrl-C stops a sweep: the KeyboardInterrupt propagates, carrying the
rows measured so far as ``err.partial``.
"""

from __future__ import annotations

import math
import signal
import time
from dataclasses import dataclass
from typing import Any, Callable, Iterable, Sequence

import numpy as np

from . import _core
from ._progress import progress as _progress
from .conservation import EnergyReport, check_conservation
from .integrate import integrate
from .scenes import Reference, Scene
from .table import Table

#: solve_ivp's methods, and REBOUND's integrators this module drives.
SCIPY_METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")
REBOUND_METHODS = ("WHFast", "IAS15")

#: The default tolerance sweep: 1e-3 … 1e-12, a decade a setting.
DEFAULT_RTOLS = tuple(10.0**-k for k in range(3, 13))
#: IAS15's default precision sweep (its own default is 1e-9).
DEFAULT_EPSILONS = tuple(10.0**-k for k in range(2, 10))

WORK_PRECISION_COLUMNS = (
    "tool",
    "method",
    "parameter",
    "value",
    "steps",
    "evaluations",
    "seconds",
    "final_error",
    "max_energy_error",
)
ENERGY_GROWTH_COLUMNS = ("tool", "method", "t", "energy_error", "max_energy_error")

# Energy samples of the separate accuracy run of a fixed-step method (every step below this).
_ENERGY_SAMPLES = 20_000
# A setting's timing repeats stop once this much time has gone into them.
_REPEAT_BUDGET = 2.0


# ------------------------------------------------------------------------------------ helpers


def _tool_of(name: str) -> str:
    if name in SCIPY_METHODS:
        return "scipy"
    if name in REBOUND_METHODS:
        return "rebound"
    return "varmech"


def _gravity(scene: Scene) -> tuple[float, list[float]] | None:
    """(G, masses) of an N-body scene, None otherwise."""
    return getattr(scene.model._core, "gravity", None)


def _energy(scene: Scene, t: np.ndarray, q: np.ndarray, p: np.ndarray) -> np.ndarray:
    return _core.energy(
        scene.model._core,
        np.ascontiguousarray(t, dtype=float),
        np.ascontiguousarray(q, dtype=float),
        np.ascontiguousarray(p, dtype=float),
    )


def _relative(h: np.ndarray) -> np.ndarray:
    """|H − H₀|/|H₀| (absolute when H₀ = 0)."""
    scale = abs(h[0]) if h[0] != 0 else 1.0
    return np.abs(h - h[0]) / scale


def _conserves_energy(scene: Scene) -> bool:
    m = scene.model
    return not (m.time_dependent or m.forced)


def _final_error(reference: Reference | None, q: np.ndarray, p: np.ndarray) -> float:
    """‖(q, p) − (q_ref, p_ref)‖₂ over the reference's finite components (NaN marks an unknown
    component); NaN without a reference."""
    if reference is None:
        return math.nan
    d = np.concatenate([np.asarray(q, float) - reference.q, np.asarray(p, float) - reference.p])
    known = np.isfinite(np.concatenate([reference.q, reference.p]))
    if not known.any():
        return math.nan
    return float(np.sqrt(np.sum(d[known] ** 2)))


def _best_time(run: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    """The best wall time of ``repeat`` runs (fewer once ``_REPEAT_BUDGET`` seconds are spent),
    and the last run's result."""
    best, spent, result = math.inf, 0.0, None
    for _ in range(max(1, int(repeat))):
        start = time.perf_counter()
        result = run()
        elapsed = time.perf_counter() - start
        best, spent = min(best, elapsed), spent + elapsed
        if spent > _REPEAT_BUDGET:
            break
    return best, result


def _interruptible(table: Table, body: Callable[[], None]) -> Table:
    """Runs ``body``; a KeyboardInterrupt propagates with the rows so far as ``err.partial``."""
    try:
        body()
    except KeyboardInterrupt as err:
        err.partial = table  # type: ignore[attr-defined]
        raise
    return table


def _horizon(scene: Scene, t_end: float | None, reference: Reference | None) -> tuple[float, Reference | None, str | None]:
    """The horizon of a work–precision sweep and the reference at it (None when there is none)."""
    ref = reference if reference is not None else scene.reference
    if t_end is None:
        t_end = ref.t if ref is not None else scene.t_end
    t_end = float(t_end)
    if not (math.isfinite(t_end) and t_end > 0):
        raise ValueError(f"t_end: must be positive and finite, got {t_end}")
    note = None
    if ref is not None and not math.isclose(ref.t, t_end, rel_tol=1e-12):
        note = f"no reference at t = {t_end:g} (the reference is at t = {ref.t:g}): final_error is NaN"
        ref = None
    elif ref is None:
        note = "the scene has no reference solution: final_error is NaN"
    return t_end, ref, note


# --------------------------------------------------------------------------- scipy baseline


class _Rhs:
    """The first-order system q̇ = q̇(q, p), ṗ = ∂L/∂q(q, q̇, t) of a model for solve_ivp: y is
    (2n,), or (2n, k) columns when ``vectorized=True`` (Radau's and BDF's finite-difference
    Jacobians), and every column counts as one force evaluation. For a separable model,
    q̇ = M⁻¹p with M⁻¹ computed once, and ∂L/∂q = −∇V(q) does not depend on q̇."""

    def __init__(self, model: Any):
        self.core = model._core
        self.n = n = model.dim
        self.count = 0
        self.inverse_mass = None
        self._diagonal = None
        self._t = np.zeros(1)
        if model.separable and not model.time_dependent:
            eye = np.eye(n)
            # Row i is q̇ for p = eᵢ: M⁻¹ is symmetric, so this is M⁻¹.
            self.inverse_mass = _core.derivative(self.core, "velocity", np.zeros(n), np.zeros((n, n)), eye)
            d = np.diag(self.inverse_mass)
            if np.array_equal(self.inverse_mass, np.diag(d)):
                self._diagonal = d.copy()

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        n = self.n
        if y.ndim == 2:  # columns (2n, k)
            q = np.ascontiguousarray(y[:n].T)
            p = np.ascontiguousarray(y[n:].T)
            tt = np.full(len(q), float(t))
            if self.inverse_mass is not None:
                v = p @ self.inverse_mass
                f = _core.derivative(self.core, "dl_dq", tt, q, p)
            else:
                v = _core.derivative(self.core, "velocity", tt, q, p)
                f = _core.derivative(self.core, "dl_dq", tt, q, v)
            self.count += len(q)
            return np.concatenate([v.T, f.T])
        # One state (2n,): the path of every explicit step, kept lean.
        y = np.ascontiguousarray(y)
        q, p = y[:n].reshape(1, n), y[n:].reshape(1, n)
        self._t[0] = t
        out = np.empty(2 * n)
        if self.inverse_mass is not None:
            out[:n] = p[0] * self._diagonal if self._diagonal is not None else p[0] @ self.inverse_mass
            out[n:] = _core.derivative(self.core, "dl_dq", self._t, q, p)[0]
        else:
            v = _core.derivative(self.core, "velocity", self._t, q, p)
            out[:n] = v[0]
            out[n:] = _core.derivative(self.core, "dl_dq", self._t, q, v)[0]
        self.count += 1
        return out


def _scipy_unsupported(scene: Scene) -> str | None:
    m = scene.model
    if m.forced:
        return "the scene is forced (solve_ivp baselines would need its forces)"
    if m.constraints:
        return "the scene is constrained (a DAE; solve_ivp baselines do not apply)"
    return None


def _import_scipy() -> Any | None:
    try:
        from scipy.integrate import solve_ivp
    except ImportError:
        return None
    return solve_ivp


def _default_atol(scene: Scene, rtol: float) -> np.ndarray:
    """rtol × 10⁻³ × the largest initial |q| (positions) and |p| (momenta): absolute tolerances
    well under the relative ones at the scene's scale."""
    n = scene.model.dim
    scales = [float(np.max(np.abs(x))) or 1.0 for x in (scene.q0, scene.p0)]
    return np.repeat(np.array(scales) * rtol * 1e-3, n)


def _solve(solve_ivp, scene: Scene, method: str, t_end: float, rtol: float, atol, t_eval=None):
    rhs = _Rhs(scene.model)
    y0 = np.concatenate([scene.q0, scene.p0])
    a = _default_atol(scene, rtol) if atol is None else atol
    # Implicit methods get columns at once for their finite-difference Jacobians.
    vectorized = method in ("Radau", "BDF")
    sol = solve_ivp(rhs, (0.0, t_end), y0, method=method, rtol=rtol, atol=a, vectorized=vectorized, t_eval=t_eval)
    if sol.status != 0:
        raise RuntimeError(f"solve_ivp {method} (rtol {rtol:g}): {sol.message}")
    return sol, rhs.count


# ------------------------------------------------------------------------- REBOUND baseline


def _import_rebound() -> Any | None:
    try:
        import rebound
    except ImportError:
        return None
    return rebound


def _rebound_sim(rebound, scene: Scene, integrator: str, *, dt: float, epsilon: float | None = None):
    G, masses = _gravity(scene)  # type: ignore[misc]
    sim = rebound.Simulation()
    sim.G = G
    for m, x, p in zip(masses, scene.q0.reshape(-1, 3), scene.p0.reshape(-1, 3)):
        v = p / m
        sim.add(m=m, x=x[0], y=x[1], z=x[2], vx=v[0], vy=v[1], vz=v[2])
    sim.integrator = integrator.lower()
    sim.dt = dt
    if epsilon is not None:
        cfg = getattr(sim, "ri_ias15", None) or sim.integrator  # REBOUND 4 / 5
        cfg.epsilon = epsilon
    return sim


def _rebound_state(sim, masses: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    x = np.array([[pt.x, pt.y, pt.z] for pt in sim.particles])
    v = np.array([[pt.vx, pt.vy, pt.vz] for pt in sim.particles])
    return x.ravel(), (np.asarray(masses)[:, None] * v).ravel()


def _restore_sigint() -> None:
    """Give SIGINT back to Python: REBOUND's C library installs its own handler while it
    integrates and leaves it, after which Ctrl-C would no longer reach varmech's loops."""
    signal.signal(signal.SIGINT, signal.getsignal(signal.SIGINT))


def _rebound_advance(sim, integrator: str, steps: int | None, t: float) -> None:
    try:
        if integrator == "WHFast":
            sim.steps(int(steps))  # type: ignore[arg-type]
        else:
            sim.integrate(t, exact_finish_time=1)
    finally:
        _restore_sigint()


def _rebound_evaluations(rebound, scene: Scene, integrator: str, t_end: float, dt: float, steps: int | None, epsilon: float | None) -> int:
    """Force evaluations of a REBOUND run, counted by a no-op additional force (in a separate,
    untimed run)."""
    sim = _rebound_sim(rebound, scene, integrator, dt=dt, epsilon=epsilon)
    count = [0]

    def tally(_sim):  # noqa: ANN001
        count[0] += 1

    sim.additional_forces = tally
    sim.force_is_velocity_dependent = 0
    _rebound_advance(sim, integrator, steps, t_end)
    return count[0]


# --------------------------------------------------------------------------------- sweeps


def _default_start(scene: Scene, t_end: float) -> int:
    """A quarter of the scene's quick-look steps over the horizon, rounded down to a power of 2."""
    base = max(t_end / scene.dt / 4, 16.0)
    return 2 ** int(math.floor(math.log2(base)))


def _done_refining(errors: list[float]) -> bool:
    """A default sweep stops at round-off: the error below 1e-14, or no longer falling (less than
    1.5× over a doubling) once under 1e-6."""
    if not errors or not math.isfinite(errors[-1]):
        return False
    if errors[-1] < 1e-14:
        return True
    return len(errors) >= 2 and errors[-2] < 1e-6 and errors[-1] > errors[-2] / 1.5


def work_precision(
    scene: Scene,
    methods: Iterable[str],
    *,
    steps: Sequence[int] | dict[str, Sequence[int]] | None = None,
    baselines: Iterable[str] = ("RK45", "DOP853", "Radau"),
    rtols: Sequence[float] = DEFAULT_RTOLS,
    atol: float | Sequence[float] | None = None,
    rebound: Iterable[str] = REBOUND_METHODS,
    epsilons: Sequence[float] = DEFAULT_EPSILONS,
    t_end: float | None = None,
    reference: Reference | None = None,
    repeat: int = 3,
    sweep_length: int = 11,
    max_seconds: float | None = 5.0,
    progress: bool | None = None,
) -> Table:
    """Measure cost against accuracy over a sweep of steps (varmech) and tolerances (baselines).

    Each row is one run to ``t_end`` (by default the time of the scene's reference solution):
    ``tool`` ("varmech", "scipy", "rebound"), ``method``, the swept ``parameter`` ("steps",
    "rtol" or "epsilon") and its ``value``, the ``steps`` taken, the force (right-hand side)
    ``evaluations``, the wall time ``seconds``, ``final_error`` = ‖(q, p) − (q_ref, p_ref)‖₂ at
    ``t_end`` over the reference's known (finite) components, and ``max_energy_error`` =
    max |H − H₀|/|H₀| over the run (NaN when L depends on t or forces act).

    Parameters
    ----------
    scene:
        A :class:`~varmech.scenes.Scene`.
    methods:
        varmech method names (``"verlet"``, ``"kahan_li8"``, ``"rk4"``, ...).
    steps:
        The step counts over the horizon: one list for every method, or a dict by method.
        Default: powers of 2 from a quarter of the scene's own step (``scene.dt``), up to
        ``sweep_length`` settings, stopping early at round-off (the error no longer falls).
    baselines:
        ``solve_ivp`` methods (``"RK45"``, ``"DOP853"``, ``"Radau"``, ...), run on the first-order
        system q̇ = q̇(q, p), ṗ = ∂L/∂q(q, q̇) (vectorized, so Radau's finite-difference
        Jacobian is one call) over ``rtols``, with ``atol`` (default rtol·10⁻³ times the largest
        initial |q| and |p|). ``evaluations`` counts every right-hand side column, Jacobian
        columns included. Skipped, with a note in ``meta["notes"]``, without SciPy, and for
        forced or constrained scenes.
    rebound, epsilons:
        On N-body scenes, REBOUND's ``"WHFast"`` over the step sweep of ``verlet`` (or
        ``steps["WHFast"]``) and ``"IAS15"`` over the precisions ``epsilons``; skipped with a
        note without REBOUND. Their force evaluations are counted in a separate untimed run.
    t_end, reference:
        The horizon, and the solution there (default: the scene's reference, and its time).
        Without a reference at ``t_end``, ``final_error`` is NaN.
    repeat:
        Wall time is the best of ``repeat`` runs that save only the final state (fewer once two
        seconds went into a setting); the energy error comes from a separate run saving up to
        20 000 states (solve_ivp's and REBOUND's from their accepted steps or samples).
    max_seconds:
        A method's sweep stops after a run slower than this (noted in ``meta["notes"]``); None
        never stops it.
    progress:
        Show a progress bar: None on a terminal only, True or False to force it.

    Ctrl-C raises KeyboardInterrupt with the rows measured so far as ``err.partial``.
    """
    methods = list(methods)
    baselines = list(baselines)
    T, ref, ref_note = _horizon(scene, t_end, reference)
    table = Table(
        WORK_PRECISION_COLUMNS,
        title=f"Work–precision: {scene.name}, t = 0 … {T:g}",
        meta={"scene": scene.name, "t_end": T, "reference": ref.source if ref is not None else None, "notes": []},
    )
    notes: list[str] = table.meta["notes"]
    if ref_note:
        notes.append(ref_note)
    conserved = _conserves_energy(scene)
    bad = [b for b in baselines if b not in SCIPY_METHODS]
    if bad:
        raise ValueError(f"baselines: unknown solve_ivp method(s) {bad}; choose from {SCIPY_METHODS}")
    rebound_methods = list(rebound)
    bad = [b for b in rebound_methods if b not in REBOUND_METHODS]
    if bad:
        raise ValueError(f"rebound: unknown REBOUND integrator(s) {bad}; choose from {REBOUND_METHODS}")

    def sweep_of(method: str) -> tuple[list[int], bool]:
        if isinstance(steps, dict) and method in steps:
            return [int(n) for n in steps[method]], False
        if steps is not None and not isinstance(steps, dict):
            return [int(n) for n in steps], False
        start = _default_start(scene, T)
        return [start * 2**k for k in range(sweep_length)], True

    # The plan: every (tool, method, settings) to run, for the progress bar's total.
    solve_ivp = None
    if baselines:
        why = _scipy_unsupported(scene)
        solve_ivp = _import_scipy() if why is None else None
        if why is not None:
            notes.append(f"solve_ivp baselines skipped: {why}")
            baselines = []
        elif solve_ivp is None:
            notes.append("solve_ivp baselines skipped: SciPy is not installed (pip install scipy)")
            baselines = []
    rb = None
    if rebound_methods and _gravity(scene) is not None:
        rb = _import_rebound()
        if rb is None:
            notes.append("REBOUND baselines skipped: REBOUND is not installed (pip install rebound)")
            rebound_methods = []
    else:
        rebound_methods = []

    plan: list[tuple[str, str, list[float], bool]] = []
    for m in methods:
        plan.append(("varmech", m, *sweep_of(m)))  # type: ignore[arg-type]
    for b in baselines:
        plan.append(("scipy", b, [float(r) for r in rtols], False))
    for r in rebound_methods:
        if r == "WHFast":
            plan.append(("rebound", r, *sweep_of("WHFast" if isinstance(steps, dict) and "WHFast" in steps else "verlet")))  # type: ignore[arg-type]
        else:
            plan.append(("rebound", r, [float(e) for e in epsilons], False))
    total = sum(len(values) for _, _, values, _ in plan)
    bar = _progress(range(total), total=total, desc=f"work–precision {scene.name}", enabled=progress)

    def tick(label: str) -> None:
        next(bar, None)

    def run_varmech(method: str, n: int) -> tuple:
        dt = T / n
        seconds, traj = _best_time(lambda: integrate(scene, dt=dt, steps=n, method=method, save_every=n), repeat)
        final = _final_error(ref, traj.q[-1], traj.p[-1])
        energy = math.nan
        if conserved:
            sampled = integrate(scene, dt=dt, steps=n, method=method, save_every=max(1, n // _ENERGY_SAMPLES))
            energy = float(np.max(_relative(sampled.energy())))
        return ("varmech", method, "steps", n, n, traj.nfev, seconds, final, energy)

    def run_scipy(method: str, rtol: float) -> tuple:
        seconds, (sol, nfev) = _best_time(lambda: _solve(solve_ivp, scene, method, T, rtol, atol), repeat)
        n = scene.model.dim
        q, p = sol.y[:n].T, sol.y[n:].T
        energy = float(np.max(_relative(_energy(scene, sol.t, q, p)))) if conserved else math.nan
        return ("scipy", method, "rtol", rtol, sol.t.size - 1, nfev, seconds, _final_error(ref, q[-1], p[-1]), energy)

    def run_rebound(method: str, value: float) -> tuple:
        _, masses = _gravity(scene)  # type: ignore[misc]
        if method == "WHFast":
            n, dt, eps, parameter = int(value), T / int(value), None, "steps"
        else:
            n, dt, eps, parameter = None, scene.dt, float(value), "epsilon"

        def timed():
            sim = _rebound_sim(rb, scene, method, dt=dt, epsilon=eps)
            start = time.perf_counter()
            _rebound_advance(sim, method, n, T)
            return time.perf_counter() - start, sim

        # Building the simulation is not the integrator's cost: time the advance only.
        best, sim = math.inf, None
        spent = 0.0
        for _ in range(max(1, int(repeat))):
            s, sim = timed()
            best, spent = min(best, s), spent + s
            if spent > _REPEAT_BUDGET:
                break
        q, p = _rebound_state(sim, masses)
        taken = int(sim.steps_done)
        evaluations = _rebound_evaluations(rb, scene, method, T, dt, n, eps)
        # Energy: sample the same run ~1000 times (WHFast by whole steps; IAS15 without forcing
        # its step onto the sample times).
        sim2 = _rebound_sim(rb, scene, method, dt=dt, epsilon=eps)
        qs, ps, ts = [scene.q0], [scene.p0], [0.0]
        try:
            if method == "WHFast":
                chunk = max(1, n // 1000)  # type: ignore[operator]
                done = 0
                while done < n:  # type: ignore[operator]
                    k = min(chunk, n - done)  # type: ignore[operator]
                    sim2.steps(k)
                    done += k
                    a, b = _rebound_state(sim2, masses)
                    qs.append(a), ps.append(b), ts.append(sim2.t)
            else:
                for t in np.linspace(0, T, 1001)[1:]:
                    sim2.integrate(t, exact_finish_time=0)
                    a, b = _rebound_state(sim2, masses)
                    qs.append(a), ps.append(b), ts.append(sim2.t)
        finally:
            _restore_sigint()
        energy = float(np.max(_relative(_energy(scene, np.array(ts), np.array(qs), np.array(ps)))))
        return ("rebound", method, parameter, value, taken, evaluations, best, _final_error(ref, q, p), energy)

    runners = {"varmech": run_varmech, "scipy": run_scipy, "rebound": run_rebound}

    def body() -> None:
        for tool, method, values, adaptive in plan:
            errors: list[float] = []
            for k, value in enumerate(values):
                try:
                    row = runners[tool](method, value)
                except (_core.DivergenceError, _core.ConvergenceError, RuntimeError) as err:
                    notes.append(f"{tool} {method} at {value:g}: failed ({type(err).__name__}: {err})")
                    tick(method)
                    continue
                table.append(*row)
                tick(method)
                errors.append(row[7] if math.isfinite(row[7]) else row[8])
                if max_seconds is not None and row[6] > max_seconds and k < len(values) - 1:
                    notes.append(f"{tool} {method}: stopped after {value:g} (a run took {row[6]:.1f} s > max_seconds = {max_seconds:g})")
                    for _ in values[k + 1 :]:
                        tick(method)
                    break
                if adaptive and _done_refining(errors) and k < len(values) - 1:
                    for _ in values[k + 1 :]:
                        tick(method)
                    break

    return _interruptible(table, body)


# --------------------------------------------------------------------------- energy growth


def _log_bins(t: np.ndarray, err: np.ndarray, samples: int, t_min: float, t_max: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """In each of ``samples`` log-spaced bins of (t_min, t_max], the sample with the largest
    error, and the largest error up to it over all samples: (t, error, running maximum), in
    order of t."""
    keep = (t > 0) & np.isfinite(err)
    t, err = t[keep], err[keep]
    order = np.argsort(t, kind="stable")
    t, err = t[order], err[order]
    if t.size == 0:
        return t, err, err
    running = np.maximum.accumulate(err)
    edges = np.geomspace(t_min, t_max * (1 + 1e-12), samples + 1)
    b = np.clip(np.searchsorted(edges, t, side="left") - 1, 0, samples - 1)
    by_bin = np.lexsort((err, b))  # by bin, then by error: the last of each bin is its largest
    last = np.r_[b[by_bin][1:] != b[by_bin][:-1], True]
    pick = np.sort(by_bin[last])
    return t[pick], err[pick], running[pick]


def _prime_at_least(k: int) -> int:
    while any(k % d == 0 for d in range(2, math.isqrt(k) + 1)):
        k += 1
    return k


def _varmech_series(scene: Scene, method: str, dt: float, n: int, uniform: int, per_level: int):
    """Energy errors of one run at log-spaced times: the whole run saved at ``uniform`` evenly
    spaced states (its conservation report gives the verdict), then the first tenth, hundredth, …
    of it again with ``per_level`` states each (the same steps, so the same trajectory), until
    every step is saved. About 1.11× the cost of the run."""
    traj = integrate(scene, dt=dt, steps=n, method=method, save_every=max(1, n // uniform))
    report = check_conservation(traj)
    ts, es = [traj.t], [_relative(traj.energy())]
    m = n
    while m > per_level and m > 1:
        m //= 10
        if m < 1:
            break
        part = integrate(scene, dt=dt, steps=m, method=method, save_every=max(1, m // per_level))
        ts.append(part.t)
        es.append(_relative(part.energy()))
    return np.concatenate(ts), np.concatenate(es), report.energy


def energy_growth(
    scene: Scene,
    methods: Iterable[str],
    *,
    t_end: float | None = None,
    dt: float | None = None,
    samples: int = 2000,
    baselines: Iterable[str] = ("DOP853",),
    rtol: float = 1e-10,
    atol: float | Sequence[float] | None = None,
    baseline_t_end: float | None = None,
    progress: bool | None = None,
) -> Table:
    """The relative energy error |H(t) − H₀|/|H₀| over a long run, log-spaced in t, with a
    verdict for each method.

    Rows are (tool, method, t, energy_error, max_energy_error): in each of ``samples``
    log-spaced bins of t, the sample with the largest error |ΔH/H₀|, and the largest error of
    all samples up to t (a monotone envelope; the samples are the evenly spaced states below
    plus denser ones early in the run, so it can miss a peak between late samples). The verdict
    of each method ("bounded" or "secular drift", see :class:`~varmech.EnergyReport`) comes from
    the same run sampled evenly in time: varmech runs from :func:`~varmech.check_conservation`,
    baselines from the same statistics of their series. ``table.meta["verdicts"]`` maps each
    method to a dict: tool, verdict, drift_rate (of the relative error per unit time) and its
    stderr, max_error, max_error_first_tenth, max_error_last_tenth, t_end, and dt or rtol.

    Parameters
    ----------
    scene:
        A :class:`~varmech.scenes.Scene` whose energy is conserved.
    methods:
        varmech method names.
    t_end, dt:
        The horizon (default 50 × ``scene.t_end``: 10⁴ periods for :func:`~varmech.scenes.kepler`)
        and the step (default ``scene.dt``); the horizon is rounded to whole steps.
    samples:
        Log-spaced bins of t per method (and the number of evenly spaced states for the
        verdicts, at least 1000).
    baselines, rtol, atol:
        ``solve_ivp`` methods (default DOP853) at tolerance ``rtol`` (atol as in
        :func:`work_precision`), sampled by their dense output; and, on N-body scenes,
        ``"WHFast"`` (step ``dt``) and ``"IAS15"`` (its default precision). Skipped with a note
        in ``meta["notes"]`` when SciPy or REBOUND is missing.
    baseline_t_end:
        The baselines' horizon (default ``t_end``/10: a Python-driven adaptive solver is slow
        over 10⁴ periods; ``meta["baseline_t_end"]`` records it).
    progress:
        Show a progress bar: None on a terminal only, True or False to force it.

    Ctrl-C raises KeyboardInterrupt with the rows measured so far as ``err.partial``.
    """
    if not _conserves_energy(scene):
        raise ValueError(f"scene: the energy of {scene.name!r} is not conserved (L depends on t, or forces act)")
    methods = list(methods)
    baselines = list(baselines)
    bad = [b for b in baselines if b not in SCIPY_METHODS + REBOUND_METHODS]
    if bad:
        raise ValueError(f"baselines: unknown method(s) {bad}; choose from {SCIPY_METHODS + REBOUND_METHODS}")
    h = float(scene.dt if dt is None else dt)
    if not (math.isfinite(h) and h > 0):
        raise ValueError(f"dt: must be positive and finite, got {h}")
    T = 50 * scene.t_end if t_end is None else float(t_end)
    n = max(1, round(T / h))
    T = n * h
    Tb = T / 10 if baseline_t_end is None else float(baseline_t_end)
    samples = int(samples)
    if samples < 10:
        raise ValueError(f"samples: must be at least 10, got {samples}")
    # A prime count of evenly spaced states, so that their spacing is unlikely to be a whole
    # number of periods (which would sample every orbit at the same phase).
    uniform = _prime_at_least(max(samples, 1000))
    per_level = max(50, samples // max(1, math.ceil(math.log10(max(n, 10)))))
    table = Table(
        ENERGY_GROWTH_COLUMNS,
        title=f"Energy error against time: {scene.name}, dt = {h:g}, t = 0 … {T:g}",
        meta={
            "scene": scene.name,
            "dt": h,
            "t_end": T,
            "baseline_t_end": Tb,
            "rtol": rtol,
            "sampling": f"max |ΔH/H0| in each of {samples} log-spaced bins of t, and its running maximum; verdicts from {uniform} evenly spaced states",
            "verdicts": {},
            "notes": [],
        },
    )
    notes: list[str] = table.meta["notes"]
    verdicts: dict[str, dict[str, Any]] = table.meta["verdicts"]

    scipy_names = [b for b in baselines if b in SCIPY_METHODS]
    rebound_names = [b for b in baselines if b in REBOUND_METHODS]
    solve_ivp = rb = None
    if scipy_names:
        why = _scipy_unsupported(scene)
        solve_ivp = _import_scipy() if why is None else None
        if why is not None:
            notes.append(f"solve_ivp baselines skipped: {why}")
            scipy_names = []
        elif solve_ivp is None:
            notes.append("solve_ivp baselines skipped: SciPy is not installed (pip install scipy)")
            scipy_names = []
        elif Tb != T:
            notes.append(f"solve_ivp baselines run to t = {Tb:g} (the varmech methods to {T:g})")
    if rebound_names:
        if _gravity(scene) is None:
            notes.append(f"REBOUND baselines {rebound_names} skipped: {scene.name} is not an N-body scene")
            rebound_names = []
        else:
            rb = _import_rebound()
            if rb is None:
                notes.append("REBOUND baselines skipped: REBOUND is not installed (pip install rebound)")
                rebound_names = []

    def record(tool: str, method: str, t: np.ndarray, err: np.ndarray, report: EnergyReport, horizon: float, **setting: float) -> None:
        tb, eb, mb = _log_bins(t, err, samples, min(h, horizon / 1e6), horizon)
        for ti, ei, mi in zip(tb, eb, mb):
            table.append(tool, method, float(ti), float(ei), float(mi))
        verdicts[method] = {
            "tool": tool,
            "verdict": report.verdict,
            "drift_rate": report.drift_rate,
            "drift_rate_stderr": report.drift_rate_stderr,
            "max_error": report.max_error,
            "max_error_first_tenth": report.max_error_first_tenth,
            "max_error_last_tenth": report.max_error_last_tenth,
            "t_end": horizon,
            **setting,
        }

    def run_scipy(method: str) -> None:
        even = np.linspace(0.0, Tb, uniform + 1)
        logs = np.geomspace(min(h, Tb / 1e6), Tb, samples * 2)
        t_eval = np.unique(np.concatenate([even, logs]))
        t_eval = t_eval[t_eval <= Tb]
        sol, _ = _solve(solve_ivp, scene, method, Tb, rtol, atol, t_eval=t_eval)
        k = scene.model.dim
        energies = _energy(scene, sol.t, sol.y[:k].T, sol.y[k:].T)
        on_grid = np.isin(sol.t, even)
        report = EnergyReport(**_core.energy_statistics(np.ascontiguousarray(sol.t[on_grid]), np.ascontiguousarray(energies[on_grid])))
        record("scipy", method, sol.t, _relative(energies), report, Tb, rtol=rtol)

    def run_rebound(method: str) -> None:
        _, masses = _gravity(scene)  # type: ignore[misc]
        sim = _rebound_sim(rb, scene, method, dt=h, epsilon=None)
        # Every saved time is a whole number of steps: evenly spaced, and log-spaced below.
        marks = np.unique(np.concatenate([np.linspace(0, n, uniform + 1).round(), np.geomspace(1, n, samples * 2).round()])).astype(np.int64)
        ts, qs, ps, done = [], [], [], 0
        try:
            for k in marks:
                if method == "WHFast":
                    if k > done:
                        sim.steps(int(k - done))
                        done = int(k)
                else:
                    sim.integrate(k * h, exact_finish_time=1)
                a, b = _rebound_state(sim, masses)
                ts.append(k * h), qs.append(a), ps.append(b)
        finally:
            _restore_sigint()
        t = np.array(ts)
        energies = _energy(scene, t, np.array(qs), np.array(ps))
        on_grid = np.isin(marks, np.linspace(0, n, uniform + 1).round().astype(np.int64))
        report = EnergyReport(**_core.energy_statistics(t[on_grid], energies[on_grid]))
        record("rebound", method, t, _relative(energies), report, T, dt=h)

    plan = [("varmech", m) for m in methods] + [("scipy", b) for b in scipy_names] + [("rebound", b) for b in rebound_names]

    def body() -> None:
        for tool, method in _progress(plan, total=len(plan), desc=f"energy growth {scene.name}", enabled=progress):
            if tool == "varmech":
                t, err, report = _varmech_series(scene, method, h, n, uniform, per_level)
                record("varmech", method, t, err, report, T, dt=h)
            elif tool == "scipy":
                run_scipy(method)
            else:
                run_rebound(method)

    return _interruptible(table, body)


def verdicts(table: Table) -> Table:
    """The verdicts of an :func:`energy_growth` table as a small Table (tool, method, verdict,
    drift_rate, drift_rate_stderr, max_error, t_end)."""
    out = Table(("tool", "method", "verdict", "drift_rate", "drift_rate_stderr", "max_error", "t_end"), title=f"Energy verdicts: {table.meta.get('scene', '')}")
    for method, v in table.meta.get("verdicts", {}).items():
        out.append(v["tool"], method, v["verdict"], v["drift_rate"], v["drift_rate_stderr"], v["max_error"], v["t_end"])
    return out
