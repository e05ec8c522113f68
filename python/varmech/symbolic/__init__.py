"""Models from SymPy: write the Lagrangian, get every derivative, run at native speed.

The user gives L(q, q̇, t) (or the mechanical form: a mass matrix M and a potential V), and
varmech derives what the integrators need (∂L/∂q, ∂L/∂q̇ and the three Hessians; or ∇V and M
for L = ½q̇ᵀMq̇ − V(q) with M constant), the generalized force of ``force`` and ``rayleigh`` and
the Jacobian of the constraints, finds the cyclic coordinates, and lowers every function to an
instruction tape that the Rust core runs with no Python call per step::

    import sympy as sp
    import varmech

    q1, q2, v1, v2 = sp.symbols("q1 q2 v1 v2")
    m1, m2, l1, l2, g = sp.symbols("m1 m2 l1 l2 g", positive=True)
    L = (sp.Rational(1, 2) * (m1 + m2) * l1**2 * v1**2 + sp.Rational(1, 2) * m2 * l2**2 * v2**2
         + m2 * l1 * l2 * v1 * v2 * sp.cos(q1 - q2) + (m1 + m2) * g * l1 * sp.cos(q1) + m2 * g * l2 * sp.cos(q2))
    model = varmech.symbolic.lagrangian(L, q=[q1, q2], v=[v1, v2],
                                        parameters={m1: 1.0, m2: 2.0, l1: 2.0, l2: 3.0, g: 9.80665})
    traj = varmech.integrate(model, [0.5, 1.0], [0.0, 0.0], dt=0.01, steps=1000, method="midpoint")

:func:`routh` gives the Routhian of cyclic coordinates in closed form, and
:mod:`varmech.symbolic.examples` holds the symbolic twins of the built-in scenes, the elastic
pendulum and the bead on a rotating hoop.

Needs SymPy: ``pip install varmech[symbolic]``.
"""

from __future__ import annotations

try:
    import sympy  # noqa: F401 - here, so that a missing SymPy is named with the extra to install
except ImportError as err:  # pragma: no cover - exercised without SymPy only
    raise ImportError("varmech.symbolic needs SymPy: pip install varmech[symbolic]") from err

from . import examples
from ._constructors import MAX_COORDINATES, lagrangian, mechanical, routh
from ._delays import Delayed
from ._lower import TAPE_OPS
from ._mass_flow import MassFlow
from ._mechanics import from_mechanics
from ._model import SymbolicModel

__all__ = ["MAX_COORDINATES", "TAPE_OPS", "Delayed", "MassFlow", "SymbolicModel", "examples", "from_mechanics", "lagrangian", "mechanical", "routh"]
