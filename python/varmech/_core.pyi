"""Stubs of the compiled extension ``varmech._core`` (hand-written; see rust/python/src)."""

from collections.abc import Callable, Sequence
from typing import Any, final

import numpy as np
from numpy.typing import NDArray
from typing_extensions import disjoint_base

__all__ = [
    "FAILURE",
    "IMPACT_LAWS",
    "ROUND_OFF",
    "TAPE_OPS",
    "TOO_COARSE",
    "VERDICTS",
    "CatalogueEntry",
    "ClosureConstrained",
    "ClosureLagrangian",
    "ClosureModel",
    "ClosureNatural",
    "ClosureNonholonomic",
    "CompiledModel",
    "ContactError",
    "ConvergenceError",
    "DivergenceError",
    "Generator",
    "MethodInfo",
    "ModelKind",
    "NativeModel",
    "PointerLagrangian",
    "PointerSystem",
    "RouthModel",
    "RunSpec",
    "SceneRecord",
    "SceneReference",
    "SpuriousBranchError",
    "Statistics",
    "Stepper",
    "TrajectoryRecord",
    "VarmechError",
    "accurate_step",
    "amended_potential",
    "beyond_limit",
    "catalogue",
    "central_differences",
    "check_allocation",
    "constraint_curvature",
    "constraint_residuals",
    "cyclic_increments",
    "cyclic_velocity",
    "derivative",
    "energy_statistics",
    "energy_terms",
    "engage",
    "ensemble",
    "equilibrium",
    "fastest_frequency",
    "impulse_components",
    "impulse_response",
    "integrate",
    "inverse_mass",
    "is_affine",
    "is_forced",
    "is_time_dependent",
    "kind_of",
    "linearize",
    "lyapunov",
    "methods",
    "momentum",
    "momentum_along",
    "nbody",
    "normal_modes",
    "project",
    "reactions",
    "resume",
    "routh",
    "scene",
    "stable_step",
    "statistics",
    "symplecticity_defect",
]

_FloatArray = NDArray[np.float64]

@disjoint_base
class Generator:
    """A generator ξ(q) of a symmetry: one of the variants below."""

    @property
    def name(self) -> str:
        """The name of the conserved momentum (P_x, L, p[1], ...)."""

    @final
    class Translation(Generator):
        __match_args__ = ("axis", "spatial_dim")
        def __new__(cls, axis: int, spatial_dim: int) -> Generator.Translation: ...
        @property
        def axis(self) -> int: ...
        @property
        def spatial_dim(self) -> int: ...

    @final
    class Rotation(Generator):
        __match_args__ = ("axis", "spatial_dim")
        def __new__(cls, axis: int, spatial_dim: int) -> Generator.Rotation: ...
        @property
        def axis(self) -> int: ...
        @property
        def spatial_dim(self) -> int: ...

    @final
    class Cyclic(Generator):
        __match_args__ = ("index",)
        def __new__(cls, index: int) -> Generator.Cyclic: ...
        @property
        def index(self) -> int: ...

@final
class TrajectoryRecord:
    """The saved states of a run (or of a failed run, up to the failure)."""

    @property
    def t(self) -> _FloatArray: ...
    @property
    def q(self) -> _FloatArray: ...
    @property
    def p(self) -> _FloatArray: ...
    @property
    def steps(self) -> int: ...
    @property
    def force_evaluations(self) -> int: ...
    @property
    def newton(self) -> NDArray[np.uint64]:
        """Cumulative Newton iterations at each saved state (zeros for the explicit methods)."""
    @property
    def work(self) -> _FloatArray:
        """Cumulative work of the non-conservative forces at each saved state (zeros without forces)."""
    @property
    def checkpoint(self) -> bytes: ...
    @property
    def events(self) -> tuple[NDArray[np.uint64], _FloatArray, _FloatArray, _FloatArray, _FloatArray, _FloatArray]:
        """The located event crossings in order of time: the event's index (k,), t (k,), q and p
        (k, n), and the state (q, p) at the start of each one's step (k, n)."""
    @property
    def terminated_by(self) -> int | None:
        """The index of the event whose terminal count stopped the run, if one did."""
    @property
    def impacts(self) -> tuple[NDArray[np.uint64], _FloatArray, _FloatArray, _FloatArray, _FloatArray]:
        """The impacts on the run's contacts in order of time: the contact's index (k,), t (k,),
        the contact configuration q and the momenta just before and just after (k, n)."""
    @property
    def switches(self) -> tuple[NDArray[np.uint64], _FloatArray, NDArray[np.uint8], _FloatArray, _FloatArray]:
        """The contacts' closures and releases in order of time: the contact's index (k,), t (k,),
        whether it closed (k,), q and p (k, n)."""
    @property
    def grazing(self) -> int:
        """Impacts under the variational law that took Newton's law for want of a discrete-energy
        root near the reflection (grazing)."""

@final
class Stepper:
    """One model, one method and the state, advanced step by step; with `contacts`,
    `impulses` and `events`, the steps go through their impacts and blows and locate the
    crossings as a run's do, bit for bit."""

    def __new__(cls, model: _Model, q0: _FloatArray, p0: _FloatArray, spec: RunSpec) -> Stepper: ...
    def checkpoint(self) -> bytes:
        """The stepper's whole state as bytes, with its model's fingerprint (see [`Checkpoint`])."""
    @staticmethod
    def from_checkpoint(model: _Model, checkpoint: bytes, spec: RunSpec) -> Stepper:
        """The stepper of `model` at the state of `checkpoint` (from `checkpoint()`, or a run's),
        checked against the model (and the spec's `method` and `dt` where given), watching its
        `contacts` (checked at its state, naming `checkpoint`) and `events` and applying its
        `impulses` after its time."""
    def step(self) -> None:
        """Advances one step."""
    def advance(self, n: int) -> None:
        """Advances `n` steps, checking for Ctrl-C on the way."""
    def advance_tangent(self, n: int, x: _FloatArray) -> _FloatArray:
        """Advances `n` steps carrying the tangent vectors `x` by the steps' tangent map."""
    def reset(
        self, q0: _FloatArray, p0: _FloatArray, t0: float, *, events: list[tuple[str, int, int, str, Any]] | None = None
    ) -> None:
        """Starts afresh from (q0, p0) at t0, with the step count at 0, no impacts and no event
        crossings, the impulses at t0 applied and the `events` started as a new stepper's; a
        state outside a contact is refused (naming `q0`), the stepper unchanged."""
    @property
    def t(self) -> float: ...
    @property
    def q(self) -> _FloatArray: ...
    @property
    def p(self) -> _FloatArray: ...
    @property
    def steps(self) -> int: ...
    @property
    def dt(self) -> float: ...
    @dt.setter
    def dt(self, dt: float) -> None: ...
    @property
    def method(self) -> str: ...
    @property
    def force_evaluations(self) -> int: ...
    @property
    def newton_iterations(self) -> int: ...
    @property
    def work(self) -> float: ...
    @property
    def impacts(self) -> tuple[NDArray[np.uint64], _FloatArray, _FloatArray, _FloatArray, _FloatArray]:
        """The impacts gone through since the start or the last reset, as a run's record has them:
        the contact's index (k,), t (k,), q, p before and p after (k, n)."""
    @property
    def switches(self) -> tuple[NDArray[np.uint64], _FloatArray, NDArray[np.uint8], _FloatArray, _FloatArray]:
        """The contacts' closures and releases since the start or the last reset, as a run's
        record has them: the contact's index (k,), t (k,), closed (k,), q and p (k, n)."""
    @property
    def grazing(self) -> int:
        """Impacts under the variational law that took Newton's law (grazing), as a run's."""
    @property
    def events(
        self,
    ) -> tuple[NDArray[np.uint64], _FloatArray, _FloatArray, _FloatArray, _FloatArray, _FloatArray]:
        """The events' crossings since the start or the last reset, as a run's record has them."""
    @property
    def terminated_by(self) -> int | None:
        """The index of the event whose terminal count stopped the last call, if one did."""

@final
class MethodInfo:
    """Facts about one fixed-step method."""

    @property
    def name(self) -> str: ...
    @property
    def order(self) -> int: ...
    @property
    def stages(self) -> int: ...
    @property
    def force_evaluations(self) -> int: ...
    @property
    def implicit(self) -> bool: ...
    @property
    def constrained(self) -> bool: ...
    @property
    def nonholonomic(self) -> bool: ...
    @property
    def nbody(self) -> bool: ...
    @property
    def symplectic(self) -> bool: ...
    @property
    def symmetric(self) -> bool: ...
    @property
    def h_omega_max(self) -> float: ...
    @property
    def reference(self) -> str: ...
    @property
    def splitting(self) -> tuple[list[float], list[float]] | None:
        """The kick fractions a₀, …, aₛ and drift fractions b₁, …, bₛ of a kick–drift method."""
    @property
    def features(self) -> list[str]:
        """What its step offers: ``discrete_energy``, ``tangent_map``, ``held_step``, ``delayed_forces``."""

@final
class ModelKind:
    """The kind of a model: the core's table decides which methods apply and which is the default."""

    @property
    def name(self) -> str: ...
    @property
    def separable(self) -> bool: ...
    @property
    def default_method(self) -> str: ...
    @property
    def accurate_method(self) -> str: ...
    def admits(self, method: str) -> bool:
        """Whether `method` integrates a model of this kind."""

class VarmechError(RuntimeError):
    """Base class of varmech's errors."""

class DivergenceError(VarmechError):
    """The solution blew up: a non-finite state, or an energy error beyond max_energy_error."""

    step: int
    time: float
    partial: Any

class ConvergenceError(VarmechError):
    """Newton's method did not solve a step's implicit equations."""

    step: int
    time: float
    residual: float
    iterations: int
    partial: Any

class ContactError(VarmechError):
    """An impact could not be resolved: a resting or grazing contact, or an accumulation of impacts."""

    step: int
    time: float
    partial: Any

class SpuriousBranchError(ConvergenceError):
    """A step was solved beyond a fold of the DEL map, on a branch that need not continue the
    trajectory; ``residual`` and ``iterations`` are not set."""

class _ModelProperties:
    """What every model class reports (a stub-only base: the classes do not share one)."""

    @property
    def dim(self) -> int: ...

@final
class NativeModel(_ModelProperties):
    """A native scene: evaluated in Rust with the GIL released."""

    @property
    def name(self) -> str: ...
    @property
    def symmetries(self) -> list[Generator]: ...
    @property
    def constraints(self) -> int: ...
    @property
    def velocity_constraints(self) -> int: ...
    @property
    def gravity(self) -> tuple[float, list[float]] | None:
        """(G, masses) of an N-body scene, None for the others."""

def constraint_residuals(
    model: _Model, q: _FloatArray, p: _FloatArray
) -> tuple[tuple[_FloatArray, _FloatArray], tuple[_FloatArray, _FloatArray]]:
    """((|g(q)|∞, |G(q)M⁻¹p|∞), (‖G‖∞‖q‖∞, ‖G‖∞‖M⁻¹p‖∞)) at each state."""
def constraint_curvature(model: _Model, q: _FloatArray) -> list[float] | None:
    """Frobenius' test of the velocity constraints at each row of q: the curvature of ker A(q)
    relative to ∂A/∂q (round-off where they integrate); None without velocity constraints."""
def project(model: _Model, q0: _FloatArray, p0: _FloatArray) -> tuple[_FloatArray, _FloatArray]: ...
def reactions(
    model: _Model, t: _FloatArray, q: _FloatArray, p: _FloatArray
) -> tuple[_FloatArray, _FloatArray, tuple[_FloatArray, _FloatArray]]:
    """(λ (N, m), Cᵀλ (N, n), (Cᵀλ·q̇, Σ|(Cᵀλ)ᵢq̇ᵢ|)) at each state: the forces of constraint."""

# Lagrange's impulsive equations at one state (rust/python/src/impulsive.rs). A blow is
# (kind, payload) as in a run's impulses: "generalized" (numbers), "function" (P(q)), "point"
# ((x(q), its Jacobian or None, the impulse vector)).
def impulse_components(kind: str, payload: object, q: _FloatArray) -> _FloatArray:
    """P(q), the blow's components of impulse."""

def impulse_response(
    model: _Model, t: float, q: _FloatArray, p: _FloatArray, kind: str, payload: object
) -> tuple[_FloatArray, _FloatArray, _FloatArray, float]:
    """(p⁺, q̇⁺, q̇⁻, T⁺ − T⁻) just after the blow at (q, p)."""

def engage(
    model: _Model, t: float, q: _FloatArray, p: _FloatArray, a: _FloatArray, argument: str
) -> tuple[_FloatArray, _FloatArray, _FloatArray, float, float]:
    """(p⁺, q̇⁺, λ, T⁻ − T⁺, Carnot's ½Δq̇ᵀMΔq̇) just after A(q)q̇ = 0 engages; dependent
    constraints are a ValueError naming ``argument``."""

def inverse_mass(model: _Model, q: _FloatArray, t: float) -> _FloatArray:
    """M(q)⁻¹, shape (n, n)."""

def central_differences(g: Callable[[_FloatArray], object], q: _FloatArray, call: str) -> _FloatArray:
    """∂g/∂q, shape (m, n), by central differences; ``call`` names g in errors."""

@final
class ClosureModel(_ModelProperties):
    """L = ½q̇ᵀMq̇ − V(q) from Python closures."""

    def __new__(
        cls,
        dim: int,
        potential: Callable[[_FloatArray], float],
        gradient: Callable[[_FloatArray], Any] | None,
        mass: _FloatArray,
        symmetries: Sequence[Generator],
    ) -> ClosureModel: ...
    @property
    def has_gradient(self) -> bool: ...

@final
class ClosureConstrained(_ModelProperties):
    """A ClosureModel on holonomic constraints g(q) = 0 from Python closures."""

    def __new__(
        cls,
        system: ClosureModel | ClosureNatural,
        count: int,
        constraints: Callable[[_FloatArray], Any],
        jacobian: Callable[[_FloatArray], Any] | None,
    ) -> ClosureConstrained: ...
    @property
    def constraints(self) -> int: ...

@final
class ClosureNonholonomic(_ModelProperties):
    """A closure model with velocity constraints A(q)q̇ = 0 from a Python closure, alone or
    beside holonomic ones (a ClosureConstrained system)."""

    def __new__(
        cls,
        system: ClosureModel | ClosureNatural | ClosureLagrangian | ClosureConstrained,
        count: int,
        matrix: Callable[[_FloatArray], Any],
        offset: Callable[[_FloatArray], Any] | None = None,
    ) -> ClosureNonholonomic: ...
    @property
    def constraints(self) -> int: ...
    @property
    def velocity_constraints(self) -> int: ...

@final
class ClosureNatural(_ModelProperties):
    """L = ½q̇ᵀM(q)q̇ − V(q) from Python closures (configuration-dependent mass)."""

    def __new__(
        cls,
        dim: int,
        mass: Callable[[_FloatArray], Any],
        potential: Callable[[_FloatArray], float],
        gradient: Callable[[_FloatArray], Any] | None,
        mass_derivative: Callable[[_FloatArray], Any] | None,
        symmetries: Sequence[Generator],
    ) -> ClosureNatural: ...

@final
class ClosureLagrangian(_ModelProperties):
    """A general Lagrangian L(q, q̇, t) from Python closures."""

    def __new__(
        cls,
        dim: int,
        lagrangian: Callable[[_FloatArray, _FloatArray, float], float],
        dl_dq: Callable[[_FloatArray, _FloatArray, float], Any] | None,
        dl_dv: Callable[[_FloatArray, _FloatArray, float], Any] | None,
        hessians: Callable[[_FloatArray, _FloatArray, float], Any] | None,
        force: Callable[[_FloatArray, _FloatArray, float], Any] | None,
        time_dependent: bool,
        symmetries: Sequence[Generator],
        dl_dt: Callable[[_FloatArray, _FloatArray, float], float] | None = None,
    ) -> ClosureLagrangian: ...

#: A function pointer as varmech.pointers hands it over: (address, the object that owns it).
_Pointer = tuple[int, object]

@final
class PointerSystem(_ModelProperties):
    """L = ½q̇ᵀMq̇ − V(q) with constant M, V and ∇V function pointers (see varmech.pointers),
    called with the GIL released."""

    def __new__(
        cls, dim: int, potential: _Pointer, gradient: _Pointer, mass: _FloatArray, symmetries: Sequence[Generator]
    ) -> PointerSystem: ...

@final
class PointerLagrangian(_ModelProperties):
    """A general Lagrangian L(q, q̇, t) whose functions are function pointers (see
    varmech.pointers), called with the GIL released."""

    def __new__(
        cls,
        dim: int,
        lagrangian: _Pointer,
        dl_dq: _Pointer | None,
        dl_dv: _Pointer | None,
        hessians: _Pointer | None,
        force: _Pointer | None,
        time_dependent: bool,
        symmetries: Sequence[Generator],
    ) -> PointerLagrangian: ...

_IntArray = NDArray[np.int64]

@final
class CompiledModel(_ModelProperties):
    """A model whose functions are instruction tapes (made by :mod:`varmech.symbolic`),
    evaluated in the core with the GIL released."""

    def __new__(
        cls,
        kind: str,
        dim: int,
        functions: dict[str, tuple[_IntArray, _FloatArray, _IntArray]],
        parameters: _FloatArray,
        *,
        constraints: int = 0,
        velocity_constraints: int = 0,
        time_dependent: bool = False,
        forced: bool = False,
        symmetries: Sequence[Generator] = ...,
        jit: bool = True,
        delays: Sequence[float] = ...,
    ) -> CompiledModel: ...
    @property
    def constraints(self) -> int: ...
    @property
    def velocity_constraints(self) -> int: ...
    @property
    def parameters(self) -> _FloatArray: ...
    @property
    def jit(self) -> bool: ...
    def with_parameters(self, values: _FloatArray) -> CompiledModel: ...

#: The names of the tape's ops, by code.
TAPE_OPS: list[str]

@final
class RouthModel(_ModelProperties):
    """The Routhian R = L − μ·ċ of a full model on its non-cyclic coordinates (built by
    :func:`routh`)."""

    @property
    def full(self) -> _FullModel: ...
    @property
    def cyclic(self) -> list[int]: ...
    @property
    def momenta(self) -> list[float]: ...

_FullModel = (
    NativeModel
    | ClosureModel
    | ClosureConstrained
    | ClosureNonholonomic
    | ClosureNatural
    | ClosureLagrangian
    | CompiledModel
    | PointerSystem
    | PointerLagrangian
)
_Model = _FullModel | RouthModel

def kind_of(model: _Model) -> ModelKind: ...
def is_affine(model: _Model) -> bool:
    """Whether the model's velocity constraints are affine, A(q)q̇ + b(q) = 0 with b ≠ 0."""

def is_time_dependent(model: _Model) -> bool:
    """Whether L depends on t explicitly."""

def is_forced(model: _Model) -> bool:
    """Whether non-conservative forces act."""

def routh(full: _Model, cyclic: Sequence[int], momenta: Sequence[float], reference: Sequence[float]) -> RouthModel:
    """The reduced model ignoring ``cyclic`` at momenta μ; ValueError for constrained, forced
    or reduced models and malformed indices."""

def cyclic_increments(model: RouthModel, t: _FloatArray, x: _FloatArray, p: _FloatArray, rule: str | None) -> _FloatArray:
    """Δc between consecutive reduced states, (N − 1, m): by the discrete momentum equation of
    ``rule`` (``"midpoint"``, ``"trapezoid"``) or Hermite–Gauss quadrature (None)."""

def amended_potential(model: RouthModel, t: _FloatArray, x: _FloatArray) -> _FloatArray:
    """V_μ(x, t) = −R(x, 0, t) at each state, (N,)."""

def cyclic_velocity(model: RouthModel, t: _FloatArray, x: _FloatArray, xdot: _FloatArray) -> _FloatArray:
    """ċ with ∂L/∂ċ = μ at each state, (N, m)."""

def ensemble(
    models: list[NativeModel | CompiledModel],
    q0: _FloatArray,
    p0: _FloatArray,
    spec: RunSpec,
    *,
    workers: int | None = None,
    chunk_size: int | None = None,
    progress: Callable[[int], object] | None = None,
) -> tuple[list[tuple[TrajectoryRecord, BaseException | None]], BaseException | None]:
    """Members (rows of q0 and p0, (members, n)) integrated in parallel with the GIL released,
    with one shared model or one a member, each watching the built-in ``events``: each member's
    record (the partial one of a failure) and exception, and the exception (KeyboardInterrupt)
    that stopped the ensemble, if any. ``progress(steps)`` gets the steps of all members every
    10 ms. The spec's contacts: native ones, each member resolving its impacts; its impulses:
    their components as numbers."""

def check_allocation(argument: str, count: int, size: int) -> None:
    """ValueError naming ``argument`` for ``count`` items of ``size`` bytes each that the memory
    available to the process (free memory, its address-space limit, its cgroup's) cannot hold."""

@final
class RunSpec:
    """How a run goes (varmech._runspec.RunSpec's binding): a new run's `method`, `dt` and
    options, or a continued one's (`method` and `dt`, where given, checked against its
    checkpoint, and its energy check kept unless `keep_energy_check` is false, then
    `max_energy_error` sets it), and what it watches and applies. ``events``: spec tuples
    (name, direction, terminal count or 0, kind, payload), kind ``"p"``/``"v"`` (payload g(t, q,
    p) or g(t, q, v)), ``"crossing"`` ((k, value)), ``"ellipsoid"`` ((coordinates, centre,
    semi_axes, inside)), ``"energy_error"`` (bound), ``"escape"``, ``"encounter"`` ((radius,
    groups)); see varmech.events and varmech.surfaces. ``contacts``: tuples (name, restitution,
    law, kind, payload, friction), kind ``"crossing"`` or ``"ellipsoid"`` (the events' payloads)
    or ``"functions"`` ((phi, gradient)), law one of ``IMPACT_LAWS``; the impacts on them are
    resolved in the step loop (see varmech.impacts). ``impulses``: tuples (t, kind, payload),
    kind ``"generalized"`` (the components), ``"function"`` (P(q)) or ``"point"`` ((x(q), its
    Jacobian or None, the impulse vector)), each splitting its step. ``t_eval``: the sample
    times, whose states alone are then saved."""

    def __new__(
        cls,
        *,
        method: str | None = None,
        dt: float | None = None,
        steps: int = 0,
        save_every: int = 1,
        compensated: bool = True,
        max_energy_error: float | None = None,
        keep_energy_check: bool = True,
        t0: float = 0.0,
        newton_tolerance: float = 1e-14,
        newton_max_iterations: int = 50,
        events: list[tuple[str, int, int, str, Any]] | None = None,
        contacts: list[tuple[str, float, str, str, Any, Any]] | None = None,
        impulses: list[tuple[float, str, Any]] | None = None,
        t_eval: _FloatArray | list[float] | None = None,
    ) -> RunSpec: ...

def integrate(
    model: _Model, q0: _FloatArray, p0: _FloatArray, spec: RunSpec, *, progress: Callable[[int], object] | None = None
) -> TrajectoryRecord:
    """The saved states of the run `spec` describes; on failure the exception carries
    ``_varmech_partial``, the TrajectoryRecord up to the failure. ``progress(steps)`` is called
    with the steps completed at the Ctrl-C check's stride; an exception from it stops the run."""

def resume(
    model: _Model, checkpoint: bytes, spec: RunSpec, *, progress: Callable[[int], object] | None = None
) -> TrajectoryRecord:
    """Goes on from a run's checkpoint for the spec's `steps` more steps, watching its events,
    resolving the impacts on its contacts, applying its impulses and taking its samples
    `t_eval` after the checkpoint's time (as `integrate`'s); a checkpoint of another `method`
    or `dt` than the spec's is refused."""

def energy_terms(model: _Model, t: _FloatArray, q: _FloatArray, p: _FloatArray) -> tuple[_FloatArray, _FloatArray, _FloatArray]:
    """(E, T, V) at each state: the energy function p·q̇ − L, its kinetic term E − V and its
    potential V = −L(q, 0, t)."""

def derivative(
    model: _Model, what: str, t: _FloatArray, q: _FloatArray, x: _FloatArray, *, names: str | None = None
) -> _FloatArray:
    """At each state: ``"momentum"`` p = ∂L/∂q̇(q, x, t), ``"velocity"`` the q̇ with
    ∂L/∂q̇ = x, ``"dl_dq"`` ∂L/∂q(q, x, t), or ``"dp_dt"`` ṗ = ∂L/∂q + f(q, x, t) with x = q̇.
    With ``names`` (the user's arguments the states come from), the core's own errors name them."""

def momentum(
    generator: Generator, q: _FloatArray, p: _FloatArray, *, argument: str = "generator"
) -> tuple[_FloatArray, _FloatArray]:
    """(J, Σ|pᵢξᵢ|) at each state; ValueError naming ``argument`` for a generator that does not
    apply to the states' coordinates."""

def momentum_along(xi: _FloatArray, p: _FloatArray) -> tuple[_FloatArray, _FloatArray]:
    """(J = p·ξ, its size) at each state, from ξ(q) evaluated there."""

VERDICTS: tuple[str, str, str, str, str, str]
IMPACT_LAWS: tuple[str, ...]
FAILURE: float
TOO_COARSE: float
ROUND_OFF: float

@final
class Statistics:
    """The error of a conserved quantity against its scale, and its verdict."""

    @property
    def scale(self) -> float: ...
    @property
    def judged_scale(self) -> float: ...
    @property
    def round_off(self) -> float: ...
    @property
    def max_abs_error(self) -> float: ...
    @property
    def max_rel_error(self) -> float: ...
    @property
    def band(self) -> float: ...
    @property
    def drift_rate(self) -> float: ...
    @property
    def drift_rate_stderr(self) -> float: ...
    @property
    def oscillations(self) -> float: ...
    @property
    def first_non_finite(self) -> int | None: ...
    @property
    def verdict(self) -> str: ...

def energy_statistics(
    t: _FloatArray, energy: _FloatArray, kinetic: _FloatArray, potential: _FloatArray, work: _FloatArray, steps: int
) -> Statistics: ...
def statistics(t: _FloatArray, error: _FloatArray, size: _FloatArray, terms: _FloatArray, steps: int) -> Statistics: ...
def symplecticity_defect(model: _Model, method: str, q: _FloatArray, p: _FloatArray, dt: float) -> float: ...
def lyapunov(
    model: _Model,
    method: str,
    q0: _FloatArray,
    p0: _FloatArray,
    *,
    t0: float,
    dt: float,
    steps: int,
    k: int,
    every: int,
    start: _FloatArray | None = None,
) -> tuple[_FloatArray, NDArray[np.float64], tuple[_FloatArray, _FloatArray], int]: ...
def methods() -> list[MethodInfo]: ...
@final
class CatalogueEntry:
    """One scene of the core's catalogue, with its defaults."""

    @property
    def name(self) -> str: ...
    @property
    def parameters(self) -> dict[str, float]:
        """The defaults of the parameters, by name (whole-number ones as ints)."""
    @property
    def description(self) -> str: ...

@final
class SceneReference:
    """A scene's reference solution at time ``t``, exact or published, and where it comes from."""

    @property
    def t(self) -> float: ...
    @property
    def q(self) -> _FloatArray: ...
    @property
    def p(self) -> _FloatArray: ...
    @property
    def source(self) -> str: ...

@final
class SceneRecord:
    """A scene built from the catalogue: model, initial state, horizon and reference, and the
    catalogue's description, step, invariants and parameter values."""

    @property
    def name(self) -> str: ...
    @property
    def description(self) -> str: ...
    @property
    def model(self) -> NativeModel: ...
    @property
    def q0(self) -> _FloatArray: ...
    @property
    def p0(self) -> _FloatArray: ...
    @property
    def t_end(self) -> float: ...
    @property
    def dt(self) -> float: ...
    @property
    def invariants(self) -> dict[str, float]:
        """The conserved quantities by name, with their values at t = 0."""
    @property
    def reference(self) -> SceneReference | None: ...
    @property
    def parameters(self) -> dict[str, float]:
        """The values of the parameters the scene was built with, by name."""

def scene(name: str, **parameters: float) -> SceneRecord:
    """The catalogue scene ``name`` with ``parameters`` set by keyword; ValueError for an
    unknown scene or parameter, or a value out of range."""

def catalogue() -> list[CatalogueEntry]:
    """Every scene of the catalogue, in the order of the tour."""

def nbody(g: float, masses: Sequence[float]) -> NativeModel: ...

def linearize(
    model: _Model, q: _FloatArray, t: float = 0.0
) -> tuple[_FloatArray, _FloatArray, _FloatArray, _FloatArray, _FloatArray, _FloatArray]:
    """(M, K, G, D, T, λ) of the linearized equations at (q, q̇ = 0, t) in the tangent
    coordinates δq = T y: each matrix (r, r), T (n, r), λ the multipliers at rest."""

def normal_modes(
    model: _Model, q: _FloatArray, t: float = 0.0, symmetries: list[Generator] = ...
) -> tuple[_FloatArray, _FloatArray, _FloatArray, list[int], np.ndarray, list[int | None]]:
    """(ω, σ, κ, K's inertia, shapes (n, r), real or complex, the symmetry of each mode) of the
    modes at (q, t)."""

def equilibrium(
    model: _Model,
    guess: _FloatArray,
    t: float = 0.0,
    newton_tolerance: float = 1e-14,
    newton_max_iterations: int = 50,
) -> tuple[_FloatArray, _FloatArray, float, int]:
    """(q, λ, residual, Newton iterations) of the equilibrium nearest the guess."""

def fastest_frequency(model: _Model, q: _FloatArray, t: float = 0.0) -> tuple[float, int, bool]:
    """(ω_max, Lanczos iterations, converged) of the small oscillations at (q, t)."""

def beyond_limit(
    model: _Model, method: str, q: _FloatArray, dt: float, t: float = 0.0
) -> tuple[float, float, float] | None:
    """(h·ω_max, the method's limit, ω_max) where the step is beyond the limit at (q, t), else None."""

def stable_step(method: str, omega_max: float) -> float:
    """The largest stable step of the method on frequencies up to omega_max."""

def accurate_step(method: str, omega_max: float, accuracy: float) -> float:
    """The largest step with a phase error a period of at most accuracy on omega_max."""
