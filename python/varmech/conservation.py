"""What a run conserves: energy, Noether momenta, and a verdict."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from . import _core
from .integrate import Trajectory
from .model import Cyclic, Generator, Rotation, Translation


def momentum(traj: Trajectory, generator: Generator) -> np.ndarray:
    """The Noether momentum J = p·ξ(q) at every saved state of ``traj``, shape (N,).

    ``generator`` is a :class:`~varmech.Translation`, :class:`~varmech.Rotation` or
    :class:`~varmech.Cyclic`, or a closure ``xi(q) -> array (n,)``.
    """
    if isinstance(generator, (Translation, Rotation, Cyclic)):
        return _core.momentum(generator.spec(), traj.q, traj.p)
    if not callable(generator):
        raise TypeError(f"generator: expected a Translation, Rotation, Cyclic or a callable xi(q), got {generator!r}")
    n = traj.q.shape[1]
    out = np.empty(len(traj.t))
    for k, (q, p) in enumerate(zip(traj.q, traj.p)):
        xi = np.asarray(generator(q.copy()), dtype=float)
        if xi.shape != (n,):
            raise ValueError(f"generator: xi(q) must return shape ({n},), got {xi.shape}")
        out[k] = p @ xi
    return out


@dataclass(frozen=True)
class EnergyReport:
    """The energy error e(t) = (H(t) − H₀)/|H₀| of a run (absolute when H₀ = 0).

    ``verdict`` is "secular drift" when the largest |e| over the last tenth of the run exceeds
    twice that over the first tenth, the fitted drift rate differs from zero by more than three
    standard errors, and the error is above round-off (``noise_floor``); otherwise "bounded".
    """

    initial: float
    max_error: float
    band: float
    max_error_first_tenth: float
    max_error_last_tenth: float
    drift_rate: float
    drift_rate_stderr: float
    verdict: str
    noise_floor: float


@dataclass(frozen=True)
class MomentumReport:
    """max |J − J₀| of a Noether momentum, absolute and relative to |J₀|."""

    name: str
    initial: float
    max_abs_error: float
    max_rel_error: float


NOT_CONSERVED = "not conserved (L depends on t)"
FORCED = "not conserved (forced); see the energy balance"


@dataclass(frozen=True)
class ConservationReport:
    """What a run conserved: its energy statistics and the errors of its Noether momenta."""

    model: str
    method: str
    dt: float
    t_end: float
    #: None when L depends on t or forces act: the energy is then not conserved, so not judged.
    energy: EnergyReport | None
    momenta: tuple[MomentumReport, ...]
    #: For forced systems, max |E(t) − E(0) − W(t)| / |E(0)| (absolute when E(0) = 0): the
    #: discrete Lagrange–d'Alembert energy balance with the tracked work W.
    energy_balance: float | None = None
    #: For constrained models, max |g(q)|∞ and max |G(q)M⁻¹p|∞ over the run.
    constraint_residuals: tuple[float, float] | None = None

    @property
    def verdict(self) -> str:
        """The energy verdict: "bounded", "secular drift", or why the energy is not conserved."""
        if self.energy is not None:
            return self.energy.verdict
        return FORCED if self.energy_balance is not None else NOT_CONSERVED

    def __str__(self) -> str:
        e = self.energy
        lines = [f"Conservation report: {self.model}, {self.method}, dt = {self.dt:g}, t = 0 … {self.t_end:g}"]
        if e is None:
            lines.append(f"  energy   {self.verdict}")
            if self.energy_balance is not None:
                lines.append(f"           max |E − E0 − W|/|E0| = {self.energy_balance:.3e}")
        else:
            lines += [
                f"  energy   H0 = {e.initial:.12g}",
                f"           max |ΔH/H0| = {e.max_error:.3e}   band = {e.band:.3e}",
                f"           first tenth {e.max_error_first_tenth:.3e}   last tenth {e.max_error_last_tenth:.3e}",
                f"           drift rate {e.drift_rate:+.3e} ± {e.drift_rate_stderr:.1e} per unit time",
                f"           verdict: {e.verdict}",
            ]
        for m in self.momenta:
            lines.append(f"  momentum {m.name:<6} J0 = {m.initial:+.12g}   max |ΔJ| = {m.max_abs_error:.3e} (rel {m.max_rel_error:.3e})")
        if self.constraint_residuals is not None:
            g, v = self.constraint_residuals
            lines.append(f"  constraints  max |g(q)| = {g:.3e}   max |G M⁻¹ p| = {v:.3e}")
        return "\n".join(lines)


def check_conservation(traj: Trajectory, generators: Sequence[Generator] | None = None) -> ConservationReport:
    """Check the energy and the Noether momenta of ``traj``.

    The energy function p·q̇ − L is judged only when L does not depend on t and no forces act;
    for forced systems the report gives the energy balance E(t) − E(0) − W(t) with the work W
    of the forces instead.

    ``generators`` defaults to the symmetries the model declares; a closure generator is named
    ``xi[k]``.
    """
    if generators is None:
        generators = traj.model.symmetries
    model = traj.model
    conserved = not (model.time_dependent or model.forced)
    energy = EnergyReport(**_core.energy_statistics(traj.t, traj.energy())) if conserved else None
    balance = None
    if model.forced and not model.time_dependent:
        e = traj.energy()
        balance = float(np.max(np.abs(e - e[0] - traj.work)) / (abs(e[0]) or 1.0))
    momenta = []
    for k, xi in enumerate(generators):
        name = xi.name if isinstance(xi, (Translation, Rotation, Cyclic)) else f"xi[{k}]"
        momenta.append(MomentumReport(name, *_core.invariant_statistics(momentum(traj, xi))))
    residuals = None
    if model.constraints:
        g, v = traj.constraint_residuals()
        residuals = (float(np.max(g)), float(np.max(v)))
    return ConservationReport(model.name, traj.method, traj.dt, float(traj.t[-1]), energy, tuple(momenta), balance, residuals)
