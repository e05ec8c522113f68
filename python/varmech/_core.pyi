"""Stubs of the compiled extension ``varmech._core`` (hand-written; see rust/python/src)."""

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
GeneratorSpec = tuple[str, int, int]

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

class SpuriousBranchError(ConvergenceError):
    """A step was solved beyond a fold of the DEL map, on a branch that need not continue the
    trajectory; ``residual`` and ``iterations`` are not set."""

class _ModelProperties:
    """What every model class reports (a stub-only base: the classes do not share one)."""

    @property
    def dim(self) -> int: ...
    @property
    def separable(self) -> bool: ...
    @property
    def time_dependent(self) -> bool: ...
    @property
    def forced(self) -> bool: ...

class NativeModel(_ModelProperties):
    """A native scene: evaluated in Rust with the GIL released."""

    @property
    def name(self) -> str: ...
    @property
    def symmetries(self) -> list[tuple[str, int, int, str]]: ...
    @property
    def constraints(self) -> int: ...
    @property
    def default_method(self) -> str | None: ...
    @property
    def gravity(self) -> tuple[float, list[float]] | None:
        """(G, masses) of an N-body scene, None for the others."""

def constraint_residuals(model: Model, q: FloatArray, p: FloatArray) -> tuple[FloatArray, FloatArray]: ...
def project(model: Model, q0: FloatArray, p0: FloatArray) -> tuple[FloatArray, FloatArray]: ...

class ClosureModel(_ModelProperties):
    """L = ½q̇ᵀMq̇ − V(q) from Python closures."""

    def __init__(
        self,
        dim: int,
        potential: Callable[[FloatArray], float],
        gradient: Callable[[FloatArray], Any] | None,
        mass: FloatArray,
        symmetries: Sequence[GeneratorSpec],
    ) -> None: ...
    @property
    def has_gradient(self) -> bool: ...

class ClosureConstrained(_ModelProperties):
    """A ClosureModel on holonomic constraints g(q) = 0 from Python closures."""

    def __init__(
        self,
        system: ClosureModel | ClosureNatural,
        count: int,
        constraints: Callable[[FloatArray], Any],
        jacobian: Callable[[FloatArray], Any] | None,
    ) -> None: ...
    @property
    def constraints(self) -> int: ...
    @property
    def default_method(self) -> str: ...

class ClosureNatural(_ModelProperties):
    """L = ½q̇ᵀM(q)q̇ − V(q) from Python closures (configuration-dependent mass)."""

    def __init__(
        self,
        dim: int,
        mass: Callable[[FloatArray], Any],
        potential: Callable[[FloatArray], float],
        gradient: Callable[[FloatArray], Any] | None,
        mass_derivative: Callable[[FloatArray], Any] | None,
        symmetries: Sequence[GeneratorSpec],
    ) -> None: ...

class ClosureLagrangian(_ModelProperties):
    """A general Lagrangian L(q, q̇, t) from Python closures."""

    def __init__(
        self,
        dim: int,
        lagrangian: Callable[[FloatArray, FloatArray, float], float],
        dl_dq: Callable[[FloatArray, FloatArray, float], Any] | None,
        dl_dv: Callable[[FloatArray, FloatArray, float], Any] | None,
        hessians: Callable[[FloatArray, FloatArray, float], Any] | None,
        force: Callable[[FloatArray, FloatArray, float], Any] | None,
        time_dependent: bool,
        symmetries: Sequence[GeneratorSpec],
    ) -> None: ...

class RouthModel(_ModelProperties):
    """The Routhian R = L − μ·ċ of a full model on its non-cyclic coordinates (built by
    :func:`routh`)."""

    @property
    def full(self) -> FullModel: ...
    @property
    def cyclic(self) -> list[int]: ...
    @property
    def momenta(self) -> list[float]: ...

FullModel = NativeModel | ClosureModel | ClosureConstrained | ClosureNatural | ClosureLagrangian
Model = FullModel | RouthModel

def routh(full: Model, cyclic: Sequence[int], momenta: Sequence[float], reference: Sequence[float]) -> RouthModel:
    """The reduced model ignoring ``cyclic`` at momenta μ; ValueError for constrained, forced
    or reduced models and malformed indices."""

def cyclic_increments(model: RouthModel, t: FloatArray, x: FloatArray, p: FloatArray, rule: str | None) -> FloatArray:
    """Δc between consecutive reduced states, (N − 1, m): by the discrete momentum equation of
    ``rule`` (``"midpoint"``, ``"trapezoid"``) or Hermite–Gauss quadrature (None)."""

def amended_potential(model: RouthModel, t: FloatArray, x: FloatArray) -> FloatArray:
    """V_μ(x, t) = −R(x, 0, t) at each state, (N,)."""

def cyclic_velocity(model: RouthModel, t: FloatArray, x: FloatArray, xdot: FloatArray) -> FloatArray:
    """ċ with ∂L/∂ċ = μ at each state, (N, m)."""

def integrate(
    model: Model,
    q0: FloatArray,
    p0: FloatArray,
    *,
    dt: float,
    steps: int,
    method: str,
    save_every: int = 1,
    compensated: bool = True,
    max_energy_error: float | None = None,
    t0: float = 0.0,
    newton_tolerance: float = 1e-14,
    newton_max_iterations: int = 50,
) -> tuple[FloatArray, FloatArray, FloatArray, int, int, NDArray[np.uint64], FloatArray]:
    """(t, q, p, steps, force_evaluations, newton, work): the cumulative Newton iterations and
    work of the forces at each saved state; on failure the exception carries
    ``_varmech_partial``."""

def energy(model: Model, t: FloatArray, q: FloatArray, p: FloatArray) -> FloatArray:
    """The energy function p·q̇ − L at each state."""

def derivative(model: Model, what: str, t: FloatArray, q: FloatArray, x: FloatArray) -> FloatArray:
    """At each state: ``"momentum"`` p = ∂L/∂q̇(q, x, t), ``"velocity"`` the q̇ with
    ∂L/∂q̇ = x, or ``"dl_dq"`` ∂L/∂q(q, x, t)."""

def momentum(generator: GeneratorSpec, q: FloatArray, p: FloatArray) -> FloatArray: ...
def energy_statistics(t: FloatArray, h: FloatArray) -> dict[str, Any]: ...
def invariant_statistics(values: FloatArray) -> tuple[float, float, float]: ...
def symplecticity_defect(model: Model, method: str, q: FloatArray, p: FloatArray, dt: float) -> float: ...
def methods() -> list[dict[str, Any]]: ...
def scene(
    name: str,
    *,
    e: float = 0.6,
    omega: float = 1.0,
    b: float = 1.0,
    gamma: float = 0.5,
    amplitude: float = 1.5,
    drive: float = 2.0 / 3.0,
) -> tuple[NativeModel, FloatArray, FloatArray, float, tuple[float, FloatArray, FloatArray, str] | None]: ...
def nbody(g: float, masses: Sequence[float]) -> NativeModel: ...
