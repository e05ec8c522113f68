"""Lyapunov exponents from the integrator's own tangent map.

A kick–drift step is a composition of shears, and so is its linearization (symplectic,
determinant 1 to round-off); an implicit step (midpoint, trapezoid, Galerkin, forced or not;
RATTLE on holonomic constraints) is linearized through its own equations at their solution. The core carries k tangent vectors along
the run with that tangent map, re-orthonormalizes them every few steps by a QR factorization and
sums the logarithms of R's diagonal (Benettin, Galgani, Giorgilli & Strelcyn 1980). Python
declares the run and turns the sums into exponents and their standard errors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .. import _core
from .._util import finite, floats, positive, positive_int, vector
from ..model import Model

__all__ = ["LyapunovSpectrum", "Megno", "lyapunov_spectrum", "megno"]


@dataclass(frozen=True)
class LyapunovSpectrum:
    """The Lyapunov exponents of one run, as :func:`lyapunov_spectrum` measures them.

    Attributes
    ----------
    exponents : numpy.ndarray
        λ₁ ≥ … ≥ λ_k at the run's end, shape (k,): Σ ln Rⱼⱼ over the run's time.
    stderr : numpy.ndarray
        The standard error of each, shape (k,), from ``segments`` consecutive pieces of the run
        taken as independent estimates.
    t : numpy.ndarray
        The times of the re-orthonormalizations, shape (m,).
    running : numpy.ndarray
        The running estimates λⱼ(t) = Σ ln Rⱼⱼ / (t − t₀) there, shape (m, k): their convergence.
    q : numpy.ndarray
        The run's end.
    p : numpy.ndarray
        The run's end.
    method : str
    t0 : float
    dt : float
    steps : int
    every : int
        Steps between re-orthonormalizations.
    evaluations : int
        Evaluations the tangent map made: of ∇V and of its Hessian for a kick–drift method (a
        differenced Hessian counts its 2n gradients), of the step's equations for an implicit one.
    sum : float
        Σλⱼ: for the full spectrum the tangent map's volume change per unit time, 0 for a
        Hamiltonian model (to round-off under a kick–drift method, to about 1e-10 under an
        implicit one), the step's own contraction for a damped one.

    Examples
    --------
    >>> import varmech
    >>> hh = varmech.scenes.henon_heiles().model
    >>> s = varmech.lyapunov_spectrum(hh, [0.1, 0.0], [0.0, 0.5], dt=0.05, steps=2000, k=2)
    >>> s.exponents.shape, s.running.shape, bool(s.t[-1] == 100.0)
    ((2,), (200, 2), True)
    """

    exponents: np.ndarray
    stderr: np.ndarray
    t: np.ndarray
    running: np.ndarray
    q: np.ndarray
    p: np.ndarray
    method: str
    t0: float
    dt: float
    steps: int
    every: int
    evaluations: int

    @property
    def sum(self) -> float:
        """Σλⱼ (see the class's attributes)."""
        return float(np.sum(self.exponents))

    def __str__(self) -> str:
        lines = [f"{'j':>3} {'λ':>14} {'± stderr':>11}"]
        lines += [f"{j + 1:>3} {lam:>14.6e} {err:>11.2e}" for j, (lam, err) in enumerate(zip(self.exponents, self.stderr))]
        span = self.t[-1] - self.t0
        lines.append(f"{self.method}, dt = {self.dt:g}, {self.steps} steps (t = {span:g}); Σλ = {self.sum:.3e}")
        return "\n".join(lines)


def lyapunov_spectrum(
    model: Model,
    q0: ArrayLike,
    p0: ArrayLike,
    *,
    dt: float,
    steps: int,
    method: str | None = None,
    k: int | None = None,
    every: int = 10,
    segments: int = 10,
    t0: float = 0.0,
    tangent0: ArrayLike | None = None,
) -> LyapunovSpectrum:
    """The Lyapunov spectrum of the orbit from (q0, p0), from the step's own tangent map.

    The run is the plain run of ``method`` (the same states, bit for bit); its tangent map
    carries k tangent vectors, re-orthonormalized every ``every`` steps. For a kick–drift step
    it is exact (shears: δq += bh M⁻¹δp at each drift, δp −= ah H(q) δq at each kick, H the
    Hessian of V where the kick acts), with the model's own Hessian where it has one (native
    scenes such as Hénon–Heiles), else central differences of ∇V, symmetrized: the map stays
    symplectic either way. For an implicit step, which solves F(x; q₀, p₀) = 0 and ends at
    p₁ = P(x; q₀, p₀), it is the implicit function theorem's, δx = −F_x⁻¹(F_q₀δq₀ + F_p₀δp₀),
    the step's equations differentiated at their solution (central differences, error about
    1e-11): for any Lagrangian, with its forces, so that a damped, driven model's Σλ is the
    step's own volume change.

    Parameters
    ----------
    model
        A model without delayed forces: separable, L = ½q̇ᵀMq̇ − V(q), for the kick–drift
        methods; any unconstrained Lagrangian, forced or not, for the implicit ones; a separable
        model on holonomic constraints for RATTLE (a native scene, a SymPy model, or closures).
    q0, p0
        The initial state, shape (n,) each.
    dt
        The step.
    steps
        Steps of the run.
    method
        A method with ``"tangent_map"`` in its ``MethodInfo.features``: a kick–drift method
        (``"verlet"``, ``"yoshida4"``, ``"blanes_moan4"``, ``"aba864"``, …) or an implicit rule
        (``"midpoint"``, ``"trapezoid"``, ``"galerkin4"``, ``"galerkin6"``), or ``"rattle"`` on
        holonomic constraints.
        Default: the model's default method (``"verlet"`` for a separable model, ``"midpoint"``
        for any other).
    k
        How many exponents, the k largest: 1 … 2n (2(n − m) on m holonomic constraints); default
        all of them, the full spectrum.
    every
        Steps between re-orthonormalizations (a vector that grows past 1e100 is
        re-orthonormalized at once; one step that stretches the vectors past the largest float,
        1e208 from 1e100, is a :class:`~varmech.DivergenceError` asking for a smaller ``dt``).
    segments
        The run's pieces whose estimates give the standard errors (at least 2).
    t0
        The initial time.
    tangent0
        The tangent vectors' start, the k columns (δq, δq̇) of an array of shape (2n, k)
        (shape (2n,) for k = 1), linearly independent; δp is the Legendre transform's
        differential at (q0, p0). Default: fixed pseudo-random directions of (δq, δq̇).

    Returns
    -------
    LyapunovSpectrum

    Raises
    ------
    ValueError
        ``k`` outside 1 … 2n, ``every`` or ``steps`` not a positive integer, ``segments`` < 2 or
        more than the run's re-orthonormalizations, a kick–drift method on a model that is not
        separable, a model with constraints or delayed forces, a method without a tangent
        map, or a ``tangent0`` of another shape or of dependent columns, naming the argument.
    DivergenceError
        The tangent vectors overflowed in one step (the step is far too long for the motion's
        instability: take a smaller ``dt``), or a column contracted past the smallest float
        between re-orthonormalizations (take a smaller ``every``): their exponents would be NaN.
    VarmechError
        The model failing during the run, with the step and time.

    Examples
    --------
    The Hénon–Heiles system in its chaotic sea: one positive exponent, its mirror image
    negative, two near 0 (the flow's direction and the energy), and a sum of 0 to round-off.

    >>> import varmech
    >>> hh = varmech.scenes.henon_heiles().model
    >>> s = varmech.lyapunov_spectrum(hh, [0.0, -0.25], [0.42, 0.0], dt=0.05, steps=20_000)
    >>> bool(s.exponents[0] > 0.02), bool(abs(s.sum) < 1e-12)
    (True, True)

    The damped, driven pendulum in Taylor's chaotic regime (γ = 1.105; the scene's time unit
    is 1/ω₀, its damping 2β/ω₀ = 0.5), under the midpoint rule: λ₁ > 0, and Σλ the damping's
    −2β to the method's order.

    >>> import math
    >>> pendulum = varmech.scenes.get("damped_driven_pendulum", amplitude=1.105).model
    >>> s = varmech.lyapunov_spectrum(pendulum, [-math.pi / 2], [0.0], dt=0.02, steps=50_000)
    >>> bool(s.exponents[0] > 0.05), bool(abs(s.sum + 0.5) < 1e-4)
    (True, True)
    """
    n = model.dim
    q0, p0 = vector("q0", q0, n), vector("p0", p0, n)
    dt, t0 = positive("dt", dt), finite("t0", t0)
    steps, every = positive_int("steps", steps), positive_int("every", every)
    # On holonomic constraints the motion's phase space is the constraint manifold's, 2(n − m).
    dimension = 2 * (n - model.constraints)
    k = dimension if k is None else positive_int("k", k)
    if k > dimension:
        where = "the phase space's dimension 2n" if not model.constraints else "the constraint manifold's phase space, 2(n − m)"
        raise ValueError(f"k: must be 1 … {dimension} ({where}), got {k}")
    segments = positive_int("segments", segments)
    if segments < 2:
        raise ValueError(f"segments: must be at least 2 (the standard error compares pieces of the run), got {segments}")
    if segments > steps // every:
        raise ValueError(
            f"segments: the run re-orthonormalizes {steps // every} times, fewer than its {segments} segments; "
            "run more steps, re-orthonormalize more often (a smaller every), or take fewer segments"
        )
    method = model.kind.default_method if method is None else method
    start = _tangent0(tangent0, 2 * n, k)
    t, sums, (q, p), evaluations = _core.lyapunov(model._core, method, q0, p0, t0=t0, dt=dt, steps=steps, k=k, every=every, start=start)
    elapsed = t - t0
    running = sums / elapsed[:, None]
    exponents = running[-1]
    # Each segment's estimate, over the rows that close its share of the run's time.
    edges = np.searchsorted(elapsed, elapsed[-1] * np.arange(1, segments + 1) / segments, side="left")
    ends = np.minimum(edges, len(t) - 1)
    starts = np.concatenate(([-1], ends[:-1]))
    start_sums = np.where(starts[:, None] < 0, 0.0, sums[np.maximum(starts, 0)])
    start_t = np.where(starts < 0, 0.0, elapsed[np.maximum(starts, 0)])
    pieces = (sums[ends] - start_sums) / (elapsed[ends] - start_t)[:, None]
    stderr = pieces.std(axis=0, ddof=1) / math.sqrt(segments)
    return LyapunovSpectrum(
        exponents=exponents,
        stderr=stderr,
        t=t,
        running=running,
        q=q,
        p=p,
        method=method,
        t0=t0,
        dt=dt,
        steps=steps,
        every=every,
        evaluations=int(evaluations),
    )


def _tangent0(tangent0: ArrayLike | None, dim: int, k: int) -> np.ndarray | None:
    """``tangent0`` as the core takes it (its k columns of ``dim`` one after the other), or
    ValueError naming it; the core checks that the columns are independent."""
    if tangent0 is None:
        return None
    a = floats("tangent0", tangent0)
    if a.shape == (dim,):
        a = a[:, None]
    if a.shape != (dim, k):
        raise ValueError(f"tangent0: must have shape ({dim}, {k}) (k columns (δq, δq̇)), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError("tangent0: must be finite")
    return np.ascontiguousarray(a.T).ravel()


@dataclass(frozen=True)
class Megno:
    """MEGNO, the mean exponential growth factor of nearby orbits (Cincotta & Simó 2000), as
    :func:`megno` measures it.

    Attributes
    ----------
    t : numpy.ndarray
        The times t₀ + kh after each step.
    y : numpy.ndarray
        Y(t) = (2/t)∫₀ᵗ s (δ̇·δ/δ·δ) ds.
    mean : numpy.ndarray
        ⟨Y⟩(t) = (1/t)∫₀ᵗ Y(s) ds: → 0 for a stable equilibrium's neighbourhood (bounded δ),
        → 2 for a quasi-periodic orbit (δ growing linearly), ≈ λ₁t/2 for a chaotic one.
    method : str
    dt : float
    value : float
        ⟨Y⟩ at the run's end.

    Examples
    --------
    >>> import varmech
    >>> m = varmech.megno(varmech.scenes.get("harmonic_oscillator").model, [1.0], [0.0], dt=0.05, steps=1000)
    >>> m.t.shape, bool(abs(m.value) < 1e-5)
    ((1000,), True)
    """

    t: np.ndarray
    y: np.ndarray
    mean: np.ndarray
    method: str
    dt: float

    @property
    def value(self) -> float:
        """⟨Y⟩ at the run's end (see the class's attributes)."""
        return float(self.mean[-1])


def megno(
    model: Model,
    q0: ArrayLike,
    p0: ArrayLike,
    *,
    dt: float,
    steps: int,
    method: str | None = None,
    t0: float = 0.0,
    tangent0: ArrayLike | None = None,
) -> Megno:
    """MEGNO along the orbit from (q0, p0), from the step's own tangent map.

    One tangent vector is carried by the tangent map as :func:`lyapunov_spectrum` carries it,
    normalized at every step; the step's log growth gₖ = ln(‖δₖ‖/‖δₖ₋₁‖) is ∫δ̇·δ/δ·δ over the
    step, so Y(tₙ) = (2/tₙ)Σₖ tₖ₋½ gₖ and ⟨Y⟩(tₙ) = (h/tₙ)Σₖ Y(tₖ) (times counted from t₀).

    Parameters
    ----------
    model, q0, p0, dt, steps, method, t0
        As for :func:`lyapunov_spectrum`.
    tangent0
        The tangent vector's start (δq, δq̇), shape (2n,); δp is the Legendre transform's
        differential at (q0, p0) (for an N-body model pᵢ = mᵢvᵢ, so δpᵢ = mᵢδvᵢ). Default: a
        fixed pseudo-random direction. ⟨Y⟩ → 2 from any start on a quasi-periodic orbit, but its
        approach depends on the start: REBOUND's ``init_megno`` draws (δx, δv) at random, and
        from the same start the two agree (``benches/megno.py``).

    Returns
    -------
    Megno

    Raises
    ------
    ValueError
        As for :func:`lyapunov_spectrum`.

    Examples
    --------
    A Kepler orbit is quasi-periodic: ⟨Y⟩ → 2.

    >>> import varmech
    >>> kepler = varmech.scenes.get("kepler", e=0.5)
    >>> m = varmech.megno(kepler.model, kepler.q0, kepler.p0, dt=0.01, steps=100_000)
    >>> bool(abs(m.value - 2.0) < 0.1)
    True
    """
    n = model.dim
    q0, p0 = vector("q0", q0, n), vector("p0", p0, n)
    dt, t0 = positive("dt", dt), finite("t0", t0)
    steps = positive_int("steps", steps)
    method = model.kind.default_method if method is None else method
    start = _tangent0(tangent0, 2 * n, 1)
    t, sums, _, _ = _core.lyapunov(model._core, method, q0, p0, t0=t0, dt=dt, steps=steps, k=1, every=1, start=start)
    elapsed = t - t0
    growth = np.diff(sums[:, 0], prepend=0.0)
    y = 2.0 * np.cumsum((elapsed - 0.5 * dt) * growth) / elapsed
    mean = dt * np.cumsum(y) / elapsed
    return Megno(t=t, y=y, mean=mean, method=method, dt=dt)
