"""The model base class: what every model kind answers (its dimension, kind, energy's name,
coordinates' names, the Legendre transform and its inverse), its initial state, and models as
data (recipes) and as pickles."""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import _core, pointers
from ._core import ModelKind
from ._symmetries import Symmetry
from ._util import floats, vector


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


def handed_pointer(function: pointers.Function) -> tuple[int, pointers.Function]:
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
        ``"E"``) where the model states them: a catalogue scene's (as declared with it;
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
