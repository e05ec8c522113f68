"""Models from Python closures (or C function pointers): mechanical systems L = ½q̇ᵀMq̇ − V(q),
on holonomic or velocity constraints, and general Lagrangians L(q, q̇, t) with forces; and
Meshchersky's reactive force of a body of variable mass as such a force."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import _core, pointers
from ._model import Model, coordinate_names, handed_pointer
from ._symmetries import Symmetry, generator_specs
from ._util import callable_as, floats, positive_int, returned
from ._warnings import DerivativeWarning


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
        # What it pickles as (Model.__reduce__): every argument by name, as given, before any
        # is checked; only the arguments are local yet.
        self._arguments = {name: value for name, value in locals().items() if name != "self"}
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
            self._core = _core.ClosureNatural(int(dim), mass, potential, gradient, mass_derivative, generator_specs(symmetries))
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
                int(dim), handed_pointer(native["potential"]), handed_pointer(native["gradient"]), m, generator_specs(symmetries)
            )
            return
        self._core = _core.ClosureModel(int(dim), potential, gradient, m, generator_specs(symmetries))
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
        # What it pickles as (Model.__reduce__): every argument by name, as given, before any
        # is checked; only the arguments are local yet.
        self._arguments = {name: value for name, value in locals().items() if name != "self"}
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
            handed = {k: handed_pointer(f) for k, f in native.items()}
            self._core = _core.PointerLagrangian(
                int(dim),
                handed["lagrangian"],
                handed.get("dl_dq"),
                handed.get("dl_dv"),
                handed.get("hessians"),
                handed.get("force"),
                bool(time_dependent),
                generator_specs(symmetries),
            )
            lagrangian = native["lagrangian"]
            dl_dq, dl_dv, hessians, total_force = (native[k] if k in native else None for k in list(functions)[1:])
        else:
            self._core = _roll(
                _core.ClosureLagrangian(
                    int(dim), lagrangian, dl_dq, dl_dv, hessians, total_force, bool(time_dependent), generator_specs(symmetries), dl_dt
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
