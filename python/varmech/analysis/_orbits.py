"""What the phase-space tools share: the model a section or portrait may take, its energy, the
method it runs by default, and its orbits, one ensemble in which an orbit that escapes keeps its
partial trajectory."""

from __future__ import annotations

import numpy as np

from .. import _core
from ..ensemble import Ensemble, ensemble
from ..events import Event
from ..model import Model
from ..scenes import Scene
from ..trajectory import Trajectory
from ._energy import energy_of

ModelLike = Model | Scene


def model_of(model_or_scene: ModelLike, forced: bool = False) -> Model:
    """The model of ``model_or_scene``, unconstrained, and conservative unless ``forced``."""
    model = model_or_scene.model if isinstance(model_or_scene, Scene) else model_or_scene
    if not isinstance(model, Model):
        raise TypeError(f"model_or_scene: expected a varmech model or scene, got {type(model_or_scene).__name__}")
    if model.constraints:
        raise ValueError(f"model_or_scene: {model.name} is constrained; sections need an unconstrained model")
    if not forced and not model.conserves_energy:
        raise ValueError(f"model_or_scene: {model.name} does not conserve its energy (time-dependent or forced)")
    return model


def energy_at(model: Model, q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """H(q, p) = p·q̇ − L for rows (N, n)."""
    q, p = np.atleast_2d(q), np.atleast_2d(p)
    return energy_of(model, np.zeros(len(q)), q, p)


def relative(h: np.ndarray, energy: float) -> np.ndarray:
    return (h - energy) / (abs(energy) if energy != 0 else 1.0)


def default_method(model: Model, method: str | None) -> str:
    if method is not None:
        return method
    return model.kind.accurate_method


def run_orbits(
    model: Model,
    q0: np.ndarray,
    p0: np.ndarray,
    *,
    dt: float,
    t_end: float,
    method: str,
    save_every: int = 1,
    events: list[Event] | None = None,
    progress: bool | None = None,
) -> list[tuple[Trajectory, str | None]]:
    """The orbits from the rows of ``q0`` and ``p0``, one :func:`varmech.ensemble` (each bit for
    bit its :func:`varmech.integrate` call, on every core for native models), with the crossings
    of ``events`` located: each with None, or its partial trajectory and a note if it diverged
    (an orbit that escapes). Ctrl-C raises KeyboardInterrupt with the orbits so far as
    ``err.partial`` (the interrupted ones partial, noted)."""
    if len(q0) == 0:
        return []
    try:
        runs = ensemble(model, q0, p0, dt=dt, t_end=t_end, method=method, save_every=save_every, events=events, progress=progress)
    except KeyboardInterrupt as err:
        err.partial = _outcomes(err.partial)  # type: ignore[attr-defined]
        raise
    return _outcomes(runs)


def _outcomes(runs: Ensemble) -> list[tuple[Trajectory, str | None]]:
    """Each member with None, or a note on why it stopped early; a failure other than a
    divergence or an interrupt is raised."""
    out: list[tuple[Trajectory, str | None]] = []
    for traj, err in zip(runs, runs.errors):
        if err is None:
            out.append((traj, None))
        elif isinstance(err, KeyboardInterrupt):
            out.append((traj, "interrupted"))
        elif isinstance(err, _core.DivergenceError) and len(traj):
            out.append((traj, f"diverged at t = {traj.t[-1]:.6g} ({err})"))
        else:
            raise err
    return out


def solve_momentum(model: Model, q: np.ndarray, p: np.ndarray, k: int, energy: float, direction: int) -> tuple[np.ndarray, np.ndarray]:
    """The momentum p_k that puts the states (q, p) (rows; p_k ignored) on H = ``energy`` with
    q̇_k of sign ``direction`` (+ when 0), and a mask of the rows where one exists.

    H is quadratic in p for every Lagrangian quadratic in q̇ (mechanical systems, magnetic
    terms), so three evaluations give it exactly; the result is checked to 1e-12."""
    q = np.ascontiguousarray(q, dtype=float)
    rows = []
    for value in (0.0, 1.0, -1.0):
        pp = np.array(p, dtype=float)
        pp[:, k] = value
        rows.append(energy_at(model, q, pp))
    e0, e1, em = rows
    a = 0.5 * (e1 + em) - e0
    b = 0.5 * (e1 - em)
    c = e0 - energy
    disc = b * b - 4 * a * c
    ok = (a > 0) & (disc > 0)
    root = np.sqrt(np.where(ok, disc, 0.0))
    out = np.array(p, dtype=float)
    want = 1 if direction >= 0 else -1
    best = np.full(len(q), np.nan)
    for sign in (1.0, -1.0):
        s = np.where(ok, (-b + sign * root) / np.where(ok, 2 * a, 1.0), np.nan)
        trial = np.array(p, dtype=float)
        trial[:, k] = np.where(ok, s, 0.0)
        v = model.velocity(q, trial)[:, k]
        pick = ok & np.isnan(best) & (np.sign(v) == want)
        best = np.where(pick, s, best)
    ok &= np.isfinite(best)
    out[:, k] = np.where(ok, best, 0.0)
    if ok.any():
        err = np.abs(energy_at(model, q[ok], out[ok]) - energy)
        if np.max(err) > 1e-12 * max(1.0, abs(energy)):
            raise ValueError(
                f"energy: H of {model.name} is not quadratic in p_{k} (|H − E| = {np.max(err):.2e} at the seed); "
                "give the full initial states instead"
            )
    return out, ok
