"""The energy of a rolling disk over a long run: the discrete Lagrange–d'Alembert integrators
against a naive projection method.

The vertical disk rolling without slipping (q = (x, y, θ, φ), ẋ = Rφ̇ cos θ, ẏ = Rφ̇ sin θ)
conserves its energy, its spin θ̇ and its rolling rate φ̇. :func:`nonholonomic_energy` follows
the relative energy error |E(t) − E₀|/E₀ of the reversible discrete Lagrange–d'Alembert
integrator (``midpoint``, McLachlan & Perlmutter 2006), of its order-4 composition (``dla4``),
of Cortés & Martínez's non-reversible step (``cortes_martinez``) and of ``rk4_projection``,
classical RK4 on the Lagrange–d'Alembert equations followed by a projection of the velocity
onto A(q)q̇ = 0 (a comparator here, not a varmech method).
:func:`varmech.charts.nonholonomic.nonholonomic_energy_chart` plots the table.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from .._progress import progress as _progress
from ..conservation import energy_statistics
from ..integrate import integrate
from ..model import MechanicalSystem
from ..table import Table
from ._interrupt import interruptible

__all__ = [
    "NONHOLONOMIC_ENERGY_COLUMNS",
    "RK4_PROJECTION",
    "nonholonomic_energy",
]

#: The columns of a :func:`nonholonomic_energy` table.
NONHOLONOMIC_ENERGY_COLUMNS = ("method", "t", "energy_error")

#: The naive comparator's name in the table.
RK4_PROJECTION = "rk4_projection"

#: The disk: mass m = 1, moments I = mR²/4 about a diameter and J = mR²/2 about the axle, R = 1.
DISK_MASS = np.array([1.0, 1.0, 0.25, 0.5])

#: From the origin heading θ = 0.3, turning at θ̇ = 0.7 and rolling at φ̇ = 2 (on the constraint).
DISK_Q0 = np.array([0.0, 0.0, 0.3, 0.0])
DISK_V0 = np.array([2.0 * np.cos(0.3), 2.0 * np.sin(0.3), 0.7, 2.0])


def rolling(q: np.ndarray) -> np.ndarray:
    """A(q) of the disk of radius 1: rows ẋ − φ̇ cos θ = 0 and ẏ − φ̇ sin θ = 0."""
    return np.array([[1.0, 0.0, 0.0, -np.cos(q[2])], [0.0, 1.0, 0.0, -np.sin(q[2])]])


def rolling_rate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(dA/dt)q̇ of the disk: θ̇φ̇ (sin θ, −cos θ)."""
    return v[2] * v[3] * np.array([np.sin(q[2]), -np.cos(q[2])])


def rolling_disk() -> MechanicalSystem:
    """The vertical rolling disk as a closure model with velocity constraints."""
    return MechanicalSystem(
        4, lambda q: 0.0, lambda q: np.zeros(4), mass=DISK_MASS,
        velocity_constraints=rolling, velocity_constraint_count=2, name="rolling disk",
    )


def rk4_projection(
    mass: np.ndarray,
    force: Callable[[np.ndarray], np.ndarray],
    constraints: Callable[[np.ndarray], np.ndarray],
    constraints_rate: Callable[[np.ndarray, np.ndarray], np.ndarray],
    q0: np.ndarray,
    v0: np.ndarray,
    *,
    dt: float,
    steps: int,
    save_every: int = 1,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Classical RK4 on the Lagrange–d'Alembert equations of a diagonal mass M, then the
    velocity projected M-orthogonally onto A(q)q̇ = 0 after every step: the naive method.

    The acceleration solves M q̈ = f(q) + A(q)ᵀλ with A q̈ + (dA/dt) q̇ = 0, so
    (A M⁻¹ Aᵀ) λ = −(dA/dt) q̇ − A M⁻¹ f; the projection is q̇ ← q̇ − M⁻¹Aᵀ(A M⁻¹ Aᵀ)⁻¹ A q̇.
    Returns (t, q, v) at every ``save_every``-th state, the first included.

    Examples
    --------
    >>> from varmech.analysis.nonholonomic import DISK_MASS, DISK_Q0, DISK_V0, rolling, rolling_rate
    >>> t, q, v = rk4_projection(DISK_MASS, lambda q: np.zeros(4), rolling, rolling_rate,
    ...                          DISK_Q0, DISK_V0, dt=0.1, steps=10)
    >>> bool(np.abs(rolling(q[-1]) @ v[-1]).max() < 1e-15)
    True
    """
    minv = 1.0 / np.asarray(mass, dtype=float)

    def acceleration(q: np.ndarray, v: np.ndarray) -> np.ndarray:
        a, u = constraints(q), minv * force(q)
        lam = np.linalg.solve((a * minv) @ a.T, -constraints_rate(q, v) - a @ u)
        return u + minv * (a.T @ lam)

    q, v = np.array(q0, dtype=float), np.array(v0, dtype=float)
    saved = [(0.0, q.copy(), v.copy())]
    for k in range(1, steps + 1):
        k1q, k1v = v, acceleration(q, v)
        k2q, k2v = v + 0.5 * dt * k1v, acceleration(q + 0.5 * dt * k1q, v + 0.5 * dt * k1v)
        k3q, k3v = v + 0.5 * dt * k2v, acceleration(q + 0.5 * dt * k2q, v + 0.5 * dt * k2v)
        k4q, k4v = v + dt * k3v, acceleration(q + dt * k3q, v + dt * k3v)
        q = q + dt / 6 * (k1q + 2 * k2q + 2 * k3q + k4q)
        v = v + dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        a = constraints(q)
        v = v - minv * (a.T @ np.linalg.solve((a * minv) @ a.T, a @ v))
        if k % save_every == 0:
            saved.append((k * dt, q.copy(), v.copy()))
    t, qs, vs = zip(*saved)
    return np.array(t), np.array(qs), np.array(vs)


def nonholonomic_energy(
    methods: Iterable[str] = ("midpoint", "cortes_martinez", RK4_PROJECTION),
    *,
    dt: float = 0.1,
    steps: int = 100_000,
    samples: int = 2000,
    progress: bool | None = None,
) -> Table:
    """The rolling disk's relative energy error |E(t) − E₀|/E₀ over ``steps`` steps of ``dt``,
    at ``samples`` evenly spaced times, for each of ``methods`` (varmech methods for velocity
    constraints, and ``"rk4_projection"``: classical RK4 followed by the projection of the
    velocity onto the constraints A(q)v = 0 in the mass metric). This is the measurement behind
    ``python -m varmech chart nonholonomic``.

    Ctrl-C stops the sweep: the KeyboardInterrupt propagates with the methods measured so far as
    ``err.partial``.

    Parameters
    ----------
    methods : iterable of str, default ("midpoint", "cortes_martinez", "rk4_projection")
        varmech methods that take velocity constraints, and :data:`RK4_PROJECTION`.
    dt : float, default 0.1
        The step.
    steps : int, default 100000
        Steps of each run.
    samples : int, default 2000
        Evenly spaced times at which the energy error is recorded.
    progress : bool, optional
        Show a progress bar; default: on a terminal (stderr) or in a Jupyter notebook, unless TQDM_DISABLE is set.

    Returns
    -------
    Table
        Columns :data:`NONHOLONOMIC_ENERGY_COLUMNS` (``method``, ``t``, ``energy_error``), one
        row a sample; ``table.meta["verdicts"]`` holds each method's energy verdict
        ("bounded" or "secular drift") and ``table.meta["drift_rates"]`` its fitted drift rate
        d(E − E₀)/dt.

    Raises
    ------
    ValueError
        Naming ``steps`` or ``samples`` when below 1, or ``method`` for a method that does not
        take velocity constraints.

    See Also
    --------
    varmech.charts.nonholonomic_energy_chart : draws this table.
    varmech.analysis.energy_growth.energy_growth : the same measurement for other scenes.

    Examples
    --------
    >>> table = nonholonomic_energy(steps=200, samples=10)
    >>> table.unique("method")
    ['midpoint', 'cortes_martinez', 'rk4_projection']
    >>> bool(table.where(method="midpoint").column("energy_error").max() < 1e-13)
    True
    """
    methods = tuple(methods)
    steps, samples = int(steps), int(samples)
    if steps < 1:
        raise ValueError(f"steps: must be at least 1, got {steps}")
    if samples < 1:
        raise ValueError(f"samples: must be at least 1, got {samples}")
    save_every = max(1, steps // samples)
    model = rolling_disk()
    table = Table(
        NONHOLONOMIC_ENERGY_COLUMNS,
        title=f"rolling disk: relative energy error over {steps} steps of dt = {dt:g}",
        meta={"scene": "rolling disk", "dt": dt, "steps": steps, "verdicts": {}, "drift_rates": {}},
    )

    def body() -> None:
        for method in _progress(methods, desc="nonholonomic energy", enabled=progress):
            if method == RK4_PROJECTION:
                zero = lambda q: np.zeros(4)  # noqa: E731
                t, q, v = rk4_projection(
                    DISK_MASS, zero, rolling, rolling_rate, DISK_Q0, DISK_V0, dt=dt, steps=steps, save_every=save_every
                )
                p = v * DISK_MASS
            else:
                traj = integrate(
                    model, DISK_Q0, v0=DISK_V0, dt=dt, steps=steps, method=method, save_every=save_every,
                    max_energy_error=None,  # the drifting methods must be let drift
                )
                t, q, p = traj.t, traj.q, traj.p
            energy = 0.5 * np.sum(p * p / DISK_MASS, axis=1)
            stats = energy_statistics(model, t, q, p, steps=steps)
            table.meta["verdicts"][method] = stats.verdict
            table.meta["drift_rates"][method] = stats.drift_rate
            for ti, e in zip(t, np.abs(energy - energy[0]) / energy[0]):
                table.append(method, float(ti), float(e))

    return interruptible(table, body)
