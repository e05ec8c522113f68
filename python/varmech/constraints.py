"""Holonomic and velocity constraints: consistent initial data."""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from ._util import vector
from ._warnings import VarmechWarning
from .model import Model

__all__ = [
    "INTEGRABLE_CURVATURE",
    "IntegrableConstraintsWarning",
    "integrable_near",
    "project",
]


def project(model: Model, q0: ArrayLike, p0: ArrayLike | None = None, *, v0: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The nearest consistent state (q, p) of a constrained model: q on g(q) = 0 by Newton's
    method along M⁻¹Gᵀ, then p on the hidden constraint G(q)M⁻¹p = 0 by the M-orthogonal
    projection p − Gᵀ(GM⁻¹Gᵀ)⁻¹GM⁻¹p. With velocity constraints A(q)q̇ = 0, q as it is and p
    on them by the same projection with A for G (onto A(q)q̇ + b(q) = 0 for affine ones:
    p − Aᵀ(AM⁻¹Aᵀ)⁻¹(AM⁻¹p + b)). Give the momenta ``p0`` or the velocities
    ``v0`` (default: at rest).

    Parameters
    ----------
    model : Model
        A model with holonomic constraints or velocity constraints.
    q0 : array_like, shape (n,)
        The positions, near the constraints.
    p0, v0 : array_like, shape (n,), optional
        The momenta, or the velocities (one of them; default: at rest).

    Returns
    -------
    q, p : ndarray, shape (n,)
        A state on the constraints (and on the hidden constraint), from which
        :func:`varmech.integrate` starts.

    Raises
    ------
    ValueError
        Naming ``q0`` when no point of the constraints is near (Newton fails) or the constraints
        are not independent there, ``model`` when it has no constraints, ``p0, v0`` when both are
        given, or an argument of the wrong shape.

    Examples
    --------
    A disk rolling upright, ẋ = Rφ̇cosθ and ẏ = Rφ̇sinθ (q = (x, y, θ, φ), R = 1), set off
    sideways: the projection keeps the rolling part.

    >>> import numpy as np, varmech
    >>> A = lambda q: np.array([[1.0, 0, 0, -np.cos(q[2])], [0, 1.0, 0, -np.sin(q[2])]])
    >>> disk = varmech.MechanicalSystem(4, lambda q: 0.0, lambda q: np.zeros(4), mass=[1, 1, 0.25, 0.5],
    ...                                 velocity_constraints=A, velocity_constraint_count=2)
    >>> q, p = varmech.project(disk, [0, 0, 0, 0], v0=[1.0, 1.0, 0, 0])
    >>> np.round(p, 12).tolist()
    [0.666666666667, 0.0, 0.0, 0.333333333333]
    """
    if not model.constraints and not model.velocity_constraints:
        raise ValueError("model: has no holonomic constraints (nor velocity constraints)")
    n = model.dim
    q0 = vector("q0", q0, n)
    if p0 is not None and v0 is not None:
        raise ValueError("p0, v0: give one of them")
    p0 = model.momentum(q0, vector("v0", v0, n)) if v0 is not None else vector("p0", p0 if p0 is not None else np.zeros(n), n)
    return _core.project(model._core, q0, p0)


class IntegrableConstraintsWarning(VarmechWarning):
    """Velocity constraints that integrate to holonomic ones near the initial state: give them
    as g(q) = 0 (``constraints=``), for RATTLE or the constrained DEL step.

    :func:`varmech.integrate` warns so when Frobenius' test (:func:`integrable_near`) finds
    the distribution ker A(q) flat at the initial state: the constraints A(q)q̇ = 0 are then
    the derivative of some g(q) = 0, and the nonholonomic integrators would keep g only to
    their order, where RATTLE keeps it to round-off.

    See Also
    --------
    integrable_near : the test itself.

    Examples
    --------
    x ẋ + y ẏ = 0 is the derivative of the circle x² + y² = 1:

    >>> import warnings, numpy as np, varmech
    >>> circle = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2),
    ...     velocity_constraints=lambda q: np.array([[q[0], q[1]]]), velocity_constraint_count=1)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     traj = varmech.integrate(circle, [1.0, 0.0], v0=[0.0, 1.0], dt=0.01, steps=10)
    >>> [w.category.__name__ for w in caught]
    ['IntegrableConstraintsWarning']
    """


#: Frobenius' test calls the constraints integrable below this relative curvature: far above
#: the accuracy of a differenced ∂A/∂q (about 1e-10), far below rolling's order 1.
INTEGRABLE_CURVATURE = 1e-6


def integrable_near(model: Model, q0: ArrayLike) -> bool:
    """Whether the velocity constraints A(q)q̇ = 0 of ``model`` integrate to holonomic ones
    near ``q0``, by Frobenius' test: each constraint form ω_k = A_k·dq has dω_k = 0 on ker A,
    Nᵀ(∂A_kj/∂qᵢ − ∂A_ki/∂qⱼ)N = 0 for a basis N of ker A(q), at q0 and at three points
    about it (0.1·max(1, |q0|) away). Rolling twists ker A and is not integrable; x ẋ + y ẏ = 0
    is the circle's derivative.

    Parameters
    ----------
    model
        A model with velocity constraints.
    q0
        The configuration near which to test, shape (n,).

    Returns
    -------
    bool
        True when the relative curvature of ker A (the core's ``model::curvature``) is below
        :data:`INTEGRABLE_CURVATURE` at all four points.

    Raises
    ------
    ValueError
        ``q0`` of the wrong shape or not finite, or a ``model`` without velocity constraints.

    Examples
    --------
    >>> import numpy as np, varmech
    >>> circle = varmech.MechanicalSystem(2, lambda q: 0.0, lambda q: np.zeros(2),
    ...     velocity_constraints=lambda q: np.array([[q[0], q[1]]]), velocity_constraint_count=1)
    >>> varmech.constraints.integrable_near(circle, [1.0, 0.0])
    True
    """
    q0 = vector("q0", q0, model.dim)
    rng = np.random.default_rng(0)
    points = q0 + 0.1 * max(1.0, float(np.max(np.abs(q0)))) * np.vstack([np.zeros(model.dim), rng.standard_normal((3, model.dim))])
    curvature = _core.constraint_curvature(model._core, points)
    if curvature is None:
        raise ValueError(f"model: {model.name} has no velocity constraints")
    return bool(np.all(np.asarray(curvature) < INTEGRABLE_CURVATURE))


def warn_if_integrable(model: Model, q0: np.ndarray) -> None:
    """An :class:`IntegrableConstraintsWarning` if the model's velocity constraints are
    holonomic in disguise near ``q0`` (:func:`integrable_near`)."""
    if integrable_near(model, q0):
        warnings.warn(
            f"velocity_constraints: the constraints of {model.name} integrate to holonomic ones near q0 (Frobenius: "
            "dω vanishes on ker A); give them as g(q) = 0 with constraints= for RATTLE or the constrained DEL step",
            IntegrableConstraintsWarning,
            stacklevel=3,
        )
