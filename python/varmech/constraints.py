"""Holonomic constraints: consistent initial data."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from ._util import vector
from .model import Model


def project(model: Model, q0: ArrayLike, p0: ArrayLike | None = None, *, v0: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The nearest consistent state (q, p) of a constrained model: q on g(q) = 0 by Newton's
    method along M⁻¹Gᵀ, then p on the hidden constraint G(q)M⁻¹p = 0 by the M-orthogonal
    projection p − Gᵀ(GM⁻¹Gᵀ)⁻¹GM⁻¹p. Give the momenta ``p0`` or the velocities ``v0``
    (default: at rest).

    Raises ValueError naming ``q0`` when no point of the constraints is near (Newton fails) or
    the constraints are not independent there, and ``model`` when it has no constraints.
    """
    if not model.constraints:
        raise ValueError("model: has no holonomic constraints")
    n = model.dim
    q0 = vector("q0", q0, n)
    if p0 is not None and v0 is not None:
        raise ValueError("p0, v0: give one of them")
    p0 = model.momentum(q0, vector("v0", v0, n)) if v0 is not None else vector("p0", p0 if p0 is not None else np.zeros(n), n)
    return _core.project(model._core, q0, p0)
