"""Poincaré sections and phase portraits, as tables of measurements.

:func:`poincare_section` integrates orbits of one energy and records where they pierce a
section q_k = c in a chosen direction (for Hénon–Heiles, the classic x = 0 with p_x > 0, seen in
the (y, p_y) plane). :func:`orbit_divergence` measures, orbit by orbit, how fast a neighbour on
the same energy shell separates: a cheap indicator of chaos. :func:`covered_cells` counts the
grid cells an orbit's section points fall into (area-filling). Phase portraits of one degree of
freedom are in :mod:`varmech.analysis.phase_portrait`. All return a :class:`~varmech.Table`;
:mod:`varmech.charts.sections` plots them.

Every orbit is one native :func:`varmech.integrate` call (no Python call per step for a native
scene). Long sweeps show a progress bar (tqdm) on a terminal; Ctrl-C stops them, and the
KeyboardInterrupt carries the rows measured so far as ``err.partial``.

How a crossing is located
-------------------------
Each orbit is one :func:`varmech.integrate` run with the event
:func:`varmech.events.crossing` (k, c, direction), evaluated natively. With ``locate="step"``
(the default) each crossing is the event's located state: a *partial step*, one step of the same
integrator of size τ ≤ h from the state before the crossing, with τ found by the core's
root finder (Illinois on the bracket [0, h], see :mod:`varmech.events`) until q_k(τ) = c to
round-off. The reported state is then an actual state of the integrator (a step of size τ
instead of h, local error O(τ^{p+1})), it lies on the section to round-off (|q_k − c| ≤ 1.1e-17
measured), and its energy error is the method's own, of the same size as at the grid points
(order 6 for kahan_li6: 1.3e-9, 2.0e-11, 3.2e-13 at h = 0.1, 0.05, 0.025). Integrating the
exact flow (kahan_li8, 64 substeps) from the same grid state over the same τ lands within
1.1e-12 of it, on x = 0 to 1.1e-12. The crossing costs a handful of extra steps in the core.

``locate="hermite"`` reports instead the root of the cubic Hermite interpolant between the saved
states on either side (every step is saved), with the exact derivatives q̇ = ``model.velocity(q,
p)`` and ṗ = ∂L/∂q(q, q̇) (= −∇V for a mechanical system), found by bisection: accurate to
O(h⁴), not to the method's order. On Hénon–Heiles at E = 1/8 with kahan_li6 it is within 5.8e-7,
3.8e-8, 2.4e-9, 1.5e-10 of the partial-step point at h = 0.1, 0.05, 0.025, 0.0125 (ratios 15–16;
``meta["max_hermite_gap"]`` of a ``"step"`` section), and its energy error is 1.1e-7 at
h = 0.05, where the integrator's own is 2e-11. It is kept as the interpolant's check on the
located points.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._util import positive
from ..events import crossing
from ..model import Model, coordinate_names, momentum_name
from ..table import Table
from ..trajectory import Trajectory
from ._interrupt import interruptible
from ._orbits import ModelLike, default_method, energy_at, model_of, relative, run_orbits, solve_momentum

#: The Hénon–Heiles energies of Hénon & Heiles (1964): mostly regular motion at 1/12,
#: widespread chaos at 1/8 (the region stays bounded below the escape energy 1/6).
HENON_HEILES_ENERGIES = (1.0 / 12.0, 1.0 / 8.0)

#: The default chaos threshold of :func:`orbit_divergence`: a neighbour 1e-9 away that got
#: 10⁵ times farther (to 1e-4) within the run.
CHAOS_THRESHOLD = 5.0



# ------------------------------------------------------------------------------------ helpers


def _is_henon_heiles(model: Model) -> bool:
    return model.name == "henon_heiles"


def _names(model: Model, names: Sequence[str] | None) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The coordinates' and momenta's column names: ``names``, or the model's own."""
    cols = coordinate_names(names, model.dim, "names") or model.coordinates
    return cols, tuple(momentum_name(name, i) for i, name in enumerate(cols))


def _section(model: Model, section: Sequence[Any] | None) -> tuple[int, float, int]:
    if section is None:
        section = (0, 0.0, 1)
    try:
        k, c, d = section
        k, c, d = int(k), float(c), int(d)
    except (TypeError, ValueError):
        raise ValueError(f"section: expected (coordinate index, value, direction), got {section!r}") from None
    if not 0 <= k < model.dim:
        raise ValueError(f"section: coordinate index {k} is not in 0 … {model.dim - 1}")
    if d not in (-1, 0, 1) or not math.isfinite(c):
        raise ValueError(f"section: direction must be +1, -1 or 0 and the value finite, got {section!r}")
    return k, c, d


def _henon_heiles_box(energy: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """The (y, p_y) box around the allowed region of the section x = 0 of Hénon–Heiles:
    ½p_y² + ½y² − y³/3 ≤ E, for 0 < E < 1/6."""
    if not 0 < energy < 1 / 6:
        raise ValueError(f"energy: the Hénon–Heiles section is bounded for 0 < E < 1/6, got {energy}")
    roots = np.sort(np.roots([-1.0 / 3.0, 0.5, 0.0, -energy]).real)
    return (float(roots[0]), float(roots[1])), (-math.sqrt(2 * energy), math.sqrt(2 * energy))


def _seeds(
    model: Model,
    energy: float,
    k: int,
    c: float,
    direction: int,
    seeds: ArrayLike | str,
    orbits: int,
    box: Any,
    seed: int,
) -> tuple[np.ndarray, np.ndarray]:
    """Initial states (q, p) on the section and the energy shell, rows (orbits, n)."""
    n = model.dim
    others = [i for i in range(n) if i != k]
    if isinstance(seeds, str):
        if seeds not in ("random", "line"):
            raise ValueError(f"seeds: 'random', 'line' or an array of seeds, got {seeds!r}")
        if n != 2:
            raise ValueError(f"seeds: give explicit seeds (rows of the other {n - 1} coordinates, then their momenta) for {n} coordinates")
        if isinstance(orbits, bool) or not isinstance(orbits, (int, np.integer)) or orbits < 1:
            raise ValueError(f"orbits: must be a positive integer, got {orbits!r}")
        if box is None:
            if not _is_henon_heiles(model) or (k, c) != (0, 0.0):
                raise ValueError("box: give ((q_min, q_max), (p_min, p_max)) of the plane to seed in")
            box = _henon_heiles_box(energy)
        (q_lo, q_hi), (p_lo, p_hi) = box
        j = others[0]
        found_q: list[np.ndarray] = []
        found_p: list[np.ndarray] = []
        if seeds == "line":
            # Evenly spaced along p_j = 0 across the allowed part of the box's q_j range.
            grid = np.linspace(q_lo, q_hi, 4001)
            q = np.zeros((grid.size, n))
            q[:, k], q[:, j] = c, grid
            _, ok = solve_momentum(model, q, np.zeros((grid.size, n)), k, energy, direction)
            if not ok.any():
                raise ValueError(f"energy: no allowed state on the line p_{j} = 0 at E = {energy}")
            a, b = grid[ok].min(), grid[ok].max()
            span = np.linspace(a, b, orbits + 2)[1:-1]
            q = np.zeros((orbits, n))
            q[:, k], q[:, j] = c, span
            p, ok = solve_momentum(model, q, np.zeros((orbits, n)), k, energy, direction)
            return q[ok], p[ok]
        rng = np.random.default_rng(seed)
        count = 0
        for _ in range(1000):
            m = 4 * orbits
            q = np.zeros((m, n))
            p = np.zeros((m, n))
            q[:, k], q[:, j] = c, rng.uniform(q_lo, q_hi, m)
            p[:, j] = rng.uniform(p_lo, p_hi, m)
            p, ok = solve_momentum(model, q, p, k, energy, direction)
            found_q.append(q[ok])
            found_p.append(p[ok])
            count += int(ok.sum())
            if count >= orbits:
                break
        if count < orbits:
            raise ValueError(f"box: found only {count} allowed seeds at E = {energy}")
        return np.concatenate(found_q)[:orbits], np.concatenate(found_p)[:orbits]
    s = np.array(seeds, dtype=float)
    s = np.atleast_2d(s)
    if s.ndim != 2 or s.shape[1] != 2 * (n - 1) or not np.all(np.isfinite(s)):
        raise ValueError(f"seeds: expected rows of {2 * (n - 1)} finite numbers (the other coordinates, then their momenta), got shape {s.shape}")
    q = np.zeros((len(s), n))
    p = np.zeros((len(s), n))
    q[:, k] = c
    q[:, others] = s[:, : n - 1]
    p[:, others] = s[:, n - 1 :]
    p, ok = solve_momentum(model, q, p, k, energy, direction)
    if not ok.all():
        bad = s[~ok][0]
        raise ValueError(f"seeds: {bad} is outside the energy-allowed region at E = {energy} (or has no crossing in the direction asked)")
    return q, p


def _orbits(
    model: Model,
    energy: float,
    section: Sequence[Any] | None,
    dt: float,
    t_end: float,
    method: str | None,
    seeds: ArrayLike | str,
    orbits: int,
    box: Any,
    seed: int,
) -> tuple[int, float, int, float, float, str, np.ndarray, np.ndarray]:
    """The checked set-up shared by the orbit sweeps: the section (k, c, direction), dt, t_end,
    the method, and the seeds' initial states (q, p) on the section and the energy shell."""
    k, c, direction = _section(model, section)
    dt = positive("dt", dt)
    t_end = positive("t_end", t_end)
    method = default_method(model, method)
    q_seed, p_seed = _seeds(model, energy, k, c, direction, seeds, orbits, box, seed)
    return k, c, direction, dt, t_end, method, q_seed, p_seed


def _states(model: Model, seeds: ArrayLike | str) -> tuple[np.ndarray, np.ndarray]:
    """A forced model's initial states, rows (q, p) of 2n, as (q, p) rows."""
    n = model.dim
    s = None if isinstance(seeds, str) else np.atleast_2d(np.array(seeds, dtype=float))
    if s is None or s.ndim != 2 or s.shape[1] != 2 * n or not np.all(np.isfinite(s)):
        shape = seeds if isinstance(seeds, str) else np.shape(seeds)
        raise ValueError(f"seeds: a forced model's orbits start from given states, rows of {2 * n} finite numbers (q, then p), got {shape!r}")
    return s[:, :n].copy(), s[:, n:].copy()


def _balance_before(traj: Trajectory, idx: np.ndarray) -> np.ndarray:
    """The balance (E − W) − (E₀ − W₀) at the states before the crossings ``idx``, relative to
    the largest |E| of the orbit: the run's own accuracy where its energy is not conserved."""
    balance = traj.energy() - np.asarray(traj.work)
    scale = max(float(np.max(np.abs(traj.energy()))), np.finfo(float).tiny)
    return (balance[idx] - balance[0]) / scale


def _hermite(x0, v0, x1, v1, h, s):
    """Cubic Hermite interpolant on [0, h] at s = τ/h (arrays broadcast), and its τ-derivative."""
    s2, s3 = s * s, s * s * s
    val = (2 * s3 - 3 * s2 + 1) * x0 + (s3 - 2 * s2 + s) * h * v0 + (-2 * s3 + 3 * s2) * x1 + (s3 - s2) * h * v1
    der = ((6 * s2 - 6 * s) * x0 + (3 * s2 - 4 * s + 1) * h * v0 + (-6 * s2 + 6 * s) * x1 + (3 * s2 - 2 * s) * h * v1) / h
    return val, der


def _hermite_points(model: Model, traj: Trajectory, idx: np.ndarray, k: int, c: float, sign: np.ndarray):
    """The Hermite estimate of each crossing: (τ, q, p) at the root of q_k(τ) − c."""
    t0, t1 = traj.t[idx], traj.t[idx + 1]
    q0, q1, p0, p1 = traj.q[idx], traj.q[idx + 1], traj.p[idx], traj.p[idx + 1]
    v0, v1 = model.velocity(q0, p0, t0), model.velocity(q1, p1, t1)
    f0, f1 = model._derivative("dl_dq", q0, v0, t0), model._derivative("dl_dq", q1, v1, t1)
    dt = (t1 - t0)[:, None]
    # Bisection on the signed g(s) = sign·(q_k(s) − c), negative at s = 0, ≥ 0 at s = 1.
    lo = np.zeros(len(idx))
    hi = np.ones(len(idx))
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        val, _ = _hermite(q0[:, k], v0[:, k], q1[:, k], v1[:, k], dt[:, 0], mid)
        neg = sign * (val - c) < 0
        lo = np.where(neg, mid, lo)
        hi = np.where(neg, hi, mid)
    s = hi[:, None]
    q, _ = _hermite(q0, v0, q1, v1, dt, s)
    p, _ = _hermite(p0, f0, p1, f1, dt, s)
    q[:, k] = c
    return hi * dt[:, 0], q, p


# ------------------------------------------------------------------------------ Poincaré


def poincare_section(
    model_or_scene: ModelLike,
    energy: float | None,
    *,
    orbits: int = 24,
    seeds: ArrayLike | str = "random",
    box: Any = None,
    dt: float = 0.05,
    t_end: float = 1000.0,
    method: str | None = None,
    section: Sequence[Any] | None = None,
    locate: str = "step",
    names: Sequence[str] | None = None,
    seed: int = 0,
    progress: bool | None = None,
) -> Table:
    """The points where orbits of energy ``energy`` (or of a forced model) pierce the section q_k = c.

    One row per crossing: ``orbit`` (0, 1, …), the crossing time ``t``, the state (a column per
    coordinate, e.g. ``x``, ``y``, then ``p_x``, ``p_y``), and ``energy_error`` = (H − E)/|E| at
    the located point. ``meta["plane"]`` names the two columns to plot (the first other
    coordinate and its momentum), ``meta["seeds"]`` the orbits' initial states, and
    ``meta["max_section_residual"]``, ``meta["max_energy_error"]`` the largest |q_k − c| and
    |ΔH|/|E| over all points. A forced model (or one whose L depends on t) has no energy shell:
    its orbits start from given states, and its accuracy column is ``balance_error``, the run's
    energy balance (E − W) − (E₀ − W₀) at the step before each crossing over the orbit's largest
    |E| (``meta["max_balance_error"]``), W the energy put in (``traj.work``).

    Parameters
    ----------
    model_or_scene
        An unconstrained model or scene, e.g. :func:`varmech.scenes.henon_heiles`
        (H = ½(p_x² + p_y²) + ½(x² + y²) + x²y − y³/3), conservative or forced.
    energy
        The energy shell, e.g. 1/12 or 1/8 (:data:`HENON_HEILES_ENERGIES`); None for a forced
        model, whose ``seeds`` are then its orbits' initial states, rows (q, then p) of 2n.
    orbits, seeds, box, seed
        Where the orbits start, on the section: ``seeds="random"`` draws ``orbits`` points
        uniformly (``numpy.random.default_rng(seed)``) from the energy-allowed part of the
        plane box ``box = ((q_min, q_max), (p_min, p_max))`` (Hénon–Heiles: the region
        ½p_y² + ½y² − y³/3 ≤ E by default); ``"line"`` spaces them evenly along p = 0 across
        it; an array gives them explicitly, rows of the other coordinates then their momenta
        (for Hénon–Heiles, rows (y, p_y)). The section's own momentum comes from the energy
        (p_x = √(2(E − V) − p_y²) for Hénon–Heiles), with q̇_k of the section's direction.
    dt, t_end, method
        Each orbit is one :func:`varmech.integrate` call to ``t_end`` with step ``dt``
        (default ``kahan_li6`` for separable models, ``galerkin6`` otherwise), saving every step.
        Hénon–Heiles at h = 0.05 with kahan_li6: |ΔH|/E ≲ 2e-11; an orbit crosses x = 0 upward
        about once per 2π.
    section
        ``(k, c, direction)``: the section q_k = c crossed with q̇_k > 0 (+1), < 0 (−1) or
        either way (0). Default ``(0, 0.0, +1)``, Hénon–Heiles' x = 0 with p_x > 0.
    locate
        ``"step"`` (default): each crossing is a state of the integrator itself, a partial step
        from the state before it (the event's located state, :mod:`varmech.events`), on the
        section to round-off; ``"hermite"``: the cubic Hermite interpolant's root (O(dt⁴)). See
        the module docstring.
    names
        Coordinate names for the columns (default: the model's, :attr:`~varmech.Model.coordinates`).
    progress
        Show a progress bar: None on a terminal only, True or False to force it.

    Returns
    -------
    Table
        Columns ``orbit``, ``t``, the coordinates, their momenta ``p_<name>`` and
        ``energy_error``, one row a crossing, orbit by orbit in time order. ``meta`` holds
        ``"plane"``, ``"seeds"``, ``"max_section_residual"``, ``"max_energy_error"``,
        ``"max_hermite_gap"`` (``locate="step"``), the set-up (``"model"``, ``"energy"``,
        ``"section"``, ``"method"``, ``"dt"``, ``"t_end"``, ``"locate"``) and ``"notes"``: an
        orbit that diverges (above Hénon–Heiles' escape energy 1/6) keeps its crossings up to
        the divergence, with a note.

    Raises
    ------
    TypeError
        ``model_or_scene`` is neither a model nor a scene.
    ValueError
        A constrained model; ``energy`` not finite, or given for a forced model, or None for a
        conservative one; a forced model's ``seeds`` not rows of 2n states, or ``locate`` other
        than ``"step"``; ``names``, ``section``,
        ``locate``, ``seeds``, ``orbits``, ``dt`` or ``t_end`` malformed; no ``box`` where one is
        needed (any model but Hénon–Heiles on x = 0), or too few energy-allowed seeds in it; an
        explicit seed outside the energy-allowed region; or an unknown ``method``.
    KeyboardInterrupt
        On Ctrl-C, with the rows measured so far as ``err.partial``.

    See Also
    --------
    orbit_divergence : The same orbits' divergence from a neighbour, a chaos indicator.
    covered_cells : Box counting on the section: curve or area.
    varmech.charts.sections.poincare_chart : Plots the section.

    Notes
    -----
    A Poincaré section reduces a flow on the three-dimensional energy shell of a system of two
    degrees of freedom to a map of a plane: regular orbits lie on invariant tori and pierce
    the plane on closed curves, chaotic ones scatter over an area [1]_.

    References
    ----------
    .. [1] M. Hénon and C. Heiles, "The applicability of the third integral of motion: some
       numerical experiments", *Astron. J.* 69, 73–79 (1964).

    Examples
    --------
    >>> import varmech
    >>> from varmech.analysis.sections import poincare_section
    >>> table = poincare_section(varmech.scenes.henon_heiles(), 1 / 12, orbits=3, dt=0.1,
    ...                          t_end=60.0, progress=False)
    >>> table.columns
    ('orbit', 't', 'x', 'y', 'p_x', 'p_y', 'energy_error')
    >>> table.meta["plane"], table.meta["method"]
    (('y', 'p_y'), 'kahan_li6')
    >>> table.meta["max_section_residual"] < 1e-12, table.meta["max_energy_error"] < 1e-8
    (True, True)
    """
    model = model_of(model_or_scene, forced=True)
    forced = not model.conserves_energy
    cols, momenta = _names(model, names)
    if locate not in ("step", "hermite"):
        raise ValueError(f"locate: 'step' or 'hermite', got {locate!r}")
    if forced:
        if energy is not None:
            raise ValueError(f"energy: {model.name} is forced or depends on t, so it has no energy shell; pass energy=None and seeds")
        if locate != "step":
            raise ValueError("locate: a forced model's crossings are the integrator's own partial steps ('step'); its ṗ is not ∂L/∂q")
        k, c, direction = _section(model, section)
        dt, t_end, method = positive("dt", dt), positive("t_end", t_end), default_method(model, method)
        q_seed, p_seed = _states(model, seeds)
    else:
        if energy is None:
            raise ValueError(f"energy: the energy shell of {model.name}'s orbits is needed (a forced model takes None)")
        energy = float(energy)
        if not math.isfinite(energy):
            raise ValueError(f"energy: must be finite, got {energy}")
        k, c, direction, dt, t_end, method, q_seed, p_seed = _orbits(model, energy, section, dt, t_end, method, seeds, orbits, box, seed)
    others = [i for i in range(model.dim) if i != k]
    plane = others[0]
    error = "balance_error" if forced else "energy_error"
    columns = ("orbit", "t", *cols, *momenta, error)
    arrow = {1: f"{momenta[k]} > 0", -1: f"{momenta[k]} < 0", 0: "both directions"}[direction]
    shell = "forced" if energy is None else f"E = {energy:.6g}"
    table = Table(
        columns,
        title=f"Poincaré section {cols[k]} = {c:g} ({arrow}): {model.name}, {shell}",
        meta={
            "model": model.name,
            "energy": energy,
            "section": (k, c, direction),
            "plane": (cols[plane], momenta[plane]),
            "method": method,
            "dt": dt,
            "t_end": t_end,
            "locate": locate,
            "seeds": [tuple(np.concatenate([q[others], p[others]]).tolist()) for q, p in zip(q_seed, p_seed)],
            "notes": [],
        },
    )
    worst = {"residual": 0.0, "energy": 0.0, "hermite_gap": 0.0}
    event = crossing(k, c, direction=direction)

    def add(o: int, traj: Trajectory, note: str | None) -> None:
        """Orbit o's crossings."""
        if note:
            table.meta["notes"].append(f"orbit {o}: {note}")
        found = traj.events[0]
        if not len(found):
            return
        # The step of each crossing, (t_i, t_i+1], and its sign (+1 upward, −1 downward).
        idx = np.searchsorted(traj.t, found.t, side="left") - 1
        sign = np.where(traj.q[idx, k] < c, 1.0, -1.0)
        taus, qs, ps = _hermite_points(model, traj, idx, k, c, sign)
        times = traj.t[idx] + taus
        if locate == "step":
            gap = np.max(np.abs(np.concatenate([found.q - qs, found.p - ps], axis=1)))
            worst["hermite_gap"] = max(worst["hermite_gap"], float(gap))
            times, qs, ps = found.t, found.q, found.p
        errs = _balance_before(traj, idx) if energy is None else relative(energy_at(model, qs, ps), energy)
        worst["residual"] = max(worst["residual"], float(np.max(np.abs(qs[:, k] - c))))
        worst["energy"] = max(worst["energy"], float(np.max(np.abs(errs))))
        for j in range(len(idx)):
            table.rows.append((o, float(times[j]), *map(float, qs[j]), *map(float, ps[j]), float(errs[j])))
        table.meta["max_section_residual"] = worst["residual"]
        table.meta[f"max_{error}"] = worst["energy"]
        if locate == "step":
            table.meta["max_hermite_gap"] = worst["hermite_gap"]

    def body() -> None:
        try:
            found = run_orbits(model, q_seed, p_seed, dt=dt, t_end=t_end, method=method, events=[event], progress=progress)
        except KeyboardInterrupt as err:
            # The orbits that ran to their end (or diverged) keep their rows.
            for o, (traj, note) in enumerate(err.partial):  # type: ignore[attr-defined]
                if note != "interrupted":
                    add(o, traj, note)
            raise
        for o, (traj, note) in enumerate(found):
            add(o, traj, note)

    return interruptible(table, body)


def orbit_divergence(
    model_or_scene: ModelLike,
    energy: float,
    *,
    orbits: int = 24,
    seeds: ArrayLike | str = "random",
    box: Any = None,
    dt: float = 0.05,
    t_end: float = 1000.0,
    method: str | None = None,
    section: Sequence[Any] | None = None,
    separation: float = 1e-9,
    threshold: float = CHAOS_THRESHOLD,
    seed: int = 0,
    progress: bool | None = None,
) -> Table:
    """A cheap chaos indicator: how far a neighbour on the same energy shell gets.

    For each orbit (seeded exactly as :func:`poincare_section` seeds it with the same
    arguments, so the ``orbit`` numbers match) a twin starts ``separation`` away in the plane
    momentum (p_y for Hénon–Heiles), with its section momentum re-solved so that both have
    energy E. Both run with the same integrator to ``t_end``; ``divergence`` is
    log₁₀(max_t ‖z(t) − z̃(t)‖ / ‖z(0) − z̃(0)‖) over states saved every 10 steps. On a torus
    (regular motion) neighbours separate linearly in t, a few decades at most over 1000 time
    units; in a chaotic region exponentially, until the separation saturates at the size of
    the region (≈ 8 decades from 1e-9). ``chaotic`` is ``divergence ≥ threshold`` (default 5).
    A sticky chaotic orbit that stays near an island for the whole run counts as regular: the
    fraction is a lower bound that grows with ``t_end``.

    Parameters
    ----------
    model_or_scene, energy, orbits, seeds, box, dt, t_end, method, section, seed, progress
        As for :func:`poincare_section`.
    separation : float, default 1e-9
        The twin's initial offset in the plane momentum.
    threshold : float, default 5.0
        Decades of growth from which an orbit counts as chaotic (:data:`CHAOS_THRESHOLD`).

    Returns
    -------
    Table
        One row per orbit: ``orbit``, the seed's plane coordinates (``y0``, ``p_y0`` for
        Hénon–Heiles), ``divergence``, ``chaotic``. ``meta["chaotic_fraction"]`` is the fraction
        of chaotic orbits; ``meta["notes"]`` names orbits without a twin or that diverged.

    Raises
    ------
    TypeError
        ``model_or_scene`` is neither a model nor a scene.
    ValueError
        As for :func:`poincare_section`, and ``separation`` not positive and finite.
    KeyboardInterrupt
        On Ctrl-C, with the rows measured so far as ``err.partial``.

    See Also
    --------
    poincare_section : The section of the same orbits.

    Notes
    -----
    This is a finite-time, two-point variant of the largest Lyapunov exponent: it measures the
    growth of one separation rather than of a tangent vector, and saturates instead of growing
    without bound.

    Examples
    --------
    >>> import varmech
    >>> from varmech.analysis.sections import orbit_divergence
    >>> table = orbit_divergence(varmech.scenes.henon_heiles(), 1 / 8, orbits=3, dt=0.1,
    ...                          t_end=100.0, progress=False)
    >>> table.columns
    ('orbit', 'y0', 'p_y0', 'divergence', 'chaotic')
    >>> len(table), 0.0 <= table.meta["chaotic_fraction"] <= 1.0
    (3, True)
    """
    model = model_of(model_or_scene)
    energy = float(energy)
    cols, momenta = _names(model, None)
    separation = positive("separation", separation)
    k, c, direction, dt, t_end, method, q_seed, p_seed = _orbits(model, energy, section, dt, t_end, method, seeds, orbits, box, seed)
    j = [i for i in range(model.dim) if i != k][0]
    p_twin_in = p_seed.copy()
    p_twin_in[:, j] += separation
    p_twin, ok = solve_momentum(model, q_seed, p_twin_in, k, energy, direction)
    if not ok.all():
        # Near the boundary of the allowed region the twin goes the other way in p_j.
        p_twin_in[~ok, j] -= 2 * separation
        p_twin2, ok2 = solve_momentum(model, q_seed[~ok], p_twin_in[~ok], k, energy, direction)
        p_twin[~ok] = p_twin2
        ok[~ok] = ok2
    table = Table(
        ("orbit", f"{cols[j]}0", f"{momenta[j]}0", "divergence", "chaotic"),
        title=f"Orbit divergence: {model.name}, E = {energy:.6g}, t = 0 … {t_end:g}",
        meta={"model": model.name, "energy": energy, "method": method, "dt": dt, "t_end": t_end, "separation": separation,
              "threshold": threshold, "notes": []},
    )
    steps = round(t_end / dt)
    save = max(1, min(10, steps))

    def body() -> None:
        # Every orbit and its twin, one ensemble: the orbits with a twin, then their twins.
        paired = np.flatnonzero(ok)
        q_all = np.concatenate([q_seed[paired], q_seed[paired]])
        p_all = np.concatenate([p_seed[paired], p_twin[paired]])
        try:
            found = run_orbits(model, q_all, p_all, dt=dt, t_end=t_end, method=method, save_every=save, progress=progress)
        except KeyboardInterrupt as err:
            rows(dict(zip(paired, zip(err.partial[: len(paired)], err.partial[len(paired) :]))))  # type: ignore[attr-defined]
            raise
        rows(dict(zip(paired, zip(found[: len(paired)], found[len(paired) :]))))

    def rows(runs: dict[int, Any]) -> None:
        """A row for each orbit whose pair ran to its end (or diverged), in orbit order."""
        for o in range(len(q_seed)):
            if not ok[o]:
                table.meta["notes"].append(f"orbit {o}: no twin on the energy shell")
                continue
            (a, note_a), (b, note_b) = runs[o]
            if "interrupted" in (note_a, note_b):
                continue
            m = min(len(a.t), len(b.t))
            d = np.sqrt(np.sum((a.q[:m] - b.q[:m]) ** 2 + (a.p[:m] - b.p[:m]) ** 2, axis=1))
            value = float(np.log10(np.max(d) / d[0]))
            for note in (note_a, note_b):
                if note:
                    table.meta["notes"].append(f"orbit {o}: {note}")
            table.append(o, float(q_seed[o, j]), float(p_seed[o, j]), value, bool(value >= threshold))
            table.meta["chaotic_fraction"] = float(np.mean(table.column("chaotic").astype(bool)))

    return interruptible(table, body)


def covered_cells(table: Table, *, bins: int = 40, extent: Any = None, points: int | None = None) -> Table:
    """Box counting on a Poincaré section: how many cells of a ``bins`` × ``bins`` grid over
    ``extent`` = ((a_min, a_max), (b_min, b_max)) of the plane (default: the bounding box of all
    the table's points) each orbit's section points fall into, using its first ``points``
    points (all by default). A regular orbit's points lie on a curve and fill O(bins) cells,
    a chaotic orbit's fill an area, O(bins²) cells given enough points.

    Parameters
    ----------
    table : Table
        A table returned by :func:`poincare_section`.
    bins : int, default 40
        Cells along each axis.
    extent : ((float, float), (float, float)), optional
        The plane's ranges; default: the bounding box of all the table's points.
    points : int, optional
        Use each orbit's first ``points`` points; default all.

    Returns
    -------
    Table
        One row per orbit: ``orbit``, ``points``, ``cells``, ``fraction`` (cells / bins²).

    Examples
    --------
    >>> import varmech
    >>> from varmech.analysis.sections import covered_cells, poincare_section
    >>> section = poincare_section(varmech.scenes.henon_heiles(), 1 / 12, orbits=2, dt=0.1,
    ...                            t_end=60.0, progress=False)
    >>> cells = covered_cells(section, bins=10)
    >>> cells.columns, len(cells)
    (('orbit', 'points', 'cells', 'fraction'), 2)
    """
    a_name, b_name = table.meta.get("plane", ("y", "p_y"))
    a, b, orbit = table.column(a_name), table.column(b_name), table.column("orbit")
    if extent is None:
        extent = ((a.min(), a.max()), (b.min(), b.max())) if len(a) else ((0, 1), (0, 1))
    (a0, a1), (b0, b1) = extent
    title = f"Covered cells ({bins} × {bins}): {table.title}"
    out = Table(("orbit", "points", "cells", "fraction"), title=title, meta={"extent": extent, "bins": bins})
    for o in table.unique("orbit"):
        sel = orbit == o
        aa, bb = a[sel], b[sel]
        if points is not None:
            aa, bb = aa[:points], bb[:points]
        ia = np.clip(((aa - a0) / (a1 - a0) * bins).astype(int), 0, bins - 1)
        ib = np.clip(((bb - b0) / (b1 - b0) * bins).astype(int), 0, bins - 1)
        cells = len(set(zip(ia.tolist(), ib.tolist())))
        out.append(o, int(len(aa)), cells, cells / bins**2)
    return out


__all__ = [
    "CHAOS_THRESHOLD",
    "HENON_HEILES_ENERGIES",
    "covered_cells",
    "orbit_divergence",
    "poincare_section",
]
