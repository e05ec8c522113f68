"""varmech: variational integrators for long conservative simulations.

Describe a mechanical system in Python (a potential and its gradient as closures, or a built-in
scene from :mod:`varmech.scenes`), integrate it with a symplectic method derived from a discrete
Hamilton's principle, and check what it conserves::

    import numpy as np
    import varmech

    kepler = varmech.MechanicalSystem(
        2,
        potential=lambda q: -1.0 / np.hypot(*q),
        gradient=lambda q: q / np.hypot(*q) ** 3,
        symmetries=[varmech.Rotation(spatial_dim=2)],
    )
    traj = varmech.integrate(kepler, [0.4, 0.0], [0.0, 2.0], dt=0.01, t_end=100.0, method="kahan_li8")
    print(varmech.check_conservation(traj))
"""

from ._core import ConvergenceError, DivergenceError, SpuriousBranchError, VarmechError
from .constraints import project
from .conservation import ConservationReport, EnergyReport, MomentumReport, check_conservation, momentum
from .derivatives import DerivativeCheck, check_derivatives
from .integrate import Trajectory, integrate, symplecticity_defect
from .methods import MethodInfo, methods
from .reduction import ReducedModel, cyclic_coordinates, routh
from .table import Table
from .stability import growth_factor, growth_table, implicit_regions, stability_scan, stability_table, unstable_intervals
from .sections import phase_portrait, poincare_section
from .performance import energy_growth, work_precision
from . import sections, stability
from .model import Cyclic, Lagrangian, MechanicalSystem, Model, NativeSystem, Rotation, Translation
from . import scenes

__version__ = "0.1.0"

__all__ = [
    "ConservationReport",
    "ConvergenceError",
    "Cyclic",
    "cyclic_coordinates",
    "DerivativeCheck",
    "DivergenceError",
    "EnergyReport",
    "Lagrangian",
    "MechanicalSystem",
    "MethodInfo",
    "Model",
    "MomentumReport",
    "NativeSystem",
    "Rotation",
    "project",
    "ReducedModel",
    "routh",
    "SpuriousBranchError",
    "Trajectory",
    "Translation",
    "VarmechError",
    "check_conservation",
    "check_derivatives",
    "integrate",
    "methods",
    "momentum",
    "scenes",
    "symplecticity_defect",
    "growth_factor",
    "growth_table",
    "implicit_regions",
    "stability_scan",
    "stability_table",
    "unstable_intervals",
    "phase_portrait",
    "energy_growth",
    "work_precision",
    "poincare_section",
    "sections",
    "stability",
    "Table",
]
