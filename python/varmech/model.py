"""Models: mechanical systems from Python closures, native scenes, and their symmetries."""

from __future__ import annotations

import importlib
import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import astuple, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import _core, pointers
from ._core import ModelKind
from ._util import callable_as, floats, integer, positive_int, returned, vector
from ._warnings import DerivativeWarning

__all__ = [
    "Cyclic",
    "Lagrangian",
    "MechanicalSystem",
    "Model",
    "NativeSystem",
    "Rotation",
    "Translation",
]

_AXES = "xyz"


@dataclass(frozen=True)
class Translation:
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

    Raises
    ------
    ValueError
        ``axis`` not an integer ≥ 0 or ``spatial_dim`` not a positive integer, naming it.

    See Also
    --------
    varmech.momentum : J along a trajectory.

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

    def __post_init__(self) -> None:
        integer("axis", self.axis)
        integer("spatial_dim", self.spatial_dim, 1)

    @property
    def name(self) -> str:
        """The momentum's name in reports."""
        return f"P_{_AXES[self.axis]}" if self.axis < 3 else f"P_{self.axis}"

    def spec(self) -> _core.Generator:
        """The core's generator of this symmetry, as the binding takes it.

        Returns
        -------
        varmech._core.Generator
            The generator's kind and data, checked against the model's dimension when a model
            is built with it.

        Examples
        --------
        >>> g = Translation(1).spec()
        >>> type(g).__name__, g.axis, g.spatial_dim, g.name
        ('Translation', 1, 3, 'P_y')
        """
        return _core.Generator.Translation(self.axis, self.spatial_dim)


@dataclass(frozen=True)
class Rotation:
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

    Raises
    ------
    ValueError
        ``axis`` not an integer ≥ 0 or ``spatial_dim`` not a positive integer, naming it.

    See Also
    --------
    varmech.momentum : J along a trajectory.

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

    def __post_init__(self) -> None:
        integer("axis", self.axis)
        integer("spatial_dim", self.spatial_dim, 1)

    @property
    def name(self) -> str:
        """The momentum's name in reports."""
        return "L" if self.spatial_dim == 2 else f"L_{_AXES[self.axis]}"

    def spec(self) -> _core.Generator:
        """The core's generator of this symmetry, as the binding takes it.

        Returns
        -------
        varmech._core.Generator
            The generator's kind and data, checked against the model's dimension when a model
            is built with it.

        Examples
        --------
        In the plane the axis is ignored, and the momentum is named L:

        >>> g = Rotation(spatial_dim=2).spec()
        >>> type(g).__name__, g.spatial_dim, g.name
        ('Rotation', 2, 'L')
        """
        return _core.Generator.Rotation(self.axis, self.spatial_dim)


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

    See Also
    --------
    varmech.momentum : J along a trajectory.
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

    def spec(self) -> _core.Generator:
        """The core's generator of this symmetry, as the binding takes it.

        Returns
        -------
        varmech._core.Generator
            The generator's kind and data, checked against the model's dimension when a model
            is built with it.

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


def _specs(symmetries: Sequence[Symmetry]) -> list[_core.Generator]:
    """The specs the binding checks (it knows which generators apply to how many coordinates)."""
    for s in symmetries:
        if not isinstance(s, (Translation, Rotation, Cyclic)):
            raise TypeError(f"symmetries: expected Translation, Rotation or Cyclic, got {s!r}")
    return [s.spec() for s in symmetries]


def _symmetry_from_spec(g: _core.Generator) -> Symmetry:
    match g:
        case _core.Generator.Translation(axis, spatial_dim):
            return Translation(axis, spatial_dim)
        case _core.Generator.Rotation(axis, spatial_dim):
            return Rotation(axis, spatial_dim)
        case _core.Generator.Cyclic(index):
            return Cyclic(index)
    raise TypeError(f"symmetries: expected a generator, got {g!r}")


def coordinate_names(names: Sequence[str] | None, dim: int, argument: str = "coordinates") -> tuple[str, ...] | None:
    """``names`` checked as the names of ``dim`` coordinates (None: unnamed): ``dim`` distinct,
    non-empty strings; ValueError or TypeError naming ``argument`` otherwise."""
    if names is None:
        return None
    if isinstance(names, str) or not all(isinstance(x, str) for x in names):
        raise TypeError(f"{argument}: a sequence of {dim} names (str), such as ('x', 'theta'), not {names!r}")
    names = tuple(x.strip() for x in names)
    if len(names) != dim or len(set(names)) != dim or not all(names):
        raise ValueError(f"{argument}: need {dim} distinct non-empty names, one a coordinate, got {names}")
    return names


def momentum_name(coordinate: str, index: int) -> str:
    """The momentum conjugate to ``coordinate`` (the ``index``-th): ``p_theta``, or ``p[i]`` where the
    coordinate has no name of its own (``q[i]``)."""
    return f"p[{index}]" if coordinate == f"q[{index}]" else f"p_{coordinate}"


def _handed(function: pointers.Function) -> tuple[int, pointers.Function]:
    """A pointer as the binding takes it: its address, and the object it keeps alive."""
    return function.address, function


class Model:
    """A varmech model: a Lagrangian L(q, q̇, t) in n generalized coordinates, and the
    symmetries it declares (each with a conserved Noether momentum).

    Separable mechanical systems (L = ½q̇ᵀMq̇ − V) take every method; general Lagrangians the
    implicit variational ones (``midpoint``, ``trapezoid``, ``galerkin4``, ``galerkin6``).
    The concrete classes are :class:`~varmech.MechanicalSystem`, :class:`~varmech.Lagrangian`,
    :class:`NativeSystem` (the scenes), the symbolic models and Routh-reduced ones.

    See Also
    --------
    varmech.MechanicalSystem : a model from closures V(q), ∇V(q) and a mass matrix.
    varmech.Lagrangian : a general L(q, q̇, t) from closures.

    Examples
    --------
    >>> import varmech
    >>> model = varmech.scenes.double_pendulum().model
    >>> model.dim, model.kind.default_method, model.separable
    (2, 'midpoint', False)
    >>> model.momentum([0.1, 0.2], [1.0, 0.0]).round(6).tolist()    # M(θ)θ̇
    [12.0, 11.94005]
    """

    _core: (
        _core.NativeModel
        | _core.ClosureModel
        | _core.ClosureConstrained
        | _core.ClosureNonholonomic
        | _core.ClosureNatural
        | _core.ClosureLagrangian
        | _core.PointerSystem
        | _core.PointerLagrangian
        | _core.CompiledModel
        | _core.RouthModel
    )
    symmetries: tuple[Symmetry, ...]
    name: str
    #: The arguments the model was built with by its class's constructor: what it pickles as.
    _arguments: dict[str, Any]

    @property
    def dim(self) -> int:
        """Number of generalized coordinates n."""
        return self._core.dim

    @property
    def kind(self) -> ModelKind:
        """The model's kind, which decides which methods apply (``kind.admits(method)``), the
        default method and the most accurate one."""
        return _core.kind_of(self._core)

    @property
    def separable(self) -> bool:
        """Whether L = ½q̇ᵀMq̇ − V(q) with constant M (then explicit methods apply)."""
        return self.kind.separable

    @property
    def time_dependent(self) -> bool:
        """Whether L depends on t explicitly (then its energy function is not conserved)."""
        return _core.is_time_dependent(self._core)

    @property
    def forced(self) -> bool:
        """Whether non-conservative forces act (then the energy changes by their work)."""
        return _core.is_forced(self._core)

    @property
    def conserves_energy(self) -> bool:
        """Whether its energy function is a first integral: L does not depend on t and no force
        acts."""
        return not (self.time_dependent or self.forced)

    @property
    def energy_name(self) -> str:
        """What reports call the energy function E = p·q̇ − L: ``"energy"``, or ``"Jacobi
        integral"`` for an L autonomous in a moving frame (a symbolic L from inertial
        coordinates whose t cancels; a closure model that says so)."""
        return "energy"

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The coordinates' names, which reports, tables and charts use: a symbolic model's
        symbols, a scene's own (``theta1``, ``theta2`` of the double pendulum), the ``coordinates=``
        given to a closure model; ``q[0]``, ``q[1]``, … otherwise."""
        return getattr(self, "_coordinates", None) or tuple(f"q[{i}]" for i in range(self.dim))

    @property
    def momentum_names(self) -> tuple[str, ...]:
        """The conjugate momenta's names: ``p_theta`` for a coordinate named ``theta``, ``p[i]`` for an
        unnamed one."""
        return tuple(momentum_name(name, i) for i, name in enumerate(self.coordinates))

    @property
    def units(self) -> dict[str, str]:
        """The units of t, q, p, q̇ and the energy E (keys ``"t"``, ``"q"``, ``"p"``, ``"v"``,
        ``"E"``) where the model states them: a catalogue scene's (:data:`SCENE_UNITS`;
        dimensionless, ``"1"``, unless listed there); none for one's own model, whose units are
        its author's."""
        return {}

    @property
    def delays(self) -> tuple[float, ...]:
        """The delays τ of the model's delayed forces (none for most models)."""
        return ()

    @property
    def has_history(self) -> bool:
        """Whether the model gives the state before the run that its delayed forces read."""
        return False

    @property
    def constraints(self) -> int:
        """Number of holonomic constraints g(q) = 0 (0 for unconstrained models); constrained
        models take ``rattle``, ``rattle4`` and ``shake`` only."""
        return getattr(self._core, "constraints", 0)

    @property
    def velocity_constraints(self) -> int:
        """Number of velocity constraints A(q)q̇ = 0 (0 for models without them); such
        (nonholonomic) models take the discrete Lagrange–d'Alembert integrators: ``midpoint``
        (reversible, the default), ``dla4`` (its order-4 composition) and ``cortes_martinez``
        (not reversible, the contrast)."""
        return getattr(self._core, "velocity_constraints", 0)

    @property
    def affine(self) -> bool:
        """Whether its velocity constraints are affine, A(q)q̇ + b(q) = 0 with b ≠ 0 (a moving
        surface, such as a turntable): their forces then do work, and the energy is not
        conserved."""
        return _core.is_affine(self._core)

    def velocity(self, q: ArrayLike, p: ArrayLike, t: ArrayLike = 0.0) -> np.ndarray:
        """q̇ with ∂L/∂q̇(q, q̇, t) = p (M⁻¹p for mechanical systems), for one state (n,) or
        for rows (N, n): the inverse Legendre transform.

        Parameters
        ----------
        q : array_like, shape (n,) or (N, n)
            The positions (one row for all momenta, or one per row).
        p : array_like, shape (n,) or (N, n)
            The momenta.
        t : float or array_like, shape (N,), default 0.0
            The time (for a Lagrangian that depends on it).

        Returns
        -------
        ndarray, the shape of p
            The velocities.

        Raises
        ------
        ValueError
            Naming the argument whose shape or values do not fit (``q``, ``p`` or ``t``), or,
            starting with ``q, p``, a general Lagrangian whose Newton solve of ∂L/∂q̇ = p
            fails there.

        Examples
        --------
        The inverse of :meth:`momentum`, here for the double pendulum's M(θ):

        >>> import varmech
        >>> model = varmech.scenes.double_pendulum().model
        >>> p = model.momentum([0.1, 0.2], [1.0, -2.0])
        >>> model.velocity([0.1, 0.2], p).round(12).tolist()
        [1.0, -2.0]
        """
        return self._derivative("velocity", q, p, t)

    def momentum(self, q: ArrayLike, v: ArrayLike, t: ArrayLike = 0.0) -> np.ndarray:
        """p = ∂L/∂q̇(q, q̇, t) (Mq̇ for mechanical systems), for one state (n,) or rows (N, n):
        the Legendre transform.

        Parameters
        ----------
        q : array_like, shape (n,) or (N, n)
            The positions (one row for all velocities, or one per row).
        v : array_like, shape (n,) or (N, n)
            The velocities q̇.
        t : float or array_like, shape (N,), default 0.0
            The time (for a Lagrangian that depends on it).

        Returns
        -------
        ndarray, the shape of v
            The momenta.

        Raises
        ------
        ValueError
            Naming the argument whose shape does not fit (``q``, ``v`` or ``t``).

        Examples
        --------
        A rod on a table (x, y, θ; mass 1, k² = 1/3): p = Mq̇, one row per state.

        >>> import numpy as np, varmech
        >>> rod = varmech.MechanicalSystem(3, lambda q: 0.0, lambda q: np.zeros(3), mass=[1.0, 1.0, 1.0 / 3.0])
        >>> rod.momentum(np.zeros(3), [[1.0, 2.0, 3.0], [0.0, 0.0, 6.0]]).tolist()
        [[1.0, 2.0, 1.0], [0.0, 0.0, 2.0]]
        """
        return self._derivative("momentum", q, v, t)

    def _derivative(self, what: str, q: ArrayLike, x: ArrayLike, t: ArrayLike) -> np.ndarray:
        # x is the momenta p for the velocity, else the velocities v.
        name = "p" if what == "velocity" else "v"
        x = np.ascontiguousarray(floats(name, x))
        rows = np.atleast_2d(x)
        if rows.ndim != 2 or rows.shape[1] != self.dim:
            raise ValueError(f"{name}: expected shape ({self.dim},) or (N, {self.dim}), got {x.shape}")
        q2, t1 = _broadcast("q", q, rows.shape), _broadcast("t", t, rows.shape[:1])
        return _core.derivative(self._core, what, t1, q2, rows, names=f"q, {name}").reshape(x.shape)

    def with_parameters(self, **values: float) -> Model:
        """The model with its parameters set by name; only symbolic models
        (:mod:`varmech.symbolic`) have parameters to set.

        Parameters
        ----------
        **values : float
            The parameters' new values by name.

        Returns
        -------
        Model
            The model with those values (symbolic models only).

        Raises
        ------
        TypeError
            Naming ``parameters``, for every model but a symbolic one.

        Examples
        --------
        A model from closures has no parameters (its closures hold their values):

        >>> import varmech
        >>> oscillator = varmech.MechanicalSystem(1, lambda q: 0.5 * q @ q, lambda q: q, name="oscillator")
        >>> oscillator.with_parameters(omega=2.0)
        Traceback (most recent call last):
            ...
        TypeError: parameters: oscillator has no parameters to set (omega given); only symbolic models (varmech.symbolic) take them
        """
        raise TypeError(
            f"parameters: {self.name} has no parameters to set ({', '.join(values)} given); "
            "only symbolic models (varmech.symbolic) take them"
        )

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r}, dim={self.dim})"

    def __reduce__(self) -> tuple[Any, ...]:
        # The constructor's arguments, never the core's memory: unpickling builds the model
        # again. Closures pickle by reference (their module and name), so that a lambda or a
        # local function raises pickle's own error naming it.
        arguments = getattr(self, "_arguments", None)
        if arguments is None:
            raise TypeError(f"cannot pickle {type(self).__name__} {self.name!r}: it records no constructor arguments")
        return (_rebuild, (type(self), arguments))

    def _recipe(self) -> dict[str, Any] | None:
        """What builds the model as plain data (names, numbers and lists: JSON, with its
        ``"kind"``), which a file stores so that loading it runs no code (:func:`from_recipe`
        builds it again); None for a model only pickle can carry (one of Python closures)."""
        return None


def initial_state(
    model: Model, q0: ArrayLike | None, p0: ArrayLike | None, v0: ArrayLike | None, t0: float
) -> tuple[np.ndarray, np.ndarray]:
    """(q0, p0) checked, p0 from the velocities v0 (p0 = ∂L/∂q̇(q0, v0, t0)) when given instead:
    a run's, a stepper's and a scene's initial state."""
    n = model.dim
    if q0 is None:
        raise ValueError("q0: the initial positions are required")
    q = vector("q0", q0, n)
    if p0 is not None and v0 is None:
        return q, vector("p0", p0, n)
    if v0 is not None and p0 is None:
        v = vector("v0", v0, n)
        p = model.momentum(q, v, t0)
        if model.velocity_constraints:
            _check_rolling(model, q, v, p)
        return q, p
    raise ValueError("p0, v0: give exactly one of the initial momenta p0 and velocities v0")


def _check_rolling(model: Model, q: np.ndarray, v: np.ndarray, p: np.ndarray) -> None:
    """Refuses velocities ``v0`` off the velocity constraints, |A(q0)v0|∞ above 1e-10 of the
    state's size, as the core refuses momenta off them (naming ``p0``)."""
    (_, off), _ = _core.constraint_residuals(model._core, q[None], p[None])
    scale = max(1.0, float(np.max(np.abs(q))), float(np.max(np.abs(p))))
    if off[0] > 1e-10 * scale:
        raise ValueError(
            f"v0: is off the velocity constraints: |A(q0)v0| = {off[0]:.3e}; project the initial state first "
            "(varmech.project)"
        )


#: The builders of models from their recipes (:meth:`Model._recipe`) by kind: the module of each
#: model class adds its own.
RECIPES: dict[str, Callable[[dict[str, Any]], Model]] = {}


def from_recipe(recipe: Any) -> Model:
    """The model :meth:`Model._recipe` described, built by its class's public constructor from
    checked data (no code is run from the recipe); ValueError saying what is wrong otherwise.

    Parameters
    ----------
    recipe : dict
        A recipe, as :meth:`Model._recipe` gives it (or a file stores it).

    Returns
    -------
    Model
        The model, the same to the bit as the one the recipe came from.

    Raises
    ------
    ValueError
        When ``recipe`` is not one (an unknown kind, a field missing or of the wrong type), or
        its model cannot be built.

    Examples
    --------
    >>> import varmech
    >>> from varmech.model import from_recipe
    >>> from_recipe(varmech.scenes.kepler(e=0.3).model._recipe()).parameters
    {'e': 0.3}
    """
    kind = recipe.get("kind") if isinstance(recipe, dict) else None
    if kind == "symbolic" and kind not in RECIPES:
        # The symbolic models (SymPy, an optional extra) register their builder when imported.
        importlib.import_module("varmech.symbolic")
    builder = RECIPES.get(kind) if isinstance(kind, str) else None
    if builder is None:
        raise ValueError(f"not a model recipe of a known kind ({kind!r})")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return builder(recipe)
    except (KeyError, TypeError, IndexError, RecursionError) as e:
        raise ValueError(f"a malformed {kind} recipe: {type(e).__name__}: {e}") from None


def field(recipe: dict[str, Any], name: str, kind: type | tuple[type, ...]) -> Any:
    """``recipe[name]``, checked to be of ``kind`` (a bool is no number)."""
    value = recipe[name]
    if not isinstance(value, kind) or (isinstance(value, bool) and kind is not bool):
        raise TypeError(f"{name} is a {type(value).__name__}")
    return value


def numbers(values: Any, name: str) -> list[int | float]:
    """``values`` checked to be a list of numbers (JSON's ints and floats; no bools)."""
    if not isinstance(values, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in values):
        raise TypeError(f"{name} is not a list of numbers")
    return values


def integers(values: Any, name: str) -> list[int]:
    """``values`` checked to be a list of integers (no bools)."""
    if not isinstance(values, list) or not all(type(x) is int for x in values):
        raise TypeError(f"{name} is not a list of integers")
    return values


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


def _broadcast(name: str, value: ArrayLike, shape: tuple[int, ...]) -> np.ndarray:
    """``value`` as a contiguous float array of ``shape``; ValueError naming it when it does not
    broadcast to the states' shape."""
    array = floats(name, value)
    try:
        return np.ascontiguousarray(np.broadcast_to(array, shape))
    except ValueError:
        raise ValueError(f"{name}: shape {array.shape} does not fit the states' {shape}") from None


def _rebuild(cls: Callable[..., Model], arguments: dict[str, Any]) -> Model:
    """The model of a pickle: ``cls(**arguments)``, without the warnings its construction gave
    when it was first built (about derivatives by differences, say)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return cls(**arguments)


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
        The coordinates' names (:data:`SCENE_COORDINATES` for a scene); default ``q[0]``, ….

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
        self.symmetries = tuple(_symmetry_from_spec(g) for g in core.symmetries)
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
        return dict(SCENE_UNITS.get(self.name, DIMENSIONLESS))

    def _recipe(self) -> dict[str, Any] | None:
        if self.parameters is not None:
            return {"kind": "scene", "name": self.name, "parameters": dict(self.parameters)}
        gravity = self._core.gravity
        if gravity is not None:
            return {"kind": "nbody", "G": gravity[0], "masses": list(gravity[1])}
        return None


#: The coordinates' names of the catalogue's scenes of a fixed dimension, spelled as the names of
#: their invariants (``p_phi``); the chains, the planets and the quaternion go by index.
SCENE_COORDINATES: dict[str, tuple[str, ...]] = {
    "harmonic_oscillator": ("x",),
    "pendulum": ("theta",),
    "kepler": ("x", "y"),
    "henon_heiles": ("x", "y"),
    "double_pendulum": ("theta1", "theta2"),
    "spherical_pendulum": ("theta", "phi"),
    "heavy_top": ("theta", "phi", "psi"),
    "kepler_polar": ("r", "theta"),
    "charged_particle": ("x", "y"),
    "charged_particle_nonuniform": ("x", "y"),
    "damped_driven_pendulum": ("phi",),
    "cartesian_pendulum": ("x", "y"),
    "cartesian_spherical_pendulum": ("x", "y", "z"),
    "bouncing_ball": ("y",),
    "elliptic_billiard": ("x", "y"),
    "rolling_disk": ("x", "y", "theta", "phi"),
    "chaplygin_sleigh": ("x", "y", "theta"),
    "rolling_sphere": ("x", "y", "phi", "theta", "psi"),
    "ball_on_turntable": ("x", "y", "phi", "theta", "psi"),
}


#: The units of a scene without its own: every quantity dimensionless.
DIMENSIONLESS = {"t": "1", "q": "1", "p": "1", "v": "1", "E": "1"}

#: The units of the catalogue's scenes that have them, by name (as :attr:`Model.units` gives
#: them); every other scene is dimensionless. The outer solar system is Hairer, Lubich and
#: Wanner's: distances in astronomical units, time in days, masses in the Sun's.
SCENE_UNITS: dict[str, dict[str, str]] = {
    "outer_solar_system": {"t": "days", "q": "AU", "p": "solar masses AU/day", "v": "AU/day", "E": "solar masses AU^2/day^2"},
}


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


def _scene_model(name: str, parameters: dict[str, float]) -> NativeSystem:
    """The native model of catalogue scene ``name`` with ``parameters`` (a scene's, a pickle's)."""
    return NativeSystem(_core.scene(name, **parameters).model, parameters, SCENE_COORDINATES.get(name))


def _nbody_model(gravitational_constant: float, masses: list[float]) -> NativeSystem:
    """The native N-body model of G and ``masses`` (a pickle's)."""
    return NativeSystem(_core.nbody(gravitational_constant, masses))


def _scene_of_recipe(recipe: dict[str, Any]) -> NativeSystem:
    parameters = field(recipe, "parameters", dict)
    values = numbers(list(parameters.values()), "parameters")
    if not all(isinstance(k, str) for k in parameters):
        raise TypeError("parameters are not named")
    return _scene_model(field(recipe, "name", str), dict(zip(parameters, values)))


def _nbody_of_recipe(recipe: dict[str, Any]) -> NativeSystem:
    gravity = field(recipe, "G", (int, float))
    masses = numbers(recipe["masses"], "masses")
    if not math.isfinite(gravity):
        raise TypeError("G is not finite")
    return _nbody_model(float(gravity), [float(m) for m in masses])


RECIPES.update(scene=_scene_of_recipe, nbody=_nbody_of_recipe)


class MechanicalSystem(Model):
    """A mechanical system L = ½ q̇ᵀ M q̇ − V(q) given by Python closures, with a constant mass
    matrix (separable: every method applies) or a configuration-dependent one M(q) (a natural
    system such as a double pendulum: the implicit variational methods apply).

    Parameters
    ----------
    dim
        Number of generalized coordinates n.
    potential
        ``potential(q) -> float``, V(q) for q an array (n,). Or a function pointer of
        :data:`varmech.pointers.SIGNATURE` writing V to ``out[0]`` (with a constant mass, no
        constraints, and a pointer gradient): then the core calls it with the GIL released.
    gradient
        ``gradient(q) -> array (n,)``, ∇V(q), or a function pointer writing ∇V to ``out[0:n]``
        when the potential is one. Optional for a closure potential: without it, central
        differences of the potential are used (2n potential calls per force, about 1e-10
        relative accuracy), and a warning says so.
    mass
        The constant mass matrix: a positive scalar (M = mI), a vector (n,) of positive
        entries (diagonal), or a symmetric positive-definite matrix (n, n). Or a closure
        ``mass(q) -> array (n, n)``, M(q) symmetric positive definite: then
        p = M(q)q̇ exactly, q̇ = M(q)⁻¹p by Cholesky, and ∂L/∂q = ½q̇ᵀ(∂M/∂q)q̇ − ∇V.
    constraints, constraint_jacobian, constraint_count
        Holonomic constraints g(q) = 0: ``constraints(q) -> array (m,)`` with
        ``constraint_count`` = m, and optionally ``constraint_jacobian(q) -> array (m, n)``, G =
        ∂g/∂q (central differences of g without it). With a constant mass the system is
        integrated by ``rattle`` (the default), ``rattle4`` or ``shake``; with a ``mass``
        closure by the constrained DEL equations of ``trapezoid`` (the default; RATTLE's
        discrete Lagrangian) or ``midpoint``.
    velocity_constraints, velocity_constraint_count
        Velocity constraints A(q)q̇ = 0 that need not come from constraints on q (rolling
        without slipping, a skate's blade): ``velocity_constraints(q) -> array (m, n)``, A(q),
        with ``velocity_constraint_count`` = m. Integrated by the reversible discrete
        Lagrange–d'Alembert integrator, ``midpoint`` (the default), its order-4 composition
        ``dla4``, or the non-reversible ``cortes_martinez`` (see the user guide, "Rolling and other
        nonholonomic constraints"). With holonomic ``constraints`` too (m plus their count below
        n), each step also holds g(q) = 0 and puts the velocity on both: the model's kind stays
        ``nonholonomic``, and :func:`varmech.check_conservation` reports |g(q)| and
        |G q̇, A q̇ + b| together.
    velocity_constraint_offset
        With ``velocity_constraints``: ``velocity_constraint_offset(q) -> array (m,)``, the
        affine term b(q) of affine constraints A(q)q̇ + b(q) = 0 (a moving surface: on a table
        turning at Ω about the origin, b = (Ωy, −Ωx) for a ball's contact). The discrete
        constraint is A(q̄)δq + h b(q̄) = 0 at the step's midpoint q̄. The constraint forces
        then do work: the energy is not conserved, and :func:`varmech.check_conservation` does
        not judge it.
    mass_derivative
        With a ``mass`` closure: ``mass_derivative(q) -> array (n, n, n)`` whose ``[i]`` is
        ∂M/∂qᵢ. Optional: without it, central differences of ``mass`` are used (2n calls
        per evaluation of ∂L/∂q), and a warning says so.
    symmetries
        Symmetries of L (:class:`Translation`, :class:`Rotation`, :class:`Cyclic`); their
        momenta are checked by :func:`varmech.check_conservation`.
    name
        A label for reports.
    coordinates
        The coordinates' names (n distinct strings, such as ``("x", "theta")``), which
        reports, tables and charts use (``p_theta`` for a momentum); default ``q[0]``, ….

    Raises
    ------
    ValueError
        A malformed argument, named: ``dim`` not positive, a ``mass`` that is not positive
        (definite) or of the wrong shape, a count without its constraints or constraints
        without their count, velocity and holonomic constraints more than n − 1 together
        (naming ``velocity_constraint_count``).
    TypeError
        A function pointer with another signature than :data:`varmech.pointers.SIGNATURE`, or
        pointers and closures mixed in one model, naming the argument.

    See Also
    --------
    Lagrangian : any L(q, q̇, t) from closures.
    varmech.symbolic.mechanical : the same model from SymPy expressions, compiled.

    Examples
    --------
    A harmonic oscillator, separable: Verlet is the default.

    >>> import numpy as np
    >>> import varmech
    >>> oscillator = varmech.MechanicalSystem(1, lambda q: 0.5 * q @ q, lambda q: q, name="oscillator")
    >>> traj = varmech.integrate(oscillator, [1.0], [0.0], dt=2 * np.pi / 1000, steps=1000)
    >>> traj.method, bool(abs(traj.q[-1, 0] - 1.0) < 1e-4)
    ('verlet', True)

    A pendulum on a cart, whose mass matrix M(q) depends on the angle: the implicit midpoint
    rule is the default, and the cart's momentum (x is cyclic) is conserved to round-off.

    >>> def mass(q):
    ...     c = np.cos(q[1])
    ...     return np.array([[3.0, c], [c, 1.0]])
    >>> def mass_derivative(q):
    ...     dM = np.zeros((2, 2, 2))
    ...     dM[1] = [[0.0, -np.sin(q[1])], [-np.sin(q[1]), 0.0]]
    ...     return dM
    >>> cart = varmech.MechanicalSystem(2, lambda q: -9.81 * np.cos(q[1]),
    ...                                 lambda q: np.array([0.0, 9.81 * np.sin(q[1])]),
    ...                                 mass=mass, mass_derivative=mass_derivative,
    ...                                 symmetries=[varmech.Cyclic(0)])
    >>> traj = varmech.integrate(cart, [0.0, 2.5], v0=[1.0, 0.0], dt=0.01, t_end=10.0)
    >>> report = varmech.check_conservation(traj)
    >>> traj.method, report.verdict, report.momenta[0].verdict
    ('midpoint', 'bounded', 'conserved to round-off')
    """

    def __init__(
        self,
        dim: int,
        potential: Callable[[np.ndarray], float],
        gradient: Callable[[np.ndarray], ArrayLike] | None = None,
        *,
        mass: ArrayLike | Callable[[np.ndarray], ArrayLike] = 1.0,
        mass_derivative: Callable[[np.ndarray], ArrayLike] | None = None,
        constraints: Callable[[np.ndarray], ArrayLike] | None = None,
        constraint_jacobian: Callable[[np.ndarray], ArrayLike] | None = None,
        constraint_count: int | None = None,
        velocity_constraints: Callable[[np.ndarray], ArrayLike] | None = None,
        velocity_constraint_count: int | None = None,
        velocity_constraint_offset: Callable[[np.ndarray], ArrayLike] | None = None,
        symmetries: Sequence[Symmetry] = (),
        name: str = "mechanical system",
        coordinates: Sequence[str] | None = None,
    ):
        self._arguments = {
            "dim": dim,
            "potential": potential,
            "gradient": gradient,
            "mass": mass,
            "mass_derivative": mass_derivative,
            "constraints": constraints,
            "constraint_jacobian": constraint_jacobian,
            "constraint_count": constraint_count,
            "velocity_constraints": velocity_constraints,
            "velocity_constraint_count": velocity_constraint_count,
            "velocity_constraint_offset": velocity_constraint_offset,
            "symmetries": symmetries,
            "name": name,
            "coordinates": coordinates,
        }
        dim = positive_int("dim", dim)
        self._coordinates = coordinate_names(coordinates, dim)
        if (constraints is None) != (constraint_count is None) or (constraint_jacobian is not None and constraints is None):
            raise ValueError("constraints: give constraints(q) with constraint_count (and optionally constraint_jacobian)")
        _check_velocity_constraints(velocity_constraints, velocity_constraint_count, velocity_constraint_offset)
        native = pointers.functions({"potential": potential, "gradient": gradient}, int(dim))
        others = {"mass": mass if callable(mass) else None, "mass_derivative": mass_derivative}
        others |= {"constraints": constraints, "constraint_jacobian": constraint_jacobian}
        others |= {"velocity_constraints": velocity_constraints, "velocity_constraint_offset": velocity_constraint_offset}
        refused = [k for k, f in others.items() if f is not None and (native is not None or pointers.is_pointer(f))]
        if native is None and not refused:
            closures = {"potential": potential, "gradient": gradient, **others}
            for key, f in closures.items():
                if f is not None:
                    callable_as(key, f, "q")
        refused += ["gradient"] if native is not None and "gradient" not in native else []
        if refused:
            raise TypeError(
                f"{', '.join(refused)}: function pointers give the potential and its gradient (both) of a "
                "system with constant mass and no constraints; give the rest as closures"
            )
        missing = [what for what, f in (("gradient", gradient), ("mass_derivative", mass_derivative)) if f is None]
        if not callable(mass):
            if mass_derivative is not None:
                raise ValueError("mass_derivative: only with a mass closure mass(q); a constant mass has none")
            missing.remove("mass_derivative")
        if constraints is not None and constraint_jacobian is None:
            missing.append("constraint_jacobian")
        if missing:
            warnings.warn(
                f"{name}: no {' and no '.join(missing)} given; central differences are used "
                f"({2 * dim} calls each per force, about 1e-10 relative accuracy)",
                DerivativeWarning,
                stacklevel=2,
            )
        if native is not None:
            potential, gradient = native["potential"], native["gradient"]
        self.potential = potential
        self.gradient = gradient
        self.mass = mass
        self.mass_derivative = mass_derivative
        self.constraints_function = constraints
        self.constraint_jacobian = constraint_jacobian
        self.velocity_constraints_function = velocity_constraints
        self.symmetries = tuple(symmetries)
        self.name = name
        if callable(mass) and native is None:
            self._core = _core.ClosureNatural(int(dim), mass, potential, gradient, mass_derivative, _specs(symmetries))
            self._constrain(constraints, constraint_jacobian, constraint_count)
            self._core = _roll(self._core, velocity_constraints, velocity_constraint_count, velocity_constraint_offset)
            return
        m = np.array(floats("mass", mass))
        if m.ndim > 2 or (m.ndim >= 1 and any(s != dim for s in m.shape)):
            raise ValueError(f"mass: must be a scalar, a vector ({dim},) or a matrix ({dim}, {dim}), got shape {m.shape}")
        if not np.all(np.isfinite(m)):
            raise ValueError("mass: must be finite")
        self.mass = m
        if native is not None:
            self._core = _core.PointerSystem(
                int(dim), _handed(native["potential"]), _handed(native["gradient"]), m, _specs(symmetries)
            )
            return
        self._core = _core.ClosureModel(int(dim), potential, gradient, m, _specs(symmetries))
        self._constrain(constraints, constraint_jacobian, constraint_count)
        self._core = _roll(self._core, velocity_constraints, velocity_constraint_count, velocity_constraint_offset)

    def _constrain(self, constraints, jacobian, count) -> None:
        """Puts the model on the constraints, if any."""
        if constraints is None:
            return
        count = positive_int("constraint_count", count)
        # The constraints wrap the unconstrained closure model this class built just before.
        assert isinstance(self._core, (_core.ClosureModel, _core.ClosureNatural))
        self._core = _core.ClosureConstrained(self._core, int(count), constraints, jacobian)


def _check_velocity_constraints(
    matrix: Callable[[np.ndarray], ArrayLike] | None, count: int | None, offset: Callable[[np.ndarray], ArrayLike] | None
) -> None:
    """Refuses velocity constraints without their count, a count without them, and an affine
    term without either."""
    if (matrix is None) != (count is None):
        raise ValueError("velocity_constraints: give velocity_constraints(q) with velocity_constraint_count")
    if offset is not None and matrix is None:
        raise ValueError("velocity_constraint_offset: only with velocity_constraints(q) and velocity_constraint_count")
    if count is not None:
        positive_int("velocity_constraint_count", count)


def _forced(value: Any, n: int) -> np.ndarray:
    """A force closure's result, read as the core reads one, before a Rayleigh term is added
    to it (numpy would broadcast a wrong shape, or read a string)."""
    f = returned("force(q, v, t)", value)
    if f.shape != (n,):
        raise ValueError(f"force(q, v, t) returned an array of shape {f.shape}, expected ({n},) (one per coordinate)")
    return f


def _roll(
    core: Any, matrix: Callable[[np.ndarray], ArrayLike] | None, count: int | None, offset: Callable[[np.ndarray], ArrayLike] | None
) -> Any:
    """The closure model ``core`` (unconstrained, or on holonomic constraints) with the
    velocity constraints A(q)q̇ + b(q) = 0 of ``matrix`` (m = ``count`` rows) and ``offset`` (b;
    0 without it), if any."""
    if matrix is None or count is None:
        return core
    return _core.ClosureNonholonomic(core, int(count), matrix, offset)


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


def reactive_force(
    mass: Callable[[np.ndarray, float], float],
    velocity: Callable[[np.ndarray, np.ndarray, float], ArrayLike],
    *,
    mass_rate: Callable[[np.ndarray, float], float],
    mass_gradient: Callable[[np.ndarray, float], ArrayLike] | None = None,
    force: Callable[[np.ndarray, np.ndarray, float], ArrayLike] | None = None,
) -> Callable[[np.ndarray, np.ndarray, float], np.ndarray]:
    """Meshchersky's reactive force of a body of variable mass, as a ``force`` closure for
    :class:`Lagrangian`: the closure form of :class:`varmech.symbolic.MassFlow`.

    The body's position is q (Cartesian coordinates) and its kinetic energy ½m(q, t)|q̇|² is in
    L; matter leaves or joins it with the absolute velocity u, so that d(mq̇)/dt = F + ṁu. The
    force returned is ``force`` + Q_r with

    Q_r = ṁu − ½|q̇|² ∂m/∂q,   ṁ = ∂m/∂t + (∂m/∂q)·q̇.

    Parameters
    ----------
    mass
        ``mass(q, t) -> float``, m; it must stay positive. The run stops at the step where
        it does not: a :class:`~varmech.VarmechError` where L's ∂²L/∂q̇² is singular there
        first, else the force's ValueError naming ``mass``.
    velocity
        ``velocity(q, v, t) -> array (n,)``, the velocity u of the matter ejected or accreted.
    mass_rate
        ``mass_rate(q, t) -> float``, ∂m/∂t.
    mass_gradient
        ``mass_gradient(q, t) -> array (n,)``, ∂m/∂q; default: m does not depend on q.
    force
        Another generalized force ``force(q, v, t) -> array (n,)``, added.

    Returns
    -------
    callable
        ``force(q, v, t) -> ndarray (n,)``.

    Raises
    ------
    TypeError
        An argument that is not callable, naming it.

    Examples
    --------
    The rocket of :func:`varmech.symbolic.examples.rocket` from closures:

    >>> import math
    >>> import numpy as np
    >>> import varmech
    >>> m = lambda q, t: 10.0 - 0.4 * t
    >>> rocket = varmech.Lagrangian(
    ...     1, lambda q, v, t: m(q, t) * (v[0] ** 2 / 2 - 9.81 * q[0]), time_dependent=True,
    ...     dl_dt=lambda q, v, t: -0.4 * (v[0] ** 2 / 2 - 9.81 * q[0]),
    ...     force=varmech.reactive_force(m, lambda q, v, t: v - 400.0, mass_rate=lambda q, t: -0.4))
    >>> traj = varmech.integrate(rocket, [0.0], v0=[0.0], dt=0.01, t_end=10.0)
    >>> bool(abs(traj.v[-1, 0] - (400.0 * math.log(10.0 / 6.0) - 98.1)) < 1e-3)
    True
    """
    for name, f, arguments in (("mass", mass, "q, t"), ("velocity", velocity, "q, v, t"), ("mass_rate", mass_rate, "q, t"),
                               ("mass_gradient", mass_gradient, "q, t"), ("force", force, "q, v, t")):
        if f is not None:
            callable_as(name, f, arguments)

    def reactive(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        m = float(mass(q, t))
        if not (math.isfinite(m) and m > 0.0):
            raise ValueError(f"mass: the mass is {m} at t = {t}: it must stay positive and finite (the body has run "
                             "out of mass; end the run before)")
        gradient = np.zeros(len(q)) if mass_gradient is None else np.asarray(mass_gradient(q, t), dtype=np.float64)
        rate = float(mass_rate(q, t)) + float(gradient @ v)
        total = rate * np.asarray(velocity(q, v, t), dtype=np.float64) - 0.5 * float(v @ v) * gradient
        return total if force is None else total + np.asarray(force(q, v, t), dtype=np.float64)

    return reactive


class Lagrangian(Model):
    """A general Lagrangian L(q, q̇, t) given by Python closures, for the implicit variational
    methods (``midpoint``, ``trapezoid``, ``galerkin4``, ``galerkin6``).

    Parameters
    ----------
    dim
        Number of generalized coordinates n.
    lagrangian
        ``lagrangian(q, v, t) -> float``. Every function of this model may instead be a function
        pointer of :data:`varmech.pointers.SIGNATURE` (all given ones, or none; no
        ``rayleigh`` then): L writes ``out[0]``; ``dl_dq``, ``dl_dv`` and ``force`` n numbers;
        ``hessians`` 3n², the three matrices below one after the other, each row-major. The core
        then calls them with the GIL released.
    dl_dq, dl_dv
        ``dl_dq(q, v, t) -> array (n,)`` and ``dl_dv(q, v, t) -> array (n,)``, the derivatives
        ∂L/∂q and ∂L/∂q̇ (the momentum). Optional: missing ones come from central differences
        of L (2n calls of L each, about 1e-10 relative accuracy), and a warning says so.
        :func:`varmech.check_derivatives` checks supplied ones.
    hessians
        ``hessians(q, v, t) -> (L_qq, L_qv, L_vv)``, the second derivatives ∂²L/∂q²,
        ∂²L/∂q∂q̇ (entry (i, j) is ∂²L/∂qᵢ∂q̇ⱼ) and ∂²L/∂q̇², each an array (n, n). Optional:
        with them Newton's Jacobian of the DEL equations is assembled exactly instead of by
        differences of the equations (2·s·n fewer evaluations of ∂L/∂q and ∂L/∂q̇ per Jacobian);
        forced models still difference it.
    force
        ``force(q, v, t) -> array (n,)``, a non-conservative generalized force (friction,
        driving); integrated by the discrete Lagrange–d'Alembert principle, and its work is
        tracked (``traj.work``) so that the energy balance can be checked.
    rayleigh
        A Rayleigh dissipation R(q̇) = ½q̇ᵀCq̇, given by C (a scalar, a vector (n,) for a
        diagonal, or a matrix (n, n)); adds the force −Cq̇.
    time_dependent
        Whether L depends on t; then the energy function E = p·q̇ − L is not conserved: it
        changes by −∫∂L/∂t dt, which the run tracks with the forces' work (``traj.work``, the
        energy put in), so that the conservation report judges the balance E − W.
    dl_dt
        ``dl_dt(q, v, t) -> float``, ∂L/∂t, for an L that depends on t (closures only).
        Optional: missing, it comes from a central difference of L in t (two calls of L per
        quadrature node and step, about 1e-10 relative), and a warning says so.
    velocity_constraints, velocity_constraint_count
        Velocity constraints A(q)q̇ = 0, ``velocity_constraints(q) -> array (m, n)`` with
        ``velocity_constraint_count`` = m, as for :class:`MechanicalSystem`; closures only.
    velocity_constraint_offset
        The affine term b(q) of constraints A(q)q̇ + b(q) = 0, ``velocity_constraint_offset(q)
        -> array (m,)``, as for :class:`MechanicalSystem`.
    symmetries
        Symmetries of L whose Noether momenta :func:`varmech.check_conservation` checks.
    name
        A label for reports.
    energy_name
        What reports call E = p·q̇ − L: ``"Jacobi integral"`` for an L written in a moving
        (rotating) frame, whose conserved E is not the inertial energy.
    coordinates
        The coordinates' names, as for :class:`MechanicalSystem`.

    Raises
    ------
    ValueError
        A malformed argument, named: ``dim`` not positive, a ``rayleigh`` matrix of the wrong
        shape, a count without its velocity constraints or constraints without their count.
    TypeError
        A function pointer with another signature than :data:`varmech.pointers.SIGNATURE`,
        pointers and closures mixed, or a pointer model with ``rayleigh``, naming the argument;
        an ``energy_name`` that is not a non-empty str.

    See Also
    --------
    MechanicalSystem : L = ½q̇ᵀMq̇ − V(q) from closures, for every method when M is constant.
    varmech.symbolic.lagrangian : the same model from a SymPy expression, every derivative derived.

    Examples
    --------
    A charged particle in a uniform magnetic field B = 1 (symmetric gauge), with its derivatives:
    it gyrates on the unit circle, and the midpoint rule keeps its energy to round-off.

    >>> import numpy as np
    >>> import varmech
    >>> def A(q):
    ...     return 0.5 * np.array([-q[1], q[0]])
    >>> particle = varmech.Lagrangian(
    ...     2, lambda q, v, t: 0.5 * v @ v + A(q) @ v,
    ...     dl_dq=lambda q, v, t: 0.5 * np.array([v[1], -v[0]]),
    ...     dl_dv=lambda q, v, t: v + A(q),
    ...     symmetries=[varmech.Rotation(spatial_dim=2)], name="charged particle")
    >>> traj = varmech.integrate(particle, [1.0, 0.0], v0=[0.0, -1.0], dt=0.05, t_end=10.0)
    >>> traj.method, varmech.check_conservation(traj).verdict
    ('midpoint', 'conserved to round-off')
    """

    def __init__(
        self,
        dim: int,
        lagrangian: Callable[[np.ndarray, np.ndarray, float], float],
        *,
        dl_dq: Callable[[np.ndarray, np.ndarray, float], ArrayLike] | None = None,
        dl_dv: Callable[[np.ndarray, np.ndarray, float], ArrayLike] | None = None,
        hessians: Callable[[np.ndarray, np.ndarray, float], tuple[ArrayLike, ArrayLike, ArrayLike]] | None = None,
        force: Callable[[np.ndarray, np.ndarray, float], ArrayLike] | None = None,
        rayleigh: ArrayLike | None = None,
        time_dependent: bool = False,
        velocity_constraints: Callable[[np.ndarray], ArrayLike] | None = None,
        velocity_constraint_count: int | None = None,
        velocity_constraint_offset: Callable[[np.ndarray], ArrayLike] | None = None,
        symmetries: Sequence[Symmetry] = (),
        name: str = "lagrangian",
        dl_dt: Callable[[np.ndarray, np.ndarray, float], float] | None = None,
        energy_name: str = "energy",
        coordinates: Sequence[str] | None = None,
    ):
        self._arguments = {
            "dim": dim,
            "lagrangian": lagrangian,
            "dl_dq": dl_dq,
            "dl_dv": dl_dv,
            "hessians": hessians,
            "force": force,
            "rayleigh": rayleigh,
            "time_dependent": time_dependent,
            "velocity_constraints": velocity_constraints,
            "velocity_constraint_count": velocity_constraint_count,
            "velocity_constraint_offset": velocity_constraint_offset,
            "symmetries": symmetries,
            "name": name,
            "dl_dt": dl_dt,
            "energy_name": energy_name,
            "coordinates": coordinates,
        }
        dim = positive_int("dim", dim)
        self._coordinates = coordinate_names(coordinates, dim)
        if not isinstance(energy_name, str) or not energy_name.strip():
            raise TypeError(f"energy_name: a non-empty str, such as 'Jacobi integral', not {energy_name!r}")
        _check_velocity_constraints(velocity_constraints, velocity_constraint_count, velocity_constraint_offset)
        if dl_dt is not None and not time_dependent:
            raise ValueError("dl_dt: given for an L declared independent of t; pass time_dependent=True with it")
        if dl_dt is not None and pointers.is_pointer(dl_dt):
            raise TypeError("dl_dt: a closure; with function pointers ∂L/∂t comes from differences of the L pointer")
        functions = {"lagrangian": lagrangian, "dl_dq": dl_dq, "dl_dv": dl_dv, "hessians": hessians, "force": force}
        native = pointers.functions(functions, int(dim))
        if native is None:
            for key, f in (functions | {"dl_dt": dl_dt}).items():
                if f is not None:
                    callable_as(key, f, "q, v, t")
            for key, f in (("velocity_constraints", velocity_constraints), ("velocity_constraint_offset", velocity_constraint_offset)):
                if f is not None:
                    callable_as(key, f, "q")
        for key, f in (("velocity_constraints", velocity_constraints), ("velocity_constraint_offset", velocity_constraint_offset)):
            if f is not None and (native is not None or pointers.is_pointer(f)):
                raise TypeError(f"{key}: only with closures (not with function pointers), and as a closure")
        if native is not None and rayleigh is not None:
            raise TypeError("rayleigh: not with function pointers; add −Cq̇ to the force pointer instead")
        missing = [n for n, f in (("dl_dq", dl_dq), ("dl_dv", dl_dv)) if f is None]
        if time_dependent and dl_dt is None and native is None:
            warnings.warn(
                f"{name}: no dl_dt given; ∂L/∂t, which the energy balance tracks, comes from a central difference of L "
                "in t (two calls of L per quadrature node and step, about 1e-10 relative accuracy)",
                DerivativeWarning,
                stacklevel=2,
            )
        if missing:
            warnings.warn(
                f"{name}: no {' and no '.join(missing)} given; central differences of L are used "
                f"({2 * dim} calls of L each, about 1e-10 relative accuracy)",
                DerivativeWarning,
                stacklevel=2,
            )
        total_force = force
        if rayleigh is not None:
            c = floats("rayleigh", rayleigh)
            if c.ndim > 2 or (c.ndim >= 1 and any(s != dim for s in c.shape)) or not np.all(np.isfinite(c)):
                raise ValueError(f"rayleigh: must be a finite scalar, a vector ({dim},) or a matrix ({dim}, {dim})")
            damping = (lambda v: c @ v) if c.ndim == 2 else (lambda v: c * v)
            total_force = (lambda q, v, t: -damping(v)) if force is None else (lambda q, v, t: _forced(force(q, v, t), dim) - damping(v))
        if native is not None:
            handed = {k: _handed(f) for k, f in native.items()}
            self._core = _core.PointerLagrangian(
                int(dim),
                handed["lagrangian"],
                handed.get("dl_dq"),
                handed.get("dl_dv"),
                handed.get("hessians"),
                handed.get("force"),
                bool(time_dependent),
                _specs(symmetries),
            )
            lagrangian = native["lagrangian"]
            dl_dq, dl_dv, hessians, total_force = (native[k] if k in native else None for k in list(functions)[1:])
        else:
            self._core = _roll(
                _core.ClosureLagrangian(
                    int(dim), lagrangian, dl_dq, dl_dv, hessians, total_force, bool(time_dependent), _specs(symmetries), dl_dt
                ),
                velocity_constraints,
                velocity_constraint_count,
                velocity_constraint_offset,
            )
        self.force = total_force
        self.lagrangian = lagrangian
        self.dl_dq = dl_dq
        self.dl_dv = dl_dv
        self.hessians = hessians
        self.dl_dt = dl_dt
        self.symmetries = tuple(symmetries)
        self.name = name
        self._energy_name = energy_name

    @property
    def energy_name(self) -> str:
        """What reports call E = p·q̇ − L (the ``energy_name`` given)."""
        return self._energy_name
