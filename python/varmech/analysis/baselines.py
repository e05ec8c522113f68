"""The baselines of the measurements: SciPy's ``solve_ivp`` and REBOUND, driven on a varmech scene.

Both packages are optional: each is imported when a baseline needs it, and a baseline whose package
is missing (or that does not apply to the scene) is skipped with a note, by :func:`scipy_baselines`
and :func:`rebound_baselines`. REBOUND's C library installs its own SIGINT handler while it
integrates; every REBOUND run here gives SIGINT back to Python afterwards (:func:`restore_sigint`),
so that Ctrl-C keeps reaching varmech's loops.
"""

from __future__ import annotations

import signal
from collections.abc import Sequence
from typing import Any

import numpy as np

from .. import _core
from ..model import Model
from ..scenes import Scene

#: solve_ivp's methods, and REBOUND's integrators this package drives.
SCIPY_METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")
REBOUND_METHODS = ("WHFast", "IAS15")


# ------------------------------------------------------------------------------------ scipy


class Rhs:
    """The first-order system q̇ = q̇(q, p), ṗ = ∂L/∂q(q, q̇, t) of a model for solve_ivp: y is
    (2n,), or (2n, k) columns when ``vectorized=True`` (Radau's and BDF's finite-difference
    Jacobians), and every column counts as one force evaluation. For a separable model,
    q̇ = M⁻¹p with M⁻¹ computed once, and ∂L/∂q = −∇V(q) does not depend on q̇."""

    def __init__(self, model: Model):
        self.core = model._core
        self.n = n = model.dim
        self.count = 0
        self.inverse_mass: np.ndarray | None = None
        self._diagonal: np.ndarray | None = None
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


def scipy_unsupported(scene: Scene) -> str | None:
    """Why solve_ivp does not apply to ``scene`` (forced, or constrained), None when it does."""
    m = scene.model
    if m.forced:
        return "the scene is forced (solve_ivp baselines would need its forces)"
    if m.constraints:
        return "the scene is constrained (a DAE; solve_ivp baselines do not apply)"
    return None


def import_scipy() -> Any | None:
    """``scipy.integrate.solve_ivp``, or None without SciPy."""
    try:
        from scipy.integrate import solve_ivp
    except ImportError:
        return None
    return solve_ivp


def scipy_baselines(scene: Scene, names: Sequence[str], notes: list[str]) -> tuple[Any | None, list[str]]:
    """``(solve_ivp, names)`` of the solve_ivp baselines that will run on ``scene``: none, with a
    note saying why, when SciPy is missing or the scene is forced or constrained."""
    if not names:
        return None, []
    why = scipy_unsupported(scene)
    if why is not None:
        notes.append(f"solve_ivp baselines skipped: {why}")
        return None, []
    solve_ivp = import_scipy()
    if solve_ivp is None:
        notes.append("solve_ivp baselines skipped: SciPy is not installed (pip install scipy)")
        return None, []
    return solve_ivp, list(names)


def default_atol(scene: Scene, rtol: float) -> np.ndarray:
    """rtol × 10⁻³ × the largest initial |q| (positions) and |p| (momenta): absolute tolerances
    well under the relative ones at the scene's scale."""
    n = scene.model.dim
    scales = [float(np.max(np.abs(x))) or 1.0 for x in (scene.q0, scene.p0)]
    return np.repeat(np.array(scales) * rtol * 1e-3, n)


def solve(solve_ivp: Any, scene: Scene, method: str, t_end: float, rtol: float, atol: Any, t_eval: Any = None) -> tuple[Any, int]:
    """One solve_ivp run of ``scene`` to ``t_end``: the solution and the force evaluations. A
    symbolic model's right-hand side is its lambdified first-order system (what a SciPy user
    would write from the same L, and faster than calling the model through the binding)."""
    first_order = getattr(scene.model, "first_order", None)
    rhs = (first_order() if first_order is not None else None) or Rhs(scene.model)
    y0 = np.concatenate([scene.q0, scene.p0])
    a = default_atol(scene, rtol) if atol is None else atol
    # Implicit methods get columns at once for their finite-difference Jacobians.
    vectorized = method in ("Radau", "BDF")
    sol = solve_ivp(rhs, (0.0, t_end), y0, method=method, rtol=rtol, atol=a, vectorized=vectorized, t_eval=t_eval)
    if sol.status != 0:
        raise RuntimeError(f"solve_ivp {method} (rtol {rtol:g}): {sol.message}")
    return sol, rhs.count


# ---------------------------------------------------------------------------------- REBOUND


def gravity(scene: Scene) -> tuple[float, list[float]] | None:
    """(G, masses) of an N-body scene, None otherwise."""
    return getattr(scene.model._core, "gravity", None)


def import_rebound() -> Any | None:
    """The ``rebound`` module, or None without REBOUND."""
    try:
        import rebound
    except ImportError:
        return None
    return rebound


def rebound_baselines(scene: Scene, names: Sequence[str], notes: list[str], *, asked: bool) -> tuple[Any | None, list[str]]:
    """``(rebound, names)`` of the REBOUND baselines that will run on ``scene``: none on a scene
    that is not N-body (with a note when they were ``asked`` for by name), nor without REBOUND
    (with a note)."""
    if not names:
        return None, []
    if gravity(scene) is None:
        if asked:
            notes.append(f"REBOUND baselines {list(names)} skipped: {scene.name} is not an N-body scene")
        return None, []
    rb = import_rebound()
    if rb is None:
        notes.append("REBOUND baselines skipped: REBOUND is not installed (pip install rebound)")
        return None, []
    return rb, list(names)


def rebound_sim(rebound: Any, scene: Scene, integrator: str, *, dt: float, epsilon: float | None = None) -> Any:
    """A REBOUND simulation of the N-body ``scene`` with ``integrator`` (WHFast or IAS15)."""
    G, masses = gravity(scene)  # type: ignore[misc]
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


def rebound_state(sim: Any, masses: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """The simulation's (q, p), flattened as varmech's N-body scenes order them."""
    x = np.array([[pt.x, pt.y, pt.z] for pt in sim.particles])
    v = np.array([[pt.vx, pt.vy, pt.vz] for pt in sim.particles])
    return x.ravel(), (np.asarray(masses)[:, None] * v).ravel()


def restore_sigint() -> None:
    """Give SIGINT back to Python: REBOUND's C library installs its own handler while it
    integrates and leaves it, after which Ctrl-C would no longer reach varmech's loops."""
    signal.signal(signal.SIGINT, signal.getsignal(signal.SIGINT))


def rebound_advance(sim: Any, integrator: str, steps: int | None, t: float) -> None:
    """WHFast: ``steps`` steps; IAS15: to time ``t`` exactly."""
    try:
        if integrator == "WHFast":
            sim.steps(int(steps))  # type: ignore[arg-type]
        else:
            sim.integrate(t, exact_finish_time=1)
    finally:
        restore_sigint()


def rebound_evaluations(rebound: Any, scene: Scene, integrator: str, t_end: float, dt: float, steps: int | None, epsilon: float | None) -> int:
    """Force evaluations of a REBOUND run, counted by a no-op additional force (in a separate,
    untimed run)."""
    sim = rebound_sim(rebound, scene, integrator, dt=dt, epsilon=epsilon)
    count = [0]

    def tally(_sim: Any) -> None:
        count[0] += 1

    sim.additional_forces = tally
    sim.force_is_velocity_dependent = 0
    rebound_advance(sim, integrator, steps, t_end)
    return count[0]
