"""Routh reduction: finding the cyclic coordinates a model can ignore, the Routhian model that
ignores them, and the reconstruction of the full motion."""

from __future__ import annotations

import operator
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from ._util import floats, vector
from .model import RECIPES, Model, field, from_recipe, integers, numbers
from .scenes import Scene
from .trajectory import Trajectory

__all__ = [
    "ReducedModel",
    "cyclic_coordinates",
    "routh",
]


def cyclic_coordinates(
    model: Model, q: ArrayLike, *, spread: float = 1.0, samples: int = 64, seed: int = 0, rtol: float = 1e-9
) -> list[int]:
    """The coordinates i with ∂L/∂qᵢ ≡ 0, found numerically: ∂L/∂q is evaluated at ``samples``
    random states, positions within ``spread`` of ``q`` and velocities of size up to ``spread``
    (and at t in [0, 1] for time-dependent models), and coordinate i is a candidate when
    |∂L/∂qᵢ| ≤ ``rtol``·max(1, ‖∂L/∂q‖∞) at every one of them.

    Sampling can miss a dependence that vanishes on the samples, so the result is a list of
    candidates (Routh reduction needs ∂L/∂qᵢ = 0 everywhere); derivatives from differences
    (closures without ``dl_dq``) are accurate to about 1e-10, within the default ``rtol``.

    Parameters
    ----------
    model : Model
        A varmech model.
    q : array_like
        The configuration to sample around, shape (n,).
    spread : float, default 1.0
        The half-width of the sampled positions and the largest sampled |q̇ᵢ|.
    samples : int, default 64
        The number of random states.
    seed : int, default 0
        The seed of ``numpy.random.default_rng``.
    rtol : float, default 1e-9
        The largest relative |∂L/∂qᵢ| called zero.

    Returns
    -------
    list of int
        The indices of the candidate cyclic coordinates, increasing.

    Raises
    ------
    ValueError
        ``q`` not n finite numbers, ``spread`` not positive and finite, or ``samples`` not a
        positive integer.

    See Also
    --------
    routh : Ignores the cyclic coordinates.

    Examples
    --------
    >>> import varmech
    >>> from varmech.reduction import cyclic_coordinates
    >>> top = varmech.scenes.heavy_top()        # q = (θ, φ, ψ): nutation, precession, spin
    >>> cyclic_coordinates(top.model, top.q0)
    [1, 2]
    """
    relative = _relative_dl_dq(model, q, spread=spread, samples=samples, seed=seed)
    ignorable = np.all(relative <= rtol, axis=0)
    return [int(i) for i in np.flatnonzero(ignorable)]


def _relative_dl_dq(model: Model, q: ArrayLike, *, spread: float, samples: int, seed: int) -> np.ndarray:
    """|∂L/∂qᵢ|/max(1, ‖∂L/∂q‖∞) at random states around ``q`` (rows; see
    :func:`cyclic_coordinates`). States where ∂L/∂q is not finite (off the model's domain, such
    as r = 0) are left out: they show no dependence either way."""
    n = model.dim
    q = vector("q", q, n)
    if not (np.isfinite(spread) and spread > 0):
        raise ValueError(f"spread: must be finite and positive, got {spread!r}")
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise ValueError(f"samples: must be a positive integer, got {samples!r}")
    rng = np.random.default_rng(seed)
    qs = q + spread * rng.uniform(-1.0, 1.0, (samples, n))
    vs = spread * rng.uniform(-1.0, 1.0, (samples, n))
    ts = rng.uniform(0.0, 1.0, samples) if model.time_dependent else np.zeros(samples)
    with np.errstate(invalid="ignore", over="ignore"):
        gradients = model._derivative("dl_dq", qs, vs, ts)
    gradients = gradients[np.all(np.isfinite(gradients), axis=1)]
    scale = np.maximum(1.0, np.max(np.abs(gradients), axis=1, keepdims=True))
    return np.abs(gradients) / scale


def _check_cyclic(model: Model, cyclic: list[int], q: np.ndarray) -> None:
    """ValueError unless every coordinate in ``cyclic`` is cyclic at the states
    :func:`cyclic_coordinates` samples around ``q``: Routh reduction of a coordinate L depends on
    would integrate a different system without a word."""
    relative = _relative_dl_dq(model, q, spread=1.0, samples=64, seed=0)
    for i in cyclic:
        found = float(np.max(relative[:, i], initial=0.0))
        if found > 1e-9:
            raise ValueError(
                f"cyclic: coordinate {i} is not cyclic: |∂L/∂q{i}| reaches {found:.3e} relative to ‖∂L/∂q‖ "
                f"at states around {q.tolist()} (cyclic_coordinates(model, q) finds the cyclic ones)"
            )


def cyclic_indices(cyclic: Sequence[int], n: int) -> list[int]:
    """``cyclic`` as distinct indices of n coordinates that leave one, or ValueError."""
    try:
        indices = [operator.index(i) for i in cyclic]
    except TypeError:
        raise ValueError(f"cyclic: must be a sequence of coordinate indices, got {cyclic!r}") from None
    if not indices or len(set(indices)) != len(indices) or not all(0 <= i < n for i in indices) or len(indices) >= n:
        raise ValueError(f"cyclic: need distinct indices in [0, {n}) that leave at least one coordinate, got {indices}")
    return indices


class ReducedModel(Model):
    """The Routh-reduced model of ``full``: its Routhian on the coordinates that are not
    ignored (the shape coordinates x), built by :func:`routh`.

    Sign convention (Marsden, Ratiu & Scheurle 2000): R(x, ẋ, t; μ) = L − μ·ċ, with the
    velocities ċ of the ignored coordinates solving ∂L/∂ċ = μ. R then acts as a Lagrangian: x(t)
    solves its Euler–Lagrange equations exactly when (x, c)(t) solves those of L on the level
    set p_c = μ. (Landau–Lifshitz and Goldstein use R = μ·ċ − L, whose equations carry the
    opposite sign.) For L = ½q̇ᵀM(q)q̇ − V(q),

        R = ½ẋᵀ(M_xx − M_xc M_cc⁻¹ M_cx)ẋ + μᵀM_cc⁻¹M_cx ẋ − (V + ½μᵀM_cc⁻¹μ),

    a kinetic term, a gyroscopic term linear in ẋ, and the amended potential V_μ; the core
    finds ċ = M_cc⁻¹(μ − M_cx ẋ) in one Newton step (with exact Hessians), and by Newton's method
    for a general L. R's energy ∂R/∂ẋ·ẋ − R is the energy of L.

    The reduced model is an ordinary model: integrate it with ``midpoint``, ``trapezoid``,
    ``galerkin4`` or ``galerkin6``, then put the ignored coordinates back with
    :meth:`reconstruct`.

    Parameters
    ----------
    full : Model
        The full model, unforced and unconstrained (not itself reduced).
    cyclic : sequence of int
        The indices c of the ignored coordinates, distinct, leaving at least one.
    momenta : array_like
        Their conserved momenta μ = ∂L/∂ċ, one each.
    reference : array_like, optional
        The values of the ignored coordinates at which L is evaluated (default zeros).

    Attributes
    ----------
    full : Model
        The full model.
    cyclic : tuple of int
        The ignored coordinates' indices.
    momenta : numpy.ndarray
        μ.
    shape : tuple of int
        The indices of the remaining (shape) coordinates x in the full model.

    See Also
    --------
    routh : Builds the reduced model, checking that the coordinates are cyclic.
    cyclic_coordinates : Finds candidates.

    References
    ----------
    .. [1] J. E. Marsden, T. S. Ratiu and J. Scheurle, "Reduction theory and the
       Lagrange–Routh equations", *J. Math. Phys.* 41, 3379–3429 (2000).

    Examples
    --------
    >>> import varmech
    >>> from varmech.reduction import ReducedModel
    >>> top = varmech.scenes.heavy_top()
    >>> reduced = ReducedModel(top.model, [1, 2], top.p0[[1, 2]])
    >>> reduced.dim, reduced.shape, reduced.cyclic
    (1, (0,), (1, 2))
    """

    _core: _core.RouthModel

    def __init__(self, full: Model, cyclic: Sequence[int], momenta: ArrayLike, *, reference: ArrayLike | None = None):
        if not isinstance(full, Model):
            raise TypeError(f"model: expected a varmech model, got {type(full).__name__}")
        if isinstance(full, ReducedModel):
            raise ValueError("model: is reduced already; ignore all the cyclic coordinates of the full model at once")
        self._arguments = {"full": full, "cyclic": cyclic, "momenta": momenta, "reference": reference}
        n = full.dim
        indices = cyclic_indices(cyclic, n)
        m = len(indices)
        mu = vector("momenta", momenta, m)
        ref = np.zeros(m) if reference is None else vector("reference", reference, m)
        self._core = _core.routh(full._core, indices, mu.tolist(), ref.tolist())
        self.full = full
        self.cyclic = tuple(indices)
        self.momenta = mu
        self.shape = tuple(i for i in range(n) if i not in indices)
        self.symmetries = ()
        self.name = f"{full.name}, Routh-reduced (ignoring {', '.join(f'q[{i}]' for i in indices)})"
        self._reference = ref

    def _recipe(self) -> dict[str, Any] | None:
        full = self.full._recipe()
        if full is None:
            return None
        return {
            "kind": "reduced",
            "full": full,
            "cyclic": list(self.cyclic),
            "momenta": self.momenta.tolist(),
            "reference": self._reference.tolist(),
        }

    def reduce(self, q: ArrayLike, p: ArrayLike, *, rtol: float = 1e-12) -> tuple[np.ndarray, np.ndarray]:
        """The reduced state (x, p_x) of a full state (q, p) whose cyclic momenta are μ.

        Parameters
        ----------
        q : array_like
            The full configuration, shape (n,).
        p : array_like
            The full momenta, shape (n,); those of the cyclic coordinates must be μ.
        rtol : float, default 1e-12
            How close to μ, relative to max(1, |μ|).

        Returns
        -------
        x, p_x : numpy.ndarray
            The shape coordinates and their momenta, shape (r,) each.

        Raises
        ------
        ValueError
            ``q`` or ``p`` not n finite numbers, or the cyclic momenta of ``p`` not μ (naming
            ``p``).

        Examples
        --------
        >>> import varmech
        >>> top = varmech.scenes.heavy_top()       # q = (θ, φ, ψ); φ and ψ are cyclic
        >>> reduced = varmech.routh(top, [1, 2])
        >>> reduced.reduce(top.q0, top.p0)
        (array([0.3]), array([0.]))
        """
        n = self.full.dim
        q, p = vector("q", q, n), vector("p", p, n)
        pc = p[list(self.cyclic)]
        if np.any(np.abs(pc - self.momenta) > rtol * np.maximum(1.0, np.abs(self.momenta))):
            raise ValueError(f"p: the cyclic momenta {pc} are not the reduced model's μ = {self.momenta}")
        return q[list(self.shape)], p[list(self.shape)]

    def amended_potential(self, x: ArrayLike, t: ArrayLike = 0.0) -> np.ndarray:
        """The amended potential V_μ(x, t) = −R(x, 0, t).

        For a mechanical system V_μ = V + ½μᵀM_cc⁻¹μ. Relative equilibria (x at rest, c turning
        uniformly) are its critical points.

        Parameters
        ----------
        x : array_like
            One state (r,) or rows (N, r) of shape coordinates.
        t : float or array_like, default 0.0
            The time, or one per row.

        Returns
        -------
        numpy.ndarray
            V_μ, shape () for one state or (N,) for rows.

        Raises
        ------
        ValueError
            ``x`` not r numbers (or rows of them), or ``t`` not one time per row.

        Examples
        --------
        >>> import varmech
        >>> top = varmech.scenes.heavy_top()       # q = (θ, φ, ψ); φ and ψ are cyclic
        >>> reduced = varmech.routh(top, [1, 2])
        >>> reduced.amended_potential([[0.3], [0.4]]).round(6)
        array([7.205336, 7.19527 ])
        """
        x = floats("x", x)
        rows = np.ascontiguousarray(np.atleast_2d(x))
        t1 = np.ascontiguousarray(np.broadcast_to(floats("t", t), rows.shape[:1]))
        values = _core.amended_potential(self._core, t1, rows)
        return values.reshape(x.shape[:-1])

    def cyclic_velocity(self, x: ArrayLike, xdot: ArrayLike, t: ArrayLike = 0.0) -> np.ndarray:
        """The velocities ċ of the ignored coordinates, solving ∂L/∂ċ(x, ẋ, ċ, t) = μ.

        Parameters
        ----------
        x : array_like
            Shape coordinates, (r,) or rows (N, r) (broadcast against ``xdot``).
        xdot : array_like
            Their velocities ẋ, (r,) or rows (N, r).
        t : float or array_like, default 0.0
            The time, or one per row.

        Returns
        -------
        numpy.ndarray
            ċ, shape (m,) for one state or (N, m) for rows.

        Raises
        ------
        ValueError
            ``x`` or ``xdot`` not r numbers (or rows of them), or ``t`` not one time per row.

        Examples
        --------
        >>> import varmech
        >>> top = varmech.scenes.heavy_top()       # q = (θ, φ, ψ); φ and ψ are cyclic
        >>> reduced = varmech.routh(top, [1, 2])
        >>> reduced.cyclic_velocity([0.3], [0.0]).round(12)    # at θ = 0.3 at rest: no precession
        array([0., 5.])
        """
        xdot = floats("xdot", xdot)
        rows = np.ascontiguousarray(np.atleast_2d(xdot))
        x2 = np.ascontiguousarray(np.broadcast_to(floats("x", x), rows.shape))
        t1 = np.ascontiguousarray(np.broadcast_to(floats("t", t), rows.shape[:1]))
        out = _core.cyclic_velocity(self._core, t1, x2, rows)
        return out.reshape(xdot.shape[:-1] + (len(self.cyclic),))

    def reconstruct(self, traj: Trajectory, c0: ArrayLike | None = None) -> Trajectory:
        """The full trajectory (q, p) of a reduced one: the ignored coordinates from ``c0``
        (default: the reference values, zeros) and their increments, and p_c = μ exactly.

        The increments follow the discrete scheme where it defines them: for ``midpoint`` and
        ``trapezoid`` runs saved at every step, Δc = hċ with ċ from the discrete momentum
        equation Σᵢ bᵢ ∂L/∂ċ(x₀ + cᵢΔx, Δx/h, ċ) = μ (discrete Routh reduction; for the midpoint
        rule this is exactly what the unreduced DEL integration computes). Otherwise Δc = ∫ċ dt
        by 3-point Gauss quadrature along the cubic Hermite interpolant of the saved states,
        accurate to O(H⁴) in the spacing H of the saved states.

        Parameters
        ----------
        traj : Trajectory
            A run of this reduced model.
        c0 : array_like, optional
            The ignored coordinates at the start (default zeros).

        Returns
        -------
        Trajectory
            The run of the full model: q with x and c, p with p_x and μ.

        Raises
        ------
        ValueError
            ``traj`` is not a trajectory of this reduced model, or ``c0`` not m finite numbers.

        Examples
        --------
        The midpoint rule reduced and reconstructed is the midpoint rule on the full model:

        >>> import numpy as np, varmech
        >>> top = varmech.scenes.heavy_top()
        >>> reduced = varmech.routh(top, [1, 2])
        >>> x0, px0 = reduced.reduce(top.q0, top.p0)
        >>> run = varmech.integrate(reduced, x0, px0, dt=0.01, steps=100, method="midpoint")
        >>> full = reduced.reconstruct(run, top.q0[[1, 2]])
        >>> direct = varmech.integrate(top, dt=0.01, steps=100, method="midpoint")
        >>> bool(np.abs(full.q - direct.q).max() < 1e-13), bool((full.p[:, 1:] == top.p0[1:]).all())
        (True, True)
        """
        if not isinstance(traj, Trajectory) or traj.model is not self:
            raise ValueError("traj: must be a trajectory of this reduced model")
        m = len(self.cyclic)
        c0 = np.zeros(m) if c0 is None else vector("c0", c0, m)
        every_step = len(traj.t) == traj.steps + 1
        rule = traj.method if every_step and traj.method in ("midpoint", "trapezoid") else None
        increments = _core.cyclic_increments(self._core, *traj._arrays(), rule)
        c = c0 + np.vstack([np.zeros((1, m)), np.cumsum(increments, axis=0)])
        n = self.full.dim
        q = np.empty((len(traj.t), n))
        p = np.empty_like(q)
        q[:, list(self.shape)], q[:, list(self.cyclic)] = traj.q, c
        p[:, list(self.shape)], p[:, list(self.cyclic)] = traj.p, self.momenta
        return Trajectory(
            traj.t, q, p, self.full, traj.method, traj.dt, traj.steps, traj.nfev, traj.newton, traj.work,
            status=traj.status, message=traj.message,
        )


def routh(
    model: Model | Scene,
    cyclic: Sequence[int] | None = None,
    momenta: ArrayLike | None = None,
    *,
    reference: ArrayLike | None = None,
) -> ReducedModel:
    """Routh reduction: the model that ignores the cyclic coordinates ``cyclic`` of ``model`` at
    their conserved momenta ``momenta`` (μ = ∂L/∂ċ), a :class:`ReducedModel` with
    R = L − μ·ċ on the remaining coordinates.

    ``model`` may be a scene: its initial cyclic momenta are then the default μ, and without
    ``cyclic`` the coordinates that :func:`cyclic_coordinates` finds around its initial state
    are ignored. The coordinates must be cyclic (∂L/∂c ≡ 0, checked at the states
    :func:`cyclic_coordinates` samples around the scene's initial state or q = 0: a ValueError
    names a coordinate that is not), the model unforced and unconstrained. ``reference`` gives values for the ignored coordinates, which L must not
    depend on (default zeros).

    Parameters
    ----------
    model : Model or Scene
        The full model, unforced and unconstrained, or a scene.
    cyclic : sequence of int, optional
        The indices of the coordinates to ignore. Default (scenes only): those
        :func:`cyclic_coordinates` finds around the scene's initial state.
    momenta : array_like, optional
        Their conserved momenta μ = ∂L/∂ċ. Default (scenes only): the scene's initial ones.
    reference : array_like, optional
        Values of the ignored coordinates at which L is evaluated (L does not depend on them;
        default zeros).

    Returns
    -------
    ReducedModel
        An ordinary model on the remaining coordinates: ``reduce(q, p)`` gives its initial
        state, ``reconstruct(traj, c0)`` the full trajectory.

    Raises
    ------
    ValueError
        A coordinate that is not cyclic (naming it and the size of ∂L/∂c found), missing
        ``cyclic`` or ``momenta`` where they have no default, a forced or constrained model,
        ``momenta`` of the wrong length.

    Examples
    --------
    The heavy top with its precession φ and spin ψ ignored stays between the turning points of
    its nutation, θ = 0.3 and 0.47947487:

    >>> import varmech
    >>> top = varmech.scenes.heavy_top()
    >>> reduced = varmech.routh(top, [1, 2])
    >>> x0, px0 = reduced.reduce(top.q0, top.p0)
    >>> traj = varmech.integrate(reduced, x0, px0, dt=0.005, t_end=5.0, method="galerkin4")
    >>> round(float(traj.q.min()), 6), round(float(traj.q.max()), 6)
    (0.3, 0.479475)
    """
    if cyclic is None:
        if not isinstance(model, Scene):
            raise ValueError("cyclic: give the indices to ignore (cyclic_coordinates(model, q) finds candidates)")
        cyclic = cyclic_coordinates(model.model, model.q0)
        if not cyclic:
            raise ValueError(f"cyclic: {model.name} has no cyclic coordinate around its initial state")
    if isinstance(model, Scene):
        if momenta is None:
            momenta = np.asarray(model.p0)[cyclic_indices(cyclic, model.model.dim)]
        around = np.asarray(model.q0, dtype=float)
        model = model.model
    else:
        around = np.zeros(model.dim)
    if momenta is None:
        raise ValueError("momenta: the conserved momenta μ of the ignored coordinates are required")
    reduced = ReducedModel(model, cyclic, momenta, reference=reference)
    _check_cyclic(model, cyclic_indices(cyclic, model.dim), around)
    return reduced


def _reduced_of_recipe(recipe: dict[str, Any]) -> ReducedModel:
    full = from_recipe(field(recipe, "full", dict))
    reference = numbers(recipe["reference"], "reference")
    return ReducedModel(full, integers(recipe["cyclic"], "cyclic"), numbers(recipe["momenta"], "momenta"), reference=reference)


RECIPES["reduced"] = _reduced_of_recipe
