"""Work–precision: cost against accuracy, measured in one run against the baselines.

:func:`work_precision` sweeps the step of varmech's fixed-step methods, and the tolerance of
``scipy.integrate.solve_ivp`` (RK45, DOP853, Radau), and REBOUND's integrators on N-body
scenes and its leapfrog on Kepler (:mod:`.baselines`), and measures for each setting the wall time, the force evaluations,
the error at the final time and the largest energy error. It returns a :class:`~varmech.Table`;
:func:`varmech.charts.work_precision.work_precision_chart` plots it.

SciPy and REBOUND are optional: they are imported when a baseline needs them, and a baseline whose
package is missing is skipped with a note in ``table.meta["notes"]``. Long sweeps show a progress
bar (tqdm) on a terminal. Ctrl-C stops a sweep: the KeyboardInterrupt propagates, carrying the
rows measured so far as ``err.partial``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from .. import _core
from .._progress import progress as _progress
from .._util import positive
from ..integrate import integrate
from ..methods import method_info
from ..model import Model
from ..scenes import Reference, Scene, as_scene
from ..table import Table
from . import baselines as _baselines
from ._energy import energy_of, relative_error
from ._interrupt import interruptible
from .reference import reference_solution

__all__ = [
    "DEFAULT_EPSILONS",
    "DEFAULT_RTOLS",
    "EVALUATION_UNITS",
    "WORK_PRECISION_COLUMNS",
    "work_precision",
]

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

# Energy samples of the separate accuracy run of a fixed-step method (every step below this).
_ENERGY_SAMPLES = 20_000
# A setting's timing repeats stop once this much time has gone into them.
_REPEAT_BUDGET = 2.0

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


def _best_time(run: Callable[[Any], Any], repeat: int, prepare: Callable[[], Any] = lambda: None) -> tuple[float, Any]:
    """The best wall time of ``repeat`` runs ``run(prepare())`` (fewer once ``_REPEAT_BUDGET``
    seconds are spent), and the last run's result; ``prepare`` is not timed."""
    best, spent, result = math.inf, 0.0, None
    for _ in range(max(1, int(repeat))):
        arg = prepare()
        start = time.perf_counter()
        result = run(arg)
        elapsed = time.perf_counter() - start
        best, spent = min(best, elapsed), spent + elapsed
        if spent > _REPEAT_BUDGET:
            break
    return best, result


def _horizon(
    scene: Scene, t_end: float | None, reference: Reference | str | None, tolerance: float
) -> tuple[float, Reference | None, str | None]:
    """The horizon of a work–precision sweep, the reference at it (None when there is none) and
    a note on where it comes from, where that is not the scene's own."""
    if reference is not None and not isinstance(reference, Reference) and reference != "auto":
        raise TypeError(f"reference: expected a varmech.scenes.Reference, 'auto' or None, got {reference!r}")
    given = reference if isinstance(reference, Reference) else None
    own = given if given is not None else scene.reference
    if t_end is None:
        t_end = own.t if own is not None else scene.t_end
    t_end = positive("t_end", t_end)
    if reference is None:
        return t_end, None, "no reference (reference=None): final_error is NaN"
    if own is not None and math.isclose(own.t, t_end, rel_tol=1e-12):
        return t_end, own, None
    if given is not None:
        return t_end, None, f"no reference at t = {t_end:g} (the reference given is at t = {given.t:g}): final_error is NaN"
    computed = reference_solution(scene, t_end=t_end, tolerance=tolerance)
    why = "the scene has none" if own is None else f"the scene's is at t = {own.t:g}"
    note = f"reference {computed.source} ({why}); errors below {computed.tolerance:.1e} are not measured"
    return t_end, computed, note


# --------------------------------------------------------------------------------- sweeps


def _default_start(scene: Scene, t_end: float) -> int:
    """A quarter of the scene's quick-look steps over the horizon, rounded down to a power of 2."""
    base = max(t_end / scene.dt / 4, 16.0)
    return 2 ** int(math.floor(math.log2(base)))


#: What one of the column ``evaluations`` is, for each family of methods (the charts say it).
EVALUATION_UNITS = {
    "varmech, explicit": "one force ∇V (or ∂L/∂q) evaluation",
    "varmech, implicit": "one evaluation of the discrete Lagrangian's slot derivatives "
    "(∂L/∂q, ∂L/∂q̇ at each quadrature node, with their Hessians for Newton)",
    "scipy": "one right-hand side column, finite-difference Jacobian columns included",
    "rebound": "one gravity evaluation (an additional-force call)",
}


def _evaluation_units(plan: list[tuple[str, str, list[float], bool]]) -> dict[str, str]:
    """The units of ``evaluations`` of the families in ``plan``, in its order."""
    families = []
    for tool, method, _, _ in plan:
        if tool == "varmech":
            tool += ", implicit" if method_info(method).implicit else ", explicit"
        families.append(tool)
    return {family: EVALUATION_UNITS[family] for family in dict.fromkeys(families)}


def _done_refining(errors: list[float]) -> bool:
    """A default sweep stops at round-off: the error below 1e-14, or no longer falling (less than
    1.5× over a doubling) once under 1e-6."""
    if not errors or not math.isfinite(errors[-1]):
        return False
    if errors[-1] < 1e-14:
        return True
    return len(errors) >= 2 and errors[-2] < 1e-6 and errors[-1] > errors[-2] / 1.5


def work_precision(
    scene: Scene | Model | str,
    methods: Iterable[str],
    *,
    q0: ArrayLike | None = None,
    p0: ArrayLike | None = None,
    v0: ArrayLike | None = None,
    steps: Sequence[int] | dict[str, Sequence[int]] | None = None,
    baselines: Iterable[str] = ("RK45", "DOP853", "Radau"),
    rtols: Sequence[float] = DEFAULT_RTOLS,
    atol: float | Sequence[float] | None = None,
    rebound: Iterable[str] = _baselines.REBOUND_DEFAULTS,
    epsilons: Sequence[float] = DEFAULT_EPSILONS,
    t_end: float | None = None,
    reference: Reference | Literal["auto"] | None = "auto",
    reference_tolerance: float = 1e-10,
    repeat: int = 3,
    sweep_length: int = 11,
    max_seconds: float | None = 5.0,
    progress: bool | None = None,
) -> Table:
    """Measure cost against accuracy over a sweep of steps (varmech) and tolerances (baselines).

    Each row is one run to ``t_end`` (by default the time of the scene's reference solution, or
    its horizon):
    ``tool`` ("varmech", "scipy", "rebound"), ``method``, the swept ``parameter`` ("steps",
    "rtol" or "epsilon") and its ``value``, the ``steps`` taken, the force (right-hand side)
    ``evaluations``, the wall time ``seconds``, ``final_error`` = ‖(q, p) − (q_ref, p_ref)‖₂ at
    ``t_end`` over the reference's known (finite) components, and ``max_energy_error`` =
    max |H − H₀|/|H₀| over the run (NaN when L depends on t or forces act).

    Parameters
    ----------
    scene
        A :class:`~varmech.Scene` (built-in, symbolic, or :meth:`~varmech.Scene.of` a model), a
        scene's name, or a model with ``q0``, ``p0`` or ``v0``, and ``t_end``.
    q0, p0, v0
        A model's initial state: positions, and momenta or velocities.
    methods
        varmech method names (``"verlet"``, ``"kahan_li8"``, ``"rk4"``, ...).
    steps
        The step counts over the horizon: one list for every method, or a dict by method.
        Default: powers of 2 from a quarter of the scene's own step (``scene.dt``), up to
        ``sweep_length`` settings, stopping early at round-off (the error no longer falls).
    baselines, rtols, atol
        ``solve_ivp`` methods (``"RK45"``, ``"DOP853"``, ``"Radau"``, ...), run on the first-order
        system q̇ = q̇(q, p), ṗ = ∂L/∂q(q, q̇) (vectorized, so Radau's finite-difference
        Jacobian is one call) over ``rtols``, with ``atol`` (default rtol·10⁻³ times the largest
        initial |q| and |p|). ``evaluations`` counts every right-hand side column, Jacobian
        columns included. Skipped, with a note in ``meta["notes"]``, without SciPy, and for
        forced or constrained scenes.
    rebound, epsilons
        REBOUND's integrators (``analysis.baselines.REBOUND_METHODS``; default
        ``"WHFast"`` and ``"IAS15"``): the fixed-step ones (``"WHFast"``, ``"WHFast
        corrector=11"``, ``"leapfrog order=8"``) over the step sweep of ``verlet`` (or
        ``steps[name]``), ``"IAS15"`` over the precisions ``epsilons``. They run on N-body
        scenes, and ``"leapfrog order=8"`` also on the Kepler scene; skipped with a note without
        REBOUND. Their force evaluations are counted in a separate untimed run.
    t_end, reference, reference_tolerance
        The horizon (default: the time of the scene's reference, else its horizon), and the
        solution there: a :class:`~varmech.scenes.Reference`; ``"auto"``, the scene's own where
        it has one at ``t_end``, else one computed by the model's most accurate method to
        ``reference_tolerance`` (relative; :func:`varmech.analysis.reference.reference_solution`,
        noted in ``meta["notes"]``, its tolerance ``meta["reference_tolerance"]``); or None, none
        (``final_error`` is NaN, the energy error alone is measured).
    sweep_length
        The most settings of a default sweep of steps.
    repeat
        Wall time is the best of ``repeat`` runs that save only the final state (fewer once two
        seconds went into a setting); the energy error comes from a separate run saving up to
        20 000 states (solve_ivp's and REBOUND's from their accepted steps or samples).
    max_seconds
        A method's sweep stops after a run slower than this (noted in ``meta["notes"]``); None
        never stops it.
    progress
        Show a progress bar: None on a terminal only, True or False to force it.

    Returns
    -------
    Table
        One row a run, with the columns above; ``meta["notes"]`` says what was skipped and why,
        ``meta["reference"]`` where the reference comes from.
        :func:`varmech.charts.work_precision_chart` draws it.

    Raises
    ------
    ValueError
        An unknown method or baseline, or a method that does not fit the scene's model, named.
    KeyboardInterrupt
        On Ctrl-C, with the rows measured so far as ``err.partial``.

    Examples
    --------
    >>> import varmech
    >>> table = varmech.work_precision(varmech.scenes.harmonic_oscillator(), ["verlet", "kahan_li6"],
    ...                                steps=[64, 128], baselines=(), rebound=(), repeat=1)
    >>> error = table.column("final_error")      # verlet at 64 and 128 steps, then kahan_li6
    >>> round(float(error[0] / error[1]), 1)         # order 2: half the step, a quarter the error
    4.0
    """
    scene = as_scene(scene, q0=q0, p0=p0, v0=v0, t_end=t_end)
    methods = list(methods)
    baselines = list(baselines)
    T, ref, ref_note = _horizon(scene, t_end, reference, positive("reference_tolerance", reference_tolerance))
    table = Table(
        WORK_PRECISION_COLUMNS,
        title=f"Work–precision: {scene.name}, t = 0 … {T:g}",
        meta={
            "scene": scene.name,
            "time_unit": scene.time_unit,
            "t_end": T,
            "reference": ref.source if ref is not None else None,
            "reference_tolerance": ref.tolerance if ref is not None else None,
            "notes": [],
        },
    )
    notes: list[str] = table.meta["notes"]
    if ref_note:
        notes.append(ref_note)
    conserved = scene.model.conserves_energy
    bad = [b for b in baselines if b not in _baselines.SCIPY_METHODS]
    if bad:
        raise ValueError(f"baselines: unknown solve_ivp method(s) {bad}; choose from {_baselines.SCIPY_METHODS}")
    rebound_methods = list(rebound)
    bad = [b for b in rebound_methods if b not in _baselines.REBOUND_METHODS]
    if bad:
        raise ValueError(f"rebound: unknown REBOUND integrator(s) {bad}; choose from {_baselines.REBOUND_METHODS}")

    def sweep_of(method: str) -> tuple[list[int], bool]:
        if isinstance(steps, dict) and method in steps:
            return [int(n) for n in steps[method]], False
        if steps is not None and not isinstance(steps, dict):
            return [int(n) for n in steps], False
        start = _default_start(scene, T)
        return [start * 2**k for k in range(sweep_length)], True

    # The plan: every (tool, method, settings) to run, for the progress bar's total.
    solve_ivp, baselines = _baselines.scipy_baselines(scene, baselines, notes)
    rb, rebound_methods = _baselines.rebound_baselines(scene, rebound_methods, notes, asked=False)

    plan: list[tuple[str, str, list[float], bool]] = []
    for m in methods:
        plan.append(("varmech", m, *sweep_of(m)))  # type: ignore[arg-type]
    for b in baselines:
        plan.append(("scipy", b, [float(r) for r in rtols], False))
    for r in rebound_methods:
        if _baselines.REBOUND_BASELINES[r].adaptive:
            plan.append(("rebound", r, [float(e) for e in epsilons], False))
        else:
            plan.append(("rebound", r, *sweep_of(r if isinstance(steps, dict) and r in steps else "verlet")))  # type: ignore[arg-type]
    table.meta["evaluation_units"] = _evaluation_units(plan)
    total = sum(len(values) for _, _, values, _ in plan)
    bar = _progress(range(total), total=total, desc=f"work–precision {scene.name}", enabled=progress)

    def tick() -> None:
        next(bar, None)

    def run_varmech(method: str, n: int) -> tuple:
        dt = T / n
        seconds, traj = _best_time(lambda _: integrate(scene, dt=dt, steps=n, method=method, save_every=n, max_energy_error=None), repeat)
        final = _final_error(ref, traj.q[-1], traj.p[-1])
        energy = math.nan
        if conserved:
            sampled = integrate(scene, dt=dt, steps=n, method=method, save_every=max(1, n // _ENERGY_SAMPLES), max_energy_error=None)
            energy = float(np.max(relative_error(sampled.energy())))
        return ("varmech", method, "steps", n, n, traj.nfev, seconds, final, energy)

    def run_scipy(method: str, rtol: float) -> tuple:
        seconds, (sol, nfev) = _best_time(lambda _: _baselines.solve(solve_ivp, scene, method, T, rtol, atol), repeat)
        n = scene.model.dim
        q, p = sol.y[:n].T, sol.y[n:].T
        energy = float(np.max(relative_error(energy_of(scene.model, sol.t, q, p)))) if conserved else math.nan
        return ("scipy", method, "rtol", rtol, sol.t.size - 1, nfev, seconds, _final_error(ref, q[-1], p[-1]), energy)

    def run_rebound(method: str, value: float) -> tuple:
        adaptive = _baselines.REBOUND_BASELINES[method].adaptive
        if adaptive:
            n, dt, eps, parameter = None, scene.dt, float(value), "epsilon"
        else:
            n, dt, eps, parameter = int(value), T / int(value), None, "steps"

        def advance(sim: Any) -> Any:
            _baselines.rebound_advance(sim, method, n, T)
            return sim

        # Building the simulation is not the integrator's cost: time the advance only.
        best, sim = _best_time(advance, repeat, prepare=lambda: _baselines.rebound_sim(rb, scene, method, dt=dt, epsilon=eps))
        q, p = _baselines.rebound_state(sim, scene)
        taken = int(sim.steps_done)
        evaluations = _baselines.rebound_evaluations(rb, scene, method, T, dt, n, eps)
        # Energy: sample the same run ~1000 times (the fixed-step methods by whole steps; IAS15
        # without forcing its step onto the sample times).
        sim2 = _baselines.rebound_sim(rb, scene, method, dt=dt, epsilon=eps)
        qs, ps, ts = [scene.q0], [scene.p0], [0.0]
        try:
            if not adaptive:
                total = int(value)
                chunk = max(1, total // 1000)
                done = 0
                while done < total:
                    k = min(chunk, total - done)
                    sim2.steps(k)
                    sim2.synchronize()
                    done += k
                    a, b = _baselines.rebound_state(sim2, scene)
                    qs.append(a)
                    ps.append(b)
                    ts.append(sim2.t)
            else:
                for t in np.linspace(0, T, 1001)[1:]:
                    sim2.integrate(t, exact_finish_time=0)
                    a, b = _baselines.rebound_state(sim2, scene)
                    qs.append(a)
                    ps.append(b)
                    ts.append(sim2.t)
        finally:
            _baselines.restore_sigint()
        energy = float(np.max(relative_error(energy_of(scene.model, np.array(ts), np.array(qs), np.array(ps)))))
        return ("rebound", method, parameter, value, taken, evaluations, best, _final_error(ref, q, p), energy)

    runners: dict[str, Callable[[str, Any], tuple]] = {"varmech": run_varmech, "scipy": run_scipy, "rebound": run_rebound}

    def body() -> None:
        for tool, method, values, adaptive in plan:
            errors: list[float] = []
            for k, value in enumerate(values):
                try:
                    row = runners[tool](method, value)
                except (_core.DivergenceError, _core.ConvergenceError, RuntimeError) as err:
                    notes.append(f"{tool} {method} at {value:g}: failed ({type(err).__name__}: {err})")
                    tick()
                    continue
                table.append(*row)
                tick()
                errors.append(row[7] if math.isfinite(row[7]) else row[8])
                if max_seconds is not None and row[6] > max_seconds and k < len(values) - 1:
                    notes.append(f"{tool} {method}: stopped after {value:g} (a run took {row[6]:.1f} s > max_seconds = {max_seconds:g})")
                    for _ in values[k + 1 :]:
                        tick()
                    break
                if adaptive and _done_refining(errors) and k < len(values) - 1:
                    for _ in values[k + 1 :]:
                        tick()
                    break

    return interruptible(table, body)

