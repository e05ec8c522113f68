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
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _core
from ..model import Model
from ..scenes import Scene

__all__: list[str] = []  # internal: importable, not part of the public API

#: solve_ivp's methods.
SCIPY_METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")


@dataclass(frozen=True)
class ReboundMethod:
    """A REBOUND integrator with the settings it runs with as a baseline."""

    #: REBOUND's name of the integrator (``sim.integrator``).
    integrator: str
    #: Attributes set on ``sim.integrator``.
    settings: tuple[tuple[str, int], ...] = ()
    #: Swept over its precision ε (IAS15), not over step counts.
    adaptive: bool = False
    #: Also a baseline on the Kepler scene, as a test particle of a unit mass (WHFast's Kepler
    #: drift would solve that scene exactly).
    kepler: bool = False


#: REBOUND's integrators this package drives, by name: WHFast and IAS15 at REBOUND's defaults;
#: WHFast with Wisdom, Holman & Touma's (1996) symplectic corrector of order 11, unsynchronised
#: between steps (``safe_mode=0``; ``keep_unsynchronized=1`` lets a run be sampled without
#: leaving its trajectory); ``leapfrog`` with ``order=8``, McLachlan's (1995) 17-stage
#: composition SS17 of drift–kick–drift Verlet (Blanes & Casas 2016, p. 91), varmech's
#: ``mclachlan8_dkd``.
REBOUND_BASELINES: dict[str, ReboundMethod] = {
    "WHFast": ReboundMethod("whfast"),
    "IAS15": ReboundMethod("ias15", adaptive=True),
    "WHFast corrector=11": ReboundMethod("whfast", (("corrector", 11), ("safe_mode", 0), ("keep_unsynchronized", 1))),
    "leapfrog order=8": ReboundMethod("leapfrog", (("order", 8),), kepler=True),
}
REBOUND_METHODS = tuple(REBOUND_BASELINES)
#: The REBOUND baselines a sweep runs unless told: REBOUND's integrators at their defaults.
REBOUND_DEFAULTS = ("WHFast", "IAS15")


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


def is_kepler(scene: Scene) -> bool:
    """Whether ``scene`` is Kepler's problem H = |p|²/2 − 1/|q| in the plane (the ``kepler``
    scene), which REBOUND integrates as a test particle of a unit mass at rest, G = 1."""
    return getattr(scene.model._core, "name", None) == "kepler"


def import_rebound() -> Any | None:
    """The ``rebound`` module, or None without REBOUND."""
    try:
        import rebound
    except ImportError:
        return None
    return rebound


def rebound_baselines(scene: Scene, names: Sequence[str], notes: list[str], *, asked: bool) -> tuple[Any | None, list[str]]:
    """``(rebound, names)`` of the REBOUND baselines of ``names`` that will run on ``scene``:
    every one on an N-body scene, the ``kepler`` ones on the Kepler scene, none elsewhere (those
    skipped noted when they were ``asked`` for by name), and none without REBOUND (with a note)."""
    if not names:
        return None, []
    nbody = gravity(scene) is not None
    runs = [n for n in names if nbody or (REBOUND_BASELINES[n].kepler and is_kepler(scene))]
    skipped = [n for n in names if n not in runs]
    if skipped and asked:
        why = "is not an N-body scene" if not runs else "is not an N-body scene; only the Kepler ones run"
        notes.append(f"REBOUND baselines {skipped} skipped: {scene.name} {why}")
    if not runs:
        return None, []
    rb = import_rebound()
    if rb is None:
        notes.append("REBOUND baselines skipped: REBOUND is not installed (pip install rebound)")
        return None, []
    return rb, runs


def rebound_sim(rebound: Any, scene: Scene, method: str, *, dt: float, epsilon: float | None = None) -> Any:
    """A REBOUND simulation of ``scene`` (N-body, or Kepler's test particle) with ``method``,
    one of :data:`REBOUND_METHODS`, its settings applied."""
    spec = REBOUND_BASELINES[method]
    sim = rebound.Simulation()
    if is_kepler(scene):
        (x, y), (vx, vy) = scene.q0, scene.p0
        sim.G = 1.0
        sim.add(m=1.0)
        sim.add(m=0.0, x=x, y=y, vx=vx, vy=vy)
        sim.N_active = 1  # the test particle pulls nothing: the unit mass stays at the origin
    else:
        G, masses = gravity(scene)  # type: ignore[misc]
        sim.G = G
        for m, x, p in zip(masses, scene.q0.reshape(-1, 3), scene.p0.reshape(-1, 3)):
            v = p / m
            sim.add(m=m, x=x[0], y=x[1], z=x[2], vx=v[0], vy=v[1], vz=v[2])
    sim.integrator = spec.integrator
    for name, value in spec.settings:
        setattr(sim.integrator, name, value)
    sim.dt = dt
    if epsilon is not None:
        cfg = getattr(sim, "ri_ias15", None) or sim.integrator  # REBOUND 4 / 5
        cfg.epsilon = epsilon
    return sim


def rebound_state(sim: Any, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """The simulation's (q, p) in ``scene``'s variables: every body's, flattened as varmech's
    N-body scenes order them, or the test particle's in the plane for Kepler (p = v)."""
    if is_kepler(scene):
        pt = sim.particles[1]
        return np.array([pt.x, pt.y]), np.array([pt.vx, pt.vy])
    _, masses = gravity(scene)  # type: ignore[misc]
    x = np.array([[pt.x, pt.y, pt.z] for pt in sim.particles])
    v = np.array([[pt.vx, pt.vy, pt.vz] for pt in sim.particles])
    return x.ravel(), (np.asarray(masses)[:, None] * v).ravel()


def restore_sigint() -> None:
    """Give SIGINT back to Python: REBOUND's C library installs its own handler while it
    integrates and leaves it, after which Ctrl-C would no longer reach varmech's loops."""
    signal.signal(signal.SIGINT, signal.getsignal(signal.SIGINT))


def rebound_advance(sim: Any, method: str, steps: int | None, t: float) -> None:
    """The fixed-step methods: ``steps`` steps, the state synchronised at the end (WHFast with
    ``safe_mode=0`` leaves it unsynchronised); IAS15: to time ``t`` exactly."""
    try:
        if REBOUND_BASELINES[method].adaptive:
            sim.integrate(t, exact_finish_time=1)
        else:
            sim.steps(int(steps))  # type: ignore[arg-type]
            sim.synchronize()
    finally:
        restore_sigint()


def rebound_evaluations(rebound: Any, scene: Scene, method: str, t_end: float, dt: float, steps: int | None, epsilon: float | None) -> int:
    """Force evaluations of a REBOUND run, counted by a no-op additional force (in a separate,
    untimed run)."""
    sim = rebound_sim(rebound, scene, method, dt=dt, epsilon=epsilon)
    count = [0]

    def tally(_sim: Any) -> None:
        count[0] += 1

    sim.additional_forces = tally
    sim.force_is_velocity_dependent = 0
    rebound_advance(sim, method, steps, t_end)
    return count[0]
