"""Models: mechanical systems and Lagrangians from Python closures (:mod:`varmech._closures`),
native scenes (:mod:`varmech._native`), the base class they share (:mod:`varmech._model`) and
their symmetries (:mod:`varmech._symmetries`); this module gathers them, with what a run asks
of any model."""

from __future__ import annotations

from typing import Any

# Re-exported (``X as X``): other modules import these from here, and old pickles find _rebuild and
# the native models' builders by this module's name.
from ._closures import Lagrangian as Lagrangian
from ._closures import MechanicalSystem as MechanicalSystem
from ._closures import reactive_force as reactive_force
from ._model import RECIPES as RECIPES
from ._model import Model as Model
from ._model import _rebuild as _rebuild
from ._model import coordinate_names as coordinate_names
from ._model import field as field
from ._model import from_recipe as from_recipe
from ._model import initial_state as initial_state
from ._model import integers as integers
from ._model import momentum_name as momentum_name
from ._model import numbers as numbers
from ._native import NativeSystem as NativeSystem
from ._native import _nbody_model as _nbody_model
from ._native import _scene_model as _scene_model
from ._native import scene_model as scene_model
from ._symmetries import Cyclic as Cyclic
from ._symmetries import Generator as Generator
from ._symmetries import Rotation as Rotation
from ._symmetries import Symmetry as Symmetry
from ._symmetries import Translation as Translation
from ._symmetries import generator_specs as generator_specs
from ._symmetries import symmetry_data as symmetry_data
from ._symmetries import symmetry_of as symmetry_of

__all__ = [
    "Cyclic",
    "Lagrangian",
    "MechanicalSystem",
    "Model",
    "NativeSystem",
    "Rotation",
    "Translation",
]


def variable_attributes(model: Model) -> dict[str, dict[str, Any]]:
    """What a run's variables are, as files and labelled arrays carry it: each one's
    ``long_name`` and ``units`` (CF's attribute names; ``units`` only where the model states
    them, :attr:`Model.units`), and the names of q's and p's columns (``names``)."""
    units = model.units
    attributes: dict[str, dict[str, Any]] = {
        "t": {"long_name": "time", "units": units.get("t")},
        "q": {"long_name": "generalized coordinates q", "units": units.get("q"), "names": list(model.coordinates)},
        "p": {"long_name": "conjugate momenta p = dL/dq'", "units": units.get("p"), "names": list(model.momentum_names)},
        "v": {"long_name": "generalized velocities q'", "units": units.get("v"), "names": list(model.coordinates)},
        "newton": {"long_name": "Newton iterations up to the state", "units": "1"},
        "work": {"long_name": "energy put in up to the state: the forces' work less the integral of dL/dt", "units": units.get("E")},
    }
    return {name: {k: v for k, v in attrs.items() if v is not None} for name, attrs in attributes.items()}


def check_delays(model: Model, watched: bool, horizon: float | None = None) -> None:
    """ValueError naming ``delayed`` for a model with delayed forces run with events, contacts or
    impulses (their partial steps would need the history at other steps), or over a
    ``horizon`` no longer than its longest delay without a history (the delayed term would
    never act)."""
    if not model.delays:
        return
    if watched:
        raise ValueError(
            "delayed: a model with delayed forces takes no events, contacts or impulses yet (their partial steps "
            "would read the history between its steps)"
        )
    longest = max(model.delays)
    if horizon is not None and horizon <= longest and not model.has_history:
        raise ValueError(
            f"delayed: τ = {longest:g} is as long as the run ({horizon:g}): the delayed term would never act; run "
            "longer, shorten τ, or give the model its history="
        )
