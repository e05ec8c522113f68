"""Small oscillations: equilibria, the linearized equations and normal modes at a point, and the
step a method can take on them, before the run.

About a point q (an equilibrium, or any configuration for its local frequencies) the equations
of motion linearize to

    M δq̈ + (G + D) δq̇ + K δq = 0,   M = ∂²L/∂q̇²,  K = −∂²L/∂q² − ∂Q/∂q − Σλᵢ∇²gᵢ,
    G = ∂²L/∂q̇∂q − ∂²L/∂q∂q̇ (antisymmetric),  D = −∂Q/∂q̇,

at q̇ = 0, Q the model's own forces. On holonomic constraints g(q) = 0, λ are the multipliers
that hold q at rest (their curvature term is a pendulum's tension) and every matrix is restricted
to the constraints' tangent space, δq = T y with T an orthonormal basis of ker ∂g/∂q: the modes
move along the constraints, none across them. The core computes them (exact second derivatives
where the model supplies them: compiled symbolic models, native scenes; central differences
otherwise), finds equilibria by Newton on the generalized force, and solves the eigenproblems.
A Routh-reduced model (:func:`varmech.routh`) linearizes its Routhian: its equilibria are the
full model's steady motions (relative equilibria), its G their Coriolis coupling.

Before a run, :func:`varmech.integrate` compares h·ω_max at its first state (ω_max from a few
dozen force evaluations, by Lanczos's method) with the method's stability limit and warns with a
:class:`StabilityWarning` beyond it.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from . import impacts as _impacts
from ._util import finite, integer, number, vector
from ._warnings import VarmechWarning
from .methods import methods
from .model import Model, Symmetry

__all__ = [
    "Equilibrium",
    "Linearization",
    "NormalModes",
    "StabilityWarning",
    "StepSuggestion",
    "equilibria",
    "fastest_frequency",
    "linearize",
    "normal_modes",
    "suggest_dt",
]


def _point(model: Model, name: str, q: ArrayLike) -> np.ndarray:
    if not isinstance(model, Model):
        raise TypeError(f"model: expected a varmech model, got {type(model).__name__}")
    return vector(name, q, model.dim)


@dataclass(frozen=True)
class Linearization:
    """The linearized equations M ÿ + (G + D) ẏ + K y = 0 at (q, q̇ = 0, t), in the tangent
    coordinates y of δq = T y (T = I for a model without constraints).

    Attributes
    ----------
    q : numpy.ndarray
        The point, shape (n,).
    t : float
        The time.
    mass : numpy.ndarray
        M = Tᵀ(∂²L/∂q̇²)T, shape (r, r), r = n − (the number of independent constraints).
    stiffness : numpy.ndarray
        K = Tᵀ(−∂²L/∂q² − ∂Q/∂q − Σλᵢ∇²gᵢ)T.
    gyroscopic : numpy.ndarray
        G = Tᵀ(∂²L/∂q̇∂q − ∂²L/∂q∂q̇)T, antisymmetric (magnetic fields, rotating frames).
    damping : numpy.ndarray
        D = −Tᵀ(∂Q/∂q̇)T (zero for a model without forces).
    basis : numpy.ndarray
        T, shape (n, r): orthonormal columns spanning the constraints' tangent space ker ∂g/∂q.
    multipliers : numpy.ndarray
        λ, the multipliers that hold q at rest (Lagrange's sign: ṗ = ∂L/∂q + Q + (∂g/∂q)ᵀλ);
        empty without constraints.

    Examples
    --------
    >>> import varmech
    >>> from varmech import examples
    >>> varmech.linearize(examples.harmonic_oscillator(3.0), [0.0]).stiffness
    array([[9.]])
    """

    q: np.ndarray
    t: float
    mass: np.ndarray
    stiffness: np.ndarray
    gyroscopic: np.ndarray
    damping: np.ndarray
    basis: np.ndarray
    multipliers: np.ndarray


def linearize(model: Model, q: ArrayLike, *, t: float = 0.0) -> Linearization:
    """The linearized equations of ``model`` at (q, q̇ = 0, t), on its constraints' tangent space.

    Parameters
    ----------
    model
        Any model but one with velocity constraints (closures, compiled symbolic, native
        scenes, Routh-reduced, on holonomic constraints or not).
    q
        The point, shape (n,); on the constraints, for a constrained model.
    t
        The time (for a time-dependent model, the instantaneous linearization).

    Returns
    -------
    Linearization
        M, K, G and D in the tangent coordinates, the basis T and the multipliers λ.

    Raises
    ------
    ValueError
        ``q`` or ``t`` malformed, velocity constraints, or the model's derivatives not finite.

    Examples
    --------
    >>> import numpy as np, varmech
    >>> spring = varmech.MechanicalSystem(1, lambda q: 2.0 * q[0] ** 2, lambda q: 4.0 * q, mass=[0.5])
    >>> lin = varmech.linearize(spring, [0.0])
    >>> lin.mass, lin.stiffness
    (array([[0.5]]), array([[4.]]))

    A pendulum in Cartesian coordinates hangs on its constraint x² + y² = 1: one tangent
    coordinate, whose stiffness is the tension −λ (m = g = l = 1):

    >>> pendulum = varmech.scenes.cartesian_pendulum().model
    >>> lin = varmech.linearize(pendulum, [0.0, -1.0])
    >>> abs(lin.basis).round(12).tolist(), lin.stiffness.round(9), lin.multipliers.round(9)
    ([[1.0], [0.0]], array([[1.]]), array([-1.]))
    """
    q = _point(model, "q", q)
    t = finite("t", t)
    return Linearization(q, t, *_core.linearize(model._core, q, t))


@dataclass(frozen=True)
class NormalModes:
    """The normal modes of the linearized equations at a point.

    Each mode is one eigenvalue pair λ = σ ± iω of the linearized equations: a stable undamped
    mode has σ = 0, a damped one σ < 0, an unstable one σ > 0 (ω = 0 where it grows without
    oscillating). A zero mode (ω = σ = 0) is a neutral direction: a symmetry's (a translation,
    a rotation), named after the model's symmetry where its generator ξ(q) is one, or a
    degenerate equilibrium's. On constraints the modes are those along the constraints, r of
    them (n − the number of constraints): none across them.

    Attributes
    ----------
    q : numpy.ndarray
        The point.
    frequencies : numpy.ndarray
        ω of each mode, ascending.
    growth : numpy.ndarray
        σ of each mode.
    curvatures : numpy.ndarray
        The eigenvalues κ of K̄y = κMy (K̄ the symmetric part of K), ascending: ω² where G = D = 0.
    inertia : tuple of int
        How many κ are positive, zero and negative: K's inertia relative to M.
    shapes : numpy.ndarray
        The mode shapes δq as columns, shape (n, r), in the order of ``frequencies``. Real and
        M-orthonormal (xᵀMx = 1) where G = D = 0 and K is symmetric; otherwise complex, each the
        null vector x of the quadratic pencil (λ²M + λ(G + D) + K)x = 0 at its mode's λ = σ + iω
        (the motion Re(x e^{λt})), with xᴴMx = 1 and its largest entry real and positive.
    symmetries : tuple
        For each mode, the model's symmetry (a :class:`~varmech.Translation`,
        :class:`~varmech.Rotation` or :class:`~varmech.Cyclic` of ``model.symmetries``) whose
        direction it is, else None: a zero mode along a symmetry's generator has that generator,
        M-normalized, as its shape.
    stable : bool
        Whether no mode grows.
    omega_max : float
        The largest |λ| = √(ω² + σ²): what bounds a method's step.
    zero_modes : numpy.ndarray
        The indices of the zero modes.
    unstable_modes : numpy.ndarray
        The indices of the modes that grow.
    gyroscopically_stable : bool
        Stable although K is not positive semidefinite (some κ < 0): stabilized by G (a
        spinning top, a Penning trap).

    Examples
    --------
    >>> import varmech
    >>> from varmech import examples
    >>> modes = varmech.normal_modes(examples.pendulum(), [0.0])
    >>> modes.stable, modes.inertia, round(modes.omega_max, 9)
    (True, (1, 0, 0), 1.0)
    """

    q: np.ndarray
    frequencies: np.ndarray
    growth: np.ndarray
    curvatures: np.ndarray
    inertia: tuple[int, int, int]
    shapes: np.ndarray
    symmetries: tuple[Symmetry | None, ...]

    @property
    def stable(self) -> bool:
        return bool(np.all(self.growth <= 0.0))

    @property
    def omega_max(self) -> float:
        return float(np.max(np.hypot(self.frequencies, self.growth), initial=0.0))

    @property
    def zero_modes(self) -> np.ndarray:
        return np.flatnonzero((self.frequencies == 0.0) & (self.growth == 0.0))

    @property
    def unstable_modes(self) -> np.ndarray:
        return np.flatnonzero(self.growth > 0.0)

    @property
    def gyroscopically_stable(self) -> bool:
        return self.stable and self.inertia[2] > 0

    def __str__(self) -> str:
        named = any(s is not None for s in self.symmetries)
        rows = [f"{'mode':>4}  {'ω':>14}  {'σ':>14}" + ("  symmetry" if named else "")]
        for k, (w, s) in enumerate(zip(self.frequencies, self.growth)):
            symmetry = self.symmetries[k]
            label = f"  {type(symmetry).__name__.lower()} ({symmetry.name})" if symmetry is not None else ""
            rows.append(f"{k:>4}  {w:>14.8g}  {s:>14.8g}{label}")
        verdict = "stable" if self.stable else f"unstable ({len(self.unstable_modes)} growing)"
        if self.gyroscopically_stable:
            verdict += ", gyroscopically (K has negative curvatures)"
        return "\n".join([*rows, f"{verdict}; {len(self.zero_modes)} zero modes; ω_max = {self.omega_max:.8g}"])


def normal_modes(model: Model, q: ArrayLike, *, t: float = 0.0) -> NormalModes:
    """The normal modes of ``model`` linearized at (q, q̇ = 0, t), on its constraints.

    Where G = D = 0 (a model without velocity-linear terms or forces) the generalized symmetric
    eigenproblem K y = ω² M y, with M-orthonormal shapes; otherwise the eigenvalues of the
    first-order system (the quadratic eigenproblem), which finds gyroscopic stabilization, with
    complex shapes. Zero modes along the model's declared symmetries (``model.symmetries``)
    are named after them.

    Parameters
    ----------
    model
        Any model but one with velocity constraints; on holonomic constraints the modes are
        those along them.
    q
        The point: an equilibrium for the small oscillations about it, or any configuration for
        the local frequencies (what bounds a method's step there); on the constraints.
    t
        The time.

    Returns
    -------
    NormalModes
        Frequencies, growth rates, shapes, the symmetries of the zero modes; printing it gives
        the table.

    Raises
    ------
    ValueError
        ``q`` or ``t`` malformed, velocity constraints, M not positive definite or a non-finite
        second derivative at q (the message says which).

    Examples
    --------
    The linear triatomic molecule (masses 1, 3, 1, springs 2): a translation and two vibrations.

    >>> import numpy as np, varmech
    >>> k = 2.0
    >>> def V(q): return 0.5 * k * ((q[1] - q[0]) ** 2 + (q[2] - q[1]) ** 2)
    >>> def dV(q): return k * np.array([q[0] - q[1], 2 * q[1] - q[0] - q[2], q[2] - q[1]])
    >>> molecule = varmech.MechanicalSystem(3, V, dV, mass=[1.0, 3.0, 1.0],
    ...                                     symmetries=[varmech.Translation(0, spatial_dim=1)])
    >>> print(varmech.normal_modes(molecule, np.zeros(3)))
    mode               ω               σ  symmetry
       0               0               0  translation (P_x)
       1       1.4142136               0
       2       1.8257419               0
    stable; 1 zero modes; ω_max = 1.8257419
    """
    q = _point(model, "q", q)
    t = finite("t", t)
    specs = [s.spec() for s in model.symmetries]
    frequencies, growth, curvatures, inertia, shapes, named = _core.normal_modes(model._core, q, t, specs)
    positive, zero, negative = inertia
    symmetries = tuple(None if k is None else model.symmetries[k] for k in named)
    return NormalModes(q, frequencies, growth, curvatures, (positive, zero, negative), shapes, symmetries)


@dataclass(frozen=True)
class Equilibrium:
    """An equilibrium found by Newton on the generalized force, with its normal modes.

    Attributes
    ----------
    q : numpy.ndarray
        The equilibrium.
    multipliers : numpy.ndarray
        λ there, the constraints' forces Gᵀλ that hold it (Lagrange's sign); empty without
        constraints.
    residual : float
        ‖(∂L/∂q + Q + Gᵀλ, g)‖∞ there.
    iterations : int
        Newton iterations from the guess.
    modes : NormalModes
        The small oscillations about it.
    kind : str
        ``"minimum"`` (every curvature positive), ``"maximum"``, ``"saddle"``, or
        ``"degenerate"`` (zero curvatures besides the others'); of the potential (amended, for a
        reduced model), whatever G makes of it (``modes.stable``).

    Examples
    --------
    >>> import numpy as np, varmech
    >>> pendulum = varmech.MechanicalSystem(1, lambda q: -np.cos(q[0]), lambda q: np.sin(q))
    >>> [(round(float(e.q[0]), 12), e.kind) for e in varmech.equilibria(pendulum, [[0.3], [3.0]])]
    [(0.0, 'minimum'), (3.14159265359, 'maximum')]
    """

    q: np.ndarray
    multipliers: np.ndarray
    residual: float
    iterations: int
    modes: NormalModes

    @property
    def kind(self) -> str:
        positive, zero, negative = self.modes.inertia
        if zero:
            return "degenerate"
        if negative == 0:
            return "minimum"
        return "maximum" if positive == 0 else "saddle"


def equilibria(
    model: Model,
    guesses: ArrayLike,
    *,
    t: float = 0.0,
    newton_tolerance: float = 1e-14,
    newton_max_iterations: int = 50,
) -> list[Equilibrium]:
    """The equilibria of ``model`` nearest each guess: ∂L/∂q(q, 0, t) + Q(q, 0, t) = 0 by the
    core's Newton, with the exact Hessian where the model supplies it.

    On holonomic constraints g(q) = 0 Newton solves the balance with the constraints' forces,
    ∂L/∂q + Q + Gᵀλ = 0, and g(q) = 0 together, in (q, λ): a guess off the constraints is
    brought onto them (projected by the iteration), and λ is returned. Guesses that converge to
    the same point (to 1e-8 relative) give it once.

    Parameters
    ----------
    model
        Any model but one with velocity constraints; a Routh-reduced model for steady motions.
    guesses
        One guess, shape (n,), or several, shape (k, n); off the constraints they are brought
        onto them.
    t
        The time.
    newton_tolerance, newton_max_iterations
        Newton's stopping rule (relative correction) and cap.

    Returns
    -------
    list of Equilibrium
        In the order of the guesses.

    Raises
    ------
    varmech.ConvergenceError
        No equilibrium near a guess (Newton did not converge, or K is singular there): its
        ``residual`` and ``iterations``.
    ValueError
        Malformed guesses, ``t`` or Newton options; velocity constraints.

    Examples
    --------
    A bead on a hoop of radius R spinning at Ω about its vertical diameter: the bottom is
    unstable for Ω² > g/R, and the bead rests where cos θ = g/(RΩ²).

    >>> import math, varmech, sympy as sp
    >>> th, w = sp.symbols("theta omega")
    >>> g, R, Omega = 9.81, 1.0, 5.0
    >>> L = R**2 * (w**2 + Omega**2 * sp.sin(th) ** 2) / 2 + g * R * sp.cos(th)
    >>> bead = varmech.symbolic.lagrangian(L, [th], [w])
    >>> bottom, off = varmech.equilibria(bead, [[0.0], [1.0]])
    >>> bottom.kind, off.kind, round(math.cos(off.q[0]), 12) == round(g / (R * Omega**2), 12)
    ('maximum', 'minimum', True)
    """
    if not isinstance(model, Model):
        raise TypeError(f"model: expected a varmech model, got {type(model).__name__}")
    points = np.asarray(guesses, dtype=float) if not isinstance(guesses, str) else None
    if points is None or points.ndim not in (1, 2) or points.shape[-1] != model.dim or points.size == 0:
        shape = None if points is None else points.shape
        raise ValueError(f"guesses: must have shape ({model.dim},) or (k, {model.dim}), got {shape}")
    t = finite("t", t)
    tolerance = number("newton_tolerance", newton_tolerance)
    iterations = integer("newton_max_iterations", newton_max_iterations, 1)
    found: list[Equilibrium] = []
    for k, guess in enumerate(np.atleast_2d(points)):
        q = _point(model, f"guesses[{k}]" if points.ndim == 2 else "guesses", guess)
        q, multipliers, residual, steps = _core.equilibrium(model._core, q, t, tolerance, iterations)
        if any(np.allclose(q, e.q, rtol=1e-8, atol=1e-8) for e in found):
            continue
        found.append(Equilibrium(q, multipliers, residual, steps, normal_modes(model, q, t=t)))
    return found


#: :func:`suggest_dt`'s default ``accuracy``: the phase error a period on the fastest mode, in
#: radians.
ACCURACY = 1e-3


@dataclass(frozen=True)
class StepSuggestion:
    """The step a method can take on a model, from its frequencies.

    Attributes
    ----------
    method : str
        The method.
    dt : float
        The suggested step: ``accurate_dt``, or ``(1 − margin)·stable_dt`` where smaller.
    stable_dt : float
        The stability limit h_ω/ω_max: the method blows up on the fastest mode above it.
    accurate_dt : float
        The largest step with a phase error of at most ``accuracy`` a period on the fastest
        mode.
    omega_max : float
        The largest |λ| of the modes at the point.
    h_omega_max : float
        The method's stability limit on q̈ = −ω²q (inf for an unconditionally stable one).
    margin : float
        The fraction of ``stable_dt`` kept in reserve (the frequencies change along the run).
    accuracy : float
        The phase error a period asked for (radians).

    Examples
    --------
    >>> import varmech
    >>> from varmech import examples
    >>> s = varmech.suggest_dt(examples.harmonic_oscillator(4.0), "verlet", [0.0], accuracy=1e-3)
    >>> s.dt == s.accurate_dt < s.stable_dt == 0.5
    True
    """

    method: str
    dt: float
    stable_dt: float
    accurate_dt: float
    omega_max: float
    h_omega_max: float
    margin: float
    accuracy: float


def suggest_dt(
    model: Model,
    method: str,
    q: ArrayLike,
    *,
    t: float = 0.0,
    accuracy: float = ACCURACY,
    margin: float = 0.1,
) -> StepSuggestion:
    """The step ``method`` can take on ``model`` near q: the step that keeps the fastest mode's
    phase error a period within ``accuracy``, and within the method's stability limit over the
    fastest mode there.

    A method is stable on q̈ = −ω²q while hω < h_ω, its limit (2 for verlet; see
    :func:`varmech.methods`); on a model the fastest mode at q sets the step. The phase error a
    period is measured on the method's own one-step map of the oscillator (it grows as (hω)^p,
    p the method's order). Frequencies change along a nonlinear run: ``margin`` keeps a fraction
    of the limit in reserve.

    Stability alone is not a step to run at: near its limit a method's energy error is a
    bounded offset many times the motion's kinetic energy (Verlet's modified energy differs
    from H by a factor 1/(1 − (hω/2)²)), which the conservation report calls "failed", and an
    implicit method has no limit. The default ``accuracy``, 1e-3 rad a period
    (``varmech.modes.ACCURACY``), keeps a second-order method's energy error near 0.1% of the
    energy (Verlet's is (hω)²/4 of it, at hω = 0.062: 100 steps a period), far below the 0.3 of
    the kinetic energy of a "too coarse" verdict: room for the frequencies of a nonlinear motion
    to rise above those at q (a pendulum swinging through its bottom, an orbit at pericentre),
    and a phase that drifts by a radian in a thousand periods. The eighth-order compositions and
    the splittings reach it at hω of 1.4–1.8 (``blanes_moan6`` only at the margin).

    Parameters
    ----------
    model
        Any model but one with velocity constraints.
    method
        A method's name.
    q
        The point whose frequencies bound the step (an equilibrium, or the run's start).
    t
        The time.
    accuracy
        The largest phase error a period on the fastest mode, in radians (default 1e-3).
    margin
        The fraction of the stability limit kept in reserve, in [0, 1).

    Returns
    -------
    StepSuggestion
        ``dt``, and what it comes from; ``dt`` is infinite only where ω_max = 0 (nothing at q
        sets a time scale).

    Raises
    ------
    ValueError
        An unknown method, or one with no stable step on an oscillator (explicit Euler, the
        Wisdom–Holman methods); malformed ``q``, ``t``, ``accuracy`` or ``margin``; velocity
        constraints.

    Examples
    --------
    Two pendulums (g = l = 1) joined by a spring of stiffness 3 swing together at ω = 1 and
    against each other at ω = √7, which sets verlet's limit 2/√7; the step is the accurate one,
    a fiftieth of it:

    >>> import numpy as np, varmech
    >>> def V(q): return -np.cos(q[0]) - np.cos(q[1]) + 1.5 * (q[0] - q[1]) ** 2
    >>> def dV(q): return np.sin(q) + 3.0 * (q - q[::-1])
    >>> pendulums = varmech.MechanicalSystem(2, V, dV)
    >>> s = varmech.suggest_dt(pendulums, "verlet", [0.0, 0.0])
    >>> round(s.stable_dt * 7**0.5, 6), s.dt == s.accurate_dt, round(s.dt / s.stable_dt, 3)
    (2.0, True, 0.031)
    """
    limits = stability_limits()
    if not isinstance(method, str) or method not in limits:
        raise ValueError(f"method: expected one of {sorted(limits)}, got {method!r}")
    margin = finite("margin", margin)
    if not 0.0 <= margin < 1.0:
        raise ValueError(f"margin: must be in [0, 1), got {margin}")
    accuracy = finite("accuracy", accuracy)
    modes = normal_modes(model, q, t=t)
    omega = modes.omega_max
    stable = _core.stable_step(method, omega)
    accurate = _core.accurate_step(method, omega, accuracy)
    dt = min((1.0 - margin) * stable, accurate)
    return StepSuggestion(method, dt, stable, accurate, omega, limits[method], margin, accuracy)


def fastest_frequency(model: Model, q: ArrayLike, *, t: float = 0.0) -> float:
    """The fastest frequency ω_max of the small oscillations at (q, q̇ = 0, t), from 32 force
    evaluations at most: what bounds a method's step there.

    Lanczos's method on the pencil (K, M) on the constraints' tangent space, from products
    alone: K v by a forward difference of the force along v, M⁻¹x by the inverse Legendre
    transform; no n × n matrix is formed, and 32 iterations (one force evaluation each) at most.
    ω_max = √max(κ_max, −κ_min) over the eigenvalues κ of K y = κ M y, from below: exact for 32
    degrees of freedom or fewer, within 5e-5 where the top of the spectrum stands apart, 6.4e-4
    low on the densest top there is (a chain of 100 masses). It is
    :attr:`NormalModes.omega_max` where G = D = 0, which costs 2n evaluations and an n³
    eigenproblem, and what :func:`varmech.integrate` checks the step against before a run.

    Parameters
    ----------
    model
        Any model but one with velocity constraints.
    q
        The configuration; on the constraints, for a constrained model.
    t
        The time.

    Returns
    -------
    float
        ω_max.

    Raises
    ------
    ValueError
        Malformed ``q`` or ``t``; velocity constraints.

    Examples
    --------
    A chain of n unit masses on unit springs with fixed ends, ω_max = 2 sin(nπ/2(n + 1)): exact
    for 30 masses, 6e-4 low for 100, whose top modes are 7e-4 apart:

    >>> import numpy as np, varmech
    >>> def V(q): return 0.5 * np.sum(np.diff(q, prepend=0.0, append=0.0) ** 2)
    >>> def dV(q):
    ...     d = np.diff(q, prepend=0.0, append=0.0)
    ...     return d[:-1] - d[1:]
    >>> def error(n):
    ...     chain = varmech.MechanicalSystem(n, V, dV)
    ...     return varmech.fastest_frequency(chain, np.zeros(n)) / (2 * np.sin(n * np.pi / (2 * n + 2))) - 1
    >>> bool(abs(error(30)) < 1e-7), f"{error(100):.1e}"
    (True, '-6.4e-04')
    """
    q = _point(model, "q", q)
    t = finite("t", t)
    omega, _, _ = _core.fastest_frequency(model._core, q, t)
    return float(omega)


#: The step by trial (:func:`step_by_trial`): the steps of its first candidate, the halvings it
#: may take, and the agreement it asks of a step with its half step (of each coordinate's and
#: momentum's excursion).
TRIAL_STEPS = 8
TRIAL_HALVINGS = 4
TRIAL_TOLERANCE = 0.02


def step_by_trial(model: Model, q: np.ndarray, p: np.ndarray, t_end: float, contacts: Sequence[_impacts.Contact] = ()) -> float:
    """A step at which a short trial of the model's default method from (q, p) is accurate:
    :meth:`varmech.Scene.of`'s default ``dt``.

    The first candidate is a twentieth of the fastest small-oscillation period at q
    (:func:`fastest_frequency`), at most ``t_end``/100 (``t_end``/1000 where nothing oscillates
    there); the trial runs it over :data:`TRIAL_STEPS` steps, and again at half the step. The
    difference of the two at the candidate's times, each coordinate and momentum against how
    far it moved, estimates the candidate's error (step doubling: a fraction 1 − 2⁻ᵖ of it, p
    the method's order); a candidate within :data:`TRIAL_TOLERANCE` is the step, rounded to three
    significant digits (for tables and chart titles), else the trial halves it, over the same
    horizon, at most :data:`TRIAL_HALVINGS` times: 248 steps at most. A step whose run fails
    (a Newton iteration that does not converge, a state that blows up) is not accurate. The
    trial sees the motion's start only: a motion that speeds up later (a close approach) needs
    its own ``dt``.

    Raises
    ------
    ValueError
        Naming ``dt``, when no candidate is accurate, with each candidate and what it gave.
    """
    method = model.kind.default_method
    try:
        omega = fastest_frequency(model, q)
    except ValueError:  # velocity constraints: no small oscillations to read a period from
        omega = 0.0
    h = min(2 * math.pi / omega / 20, t_end / 100) if math.isfinite(omega) and omega > 0 else t_end / 1000
    specs = _impacts.specs(contacts) or None
    times = np.arange(TRIAL_STEPS + 1, dtype=np.float64) * h

    def trial(step: float) -> np.ndarray | str:
        """The states at the first candidate's times by steps of ``step``, or why the run failed."""
        try:
            spec = _core.RunSpec(
                dt=step, steps=round(times[-1] / step), method=method, max_energy_error=None, contacts=specs, t_eval=times
            )
            record = _core.integrate(model._core, q, p, spec)
        except _core.VarmechError as e:
            return f"{type(e).__name__} at step {getattr(e, 'step', '?')}"
        return np.hstack([record.q, record.p])

    tried = []
    coarse = trial(h)
    for _ in range(TRIAL_HALVINGS):
        fine = trial(h / 2)
        if isinstance(coarse, str) or isinstance(fine, str):
            tried.append(f"{h:.3g} ({coarse if isinstance(coarse, str) else 'its half step: ' + fine})")
        else:
            moved = np.max(np.abs(fine - fine[0]), axis=0)
            # Coordinates and momenta that move (a cyclic coordinate's momentum does not).
            moving = (moved > 1e-9 * np.abs(fine[0])) & (moved > 1e-12 * np.max(moved))
            error = float(np.max(np.abs(coarse - fine)[:, moving] / moved[moving])) if moving.any() else 0.0
            if error <= TRIAL_TOLERANCE:
                return float(f"{h:.3g}")
            tried.append(f"{h:.3g} (differs from its half step by {error:.2g} of the motion)")
        h, coarse = h / 2, fine
    raise ValueError(
        f"dt: no step of {method} is accurate over a trial of {times[-1]:.3g} from q0 "
        f"(within {TRIAL_TOLERANCE:g} of its half step); tried {', '.join(tried)}; pass dt (--dt on the command line)"
    )


class StabilityWarning(VarmechWarning):
    """The step is beyond the method's stability limit on the model's fastest mode: the run will
    blow up (or, for a nonlinear model, stay where its frequencies are lower).

    :func:`varmech.integrate` issues it before stepping when h·ω_max at the first state exceeds
    the method's limit h_ω (:func:`varmech.methods`), ω_max by :func:`fastest_frequency`.
    :func:`suggest_dt` gives a step within it. Filter it as any warning
    (``warnings.simplefilter("ignore", varmech.StabilityWarning)``).

    Examples
    --------
    A unit oscillator at h = 2.5, beyond Verlet's hω < 2:

    >>> import warnings, varmech
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     traj = varmech.integrate(varmech.scenes.harmonic_oscillator(), dt=2.5, steps=3, max_energy_error=None)
    >>> print(caught[0].category.__name__, str(caught[0].message).split(" (")[0])
    StabilityWarning dt: h·ω_max = 2.5 at the first state is beyond verlet's stability limit 2
    """


@functools.cache
def stability_limits() -> dict[str, float]:
    """Each method's stability limit h_ω on q̈ = −ω²q by name (:func:`varmech.methods`), read once.

    Returns
    -------
    dict of str to float
        inf for an unconditionally stable method, nan for one without an oscillator's limit.

    Examples
    --------
    >>> from varmech.modes import stability_limits
    >>> stability_limits()["verlet"], stability_limits()["midpoint"]
    (2.0, inf)
    """
    return {m.name: m.h_omega_max for m in methods()}


def warn_if_unstable(model: Model, method: str, q: np.ndarray, dt: float, t: float) -> None:
    """Warns with a :class:`StabilityWarning` where h·ω_max at (q, t) is beyond ``method``'s
    stability limit (the core's test, which a divergence's diagnosis shares); silent for
    unconditionally stable methods (and names that are no method's: the run refuses them),
    models with velocity constraints, and models whose frequencies do not evaluate there (a
    user's exception included: the run raises it, with its partial trajectory)."""
    try:
        beyond = _core.beyond_limit(model._core, method, q, dt, t)
    except Exception:  # noqa: BLE001 - the run's to report, with its step and partial trajectory
        return
    if beyond is not None:
        h_omega, limit, omega = beyond
        warnings.warn(
            f"dt: h·ω_max = {h_omega:.4g} at the first state is beyond {method}'s stability limit {limit:.6g} "
            f"(ω_max = {omega:.6g}, the fastest frequency of the small oscillations there): the run will blow up; "
            f"take dt below {limit / omega:.6g} (varmech.suggest_dt)",
            StabilityWarning,
            stacklevel=3,
        )
