"""Phase portraits of one-degree-of-freedom systems: orbits at chosen energies, each classified as
a libration or a rotation against the separatrix."""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np
from numpy.typing import ArrayLike

from .._util import positive
from ..model import Model
from ..table import Table
from ..trajectory import Trajectory
from ._interrupt import interruptible
from ._orbits import ModelLike, default_method, model_of, run_orbits, solve_momentum

#: The pendulum's default phase-portrait energies (H = p²/2 − cos q, separatrix at H = 1).
PENDULUM_ENERGIES = (-0.9, -0.6, -0.2, 0.3, 0.7, 0.95, 0.995, 1.005, 1.05, 1.4, 2.0, 3.0)


def _is_pendulum(model: Model) -> bool:
    return model.name == "pendulum"

def _classify(q: np.ndarray, p: np.ndarray) -> str:
    """'libration' when the momentum reverses and q stays within a window narrower than 2π;
    'rotation' when it never reverses and q advances by 2π or more; 'undetermined' otherwise
    (a run too short to tell)."""
    reverses = bool(np.any(np.sign(p[1:]) * np.sign(p[:-1]) < 0))
    span = float(np.max(q) - np.min(q))
    if reverses and span < 2 * math.pi:
        return "libration"
    if not reverses and abs(float(q[-1] - q[0])) >= 2 * math.pi:
        return "rotation"
    return "undetermined"


def phase_portrait(
    model_or_scene: ModelLike,
    energies: Iterable[float] | None = None,
    *,
    initial_states: ArrayLike | None = None,
    q_start: float = 0.0,
    mirror: bool = True,
    dt: float = 0.01,
    t_end: float = 40.0,
    method: str | None = None,
    save_every: int = 5,
    progress: bool | None = None,
) -> Table:
    """Orbits of a one-degree-of-freedom system in its phase plane (q, p).

    The orbits start from ``initial_states`` (rows (q, p)), or at q = ``q_start`` with p > 0 from
    each of ``energies`` (default for the pendulum: :data:`PENDULUM_ENERGIES`, librations below
    the separatrix energy 1, rotations above it, both close to it). With ``mirror``, an orbit
    classified as a rotation gets a twin with −p (it turns the other way; a libration's mirror
    is the same curve). The orbits are one :func:`varmech.ensemble` (each bit for bit its
    :func:`varmech.integrate` call; ``kahan_li6`` for separable models by default, ``galerkin6``
    otherwise), and their mirrors another, saving every ``save_every`` steps.

    Parameters
    ----------
    model_or_scene : Model or Scene
        An unconstrained, conservative model of one degree of freedom, e.g.
        :func:`varmech.scenes.pendulum` (H = p²/2 − cos q).
    energies : iterable of float, optional
        The orbits' energies H₀ (default :data:`PENDULUM_ENERGIES` for the pendulum; required
        otherwise, unless ``initial_states`` is given).
    initial_states : array_like, shape (m, 2), optional
        Rows (q, p) to start from instead of ``energies``.
    q_start : float, default 0.0
        Where the orbits of ``energies`` start, with p > 0 solved from H(q_start, p) = H₀.
    mirror : bool, default True
        Add a twin with −p to each rotation.
    dt : float, default 0.01
        The step, in the scene's time units.
    t_end : float, default 40.0
        Each orbit's horizon.
    method : str, optional
        A varmech method (default ``kahan_li6`` for separable models, ``galerkin6`` otherwise).
    save_every : int, default 5
        Steps between saved states.
    progress : bool, optional
        Show a progress bar: None on a terminal only, True or False to force it.

    Returns
    -------
    Table
        One row per saved state: ``orbit``, ``energy`` (H at the start), ``motion`` (from the
        trajectory: ``"libration"`` if p reverses and q stays within 2π, ``"rotation"`` if p
        never reverses and q advances by 2π or more, else ``"undetermined"``), ``t``, ``q``,
        ``p`` and ``energy_error`` = H − H₀ (absolute: a portrait's energies pass through 0).
        ``meta["max_energy_error"]`` is its largest magnitude; ``meta["separatrix_energy"]``
        is 1 for the pendulum; ``meta["notes"]`` names orbits that diverged.

    Raises
    ------
    TypeError
        ``model_or_scene`` is neither a model nor a scene.
    ValueError
        A constrained or non-conservative model, or one with more than one degree of freedom;
        ``dt`` or ``t_end`` not positive and finite; both or (except for the pendulum) neither
        of ``energies`` and ``initial_states``; ``initial_states`` not rows of two finite
        numbers; an energy below the potential at ``q_start``; or an unknown ``method``.
    KeyboardInterrupt
        On Ctrl-C, with the rows measured so far as ``err.partial``.

    See Also
    --------
    varmech.charts.sections.phase_portrait_chart : Plots the portrait.
    varmech.analysis.sections.poincare_section : The analogue for two degrees of freedom.

    Examples
    --------
    >>> import varmech
    >>> from varmech.analysis.phase_portrait import phase_portrait
    >>> table = phase_portrait(varmech.scenes.pendulum(), [-0.5, 2.0], dt=0.05, t_end=20.0,
    ...                        progress=False)
    >>> table.columns
    ('orbit', 'energy', 'motion', 't', 'q', 'p', 'energy_error')
    >>> table.unique("motion"), table.unique("orbit")   # the rotation got a mirror, orbit 2
    (['libration', 'rotation'], [0, 1, 2])
    >>> table.meta["max_energy_error"] < 1e-9
    True
    """
    model = model_of(model_or_scene)
    if model.dim != 1:
        raise ValueError(f"model_or_scene: a phase portrait needs one degree of freedom, {model.name} has {model.dim}; use poincare_section")
    dt = positive("dt", dt)
    t_end = positive("t_end", t_end)
    method = default_method(model, method)
    if initial_states is not None:
        if energies is not None:
            raise ValueError("energies, initial_states: give one of them")
        z = np.atleast_2d(np.array(initial_states, dtype=float))
        if z.shape[1] != 2 or not np.all(np.isfinite(z)):
            raise ValueError(f"initial_states: expected rows (q, p), got shape {z.shape}")
        starts = [(float(a), float(b)) for a, b in z]
    else:
        if energies is None:
            if not _is_pendulum(model):
                raise ValueError("energies: give the energies (or initial_states) of the orbits")
            energies = PENDULUM_ENERGIES
        es = np.array(list(energies), dtype=float)
        q = np.full((len(es), 1), float(q_start))
        starts = []
        for e, qi in zip(es, q):
            p, ok = solve_momentum(model, qi[None, :], np.zeros((1, 1)), 0, float(e), 1)
            if not ok[0]:
                raise ValueError(f"energies: {e} is below the potential at q = {q_start}")
            starts.append((float(qi[0]), float(p[0, 0])))
    table = Table(
        ("orbit", "energy", "motion", "t", "q", "p", "energy_error"),
        title=f"Phase portrait: {model.name}, t = 0 … {t_end:g}",
        meta={
            "model": model.name, "method": method, "dt": dt, "t_end": t_end, "max_energy_error": 0.0, "notes": [],
            "coordinates": model.coordinates, "momenta": model.momentum_names,
        },  # fmt: skip
    )
    if _is_pendulum(model):
        table.meta["separatrix_energy"] = 1.0

    def add(o: int, traj: Trajectory, note: str | None) -> str:
        if note:
            table.meta["notes"].append(f"orbit {o}: {note}")
        h = traj.energy()
        err = h - h[0]
        motion = _classify(traj.q[:, 0], traj.p[:, 0])
        for t, q, p, e in zip(traj.t, traj.q[:, 0], traj.p[:, 0], err):
            table.rows.append((o, float(h[0]), motion, float(t), float(q), float(p), float(e)))
        table.meta["max_energy_error"] = max(table.meta["max_energy_error"], float(np.max(np.abs(err))))
        return motion

    def run(states: list[tuple[float, float]]) -> list[tuple[Trajectory, str | None]]:
        z = np.array(states).reshape(-1, 2)
        return run_orbits(model, z[:, :1], z[:, 1:], dt=dt, t_end=t_end, method=method, save_every=save_every, progress=progress)

    def body() -> None:
        first = run(starts)
        turning = [mirror and _classify(traj.q[:, 0], traj.p[:, 0]) == "rotation" for traj, _ in first]
        mirrors = iter(run([(q0, -p0) for (q0, p0), turns in zip(starts, turning) if turns]))
        o = 0
        for (traj, note), turns in zip(first, turning):
            add(o, traj, note)
            o += 1
            if turns:
                add(o, *next(mirrors))
                o += 1

    return interruptible(table, body)


__all__ = ["PENDULUM_ENERGIES", "phase_portrait"]
