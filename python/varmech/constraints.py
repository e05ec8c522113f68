"""Holonomic and velocity constraints: consistent initial data."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from ._util import vector
from .model import Model


def project(model: Model, q0: ArrayLike, p0: ArrayLike | None = None, *, v0: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The nearest consistent state (q, p) of a constrained model: q on g(q) = 0 by Newton's
    method along M⁻¹Gᵀ, then p on the hidden constraint G(q)M⁻¹p = 0 by the M-orthogonal
    projection p − Gᵀ(GM⁻¹Gᵀ)⁻¹GM⁻¹p. With velocity constraints A(q)q̇ = 0, q as it is and p
    on them by the same projection with A for G (onto A(q)q̇ + b(q) = 0 for affine ones:
    p − Aᵀ(AM⁻¹Aᵀ)⁻¹(AM⁻¹p + b)). Give the momenta ``p0`` or the velocities
    ``v0`` (default: at rest).

    Raises ValueError naming ``q0`` when no point of the constraints is near (Newton fails) or
    the constraints are not independent there, and ``model`` when it has no constraints.

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
