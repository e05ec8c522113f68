"""Stroboscopic sections of time-periodic models, and orbit diagrams over a parameter.

A model driven with period T (the damped, driven pendulum of the mechanics lecture, §8.2.2) is
seen "at the period of the forcing": its states at t₀ + kT. The runs are the core's, each a plain
:func:`varmech.integrate` (one :func:`varmech.ensemble` on every core for an orbit diagram) with
a step T/m saving every m-th state; this module declares them and reads the strobe off.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .. import _core
from .._util import finite, integer, positive, positive_int, vector
from ..ensemble import ensemble
from ..integrate import integrate
from ..model import Model
from ..scenes import Scene
from ..table import Table
from ._orbits import default_method

__all__ = ["orbit_diagram", "strobe_period", "stroboscopic_section"]

#: Relative agreement of ṗ at t and t + T that makes a model T-periodic: its functions' round-off.
PERIODIC = 1e-9


def check_periodic(model: Model, q0: np.ndarray, period: float, t0: float) -> None:
    """ValueError unless ``model`` depends on t, with ``period``: ṗ = ∂L/∂q + f at sample
    states near q0 must agree at t and t + T, and differ somewhere between (an autonomous model
    has no period to strobe at)."""
    rng = np.random.default_rng(37)
    n = model.dim
    q = q0[None, :] + rng.uniform(-1.0, 1.0, (4, n))
    v = rng.uniform(-1.0, 1.0, (4, n))
    phases = t0 + period * np.array([0.0, 0.1, 0.37, 0.61])

    def rate(t: float) -> np.ndarray:
        return np.asarray(_core.derivative(model._core, "dp_dt", np.full(4, t), q, v))

    rates = [rate(t) for t in phases]
    scale = max(float(np.max(np.abs(r))) for r in rates) or 1.0
    if all(np.max(np.abs(r - rates[0])) <= PERIODIC * scale for r in rates[1:]):
        raise ValueError(
            f"model: {model.name} does not depend on t, so it has no period to strobe at; its sections are "
            "Poincaré sections (varmech.poincare_section)"
        )
    for t in phases:
        shift = np.max(np.abs(rate(t + period) - rate(t)))
        if shift > PERIODIC * scale:
            raise ValueError(
                f"period: {model.name} is not periodic with period {period:g}: its forces at t = {t:g} and "
                f"t + period differ by {shift:.3g} (of {scale:.3g}); give the period of its forcing"
            )


def stroboscopic_section(
    model: Model | Scene,
    q0: ArrayLike,
    p0: ArrayLike,
    *,
    period: float,
    periods: int,
    transient: int = 0,
    steps_per_period: int = 200,
    method: str | None = None,
    t0: float = 0.0,
) -> Table:
    """The states of a T-periodic model at the period of its forcing, t₀ + kT.

    One run of ``method`` with the step T/``steps_per_period``, saving every
    ``steps_per_period``-th state: the strobe's points are the run's own states, not
    interpolated. The first ``transient`` periods are run and dropped, so that an attractor's
    strobe is left.

    Parameters
    ----------
    model
        A model that depends on t with period ``period`` (a forced or time-dependent one), or a
        scene.
    q0, p0
        The initial state.
    period
        T, the forcing's period.
    periods
        Periods kept after the transient.
    transient
        Periods run first and dropped.
    steps_per_period
        Steps a period: the step is T/``steps_per_period``.
    method
        The method (default: the model kind's accurate one).
    t0
        The initial time.

    Returns
    -------
    Table
        Columns ``k`` (the period's index from t0), ``t``, then q and p by coordinate
        (``q0``, ``p0``, …); ``meta`` holds the run's step and method.

    Raises
    ------
    ValueError
        A model that does not depend on t (naming ``model``), or whose forces at t and t + T
        differ (naming ``period``); arguments out of range, by name.

    Examples
    --------
    The damped, driven pendulum at Taylor's drive γ = 1.075 (the scene's time unit is 1/ω₀, its
    drive period 3π): after the transient, a period-2 orbit, two points that alternate.

    >>> import math
    >>> import numpy as np
    >>> import varmech
    >>> scene = varmech.scenes.get("damped_driven_pendulum", amplitude=1.075)
    >>> table = stroboscopic_section(scene, [-math.pi / 2], [0.0], period=3 * math.pi, periods=8, transient=200)
    >>> strobe_period(table.column("p0"))
    2
    """
    model = model.model if isinstance(model, Scene) else model
    n = model.dim
    q0, p0 = vector("q0", q0, n), vector("p0", p0, n)
    period, t0 = positive("period", period), finite("t0", t0)
    periods, m = positive_int("periods", periods), positive_int("steps_per_period", steps_per_period)
    transient = integer("transient", transient)
    check_periodic(model, q0, period, t0)
    method = default_method(model, method)
    dt = period / m
    traj = integrate(model, q0, p0, dt=dt, steps=m * (transient + periods), method=method, save_every=m, t0=t0, progress=False)
    keep = slice(transient, transient + periods + 1)
    columns = ("k", "t", *(f"q{j}" for j in range(n)), *(f"p{j}" for j in range(n)))
    names = {"coordinates": model.coordinates, "momenta": model.momentum_names}
    table = Table(columns, title=f"Stroboscopic section of {model.name}", meta={"dt": dt, "method": method, "period": period, **names})
    for k, (t, q, p) in enumerate(zip(traj.t[keep], traj.q[keep], traj.p[keep]), start=transient):
        table.append(k, float(t), *map(float, q), *map(float, p))
    return table


def strobe_period(x: ArrayLike, most: int = 64, tolerance: float = 1e-6) -> int | None:
    """The least P ≤ ``most`` with |x[k + P] − x[k]| ≤ ``tolerance``·max(1, |x|) for every k (a
    period-P orbit's strobe), or None: longer, quasi-periodic or chaotic.

    Parameters
    ----------
    x : array_like
        One coordinate of a strobe, in order.
    most : int, optional
        The longest period looked for.
    tolerance : float, optional
        The agreement, relative to max(1, |x|), that counts as a repeat.

    Returns
    -------
    int or None
        The period, or None.

    Raises
    ------
    ValueError
        ``x`` not one-dimensional, or ``most`` not a positive integer.

    Examples
    --------
    >>> strobe_period([1.0, 2.0, 1.0, 2.0, 1.0])
    2
    >>> strobe_period([0.1, 0.5, 0.3, 0.9]) is None
    True
    """
    x = np.asarray(x, dtype=float)
    if x.ndim != 1:
        raise ValueError(f"x: must be one coordinate of a strobe, shape (k,), got shape {x.shape}")
    most = positive_int("most", most)
    bound = tolerance * max(1.0, float(np.max(np.abs(x)))) if x.size else tolerance
    for p in range(1, min(most, len(x) - 1) + 1):
        if np.max(np.abs(x[p:] - x[:-p])) <= bound:
            return p
    return None


def orbit_diagram(
    scene: Scene,
    q0: ArrayLike,
    p0: ArrayLike,
    *,
    parameter: str,
    values: ArrayLike,
    period: float,
    periods: int = 64,
    transient: int = 200,
    steps_per_period: int = 200,
    method: str | None = None,
    coordinate: str = "p0",
    workers: int | None = None,
) -> Table:
    """The strobe's attractor over a sweep of one parameter: a bifurcation (orbit) diagram.

    One :func:`varmech.ensemble` on ``workers`` cores, a member a value of ``parameter``, each
    member's run as :func:`stroboscopic_section` takes it; the table has a row a strobe point,
    and ``meta["periods"]`` each value's strobe period (:func:`strobe_period` of
    ``coordinate``; None where chaotic or longer than 64).

    Parameters
    ----------
    scene
        A scene with the parameter (``varmech.scenes.get(name, …)``), or a symbolic model with
        it.
    q0, p0
        Every member's initial state.
    parameter
        The parameter's name.
    values
        Its values, one a member.
    period, periods, transient, steps_per_period, method
        As for :func:`stroboscopic_section`.
    coordinate
        The column (``q0``, ``p0``, …) whose strobe gives the period.
    workers
        Threads (default: every core).

    Returns
    -------
    Table
        Columns ``value``, ``k``, then q and p by coordinate.

    Raises
    ------
    ValueError
        ``values`` empty or not finite, ``coordinate`` not a column, a model without the period
        (as for :func:`stroboscopic_section`), or a parameter the model has not, naming it.

    Examples
    --------
    >>> import math
    >>> import varmech
    >>> scene = varmech.scenes.get("damped_driven_pendulum")
    >>> table = orbit_diagram(scene, [-math.pi / 2], [0.0], parameter="amplitude", values=[1.06, 1.075, 1.08],
    ...                       period=3 * math.pi, periods=16)
    >>> [table.meta["periods"][v] for v in (1.06, 1.075, 1.08)]
    [1, 2, 4]
    """
    model = scene.model if isinstance(scene, Scene) else scene
    n = model.dim
    q0, p0 = vector("q0", q0, n), vector("p0", p0, n)
    values = np.asarray(values, dtype=float).ravel()
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise ValueError(f"values: must be finite, at least one, got {values}")
    period = positive("period", period)
    periods, m = positive_int("periods", periods), positive_int("steps_per_period", steps_per_period)
    transient = integer("transient", transient)
    columns = ("k", *(f"q{j}" for j in range(n)), *(f"p{j}" for j in range(n)))
    if coordinate not in columns[1:]:
        raise ValueError(f"coordinate: must be one of {', '.join(columns[1:])}, got {coordinate!r}")
    check_periodic(model, q0, period, 0.0)
    method = default_method(model, method)
    members = values.size
    runs = ensemble(
        scene,
        np.tile(q0, (members, 1)),
        np.tile(p0, (members, 1)),
        parameters={parameter: values},
        dt=period / m,
        steps=m * (transient + periods),
        method=method,
        save_every=m,
        workers=workers,
        progress=False,
    )
    table = Table(("value", *columns), title=f"Orbit diagram of {model.name} over {parameter}")
    found: dict[float, int | None] = {}
    index = columns.index(coordinate) - 1
    for value, traj in zip(values, runs.trajectories):
        state = np.hstack([traj.q, traj.p])[transient:]
        found[float(value)] = strobe_period(state[:, index])
        for k, row in enumerate(state, start=transient):
            table.append(float(value), k, *map(float, row))
    table.meta.update({"parameter": parameter, "period": period, "dt": period / m, "method": method, "periods": found})
    table.meta.update(coordinates=model.coordinates, momenta=model.momentum_names)
    return table
