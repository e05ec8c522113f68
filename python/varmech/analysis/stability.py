"""Linear stability on q̈ = −ω²q, measured from the integrators themselves, and the failure
regions of the implicit methods on the pendulum.

The one-step map of every method in varmech is linear on the harmonic oscillator
H = p²/2 + ω²q²/2. With ω = 1 (so h = hω) one step from (q, p) = (1, 0) and one from (0, 1) give
its two columns, the step matrix

    Ψ(hω) = [[q₁(1, 0), q₁(0, 1)],
             [p₁(1, 0), p₁(0, 1)]],

computed by :func:`varmech.integrate` on ``scenes.harmonic_oscillator()`` (the native model, so
every method runs exactly as it does elsewhere, the implicit ones with their Newton solver).
Its eigenvalues are

    λ± = τ/2 ± √(τ²/4 − δ),   τ = tr Ψ,  δ = det Ψ,

and the growth factor is the spectral radius ρ(Ψ) = max |λ±|: after n steps a generic state
grows like ρⁿ. A symplectic method preserves area, δ = 1, so λ₊λ₋ = 1. Inside its stability
interval (|τ| < 2) the eigenvalues are a complex-conjugate pair on the unit circle, e^{±iθ} with
cos θ = τ/2: the map is conjugate to a rotation by θ, and ρ = 1 *exactly* (to round-off), with no
damping and no growth; the invariant ellipse only gets elongated near the limit. Beyond it
(|τ| > 2) they are real, λ and 1/λ, and ρ = |λ| > 1: the solution grows exponentially. The
stability limit is where τ = ±2 first happens, a double eigenvalue ±1 (ρ = 1, a Jordan block).
Non-symplectic methods have ρ ≠ 1: RK4's Ψ is R(hA) with R the degree-4 Taylor polynomial, so
ρ = |R(iy)| = √(1 − y⁶/72 + y⁸/576) < 1 for 0 < y < 2√2 (damping); explicit Euler's
ρ = √(1 + y²) > 1 at every y > 0.

:func:`stability_scan` finds the largest hω below which ρ ≤ 1 + tol on the whole interval: a fine
grid from 0, then bisection at the first instability. Symmetric compositions of Verlet can turn
stable again beyond that first instability and unstable once more (resonances of the stages);
:func:`unstable_intervals` lists those windows in a scan range. The *first* instability from 0
is the documented limit ``MethodInfo.h_omega_max``; :func:`stability_table` compares the scan
with reference/compositions.json.

:func:`implicit_regions` maps where the implicit methods fail on the pendulum over step size
and initial angle: Newton's iteration failing, a spurious branch beyond a fold of the discrete
Euler–Lagrange map, a blow-up, or an energy error past a threshold.

:func:`spectrum` puts a model's own frequencies against those intervals: the modes of its
linearization at a point (:func:`varmech.normal_modes`), scaled by a step, and each method's
stability interval hω < h_ω, so that which methods take that step on that model is read off.

Everything returns a :class:`~varmech.Table`; :mod:`varmech.charts.stability` draws them (this
module does not import matplotlib).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .. import scenes
from .._progress import progress as _progress
from .._util import finite, positive, vector
from ..integrate import integrate
from ..methods import MethodInfo
from ..methods import methods as _methods
from ..model import Model
from ..modes import StabilityWarning, normal_modes, stability_limits
from ..table import Table
from ._interrupt import interruptible

#: Where the reference limits come from (a file of the repository, not of the installed package).
REFERENCE_SOURCE = "reference/compositions.json"

#: The composition names of reference/compositions.json ("methods") and varmech's names for them.
COMPOSITION_NAMES: dict[str, str] = {
    "verlet": "verlet",
    "yoshida_triple_jump_4": "yoshida4",
    "suzuki_4_5stage": "suzuki4",
    "mclachlan_4_5stage": "mclachlan4",
    "yoshida_6_7stage": "yoshida6",
    "kahan_li_6_9stage": "kahan_li6",
    "suzuki_umeno_8_15stage": "suzuki_umeno8",
    "kahan_li_8_17stage": "kahan_li8",
    "mclachlan_6_9stage": "mclachlan6",
    "mclachlan_8_17stage": "mclachlan8",
}

#: Linear stability limits hω_max by varmech method name, copied from reference/compositions.json
#: (the ``h_omega_max`` of each composition in "methods", and the "other_linear_stability_facts":
#: RK4 stable up to y = 2√2, explicit Euler never, symplectic Euler below 2, the implicit midpoint
#: rule at every h). The JSON file lives in the repository, outside the installed package, so the
#: numbers are embedded here; tests/python/test_stability.py checks them against the file.
REFERENCE_LIMITS: dict[str, float] = {
    "verlet": 2.0,
    "yoshida4": 1.5734,
    "suzuki4": 2.721,
    "mclachlan4": 3.0182,
    "yoshida6": 2.2691,
    "kahan_li6": 2.5326,
    "suzuki_umeno8": 3.3932,
    "kahan_li8": 3.0964,
    "mclachlan6": 2.7031,
    "mclachlan8": 3.0871,
    "rk4": 2.0 * math.sqrt(2.0),
    "explicit_euler": 0.0,
    "symplectic_euler": 2.0,
    "midpoint": math.inf,
}

#: The implicit (Newton-solved) methods :func:`implicit_regions` maps by default: every implicit
#: method of :func:`varmech.methods` that integrates unconstrained systems.
IMPLICIT_METHODS = tuple(m.name for m in _methods() if m.implicit and not m.constrained and not m.nonholonomic)

#: The outcomes of :func:`implicit_regions`, from good to bad.
OUTCOMES = ("ok", "energy", "spurious branch", "newton failure", "diverged")

# Defaults of the scans.
DEFAULT_SCAN_MAX = 10.0
DEFAULT_RESOLUTION = 1e-3
DEFAULT_TOL = 1e-9
# Bisection stops when the bracket is this small relative to hω (or after _BISECT_MAX halvings).
_BISECT_RTOL = 1e-13
_BISECT_MAX = 80
# Sweeps longer than this get a progress bar (on a terminal, unless told otherwise).
_PROGRESS_MIN = 50

_OSCILLATOR: Any = None


def _oscillator() -> Any:
    """The native model of q̈ = −q (built once)."""
    global _OSCILLATOR
    if _OSCILLATOR is None:
        _OSCILLATOR = scenes.harmonic_oscillator(1.0).model
    return _OSCILLATOR


def checked_method(method: str) -> MethodInfo:
    """The :class:`~varmech.MethodInfo` of ``method``, one that integrates the linear test
    equation; ValueError naming ``method`` otherwise."""
    for info in _methods():
        if info.name == method:
            if info.constrained or info.nonholonomic:
                raise ValueError(
                    f"method: {method!r} integrates constrained systems only, and the linear test equation has no "
                    "constraint (its stability on the constrained manifold is that of the method it is built on)"
                )
            if info.nbody:
                raise ValueError(f"method: {method!r} integrates the gravitational N-body problem only, not the linear test equation")
            return info
    names = ", ".join(m.name for m in _methods())
    raise ValueError(f"method: unknown method {method!r}; one of {names}")


def _unconstrained() -> list[str]:
    """The methods of the linear test equation: neither constrained (holonomic or velocity
    constraints) nor N-body only."""
    return [m.name for m in _methods() if not m.constrained and not m.nonholonomic and not m.nbody]


def probe(*args: Any, **kwargs: Any) -> Any:
    """:func:`~varmech.integrate` where a measurement steps beyond a method's limit on
    purpose: without the :class:`~varmech.StabilityWarning` it would give."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StabilityWarning)
        return integrate(*args, **kwargs)


def _step_matrix(method: str, y: float) -> np.ndarray:
    model = _oscillator()
    a = probe(model, [1.0], [0.0], dt=y, steps=1, method=method, max_energy_error=None)
    b = probe(model, [0.0], [1.0], dt=y, steps=1, method=method, max_energy_error=None)
    return np.array([[a.q[-1, 0], b.q[-1, 0]], [a.p[-1, 0], b.p[-1, 0]]])


def _rho(psi: np.ndarray) -> float:
    """max |λ±| with λ± = τ/2 ± √(τ²/4 − δ)."""
    tau = psi[0, 0] + psi[1, 1]
    delta = psi[0, 0] * psi[1, 1] - psi[0, 1] * psi[1, 0]
    root = np.sqrt(complex(0.25 * tau * tau - delta))
    return float(max(abs(0.5 * tau + root), abs(0.5 * tau - root)))


def step_matrix(method: str, h_omega: float) -> np.ndarray:
    """The 2×2 matrix Ψ of one step of ``method`` on q̈ = −q with h = ``h_omega``: its columns are
    (q₁, p₁) after one step from (q, p) = (1, 0) and from (0, 1).

    Parameters
    ----------
    method : str
        A varmech method for unconstrained systems (:func:`varmech.methods`).
    h_omega : float
        The dimensionless step hω, positive.

    Returns
    -------
    numpy.ndarray
        Ψ, shape (2, 2).

    Raises
    ------
    ValueError
        An unknown ``method``, or one for constrained systems or the N-body problem only; or
        ``h_omega`` not positive and finite.

    Examples
    --------
    Verlet's step matrix [[1 − y²/2, y], [−y(1 − y²/4), 1 − y²/2]] has determinant 1
    (symplectic):

    >>> import numpy as np
    >>> from varmech.analysis.stability import step_matrix
    >>> psi = step_matrix("verlet", 1.0)
    >>> psi
    array([[ 0.5 ,  1.  ],
           [-0.75,  0.5 ]])
    >>> float(np.linalg.det(psi))
    1.0
    """
    checked_method(method)
    return _step_matrix(method, positive("h_omega", h_omega))


def growth_factor(method: str, h_omega: float | ArrayLike, *, progress: bool | None = False) -> Any:
    """The growth factor ρ(Ψ) = max |λ±| of one step of ``method`` on q̈ = −ω²q at hω.

    λ± = τ/2 ± √(τ²/4 − δ) are the eigenvalues of the step matrix Ψ (:func:`step_matrix`),
    τ = tr Ψ, δ = det Ψ. A symplectic method has δ = 1, hence ρ = 1 to round-off at every hω
    inside its stability interval and ρ > 1 beyond it; see the module's documentation.

    Parameters
    ----------
    method : str
        A varmech method for unconstrained systems (:func:`varmech.methods`).
    h_omega : float or array_like
        The dimensionless step hω, positive.
    progress : bool or None, default False
        Show a progress bar for arrays of 50 values or more: None on a terminal only.

    Returns
    -------
    float or numpy.ndarray
        ρ(Ψ): a float for a number, an array of the shape of ``h_omega`` for an array.

    Raises
    ------
    ValueError
        An unknown ``method``, or one for constrained systems or the N-body problem only;
        or a value of ``h_omega`` not positive and finite.

    See Also
    --------
    step_matrix : The matrix Ψ itself.
    stability_scan : The largest hω with ρ ≤ 1 + tol.
    growth_table : ρ over a grid of hω for several methods, as a Table.

    References
    ----------
    .. [1] E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
       Springer (2006), section I.5 and chapter XIII (linear stability of splitting methods).

    Examples
    --------
    >>> from varmech.analysis.stability import growth_factor
    >>> growth_factor("verlet", 1.5), growth_factor("verlet", 2.5)   # inside, beyond hω = 2
    (1.0, 4.0)
    >>> growth_factor("rk4", [0.5, 1.0]).round(5)                     # damped: ρ < 1
    array([0.99989, 0.99391])
    >>> round(growth_factor("explicit_euler", 1.0), 6)                 # √(1 + y²)
    1.414214
    """
    checked_method(method)
    if np.ndim(h_omega) == 0:
        return _rho(_step_matrix(method, positive("h_omega", h_omega)))  # type: ignore[arg-type]
    ys = np.asarray(h_omega, dtype=float)
    out = np.empty(ys.shape)
    flat = ys.ravel()
    for i in _progress(range(flat.size), total=flat.size, desc=f"growth {method}", enabled=progress_for(progress, flat.size)):
        out.flat[i] = _rho(_step_matrix(method, positive("h_omega", flat[i])))
    return out


def progress_for(progress: bool | None, n: int) -> bool | None:
    """A measurement's ``progress`` for ``n`` items: none by default for a short one."""
    return False if n < _PROGRESS_MIN and progress is None else progress


def _grid(h_omega_max: float, resolution: float) -> np.ndarray:
    n = max(1, math.ceil(h_omega_max / resolution - 1e-9))
    grid = resolution * np.arange(1, n + 1)
    grid[-1] = h_omega_max
    return grid


def _boundary(method: str, stable: float, unstable: float, tol: float) -> float:
    """The hω where ρ ≤ 1 + tol changes between a ``stable`` and an ``unstable`` hω (in either
    order), by bisection: the midpoint of the final bracket."""
    for _ in range(_BISECT_MAX):
        if abs(unstable - stable) <= _BISECT_RTOL * max(stable, unstable):
            break
        mid = 0.5 * (stable + unstable)
        if _rho(_step_matrix(method, mid)) > 1.0 + tol:
            unstable = mid
        else:
            stable = mid
    return 0.5 * (stable + unstable)


def _check_scan(h_omega_max: float, resolution: float, tol: float) -> tuple[float, float, float]:
    h_omega_max = positive("h_omega_max", h_omega_max)
    resolution = positive("resolution", resolution)
    tol = positive("tol", tol)
    if resolution > h_omega_max:
        raise ValueError(f"resolution: must not exceed h_omega_max = {h_omega_max}, got {resolution}")
    return h_omega_max, resolution, tol


def stability_scan(
    method: str,
    *,
    h_omega_max: float = DEFAULT_SCAN_MAX,
    resolution: float = DEFAULT_RESOLUTION,
    tol: float = DEFAULT_TOL,
    progress: bool | None = None,
) -> float:
    """The largest hω such that ``method`` is stable on all of (0, hω]: ρ(Ψ) ≤ 1 + ``tol``.

    The growth factor is evaluated on the grid ``resolution``, 2·``resolution``, … up to
    ``h_omega_max``; at the first grid point where ρ > 1 + tol, bisection between it and the
    point before narrows the limit to about 1e-13 relative, and the midpoint of the final
    bracket is returned. This is the *first* instability from 0, the documented limit; windows of
    instability further out (and stable stretches beyond them) are reported by
    :func:`unstable_intervals`. A window narrower than ``resolution`` below the first grid
    instability would be missed (none exists for varmech's methods: a NumPy scan of the
    compositions at 1e-5 finds none).

    Parameters
    ----------
    method : str
        A varmech method for unconstrained systems (:func:`varmech.methods`).
    h_omega_max : float, default 10.0
        The end of the scanned range of hω.
    resolution : float, default 1e-3
        The grid step of hω; not above ``h_omega_max``.
    tol : float, default 1e-9
        Stable means ρ ≤ 1 + ``tol``.
    progress : bool, optional
        Show a progress bar: None on a terminal only (for 50 grid points or more).

    Returns
    -------
    float
        The limit; ``math.inf`` when no grid point up to ``h_omega_max`` is unstable (A-stable
        methods such as ``midpoint``: inf means "stable on the whole scanned range", not the
        scan limit); ``0.0`` when the method is already unstable at the first grid point
        (explicit Euler: ρ = √(1 + y²) > 1 at every y > 0; its tolerance-limited interval
        (0, √(2·tol)] lies far below any sensible resolution).

    Raises
    ------
    ValueError
        An unknown ``method``, or one for constrained systems or the N-body problem only;
        ``h_omega_max``, ``resolution`` or ``tol`` not positive and finite, or ``resolution``
        above ``h_omega_max``.

    See Also
    --------
    unstable_intervals : Every unstable window in the scanned range.
    stability_table : The scans of several methods against the reference limits.

    Notes
    -----
    The tolerance absorbs round-off: inside the stability interval of a symplectic method ρ is 1
    to about 1e-13, while just past the limit ρ − 1 ≈ √(τ²/4 − 1) rises like the square root of
    the distance, so the result does not depend on ``tol`` to many digits. The cost is one
    :func:`~varmech.integrate` call of two single steps per grid point up to the limit, plus
    about 45 for the bisection.

    Examples
    --------
    >>> from varmech.analysis.stability import stability_scan
    >>> round(stability_scan("verlet", h_omega_max=3.0, resolution=0.01), 10)
    2.0
    >>> stability_scan("midpoint", h_omega_max=3.0, resolution=0.01)   # A-stable
    inf
    """
    checked_method(method)
    h_omega_max, resolution, tol = _check_scan(h_omega_max, resolution, tol)
    grid = _grid(h_omega_max, resolution)
    previous = 0.0
    bar = _progress(grid, total=grid.size, desc=f"stability {method}", enabled=progress_for(progress, grid.size))
    for y in bar:
        if _rho(_step_matrix(method, float(y))) > 1.0 + tol:
            if previous == 0.0:
                return 0.0
            return _boundary(method, previous, float(y), tol)
        previous = float(y)
    return math.inf


def unstable_intervals(
    method: str,
    h_omega_max: float = DEFAULT_SCAN_MAX,
    *,
    resolution: float = DEFAULT_RESOLUTION,
    tol: float = DEFAULT_TOL,
    progress: bool | None = None,
) -> list[tuple[float, float]]:
    """The intervals of hω in (0, ``h_omega_max``] where ρ(Ψ) > 1 + ``tol``, as (start, end)
    pairs with both ends refined by bisection; an interval still unstable at ``h_omega_max``
    ends there (it may go on beyond). An empty list: stable on the whole scanned range.

    The first interval starts at the stability limit (:func:`stability_scan`, 0 for a method
    unstable from the start). Further intervals are resonance windows: the symmetric compositions
    of Verlet become stable again past their first instability, then unstable again, where the
    product of the stage rotations has its trace cross ±2 once more. Windows narrower than
    ``resolution`` can be missed.

    Parameters
    ----------
    method, h_omega_max, resolution, tol, progress
        As for :func:`stability_scan` (unstable means ρ > 1 + ``tol``).

    Returns
    -------
    list of (float, float)
        The unstable intervals (start, end), in increasing order.

    Raises
    ------
    ValueError
        As for :func:`stability_scan`.

    See Also
    --------
    stability_scan : The first instability only.

    Examples
    --------
    >>> from varmech.analysis.stability import unstable_intervals
    >>> [(round(a, 4), b) for a, b in unstable_intervals("yoshida4", 3.0, resolution=0.01)]
    [(1.5734, 3.0)]
    >>> unstable_intervals("midpoint", 3.0, resolution=0.01)
    []
    """
    checked_method(method)
    h_omega_max, resolution, tol = _check_scan(h_omega_max, resolution, tol)
    grid = _grid(h_omega_max, resolution)
    rho = growth_factor(method, grid, progress=progress_for(progress, grid.size))
    unstable = rho > 1.0 + tol
    intervals: list[tuple[float, float]] = []
    i, n = 0, grid.size
    while i < n:
        if not unstable[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and unstable[j + 1]:
            j += 1
        if i == 0:
            start = 0.0
        else:
            start = _boundary(method, float(grid[i - 1]), float(grid[i]), tol)
        if j == n - 1:
            end = h_omega_max
        else:
            # Between grid[j] (unstable) and grid[j + 1] (stable).
            end = _boundary(method, float(grid[j + 1]), float(grid[j]), tol)
        intervals.append((start, end))
        i = j + 1
    return intervals


def _methods_arg(methods: Iterable[str] | str | None) -> list[str]:
    if methods is None:
        return _unconstrained()
    if isinstance(methods, str):
        methods = [methods]
    names = list(methods)
    for name in names:
        checked_method(name)
    return names


def growth_table(
    methods: Iterable[str] | str | None = None,
    h_omega: ArrayLike | None = None,
    *,
    limits: bool = True,
    tol: float = DEFAULT_TOL,
    progress: bool | None = None,
) -> Table:
    """The growth factor of each method at each hω: columns ``method``, ``h_omega``, ``growth``.

    ``methods`` defaults to every unconstrained method, ``h_omega`` to 0.005 … 4 in steps of
    0.005. With ``limits`` (default), ``table.meta["limits"]`` holds each method's stability limit
    from :func:`stability_scan` over the same range (inf: stable on all of it), which
    :func:`varmech.charts.stability.stability_chart` marks; ``meta["reference"]`` the
    reference limits known for these methods.

    Parameters
    ----------
    methods : str or iterable of str, optional
        varmech methods for unconstrained systems; default all of them.
    h_omega : array_like, optional
        The values of hω, positive; default 0.005, 0.010, … 4.
    limits : bool, default True
        Also scan each method's stability limit up to the largest hω (grid step 1e-3).
    tol : float, default 1e-9
        The scans' tolerance (:func:`stability_scan`).
    progress : bool, optional
        Show a progress bar: None on a terminal only (for 50 rows or more).

    Returns
    -------
    Table
        Columns ``method``, ``h_omega`` and ``growth`` (ρ), one row per method and hω;
        ``meta`` holds ``"limits"`` (with ``limits``), ``"reference"``, ``"reference_source"``,
        ``"definition"`` and ``"tol"``.

    Raises
    ------
    ValueError
        An unknown method, or one for constrained systems or the N-body problem only; a value of
        ``h_omega`` not positive and finite; or (with ``limits``) ``tol`` not positive.
    KeyboardInterrupt
        On Ctrl-C, with the rows measured so far as ``err.partial``.

    See Also
    --------
    growth_factor : ρ of one method.
    varmech.charts.stability.stability_chart : Plots the table.

    Examples
    --------
    >>> from varmech.analysis.stability import growth_table
    >>> table = growth_table("verlet", [0.5, 1.0, 2.5])
    >>> table.column("growth").tolist()
    [1.0, 1.0, 4.0]
    >>> round(table.meta["limits"]["verlet"], 10), table.meta["reference"]
    (2.0, {'verlet': 2.0})
    """
    names = _methods_arg(methods)
    ys = np.arange(1, 801) * 0.005 if h_omega is None else np.atleast_1d(np.asarray(h_omega, dtype=float)).ravel()
    for y in ys:
        positive("h_omega", y)
    table = Table(
        ("method", "h_omega", "growth"),
        title="Growth factor ρ(Ψ) of one step on q'' = -ω²q",
        meta={
            "definition": "spectral radius of the one-step matrix Psi from (q, p) = (1, 0) and (0, 1), omega = 1",
            "tol": tol,
            "reference": {m: REFERENCE_LIMITS[m] for m in names if m in REFERENCE_LIMITS},
            "reference_source": REFERENCE_SOURCE,
        },
    )
    plan = [(name, float(y)) for name in names for y in ys]

    def body() -> None:
        for name, y in _progress(plan, total=len(plan), desc="growth table", enabled=progress_for(progress, len(plan))):
            table.append(name, y, _rho(_step_matrix(name, y)))
        if limits:
            top = float(ys.max())
            resolution = min(DEFAULT_RESOLUTION, top)
            table.meta["limits"] = {
                name: stability_scan(name, h_omega_max=top, resolution=resolution, tol=tol, progress=False)
                for name in _progress(names, total=len(names), desc="limits", enabled=progress)
            }

    return interruptible(table, body)


def stability_table(
    methods: Iterable[str] | str | None = None,
    *,
    h_omega_max: float = DEFAULT_SCAN_MAX,
    resolution: float = DEFAULT_RESOLUTION,
    tol: float = DEFAULT_TOL,
    progress: bool | None = None,
) -> Table:
    """Measured stability limits against the reference: columns ``method``, ``h_omega_max`` (the
    scan, :func:`stability_scan`), ``reference`` (:data:`REFERENCE_LIMITS`, from
    reference/compositions.json; NaN where the file has no value), ``relative_difference``
    ((measured − reference)/reference; the absolute difference when the reference is 0, 0 when
    both are inf, NaN without a reference) and ``documented`` (``MethodInfo.h_omega_max``, the
    methods table).

    Parameters
    ----------
    methods : str or iterable of str, optional
        varmech methods for unconstrained systems; default all of them.
    h_omega_max, resolution, tol
        As for :func:`stability_scan` (defaults 10, 1e-3 and 1e-9).
    progress : bool, optional
        Show a progress bar: None on a terminal only, True or False to force it.

    Returns
    -------
    Table
        One row per method, with the columns above; ``meta`` describes the scan (``"scan"``,
        ``"inf"``, ``"reference_source"``).

    Raises
    ------
    ValueError
        An unknown method, or one for constrained systems or the N-body problem only;
        ``h_omega_max``, ``resolution`` or ``tol`` not positive and finite, or ``resolution``
        above ``h_omega_max``.
    KeyboardInterrupt
        On Ctrl-C, with the rows measured so far as ``err.partial``.

    See Also
    --------
    stability_scan : The scan of one method.
    relative_difference : The comparison with the reference.

    Examples
    --------
    >>> from varmech.analysis.stability import stability_table
    >>> table = stability_table(["verlet", "yoshida4"], h_omega_max=3.0, resolution=0.01)
    >>> table.columns
    ('method', 'h_omega_max', 'reference', 'relative_difference', 'documented')
    >>> [bool(abs(d) < 1e-5) for d in table.column("relative_difference")]
    [True, True]
    """
    names = _methods_arg(methods)
    info = {m.name: m for m in _methods()}
    table = Table(
        ("method", "h_omega_max", "reference", "relative_difference", "documented"),
        title="Linear stability limits hω_max on q'' = -ω²q: scan against reference",
        meta={
            "scan": f"grid step {resolution:g} up to hω = {h_omega_max:g}, then bisection; stable means growth <= 1 + {tol:g}",
            "inf": f"no instability up to hω = {h_omega_max:g}",
            "reference_source": REFERENCE_SOURCE,
        },
    )

    def body() -> None:
        for name in _progress(names, total=len(names), desc="stability scans", enabled=progress):
            measured = stability_scan(name, h_omega_max=h_omega_max, resolution=resolution, tol=tol, progress=False)
            ref = REFERENCE_LIMITS.get(name, math.nan)
            table.append(name, measured, ref, relative_difference(measured, ref), info[name].h_omega_max)

    return interruptible(table, body)


def relative_difference(measured: float, reference: float) -> float:
    """(measured − reference)/reference; measured − reference when the reference is 0; 0 when both
    are inf; inf when only one is; NaN when either is NaN.

    Parameters
    ----------
    measured, reference : float
        The two limits hω_max.

    Returns
    -------
    float
        The relative difference, as above.

    Examples
    --------
    >>> from varmech.analysis.stability import relative_difference
    >>> relative_difference(3.0, 2.0), relative_difference(0.1, 0.0)
    (0.5, 0.1)
    >>> relative_difference(float("inf"), float("inf"))
    0.0
    """
    if math.isnan(reference) or math.isnan(measured):
        return math.nan
    if math.isinf(reference) or math.isinf(measured):
        return 0.0 if measured == reference else math.inf
    if reference == 0.0:
        return measured - reference
    return (measured - reference) / reference


__all__ = [
    "COMPOSITION_NAMES",
    "IMPLICIT_METHODS",
    "OUTCOMES",
    "REFERENCE_LIMITS",
    "REFERENCE_SOURCE",
    "growth_factor",
    "growth_table",
    "relative_difference",
    "spectrum",
    "stability_scan",
    "stability_table",
    "step_matrix",
    "unstable_intervals",
]


def spectrum(
    model: Model | scenes.Scene,
    methods: Iterable[str] | str | None = None,
    *,
    q: ArrayLike | None = None,
    dt: float | None = None,
    t: float = 0.0,
) -> Table:
    """A model's spectrum against each method's stability interval: the frequencies of its
    small oscillations at q (:func:`varmech.normal_modes`), as hω at the step ``dt``, beside
    each method's interval 0 < hω < h_ω.

    Parameters
    ----------
    model : Model or Scene
        The model (any but one with velocity constraints); a scene gives its q₀ and dt as the
        defaults.
    methods : str or iterable of str, optional
        The methods; default: every method with a finite stability limit that integrates the
        model.
    q : array_like, optional
        The point (an equilibrium, or a state whose local frequencies bound the step); default
        the scene's q₀.
    dt : float, optional
        The step; default the scene's.
    t : float, default 0.0
        The time.

    Returns
    -------
    Table
        One row per method: ``method``, ``h_omega_max`` (h_ω, inf for an unconditionally stable
        method), ``stable_dt`` (h_ω/ω_max) and ``stable`` (whether dt·ω_max < h_ω); ``meta``
        holds ``"frequencies"`` (each mode's |λ| = √(ω² + σ²)), ``"dt"``, ``"omega_max"``,
        ``"model"`` and ``"q"``. :func:`varmech.charts.spectrum_chart` draws it.

    Raises
    ------
    ValueError
        No ``q`` or ``dt`` for a model that is not a scene; an unknown method, or one that does
        not integrate the model or has no stability limit on an oscillator.

    Examples
    --------
    The FPU chain at rest: its stiff springs at ω = 50 take Verlet's step 0.03 but not
    Yoshida's fourth-order one.

    >>> import varmech
    >>> table = varmech.analysis.stability.spectrum(varmech.scenes.fermi_pasta_ulam(), ["verlet", "yoshida4"],
    ...                                             q=[0.0] * 6, dt=0.035)
    >>> [(row["method"], row["stable"]) for row in table], round(table.meta["omega_max"], 9)
    ([('verlet', True), ('yoshida4', False)], 50.0)
    """
    scene = model if isinstance(model, scenes.Scene) else None
    model = scene.model if scene is not None else model
    if not isinstance(model, Model):
        raise TypeError(f"model: expected a varmech model or scene, got {type(model).__name__}")
    if q is None:
        if scene is None:
            raise ValueError("q: the point is required for a model that is not a scene")
        q = scene.q0
    if dt is None:
        if scene is None:
            raise ValueError("dt: the step is required for a model that is not a scene")
        dt = scene.dt
    dt = positive("dt", dt)
    point = vector("q", q, model.dim)
    limits = stability_limits()
    if methods is None:
        names = [name for name, limit in limits.items() if model.kind.admits(name) and 0 < limit]
    else:
        names = [methods] if isinstance(methods, str) else list(methods)
    for name in names:
        if not isinstance(name, str) or name not in limits:
            raise ValueError(f"methods: expected names among {sorted(limits)}, got {name!r}")
        if not model.kind.admits(name):
            raise ValueError(f"methods: {name} does not integrate {model.name}, a {model.kind.name} model")
        if not limits[name] > 0:
            raise ValueError(f"methods: {name} has no stability interval on an oscillator")
    modes = normal_modes(model, point, t=finite("t", t))
    frequencies = np.hypot(modes.frequencies, modes.growth)
    omega = modes.omega_max
    table = Table(
        ("method", "h_omega_max", "stable_dt", "stable"),
        title=f"{model.name}: its spectrum hω at dt = {dt:g} against each method's stability interval",
        meta={"frequencies": frequencies.tolist(), "dt": dt, "omega_max": omega, "model": model.name, "q": point.tolist()},
    )
    for name in names:
        limit = limits[name]
        table.append(name, limit, limit / omega if omega > 0 else math.inf, bool(dt * omega < limit))
    return table
