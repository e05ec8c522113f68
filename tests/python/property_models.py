"""Random models for the property tests (issue 64).

A :class:`Spec` is plain data: a family of models (coupled anharmonic pendula and oscillators,
particles on circles and spheres, a particle above a floor), the API that builds it (closures of
:class:`varmech.MechanicalSystem` or :class:`varmech.Lagrangian`, with their derivatives, with
first derivatives alone or with none; SymPy through :func:`varmech.symbolic.lagrangian`), its
random coefficients, forces, state, method and step. :func:`build` makes the model, and the
twin with every derivative exact where the model has fewer; :func:`strategies` draws specs.
tests/python/property_oracle.py runs a spec and judges the run.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Any

import numpy as np

import varmech

#: Every method of a model of coordinates (the N-body and nonholonomic ones take other models).
METHODS = {m.name: m for m in varmech.methods() if not m.nbody and not m.nonholonomic}

#: The largest hω drawn for a method without a stability limit: 4 steps a period.
UNLIMITED = 2.0

#: Saved states a run keeps (about).
SAVED = 100


@dataclass
class Spec:
    """One random case: model, state, method and step, all plain data."""

    family: str  # "chain", "sphere" or "wall"
    api: str  # "mechanical", "lagrangian" or "symbolic"
    n: int
    coefficients: dict[str, list[float]]
    derivatives: str = "exact"  # "exact", "first" (no Hessians) or "none" (differences)
    mass: str = "constant"  # "constant", "matrix" or "configuration"
    magnetic: float = 0.0
    forcing: str = "none"  # "none", "damping", "drive" or "rayleigh"
    contact: tuple[float, str, float] | None = None  # (restitution, law, μ) of the floor
    q0: list[float] = field(default_factory=list)
    v0: list[float] = field(default_factory=list)
    method: str = "verlet"
    h_fraction: float = 0.5  # of the method's limit on the fastest mode (of UNLIMITED, or 0.05 for none)
    steps: int = 200
    dt: float | None = None  # the step itself, in place of h_fraction's (a user's round numbers)


@dataclass
class Case:
    """A built spec: the model, its twin with exact derivatives, the state and the run's arguments."""

    spec: Spec
    model: varmech.Model
    twin: varmech.Model | None
    q0: np.ndarray
    p0: np.ndarray
    dt: float
    contacts: list[varmech.Contact]

    def run(self, dt: float | None = None, *, model: varmech.Model | None = None, method: str | None = None, **kwargs: Any) -> varmech.Trajectory:
        """The run at ``dt`` (default the case's) to the same end, saving the same times."""
        dt = self.dt if dt is None else dt
        ratio = max(1, round(self.dt / dt))
        steps = self.spec.steps * ratio
        every = max(1, self.spec.steps // SAVED) * ratio
        return varmech.integrate(
            model or self.model, self.q0, self.p0, dt=dt, steps=steps, method=method or self.spec.method,
            save_every=every, contacts=self.contacts or None, progress=False, **kwargs,
        )


# The potentials: a chain of anharmonic oscillators and pendula,
# V = Σᵢ ½kᵢqᵢ² + ¼βᵢqᵢ⁴ + gᵢ(1 − cos qᵢ) + Σ links U(qᵢ₊₁ − qᵢ), U(d) = ½κd² + ⅓αd³ + ¼γd⁴
# with α² ≤ 3κγ, so that U' = d(κ + αd + γd²) vanishes at d = 0 alone: V confines.


def chain_potential(c: dict[str, np.ndarray]) -> tuple[Callable, Callable, Callable]:
    """V, ∇V and ∇²V of the chain with coefficients ``c``."""
    k, beta, g, kappa, alpha, gamma = (c[x] for x in ("k", "beta", "g", "kappa", "alpha", "gamma"))

    def potential(q: np.ndarray) -> float:
        d = np.diff(q)
        return float(np.sum(0.5 * k * q**2 + 0.25 * beta * q**4 + g * (1 - np.cos(q)))
                     + np.sum(0.5 * kappa * d**2 + alpha * d**3 / 3 + 0.25 * gamma * d**4))

    def gradient(q: np.ndarray) -> np.ndarray:
        d = np.diff(q)
        out = k * q + beta * q**3 + g * np.sin(q)
        f = kappa * d + alpha * d**2 + gamma * d**3
        out[:-1] -= f
        out[1:] += f
        return out

    def hessian(q: np.ndarray) -> np.ndarray:
        d = np.diff(q)
        h = np.diag(k + 3 * beta * q**2 + g * np.cos(q))
        u = kappa + 2 * alpha * d + 3 * gamma * d**2
        for i, ui in enumerate(u):
            h[i, i] += ui
            h[i + 1, i + 1] += ui
            h[i, i + 1] -= ui
            h[i + 1, i] -= ui
        return h

    return potential, gradient, hessian


def mass_functions(spec: Spec, c: dict[str, np.ndarray]) -> tuple[Callable, Callable, Callable]:
    """M(q), ∂M/∂q (n, n, n: [k] = ∂M/∂qₖ) and ½vᵀ(∂²M/∂qₖ∂qₗ)v (n, n) of the spec's mass."""
    n, m = spec.n, c["m"]
    if spec.mass == "configuration":
        eps = c["eps"]

        def mass(q: np.ndarray) -> np.ndarray:
            return np.diag(m * (1 + eps * np.sin(q) ** 2))

        def derivative(q: np.ndarray) -> np.ndarray:
            out = np.zeros((n, n, n))
            for i in range(n):
                out[i, i, i] = m[i] * eps[i] * math.sin(2 * q[i])
            return out

        def curvature(q: np.ndarray, v: np.ndarray) -> np.ndarray:
            return np.diag(m * eps * np.cos(2 * q) * v**2)

        return mass, derivative, curvature
    matrix = np.diag(m) + (np.outer(c["u"], c["u"]) if spec.mass == "matrix" else 0.0)
    return (lambda q: matrix), (lambda q: np.zeros((n, n, n))), (lambda q, v: np.zeros((n, n)))


def _arrays(spec: Spec) -> dict[str, np.ndarray]:
    return {k: np.asarray(v, dtype=float) for k, v in spec.coefficients.items()}


def _force(spec: Spec, c: dict[str, np.ndarray]) -> Callable | None:
    if spec.forcing == "damping":
        return lambda q, v, t: -c["damping"] * v
    if spec.forcing == "drive":
        amplitude, frequency = c["drive"]
        return lambda q, v, t: np.where(np.arange(spec.n) == 0, amplitude * math.cos(frequency * t), 0.0)
    return None


def _chain_closures(spec: Spec) -> tuple[varmech.Model, varmech.Model | None]:
    """The chain from closures, and its twin with every derivative where it has fewer."""
    c = _arrays(spec)
    potential, gradient, hessian = chain_potential(c)
    mass, dmass, curvature = mass_functions(spec, c)
    n, b = spec.n, spec.magnetic

    if spec.api == "mechanical":

        def make(exact: bool) -> varmech.Model:
            kwargs: dict[str, Any] = {}
            if spec.mass == "configuration":
                kwargs = {"mass": mass, "mass_derivative": dmass if exact else None}
            elif spec.mass == "matrix":
                kwargs = {"mass": mass(None)}
            else:
                kwargs = {"mass": c["m"]}
            return varmech.MechanicalSystem(n, potential, gradient if exact else None, name="random chain", **kwargs)

        return make(spec.derivatives == "exact"), (make(True) if spec.derivatives != "exact" else None)

    # L = ½q̇ᵀM(q)q̇ + ½bΣ(qᵢq̇ᵢ₊₁ − qᵢ₊₁q̇ᵢ) − V(q).
    def lagrangian(q: np.ndarray, v: np.ndarray, t: float) -> float:
        return float(0.5 * v @ mass(q) @ v + 0.5 * b * np.sum(q[:-1] * v[1:] - q[1:] * v[:-1]) - potential(q))

    def dl_dq(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        out = 0.5 * np.einsum("i,kij,j->k", v, dmass(q), v) - gradient(q)
        out[:-1] += 0.5 * b * v[1:]
        out[1:] -= 0.5 * b * v[:-1]
        return out

    def dl_dv(q: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        out = mass(q) @ v
        out[1:] += 0.5 * b * q[:-1]
        out[:-1] -= 0.5 * b * q[1:]
        return out

    def hessians(q: np.ndarray, v: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        qv = np.einsum("kij,j->ki", dmass(q), v)  # ∂²L/∂qₖ∂q̇ᵢ
        for i in range(n - 1):
            qv[i, i + 1] += 0.5 * b
            qv[i + 1, i] -= 0.5 * b
        return curvature(q, v) - hessian(q), qv, mass(q)

    force = _force(spec, c)
    rayleigh = c["damping"] if spec.forcing == "rayleigh" else None

    def make_lagrangian(level: str) -> varmech.Model:
        derivatives = {"exact": (dl_dq, dl_dv, hessians), "first": (dl_dq, dl_dv, None), "none": (None, None, None)}[level]
        return varmech.Lagrangian(
            n, lagrangian, dl_dq=derivatives[0], dl_dv=derivatives[1], hessians=derivatives[2], force=force,
            rayleigh=rayleigh, name="random chain",
        )

    twin = make_lagrangian("exact") if spec.derivatives != "exact" else None
    return make_lagrangian(spec.derivatives), twin


@lru_cache(maxsize=64)
def _symbolic_chain(n: int, mass: str, magnetic: bool, forcing: str) -> Any:
    """The chain's L in SymPy, its coefficients parameters: derived and compiled once a structure."""
    import sympy as sp

    q, v = sp.symbols(f"q0:{n}"), sp.symbols(f"v0:{n}")
    t = sp.Symbol("t")
    names = {x: sp.symbols(f"{x}0:{n}") for x in ("m", "k", "beta", "g", "eps", "u", "damping")}
    links = {x: sp.symbols(f"{x}0:{max(n - 1, 1)}") for x in ("kappa", "alpha", "gamma")}
    b, amplitude, frequency = sp.symbols("b amplitude frequency")
    m = names["m"]
    if mass == "configuration":
        kinetic = sum(m[i] * (1 + names["eps"][i] * sp.sin(q[i]) ** 2) * v[i] ** 2 for i in range(n)) / 2
    elif mass == "matrix":
        u = names["u"]
        kinetic = (sum(m[i] * v[i] ** 2 for i in range(n)) + sum(u[i] * v[i] for i in range(n)) ** 2) / 2
    else:
        kinetic = sum(m[i] * v[i] ** 2 for i in range(n)) / 2
    potential = sum(names["k"][i] * q[i] ** 2 / 2 + names["beta"][i] * q[i] ** 4 / 4 + names["g"][i] * (1 - sp.cos(q[i])) for i in range(n))
    for i in range(n - 1):
        d = q[i + 1] - q[i]
        potential += links["kappa"][i] * d**2 / 2 + links["alpha"][i] * d**3 / 3 + links["gamma"][i] * d**4 / 4
    L = kinetic - potential
    if magnetic:
        L += b * sum(q[i] * v[i + 1] - q[i + 1] * v[i] for i in range(n - 1)) / 2
    kwargs: dict[str, Any] = {}
    if forcing == "damping":
        kwargs["force"] = [-names["damping"][i] * v[i] for i in range(n)]
    elif forcing == "drive":
        kwargs["force"] = [amplitude * sp.cos(frequency * t)] + [0] * (n - 1)
        kwargs["t"] = t
    elif forcing == "rayleigh":
        kwargs["rayleigh"] = sum(names["damping"][i] * v[i] ** 2 for i in range(n)) / 2
    used = L.free_symbols | set().union(*(sp.sympify(f).free_symbols for f in kwargs.get("force", [])))
    used |= sp.sympify(kwargs.get("rayleigh", 0)).free_symbols
    parameters = {s: 1.0 for s in used if s not in q and s not in v and s != t}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return varmech.symbolic.lagrangian(L, list(q), list(v), parameters=parameters, name="random chain (symbolic)", **kwargs)


def _symbolic(spec: Spec) -> varmech.Model:
    model = _symbolic_chain(spec.n, spec.mass, spec.magnetic != 0.0, spec.forcing)
    values: dict[str, float] = {"b": spec.magnetic}
    for name, xs in spec.coefficients.items():
        if name == "drive":
            values["amplitude"], values["frequency"] = xs
        else:
            values.update({f"{name}{i}": x for i, x in enumerate(xs)})
    known = {p.name if hasattr(p, "name") else str(p) for p in model.parameters}
    return model.with_parameters(**{k: v for k, v in values.items() if k in known})


def _sphere(spec: Spec) -> tuple[varmech.Model, varmech.Model | None]:
    """Particles on circles or spheres: k = len(r) particles in d = n/k dimensions, particle i on
    |xᵢ − xᵢ₋₁| = rᵢ (x₋₁ = 0: "linked") or |xᵢ| = rᵢ ("anchored"), under gravity g along the
    last axis, a trap ½k|x|² and springs ½κ|xᵢ − xⱼ|² between them."""
    c = _arrays(spec)
    r, masses = c["r"], c["m"]
    count = len(r)
    d = spec.n // count
    linked = bool(c["linked"][0])
    gravity, trap, spring = float(c["g"][0]), float(c["k"][0]), float(c["kappa"][0])
    weights = np.repeat(masses, d)
    down = np.zeros(spec.n)
    down[d - 1 :: d] = 1.0

    def positions(q: np.ndarray) -> np.ndarray:
        return q.reshape(count, d)

    def potential(q: np.ndarray) -> float:
        x = positions(q)
        pairs = sum(float(np.sum((x[i] - x[j]) ** 2)) for i in range(count) for j in range(i))
        return float(gravity * np.sum(weights * down * q) + 0.5 * trap * q @ q + 0.5 * spring * pairs)

    def gradient(q: np.ndarray) -> np.ndarray:
        x = positions(q)
        out = gravity * weights * down + trap * q
        pull = np.array([sum(x[i] - x[j] for j in range(count)) for i in range(count)])
        return out + spring * pull.reshape(-1)

    def arms(q: np.ndarray) -> np.ndarray:
        x = positions(q)
        return np.array([x[i] - (x[i - 1] if linked and i > 0 else 0.0) for i in range(count)])

    def constraints(q: np.ndarray) -> np.ndarray:
        return 0.5 * (np.sum(arms(q) ** 2, axis=1) - r**2)

    def jacobian(q: np.ndarray) -> np.ndarray:
        a = arms(q)
        out = np.zeros((count, spec.n))
        for i in range(count):
            out[i, i * d : (i + 1) * d] = a[i]
            if linked and i > 0:
                out[i, (i - 1) * d : i * d] = -a[i]
        return out

    def make(exact: bool) -> varmech.Model:
        mass: Any = (lambda q: np.diag(weights)) if spec.mass == "configuration" else weights
        extra = {"mass_derivative": (lambda q: np.zeros((spec.n,) * 3))} if spec.mass == "configuration" and exact else {}
        return varmech.MechanicalSystem(
            spec.n, potential, gradient if exact else None, mass=mass, constraints=constraints,
            constraint_jacobian=jacobian if exact else None, constraint_count=count, name="particles on spheres", **extra,
        )

    exact = spec.derivatives == "exact"
    return make(exact), (None if exact else make(True))


def _wall(spec: Spec) -> tuple[varmech.Model, varmech.Model | None, list[varmech.Contact]]:
    """A particle in n = 1 … 3 dimensions in a trap ½Σkᵢxᵢ² under gravity g along its last axis,
    above the floor x_last ≥ −a, with restitution e, a law, and friction μ where n ≥ 2."""
    c = _arrays(spec)
    k, m, gravity, floor = c["k"], c["m"], float(c["g"][0]), float(c["floor"][0])
    down = np.zeros(spec.n)
    down[-1] = 1.0

    def make(exact: bool) -> varmech.Model:
        return varmech.MechanicalSystem(
            spec.n, lambda q: float(0.5 * np.sum(k * q**2) + gravity * m[-1] * q[-1]),
            (lambda q: k * q + gravity * m[-1] * down) if exact else None, mass=m, name="particle above a floor",
        )

    assert spec.contact is not None
    restitution, law, mu = spec.contact
    friction = varmech.Friction(mu, 0.8 * mu) if mu > 0 else None
    wall = varmech.Contact.wall(spec.n - 1, -floor, restitution=restitution, law=law, friction=friction, name="floor")
    exact = spec.derivatives == "exact"
    return make(exact), (None if exact else make(True)), [wall]


def build(spec: Spec) -> Case:
    """The spec's model, twin, state and step. The step: ``h_fraction`` of the method's
    stability limit over the fastest frequency at q₀ and at the displaced states q₀ ± v₀/ω
    (the frequencies grow with the amplitude on the anharmonic chains)."""
    contacts: list[varmech.Contact] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if spec.family == "chain" and spec.api == "symbolic":
            model, twin = _symbolic(spec), None
        elif spec.family == "chain":
            model, twin = _chain_closures(spec)
        elif spec.family == "sphere":
            model, twin = _sphere(spec)
        else:
            model, twin, contacts = _wall(spec)
        q0, v0 = np.asarray(spec.q0, dtype=float), np.asarray(spec.v0, dtype=float)
        if spec.family == "sphere":
            q0, p0 = varmech.project(model, q0, v0=v0)
        else:
            p0 = model.momentum(q0, v0)
        if spec.dt is not None:
            return Case(spec, model, twin, np.asarray(q0), np.asarray(p0), spec.dt, contacts)
        sphere = _pendulum(spec, model, q0, p0) if spec.family == "sphere" else None
        omega = _fastest(model, q0, v0, sphere)
    info = METHODS[spec.method]
    limit = info.h_omega_max
    if not limit > 0:  # explicit Euler: unstable at every step
        h_omega = 0.05 * spec.h_fraction
    elif math.isinf(limit):
        h_omega = UNLIMITED * spec.h_fraction
    else:
        h_omega = limit * spec.h_fraction
    return Case(spec, model, twin, np.asarray(q0), np.asarray(p0), h_omega / omega, contacts)


def _pendulum(spec: Spec, model: varmech.Model, q0: np.ndarray, p0: np.ndarray) -> tuple[float, float]:
    """The smallest radius r of the spheres, and the fastest rate a swing reaches there, which
    the modes at q₀ miss (the equator of a sphere under gravity has none): the pendulum
    frequency √(a/r) of the largest acceleration a the forces give (gravity, the trap and the
    springs at the outermost reach), and the angular speed v/r of the largest speed v that
    the energy allows, all of T₀ + V(q₀) − min V spent on the lightest particle."""
    c = spec.coefficients
    r, reach = min(c["r"]), sum(c["r"])
    a = c["g"][0] + (c["k"][0] + len(c["r"]) * c["kappa"][0]) * reach
    kinetic = 0.5 * float(p0 @ model.velocity(q0, p0))
    # V ≥ −gΣmᵢ·(reach of particle i): the trap and the springs are ≥ 0.
    lowest = -c["g"][0] * sum(m * sum(c["r"][: i + 1] if c["linked"][0] else [c["r"][i]]) for i, m in enumerate(c["m"]))
    speed = math.sqrt(2 * max(kinetic + model.potential(q0) - lowest, 0.0) / min(c["m"]))
    return r, max(math.sqrt(a / r), speed / r)


def _fastest(model: varmech.Model, q0: np.ndarray, v0: np.ndarray, sphere: tuple[float, float] | None = None) -> float:
    """The fastest frequency at q₀ and at the displaced states; on circles and spheres (the
    smallest radius and its pendulum frequency, :func:`_pendulum`), at least that frequency
    and the angular speed |v₀|/r, the rate the constraint forces turn the velocity at."""
    omega = varmech.fastest_frequency(model, q0)
    if sphere is not None:
        turning, swing = sphere
        return max(omega, swing, float(np.max(np.abs(v0))) * math.sqrt(len(v0)) / turning, 1e-2)
    reach = v0 / max(omega, 1.0)
    for q in (q0 + reach, q0 - reach, 1.5 * q0):
        try:
            omega = max(omega, varmech.fastest_frequency(model, q))
        except ValueError:
            pass
    return max(omega, 1e-2)


# The strategies: random specs of each family, and a method that fits the model (or, one time in
# ten, any method: a misfit must be a ValueError naming it).


def _apart(x: np.ndarray, linked: bool) -> bool:
    """Whether each particle lies 0.1 or more from its sphere's centre (the origin, or the last
    particle where linked): the constraints' gradients then independent."""
    arms = np.diff(x, axis=0, prepend=np.zeros((1, x.shape[1]))) if linked else x
    return bool(np.all(np.linalg.norm(arms, axis=1) > 0.1))


def _strategies() -> Any:
    from hypothesis import strategies as st

    def uniform(lo: float, hi: float) -> Any:
        return st.floats(lo, hi, allow_nan=False, allow_infinity=False)

    def vector(n: int, lo: float, hi: float) -> Any:
        return st.lists(uniform(lo, hi), min_size=n, max_size=n)

    def sometimes_zero(n: int, lo: float, hi: float) -> Any:
        return st.one_of(st.just([0.0] * n), vector(n, lo, hi))

    @st.composite
    def method(draw: Any, spec: Spec) -> Spec:
        kind = build(replace(spec, method="midpoint")).model.kind
        fitting = sorted(m for m in METHODS if kind.admits(m))
        names = sorted(METHODS) if not fitting or draw(st.integers(0, 9)) == 0 else fitting
        name = draw(st.sampled_from(names))
        # An implicit step of Python closures costs Newton's iterations of n-dimensional
        # differences: fewer steps keep a case (with its refinements) within seconds.
        slow = spec.api != "symbolic" and METHODS[name].implicit
        steps = draw(st.integers(40, 120) if slow else st.integers(60, 300))
        return replace(spec, method=name, h_fraction=draw(uniform(0.02, 0.9)), steps=steps)

    @st.composite
    def chain(draw: Any, apis: tuple[str, ...] = ("mechanical", "lagrangian", "symbolic")) -> Spec:
        api = draw(st.sampled_from(apis))
        derivatives = draw(st.sampled_from({"mechanical": ["exact", "none"], "lagrangian": ["exact", "first", "none"]}.get(api, ["exact"])))
        # L alone: each derivative 2n calls of L, each Jacobian 2n of those: up to 4 coordinates.
        n = draw(st.integers(1, 4 if api == "lagrangian" and derivatives == "none" else 6))
        links = max(n - 1, 1)
        kappa, gamma = draw(sometimes_zero(links, 0.0, 5.0)), draw(sometimes_zero(links, 0.0, 1.0))
        # α² ≤ 3κγ: each link's U' = d(κ + αd + γd²) has no root but 0.
        alpha = [s * math.sqrt(3 * k * g) for s, k, g in zip(draw(vector(links, -1.0, 1.0)), kappa, gamma)]
        coefficients = {
            "m": draw(vector(n, 0.5, 3.0)), "k": draw(vector(n, 0.1, 5.0)), "beta": draw(sometimes_zero(n, 0.0, 1.0)),
            "g": draw(sometimes_zero(n, 0.0, 5.0)), "kappa": kappa, "alpha": alpha, "gamma": gamma,
            "eps": draw(vector(n, 0.0, 0.9)), "u": draw(vector(n, -0.7, 0.7)), "damping": draw(vector(n, 0.0, 0.5)),
            "drive": [draw(uniform(0.0, 2.0)), draw(uniform(0.3, 3.0))],
        }
        general = api != "mechanical"
        amplitude, speed = draw(uniform(0.05, 1.5)), draw(uniform(0.0, 2.0))
        spec = Spec(
            "chain", api, n, coefficients,
            derivatives=derivatives,
            mass=draw(st.sampled_from(["constant", "matrix", "configuration"])),
            magnetic=draw(st.one_of(st.just(0.0), uniform(-2.0, 2.0))) if general and n > 1 else 0.0,
            forcing=draw(st.sampled_from(["none", "damping", "drive", "rayleigh"])) if general else "none",
            q0=draw(vector(n, -amplitude, amplitude)), v0=draw(vector(n, -speed, speed)),
        )
        return draw(method(spec))

    @st.composite
    def sphere(draw: Any) -> Spec:
        count, d = draw(st.sampled_from([(1, 2), (1, 3), (2, 2), (2, 3)]))
        n = count * d
        coefficients = {
            "r": draw(vector(count, 0.5, 2.0)), "m": draw(vector(count, 0.5, 2.0)), "linked": [float(draw(st.booleans()))],
            "g": [draw(uniform(0.0, 10.0))], "k": [draw(uniform(0.0, 3.0))], "kappa": [draw(uniform(0.0, 3.0))],
        }
        speed = draw(uniform(0.0, 2.0))
        spec = Spec(
            "sphere", "mechanical", n, coefficients, derivatives=draw(st.sampled_from(["exact", "none"])),
            mass=draw(st.sampled_from(["constant", "configuration"])),
            q0=draw(vector(n, -1.0, 1.0).filter(lambda x: _apart(np.reshape(x, (count, d)), bool(coefficients["linked"][0])))),
            v0=draw(vector(n, -speed, speed)),
        )
        return draw(method(spec))

    @st.composite
    def wall(draw: Any) -> Spec:
        if draw(st.integers(0, 3)) == 0:
            return draw(round_ball())
        n = draw(st.integers(1, 3))
        floor = draw(uniform(0.2, 1.5))
        mass = draw(uniform(0.5, 2.0))
        coefficients = {"k": draw(vector(n, 0.2, 5.0)), "m": [mass] * n, "g": [draw(uniform(0.5, 10.0))], "floor": [floor]}
        restitution = draw(st.one_of(st.just(1.0), uniform(0.0, 0.99)))
        law = draw(st.sampled_from(["variational", "reflect"]))
        mu = draw(st.one_of(st.just(0.0), uniform(0.1, 1.0))) if n > 1 else 0.0
        q0 = draw(vector(n - 1, -1.0, 1.0)) + [draw(uniform(-floor + 0.05, 1.5))]
        spec = Spec(
            "wall", "mechanical", n, coefficients, derivatives=draw(st.sampled_from(["exact", "none"])),
            contact=(restitution, law, mu), q0=q0, v0=draw(vector(n, -2.0, 2.0)),
        )
        return draw(method(spec))

    @st.composite
    def round_ball(draw: Any) -> Spec:
        # A ball under gravity alone in a user's round numbers: every landing time a dyadic
        # rational, so that flights end exactly at steps' ends, and on the floor to the bit.
        def pick(*values: Any) -> Any:
            return draw(st.sampled_from(values))

        floor, g = pick(0.0, 0.5, 1.0), pick(1.0, 2.0, 4.0)
        coefficients = {"k": [0.0], "m": [1.0], "g": [g], "floor": [floor]}
        spec = Spec(
            "wall", "mechanical", 1, coefficients, derivatives=pick("exact", "none"),
            contact=(pick(0.0, 0.25, 0.5, 0.75, 1.0), pick("variational", "reflect"), 0.0),
            q0=[pick(0.5, 1.0, 2.0) - floor], v0=[pick(0.0, 1.0, -1.0)],
        )
        dt = pick(0.25, 0.125, 0.0625, 0.03125)
        return replace(draw(method(spec)), dt=dt, steps=round(pick(4.0, 8.0) / dt))

    return chain, sphere, wall


def strategies() -> dict[str, Any]:
    """The families' strategies by name: ``chain`` (closures and SymPy), ``sphere``, ``wall``."""
    chain, sphere, wall = _strategies()
    return {"chain": chain(), "closures": chain(("mechanical", "lagrangian")), "symbolic": chain(("symbolic",)), "sphere": sphere(), "wall": wall()}
