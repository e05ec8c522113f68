"""The implicit methods' stability beyond the linear test: where a fixed-step run of the
pendulum stays on its energy, fails Newton, jumps to a spurious branch or diverges, over a grid
of steps and amplitudes (:func:`implicit_regions`). The explicit methods' intervals on the
linear test equation are :mod:`varmech.analysis.stability`'s."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from .. import scenes
from .._core import ConvergenceError, DivergenceError, SpuriousBranchError
from .._progress import progress as _progress
from .._util import positive
from ..model import Model
from ..table import Table
from ._energy import relative_error
from ._interrupt import interruptible
from .stability import IMPLICIT_METHODS, checked_method, probe, progress_for

DEFAULT_H_VALUES = (0.1, 0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0)
# Initial angles from rest; π/2 is left out, where H₀ = −cos q₀ = 0 and a relative energy error
# means nothing.
DEFAULT_Q0_VALUES = (0.25, 0.5, 1.0, 2.0, 2.5, 2.75, 3.0, 3.1)


def implicit_regions(
    method: str | Sequence[str] | None = None,
    *,
    scene: Any = "pendulum",
    steps: int = 20,
    h_values: Sequence[float] = DEFAULT_H_VALUES,
    q0_values: Sequence[float] = DEFAULT_Q0_VALUES,
    energy_threshold: float = 0.05,
    progress: bool | None = None,
) -> Table:
    """What happens to the implicit methods over step size h and initial angle q₀.

    For each method (default: ``midpoint``, ``trapezoid``, ``galerkin4``, ``galerkin6``), step h
    and initial position q₀ (the first coordinate, from rest: p₀ = 0), ``steps`` steps of
    ``scene`` (a :mod:`varmech.scenes` name or a Scene; default the pendulum H = p²/2 − cos q,
    whose top is q = π) are integrated and the first thing that goes wrong is recorded in
    ``outcome``:

    - ``"ok"``: all steps done, the relative energy error stayed within the threshold;
    - ``"energy"``: the relative energy error |H − H₀|/|H₀| passed ``energy_threshold`` (the
      run is cut there);
    - ``"spurious branch"``: Newton converged beyond a fold of the discrete Euler–Lagrange map
      (:class:`~varmech.SpuriousBranchError`; for the midpoint rule near the top once h ≳ 2);
    - ``"newton failure"``: Newton's iteration did not converge (:class:`~varmech.ConvergenceError`);
    - ``"diverged"``: the state became non-finite (:class:`~varmech.DivergenceError`).

    Columns: ``method``, ``h``, ``q0``, ``outcome``, ``steps_done`` (steps completed before the
    failure), ``energy_error`` (the largest relative energy error over the steps completed) and
    ``newton_per_step`` (mean Newton iterations per step completed; NaN before the first).
    The default q₀ values avoid π/2, where H₀ = 0.

    Parameters
    ----------
    method : str or sequence of str, optional
        Implicit varmech methods; default :data:`IMPLICIT_METHODS`.
    scene : str, Scene or Model, default "pendulum"
        A :mod:`varmech.scenes` name, a Scene, or a model (its other coordinates at 0).
    steps : int, default 20
        Steps per run.
    h_values : sequence of float, default (0.1, 0.25, … 6.0)
        The step sizes h, positive.
    q0_values : sequence of float, default (0.25, 0.5, … 3.1)
        The initial values of the first coordinate, finite.
    energy_threshold : float, default 0.05
        The relative energy error that counts as a failure.
    progress : bool, optional
        Show a progress bar: None on a terminal only (for 50 runs or more).

    Returns
    -------
    Table
        One row per method, h and q₀, with the columns above; ``meta`` holds ``"scene"``,
        ``"time_unit"``, ``"steps"``, ``"energy_threshold"`` and ``"p0"``.

    Raises
    ------
    TypeError
        ``scene`` is neither a scene name, a Scene nor a Model.
    ValueError
        An unknown method, or one for constrained systems or the N-body problem only; an
        unknown scene name; ``steps`` not a positive integer; ``h_values`` or
        ``energy_threshold`` not positive and finite; ``h_values`` or ``q0_values`` empty or
        not finite.
    KeyboardInterrupt
        On Ctrl-C, with the rows measured so far as ``err.partial``.

    See Also
    --------
    varmech.charts.stability.implicit_regions_chart : Plots the map.

    Notes
    -----
    Each run is 20 steps by default, so the whole default map takes well under a second.

    Examples
    --------
    >>> from varmech.analysis.implicit import implicit_regions
    >>> table = implicit_regions("midpoint", h_values=(0.5, 3.0), q0_values=(1.0, 3.0))
    >>> table.column("outcome").tolist()
    ['ok', 'ok', 'energy', 'spurious branch']
    """
    names = list(IMPLICIT_METHODS) if method is None else ([method] if isinstance(method, str) else list(method))
    for name in names:
        checked_method(name)
    # A model's runs start from rest, its other coordinates at 0; the horizon is the runs' own.
    origin = np.zeros(scene.dim) if isinstance(scene, Model) else None
    sc = scenes.as_scene(scene, q0=origin, p0=origin, t_end=1.0, dt=1.0)
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 1:
        raise ValueError(f"steps: must be a positive integer, got {steps!r}")
    hs = [positive("h_values", h) for h in h_values]
    q0s = [float(q) for q in q0_values]
    if not hs or not q0s or not all(math.isfinite(q) for q in q0s):
        raise ValueError("h_values, q0_values: must be non-empty, finite")
    energy_threshold = positive("energy_threshold", energy_threshold)
    n = sc.model.dim
    table = Table(
        ("method", "h", "q0", "outcome", "steps_done", "energy_error", "newton_per_step"),
        title=f"Implicit methods on {sc.name}: outcome of {steps} steps from rest at q0",
        meta={"scene": sc.name, "time_unit": sc.time_unit, "steps": int(steps), "energy_threshold": energy_threshold, "p0": 0.0},
    )
    plan = [(name, h, q0) for name in names for h in hs for q0 in q0s]

    def body() -> None:
        for name, h, q0 in _progress(plan, total=len(plan), desc=f"implicit regions {sc.name}", enabled=progress_for(progress, len(plan))):
            q = np.array(sc.q0, dtype=float)
            q[0] = q0
            p = np.zeros(n)
            outcome, traj = "ok", None
            try:
                traj = probe(sc.model, q, p, dt=h, steps=int(steps), method=name, max_energy_error=None)
            except SpuriousBranchError as err:
                outcome, traj = "spurious branch", getattr(err, "partial", None)
            except ConvergenceError as err:
                outcome, traj = "newton failure", getattr(err, "partial", None)
            except DivergenceError as err:
                outcome, traj = "diverged", getattr(err, "partial", None)
            done, energy, newton = 0, math.nan, math.nan
            if traj is not None and len(traj):
                # Every state is saved: the first one past the threshold is where the run fails.
                error = relative_error(traj.energy())
                past = np.flatnonzero(~(error <= energy_threshold))
                last = int(past[0]) if len(past) and np.isfinite(error[past[0]]) else len(error) - 1
                if len(past) and np.isfinite(error[past[0]]):
                    outcome = "energy"
                done = last if outcome == "energy" else int(traj.steps)
                finite = np.isfinite(error[: last + 1])
                if finite.any():
                    energy = float(np.max(error[: last + 1][finite]))
                if done and traj.newton is not None:
                    newton = float(traj.newton[done]) / done
            table.append(name, h, q0, outcome, done, energy, newton)

    return interruptible(table, body)


__all__ = ["DEFAULT_H_VALUES", "DEFAULT_Q0_VALUES", "implicit_regions"]
