"""The compiled symbolic model: its tapes and metadata (what crosses into the core once), and
the SymPy expressions they came from."""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import sympy as sp

from .. import _core
from .._util import finite
from ..model import RECIPES, Model, Symmetry, field, generator_specs, integers, numbers, symmetry_data, symmetry_of
from . import _tree
from ._lower import Tape
from ._rhs import FirstOrder


@dataclass(frozen=True)
class Spec:
    """Everything the core's compiled model is built from: the kind (``"lagrangian"`` or
    ``"separable"``), n, the tape of each function by name, the parameters in order with their
    values, the numbers of constraints and velocity constraints, the flags and the
    symmetries."""

    kind: str
    dim: int
    functions: dict[str, Tape]
    parameter_names: tuple[str, ...]
    parameters: np.ndarray
    constraints: int
    time_dependent: bool
    forced: bool
    symmetries: tuple[Symmetry, ...]
    jit: bool
    velocity_constraints: int = 0
    delays: tuple[float, ...] = ()
    #: What reports call E = p·q̇ − L: "Jacobi integral" for an L whose t cancelled.
    energy_name: str = "energy"


@dataclass(frozen=True)
class Symbolic:
    """The symbolic side of a model: its symbols, L, the expressions of each function and the
    cyclic coordinates found."""

    q: tuple[sp.Symbol, ...]
    v: tuple[sp.Symbol, ...]
    t: sp.Symbol
    L: sp.Expr
    expressions: dict[str, tuple[sp.Expr, ...]]
    cyclic: tuple[int, ...]
    name: str


def _compile(spec: Spec) -> _core.CompiledModel:
    """The core's compiled model of ``spec``: the one place that calls the binding."""
    return _core.CompiledModel(
        spec.kind,
        spec.dim,
        dict(spec.functions),
        spec.parameters,
        constraints=spec.constraints,
        velocity_constraints=spec.velocity_constraints,
        time_dependent=spec.time_dependent,
        forced=spec.forced,
        symmetries=generator_specs(spec.symmetries),
        jit=spec.jit,
        delays=list(spec.delays),
    )


class SymbolicModel(Model):
    """A model compiled from SymPy expressions (see :func:`varmech.symbolic.lagrangian`): its
    functions run as instruction tapes (or machine code) in the core, with no Python call per
    step.

    Attributes
    ----------
    q, v, t
        The coordinates, velocities and time as SymPy symbols.
    L
        The Lagrangian L(q, v, t).
    expressions
        The derived expressions of each compiled function by name (outputs row-major):
        ``lagrangian``, ``gradients`` (∂L/∂q, ∂L/∂q̇, and ∂L/∂t last for an L of t, also
        ``dl_dt``), ``hessians`` (∂²L/∂q², ∂²L/∂q∂q̇,
        ∂²L/∂q̇²) and ``force`` for a general Lagrangian; ``potential``, ``gradient`` (∇V) and
        ``mass`` (1, n or n² entries) for a separable one; ``constraints`` and
        ``constraint_jacobian`` with constraints; ``velocity_constraints`` (A, m·n) and
        ``velocity_constraint_derivative`` (∂A/∂qᵢ, n blocks) with velocity constraints.
    kind_name
        ``"lagrangian"`` or ``"separable"``.
    cyclic
        The coordinates found cyclic (∂L/∂qᵢ ≡ 0, no force on or depending on qᵢ), declared as
        :class:`~varmech.Cyclic` symmetries.
    build_seconds
        Wall time from the expressions to the ready model.
    parameters
        The parameters by name with their values.
    jit
        Whether the tapes run as machine code.

    Parameters
    ----------
    spec : Spec
        What the core's model is built from (tapes, parameters, flags, symmetries).
    symbolic : Symbolic
        The symbols, L and the derived expressions.
    core : varmech._core.CompiledModel, optional
        The core's model, when it is already built (default: compile ``spec``).
    started : float, optional
        The :func:`time.perf_counter` value the build started at, for ``build_seconds``.

    See Also
    --------
    varmech.symbolic.lagrangian : build one from L(q, q̇, t).
    varmech.symbolic.mechanical : build one from V(q) and a mass.

    Examples
    --------
    Users build it with :func:`varmech.symbolic.lagrangian` or :func:`~varmech.symbolic.mechanical`:

    >>> import sympy as sp, varmech, varmech.symbolic
    >>> th, om, g = sp.symbols("theta omega g")
    >>> model = varmech.symbolic.lagrangian(om**2 / 2 + g * sp.cos(th), [th], [om], parameters={g: 9.81})
    >>> model.kind_name, model.parameters, model.L
    ('separable', {'g': 9.81}, g*cos(theta) + omega**2/2)
    >>> traj = varmech.integrate(model.with_parameters(g=1.0), [0.0], [1.0], dt=0.01, steps=100)
    >>> round(float(traj.energy()[-1]), 4)
    -0.5
    """

    _core: _core.CompiledModel

    def __init__(self, spec: Spec, symbolic: Symbolic, *, core: Any = None, started: float | None = None):
        start = time.perf_counter() if started is None else started
        self._spec = spec
        self._symbolic = symbolic
        self._core = _compile(spec) if core is None else core
        self.symmetries = spec.symmetries
        self.name = symbolic.name
        self.build_seconds = time.perf_counter() - start

    @property
    def q(self) -> tuple[sp.Symbol, ...]:
        """The coordinates as SymPy symbols."""
        return self._symbolic.q

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The coordinates' names: their symbols' (``theta`` of ``theta(t)``)."""
        return tuple(getattr(x, "name", None) or type(x).__name__ for x in self._symbolic.q)

    @property
    def v(self) -> tuple[sp.Symbol, ...]:
        """The velocities as SymPy symbols."""
        return self._symbolic.v

    @property
    def t(self) -> sp.Symbol:
        """The time symbol."""
        return self._symbolic.t

    @property
    def L(self) -> sp.Expr:
        """The Lagrangian L(q, v, t)."""
        return self._symbolic.L

    @property
    def expressions(self) -> dict[str, tuple[sp.Expr, ...]]:
        """The derived expressions of each compiled function by name (a copy)."""
        return dict(self._symbolic.expressions)

    @property
    def cyclic(self) -> tuple[int, ...]:
        """The coordinates found cyclic."""
        return self._symbolic.cyclic

    @property
    def kind_name(self) -> str:
        """``"lagrangian"`` or ``"separable"``."""
        return self._spec.kind

    @property
    def parameters(self) -> dict[str, float]:
        """The parameters by name with their values, in the order of the parameter vector."""
        return {name: float(x) for name, x in zip(self._spec.parameter_names, self._spec.parameters)}

    def with_parameters(self, **values: float) -> SymbolicModel:
        """The same model (the same derived expressions, tapes and compiled code) with the
        parameters named by keyword set to new values and the others kept.

        Parameters
        ----------
        **values : float
            The new values by parameter name.

        Returns
        -------
        SymbolicModel
            A new model; this one is unchanged.

        Raises
        ------
        ValueError
            Naming ``parameters``: an unknown parameter, or a value that is not finite.

        Examples
        --------
        The pendulum taken to the Moon: ``g`` changes, ``l`` is kept, and nothing is derived again.

        >>> import sympy as sp, varmech.symbolic
        >>> th, om, g, l = sp.symbols("theta omega g l")
        >>> L = l**2 * om**2 / 2 + g * l * sp.cos(th)
        >>> earth = varmech.symbolic.lagrangian(L, [th], [om], parameters={g: 9.81, l: 2.0})
        >>> earth.with_parameters(g=1.62).parameters, earth.parameters
        ({'g': 1.62, 'l': 2.0}, {'g': 9.81, 'l': 2.0})
        >>> earth.with_parameters(m=1.0)
        Traceback (most recent call last):
            ...
        ValueError: parameters: m not a parameter of symbolic lagrangian (it has g, l)
        """
        started = time.perf_counter()
        names = self._spec.parameter_names
        unknown = [name for name in values if name not in names]
        if unknown:
            known = ", ".join(names) if names else "none"
            raise ValueError(f"parameters: {', '.join(unknown)} not a parameter of {self.name} (it has {known})")
        current = self.parameters
        current.update({name: finite(f"parameters: {name}", x) for name, x in values.items()})
        vector = np.array([current[name] for name in names], dtype=np.float64)
        spec = replace(self._spec, parameters=vector)
        return SymbolicModel(spec, self._symbolic, core=self._core.with_parameters(vector), started=started)

    @property
    def jit(self) -> bool:
        """Whether the tapes run as machine code (compiled by Cranelift); else the core's tape
        interpreter runs them."""
        return bool(self._core.jit)

    def with_jit(self, jit: bool) -> SymbolicModel:
        """The same model with its tapes compiled to machine code (``True``) or interpreted
        (``False``): the two agree bit for bit, the interpreter is slower and needs no compile
        step.

        Parameters
        ----------
        jit : bool
            Compile the tapes (Cranelift) or interpret them.

        Returns
        -------
        SymbolicModel
            A new model built from the same tapes; this one is unchanged.

        Examples
        --------
        Interpreted and compiled tapes give the same run bit for bit (``with_jit(True)`` falls
        back to the interpreter where Cranelift cannot compile, and ``jit`` then says False):

        >>> import sympy as sp, varmech, varmech.symbolic
        >>> th, om = sp.symbols("theta omega")
        >>> model = varmech.symbolic.lagrangian(om**2 / 2 + sp.cos(th), [th], [om])
        >>> interpreted = model.with_jit(False)
        >>> a = varmech.integrate(interpreted, [0.5], [0.0], dt=0.01, steps=100)
        >>> b = varmech.integrate(model.with_jit(True), [0.5], [0.0], dt=0.01, steps=100)
        >>> interpreted.jit, bool((a.q == b.q).all() and (a.p == b.p).all())
        (False, True)
        """
        return SymbolicModel(replace(self._spec, jit=bool(jit)), self._symbolic)

    def first_order(self) -> FirstOrder | None:
        """The first-order system ẏ = (q̇(q, p, t), ∂L/∂q) lambdified (see
        :class:`~varmech.symbolic._rhs.FirstOrder`): the right-hand side a SciPy user would
        write from this Lagrangian.

        Returns
        -------
        FirstOrder or None
            f(t, y) for y = (q, p), as :func:`scipy.integrate.solve_ivp` takes it; None where
            ∂L/∂q̇ is not linear in q̇, or for a forced or constrained model.

        Examples
        --------
        For the pendulum, θ̇ = p and ṗ = −g sin θ, the parameters substituted:

        >>> import numpy as np, sympy as sp, varmech.symbolic
        >>> th, om, g = sp.symbols("theta omega g")
        >>> model = varmech.symbolic.lagrangian(om**2 / 2 + g * sp.cos(th), [th], [om], parameters={g: 9.81})
        >>> model.first_order()(0.0, np.array([np.pi / 2, 0.5])).tolist()
        [0.5, -9.81]
        """
        return FirstOrder.build(self)

    @property
    def delays(self) -> tuple[float, ...]:
        """The delays τ of the model's delayed forces (``delayed=`` of its constructor)."""
        return self._spec.delays

    @property
    def has_history(self) -> bool:
        """Whether ``history=`` gave the state before the run for the delayed forces."""
        return "history" in self._spec.functions

    @property
    def energy_name(self) -> str:
        """``"Jacobi integral"`` for an L from inertial coordinates whose t cancelled (a moving
        frame), else ``"energy"``."""
        return self._spec.energy_name

    def __reduce__(self) -> tuple[Any, ...]:
        # The tapes and expressions, never the compiled code: unpickling compiles them again.
        return (SymbolicModel, (self._spec, self._symbolic))

    def _recipe(self) -> dict[str, Any] | None:
        # The tapes (the core checks every index of a tape it is given) and the expressions as
        # data; None for an expression of a class the data does not know.
        spec, symbolic = self._spec, self._symbolic
        try:
            expressions = {
                "q": [_tree.encode(x) for x in symbolic.q],
                "v": [_tree.encode(x) for x in symbolic.v],
                "t": _tree.encode(symbolic.t),
                "L": _tree.encode(symbolic.L),
                "expressions": {k: [_tree.encode(e) for e in v] for k, v in symbolic.expressions.items()},
            }
        except TypeError:
            return None
        return {
            "kind": "symbolic",
            "name": symbolic.name,
            "cyclic": list(symbolic.cyclic),
            **expressions,
            "model": spec.kind,
            "dim": spec.dim,
            "functions": {k: [ops.tolist(), c.tolist(), out.tolist()] for k, (ops, c, out) in spec.functions.items()},
            "parameter_names": list(spec.parameter_names),
            "parameters": spec.parameters.tolist(),
            "constraints": spec.constraints,
            "velocity_constraints": spec.velocity_constraints,
            "time_dependent": spec.time_dependent,
            "forced": spec.forced,
            "symmetries": [symmetry_data(x) for x in spec.symmetries],
            "jit": spec.jit,
            "delays": list(spec.delays),
            # The delayed forces' slots [q …], [q̇ …], [q̈ …], t; 1 (absent) was [q …], [q̇ …], t.
            "delayed_layout": 2,
            "energy_name": spec.energy_name,
        }


def _of_recipe(recipe: dict[str, Any]) -> SymbolicModel:
    """The symbolic model of :meth:`SymbolicModel._recipe`, its tapes checked by the core."""
    functions: dict[str, Any] = {}
    for name, tape in field(recipe, "functions", dict).items():
        ops, constants, outputs = tape
        functions[name] = (
            np.array(ops, dtype=np.int64).reshape(-1, 3),
            np.array(numbers(constants, "constants"), dtype=np.float64),
            np.array(outputs, dtype=np.int64),
        )
    if recipe.get("delays") and recipe.get("delayed_layout", 1) != 2:
        raise ValueError(
            "delays: its delayed forces were stored in the slots of an earlier varmech, before they could read "
            "q̈(t − τ); build the model again with varmech.symbolic.lagrangian"
        )
    names = field(recipe, "parameter_names", list)
    if not all(isinstance(x, str) for x in names):
        raise TypeError("parameter_names are not names")
    spec = Spec(
        kind=field(recipe, "model", str),
        dim=field(recipe, "dim", int),
        functions=functions,
        parameter_names=tuple(names),
        parameters=np.array(numbers(recipe["parameters"], "parameters"), dtype=np.float64),
        constraints=field(recipe, "constraints", int),
        time_dependent=field(recipe, "time_dependent", bool),
        forced=field(recipe, "forced", bool),
        symmetries=tuple(symmetry_of(x) for x in field(recipe, "symmetries", list)),
        jit=field(recipe, "jit", bool),
        velocity_constraints=field(recipe, "velocity_constraints", int),
        # A file written before delays were known has none.
        delays=tuple(float(x) for x in numbers(recipe.get("delays", []), "delays")),
        energy_name=str(recipe.get("energy_name", "energy")),
    )
    expressions = field(recipe, "expressions", dict)
    symbolic = Symbolic(
        q=tuple(_tree.decode(x) for x in field(recipe, "q", list)),
        v=tuple(_tree.decode(x) for x in field(recipe, "v", list)),
        t=_tree.decode(recipe["t"]),
        L=_tree.decode(recipe["L"]),
        expressions={k: tuple(_tree.decode(e) for e in field(expressions, k, list)) for k in expressions},
        cyclic=tuple(integers(recipe["cyclic"], "cyclic")),
        name=field(recipe, "name", str),
    )
    return SymbolicModel(spec, symbolic)


RECIPES["symbolic"] = _of_recipe
