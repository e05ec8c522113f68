"""Native models: the core's scenes and N-body models, which pickle and store as their scene's
name and parameters, or G and the masses."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from . import _core
from ._catalogue import DIMENSIONLESS, declared
from ._model import RECIPES, Model, coordinate_names, field, numbers
from ._symmetries import symmetry_of_generator


class NativeSystem(Model):
    """A model evaluated natively in Rust (a built-in scene): no Python call per step, and the
    GIL is released while it runs.

    ``parameters`` are the values of the catalogue scene's parameters the model was built with
    (:func:`varmech.scenes.get`): the model pickles as its scene's name and them. A native
    N-body model (:func:`varmech.scenes.nbody`) pickles as its G and masses. Users get these
    from the scenes rather than build them.

    Parameters
    ----------
    core : varmech._core.NativeModel
        The core's model.
    parameters : mapping of str to float, optional
        The catalogue parameters it was built with (None for an N-body model).
    coordinates : sequence of str, optional
        The coordinates' names (a scene's declared ones); default ``q[0]``, ….

    Examples
    --------
    >>> import pickle, varmech
    >>> model = varmech.scenes.kepler(e=0.3).model
    >>> model, model.parameters
    (NativeSystem('kepler', dim=2), {'e': 0.3})
    >>> pickle.loads(pickle.dumps(model)).parameters
    {'e': 0.3}
    """

    def __init__(
        self, core: _core.NativeModel, parameters: Mapping[str, float] | None = None, coordinates: Sequence[str] | None = None
    ):
        self._core: _core.NativeModel = core
        self._coordinates = coordinate_names(coordinates, core.dim)
        self.name = core.name
        self.symmetries = tuple(symmetry_of_generator(g) for g in core.symmetries)
        self.parameters = None if parameters is None else dict(parameters)

    def __reduce__(self) -> tuple[Any, ...]:
        # Rebuilt by the public constructors from the scene's name and parameters, or G and the
        # masses: the core builds the same model, bit for bit.
        if self.parameters is not None:
            return (_scene_model, (self.name, self.parameters))
        gravity = self._core.gravity
        if gravity is not None:
            return (_nbody_model, gravity)
        raise TypeError(
            f"cannot pickle NativeSystem {self.name!r} built without its parameters; "
            "build it with varmech.scenes.get(name, **parameters)"
        )

    @property
    def units(self) -> dict[str, str]:
        if self.parameters is None:
            return {}
        return dict(declared(self.name).units or DIMENSIONLESS)

    def _recipe(self) -> dict[str, Any] | None:
        if self.parameters is not None:
            return {"kind": "scene", "name": self.name, "parameters": dict(self.parameters)}
        gravity = self._core.gravity
        if gravity is not None:
            return {"kind": "nbody", "G": gravity[0], "masses": list(gravity[1])}
        return None

def scene_model(name: str, parameters: dict[str, float]) -> NativeSystem:
    """The native model of catalogue scene ``name`` with ``parameters`` (a scene's, a recipe's,
    an ensemble member's)."""
    return NativeSystem(_core.scene(name, **parameters).model, parameters, declared(name).coordinates)


def _scene_model(name: str, parameters: dict[str, float]) -> NativeSystem:
    """A pickled native scene model: pickles name this function, so it keeps its name."""
    return scene_model(name, parameters)


def _nbody_model(gravitational_constant: float, masses: list[float]) -> NativeSystem:
    """The native N-body model of G and ``masses`` (a pickle's)."""
    return NativeSystem(_core.nbody(gravitational_constant, masses))


def _scene_of_recipe(recipe: dict[str, Any]) -> NativeSystem:
    parameters = field(recipe, "parameters", dict)
    values = numbers(list(parameters.values()), "parameters")
    if not all(isinstance(k, str) for k in parameters):
        raise TypeError("parameters are not named")
    return scene_model(field(recipe, "name", str), dict(zip(parameters, values)))


def _nbody_of_recipe(recipe: dict[str, Any]) -> NativeSystem:
    gravity = field(recipe, "G", (int, float))
    masses = numbers(recipe["masses"], "masses")
    if not math.isfinite(gravity):
        raise TypeError("G is not finite")
    return _nbody_model(float(gravity), [float(m) for m in masses])


RECIPES.update(scene=_scene_of_recipe, nbody=_nbody_of_recipe)
