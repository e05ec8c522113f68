"""The symmetries a model declares (translations, rotations, cyclic coordinates), each with a
conserved Noether momentum, and their specs for the binding and data for files."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import astuple, dataclass
from typing import Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from ._util import integer, with_sections

_AXES = "xyz"

# The docstring sections the built-in symmetries share, put in for their placeholders by
# :func:`_documented` (as varmech.events does its events').
_SECTIONS = {
    # Translation's and Rotation's, both checked by _Axial.__post_init__.
    "{axial raises}": """Raises
    ------
    ValueError
        ``axis`` not an integer ≥ 0 or ``spatial_dim`` not a positive integer, naming it.""",
    # Every symmetry's: its momentum along a run.
    "{momentum}": """See Also
    --------
    varmech.momentum : J along a trajectory.""",
    "{spec}": """The core's generator of this symmetry, as the binding takes it.

        Returns
        -------
        varmech._core.Generator
            The generator's kind and data, checked against the model's dimension when a model
            is built with it.""",
}

_F = TypeVar("_F", bound=Callable[..., Any])


def _documented(f: _F) -> _F:
    """``f`` (a symmetry's class or its ``spec``) with the shared sections put into its docstring for
    their placeholders."""
    return with_sections(f, _SECTIONS)


class _Axial:
    """What Translation and Rotation share: ``axis`` and ``spatial_dim``, checked as they are made."""

    axis: int
    spatial_dim: int

    def __post_init__(self) -> None:
        integer("axis", self.axis)
        integer("spatial_dim", self.spatial_dim, 1)


@_documented
@dataclass(frozen=True)
class Translation(_Axial):
    """Every body moves along ``axis``: J is the total linear momentum along it.

    Coordinates are laid out body by body, each body with ``spatial_dim`` coordinates. The
    generator is ξ(q) = Σ_b e_axis (one unit vector per body), and Noether's momentum
    J = p·ξ(q) = Σ_b p_b,axis is conserved when L is invariant under the shift.

    Attributes
    ----------
    axis : int
        The axis (0, 1, 2 for x, y, z).
    spatial_dim : int, default 3
        The coordinates per body.
    name : str
        ``"P_x"``, ``"P_y"``, ``"P_z"`` (``"P_k"`` beyond 3 dimensions), as reports name J.

    {axial raises}

    {momentum}

    Examples
    --------
    Two free bodies on a line, pulled together by a spring: the total momentum stays.

    >>> import numpy as np, varmech
    >>> spring = varmech.MechanicalSystem(2, lambda q: 0.5 * (q[0] - q[1]) ** 2,
    ...     lambda q: np.array([q[0] - q[1], q[1] - q[0]]), symmetries=[varmech.Translation(0, spatial_dim=1)])
    >>> traj = varmech.integrate(spring, [0.0, 1.0], [0.3, 0.0], dt=0.1, steps=100)
    >>> varmech.momentum(traj, spring.symmetries[0])[-1].round(12), spring.symmetries[0].name
    (np.float64(0.3), 'P_x')
    """

    axis: int
    spatial_dim: int = 3

    @property
    def name(self) -> str:
        """The momentum's name in reports."""
        return f"P_{_AXES[self.axis]}" if self.axis < 3 else f"P_{self.axis}"

    @_documented
    def spec(self) -> _core.Generator:
        """{spec}

        Examples
        --------
        >>> g = Translation(1).spec()
        >>> type(g).__name__, g.axis, g.spatial_dim, g.name
        ('Translation', 1, 3, 'P_y')
        """
        return _core.Generator.Translation(self.axis, self.spatial_dim)


@_documented
@dataclass(frozen=True)
class Rotation(_Axial):
    """Every body turns about ``axis`` (in the plane when ``spatial_dim`` is 2): J is the total
    angular momentum about it.

    The generator is ξ(q) = e_axis × q_b for each body b (in the plane, (−y_b, x_b)), so
    J = p·ξ(q) = Σ_b (q_b × p_b)·e_axis.

    Attributes
    ----------
    axis : int, default 2
        The axis of rotation (0, 1, 2 for x, y, z; ignored in the plane).
    spatial_dim : int, default 3
        The coordinates per body, 2 or 3.
    name : str
        ``"L"`` in the plane, else ``"L_x"``, ``"L_y"``, ``"L_z"``.

    {axial raises}

    {momentum}

    Examples
    --------
    >>> import varmech
    >>> kepler = varmech.scenes.kepler()
    >>> kepler.model.symmetries
    (Rotation(axis=2, spatial_dim=2),)
    >>> traj = varmech.integrate(kepler, dt=kepler.dt, steps=100)
    >>> varmech.momentum(traj, kepler.model.symmetries[0])[-1].round(12)
    np.float64(0.8)
    """

    axis: int = 2
    spatial_dim: int = 3

    @property
    def name(self) -> str:
        """The momentum's name in reports."""
        return "L" if self.spatial_dim == 2 else f"L_{_AXES[self.axis]}"

    @_documented
    def spec(self) -> _core.Generator:
        """{spec}

        Examples
        --------
        In the plane the axis is ignored, and the momentum is named L:

        >>> g = Rotation(spatial_dim=2).spec()
        >>> type(g).__name__, g.spatial_dim, g.name
        ('Rotation', 2, 'L')
        """
        return _core.Generator.Rotation(self.axis, self.spatial_dim)


@_documented
@dataclass(frozen=True)
class Cyclic:
    """Coordinate ``index`` is cyclic (∂L/∂q_index = 0): J = p_index.

    The generator is the unit vector ξ = e_index; Routh's method (:func:`varmech.routh`)
    removes such a coordinate.

    Attributes
    ----------
    index : int
        The cyclic coordinate.
    name : str
        ``"p[index]"``, as reports name J.

    Raises
    ------
    ValueError
        ``index`` not an integer ≥ 0 (``Cyclic(-1)``, ``Cyclic(1.5)``).

    {momentum}
    varmech.routh : the model reduced by its cyclic coordinates.

    Examples
    --------
    >>> import varmech
    >>> top = varmech.scenes.heavy_top()
    >>> [s.name for s in top.model.symmetries]
    ['p[1]', 'p[2]']
    >>> traj = varmech.integrate(top, dt=top.dt, steps=100)
    >>> varmech.momentum(traj, varmech.Cyclic(2))[-1].round(12)
    np.float64(2.5)
    """

    index: int

    def __post_init__(self) -> None:
        integer("index", self.index)

    @property
    def name(self) -> str:
        """The momentum's name in reports."""
        return f"p[{self.index}]"

    @_documented
    def spec(self) -> _core.Generator:
        """{spec}

        Examples
        --------
        >>> from varmech import _core
        >>> g = Cyclic(2).spec()
        >>> isinstance(g, _core.Generator.Cyclic), g.index, g.name
        (True, 2, 'p[2]')
        """
        return _core.Generator.Cyclic(self.index)


Symmetry = Translation | Rotation | Cyclic
#: A generator ξ(q) of a symmetry: a built-in one, or a closure returning an array (n,).
Generator = Symmetry | Callable[[np.ndarray], ArrayLike]


def generator_specs(symmetries: Sequence[Symmetry]) -> list[_core.Generator]:
    """The specs the binding checks (it knows which generators apply to how many coordinates)."""
    for s in symmetries:
        if not isinstance(s, (Translation, Rotation, Cyclic)):
            raise TypeError(f"symmetries: expected Translation, Rotation or Cyclic, got {s!r}")
    return [s.spec() for s in symmetries]


def symmetry_of_generator(g: _core.Generator) -> Symmetry:
    match g:
        case _core.Generator.Translation(axis, spatial_dim):
            return Translation(axis, spatial_dim)
        case _core.Generator.Rotation(axis, spatial_dim):
            return Rotation(axis, spatial_dim)
        case _core.Generator.Cyclic(index):
            return Cyclic(index)
    raise TypeError(f"symmetries: expected a generator, got {g!r}")



def symmetry_data(s: Symmetry) -> list[Any]:
    """A built-in symmetry as data: its class's name and fields."""
    return [type(s).__name__, *astuple(s)]


def symmetry_of(data: Any) -> Symmetry:
    """The built-in symmetry of :func:`symmetry_data`."""
    classes: dict[str, type[Symmetry]] = {"Translation": Translation, "Rotation": Rotation, "Cyclic": Cyclic}
    if not isinstance(data, list) or not data or data[0] not in classes:
        raise TypeError(f"{data!r} is not a symmetry")
    if not all(isinstance(x, int) and not isinstance(x, bool) for x in data[1:]):
        raise TypeError(f"{data!r}: a symmetry's fields are integers")
    return classes[data[0]](*data[1:])
