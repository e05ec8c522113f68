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

The measurements (work–precision, energy growth, stability, sections) live in
:mod:`varmech.analysis` and are re-exported here; :mod:`varmech.charts` draws them.
"""

import importlib as _importlib
from types import ModuleType as _ModuleType

from . import _errors, analysis, events, pointers, scenes
from ._cite import cite
from ._core import ConvergenceError, DivergenceError, SpuriousBranchError, VarmechError
from ._version import __version__ as __version__
from ._warnings import DerivativeWarning, VarmechWarning
from .analysis import sections, stability
from .analysis.energy_growth import energy_growth
from .analysis.implicit import implicit_regions
from .analysis.lyapunov import LyapunovSpectrum, Megno, lyapunov_spectrum, megno
from .analysis.phase_portrait import phase_portrait
from .analysis.reference import ReferenceWarning
from .analysis.sections import poincare_section
from .analysis.stability import (
    growth_factor,
    growth_table,
    stability_scan,
    stability_table,
    unstable_intervals,
)
from .analysis.strobe import orbit_diagram, stroboscopic_section
from .analysis.work_precision import work_precision
from .conservation import ConservationReport, InvariantStatistics, check_conservation, momentum
from .constraints import IntegrableConstraintsWarning, project
from .derivatives import DerivativeCheck, check_derivatives
from .ensemble import Ensemble, EnsembleConservation, ensemble
from .impacts import Contact, ContactError, Friction, ImpactWarning
from .impulses import Engagement, Impulse, ImpulseResponse, engage, impulse_response
from .integrate import integrate, symplecticity_defect
from .methods import MethodInfo, methods
from .model import Cyclic, Lagrangian, MechanicalSystem, Model, NativeSystem, Rotation, Translation, reactive_force
from .modes import (
    Equilibrium,
    Linearization,
    NormalModes,
    StabilityWarning,
    StepSuggestion,
    equilibria,
    fastest_frequency,
    linearize,
    normal_modes,
    suggest_dt,
)
from .reduction import ReducedModel, cyclic_coordinates, routh
from .scenes import Reference, Scene
from .stepper import Stepper
from .streaming import resume
from .table import Table
from .trajectory import Reactions, Trajectory, load

__all__ = [
    "ConservationReport",
    "Contact",
    "ContactError",
    "ConvergenceError",
    "Cyclic",
    "DerivativeCheck",
    "DerivativeWarning",
    "DivergenceError",
    "Engagement",
    "Ensemble",
    "EnsembleConservation",
    "Equilibrium",
    "Friction",
    "ImpactWarning",
    "Impulse",
    "ImpulseResponse",
    "IntegrableConstraintsWarning",
    "InvariantStatistics",
    "Lagrangian",
    "Linearization",
    "LyapunovSpectrum",
    "MechanicalSystem",
    "Megno",
    "MethodInfo",
    "Model",
    "NativeSystem",
    "NormalModes",
    "Reactions",
    "ReducedModel",
    "Reference",
    "ReferenceWarning",
    "Rotation",
    "Scene",
    "SpuriousBranchError",
    "StabilityWarning",
    "StepSuggestion",
    "Stepper",
    "Table",
    "Trajectory",
    "Translation",
    "VarmechError",
    "VarmechWarning",
    "analysis",
    "check_conservation",
    "check_derivatives",
    "cite",
    "cyclic_coordinates",
    "energy_growth",
    "engage",
    "ensemble",
    "equilibria",
    "events",
    "fastest_frequency",
    "growth_factor",
    "growth_table",
    "implicit_regions",
    "impulse_response",
    "integrate",
    "linearize",
    "load",
    "lyapunov_spectrum",
    "megno",
    "methods",
    "momentum",
    "normal_modes",
    "orbit_diagram",
    "phase_portrait",
    "poincare_section",
    "pointers",
    "project",
    "reactive_force",
    "resume",
    "routh",
    "scenes",
    "sections",
    "stability",
    "stability_scan",
    "stability_table",
    "stroboscopic_section",
    "suggest_dt",
    "symplecticity_defect",
    "unstable_intervals",
    "work_precision",
]

_errors.install()


#: The public modules (the API reference's), which ``dir(varmech)`` lists beside ``__all__``;
#: the others are the package's own layers.
_MODULES = (
    "analysis", "charts", "conservation", "dense", "events", "examples", "files", "impacts",
    "pointers", "scenes", "streaming", "surfaces", "symbolic", "trajectory",
)  # fmt: skip


def __getattr__(name: str) -> _ModuleType:
    # varmech.symbolic imports SymPy (an optional extra), and charts matplotlib: imported on
    # first use.
    if name in ("symbolic", "charts", "examples"):
        return _importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*__all__, *_MODULES])
