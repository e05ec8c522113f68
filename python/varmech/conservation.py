"""What a run conserves: energy, Noether momenta, constraints, and a verdict on each.

Every quantity is judged against its own scale (see :class:`InvariantStatistics`): the energy
against the mean kinetic energy of the run, a Noether momentum J = p·ξ(q) against its mean size
max(Σ|pᵢξᵢ|, ‖p‖∞‖ξ‖∞), the constraint residuals |g(q)| and |G(q)q̇| against ‖G‖‖q‖ and ‖G‖‖q̇‖
(|A(q)q̇| against ‖A‖‖q̇‖ for velocity constraints). The scale is measured on the run's own
states, which an error shifts: the level of the error is judged against the scale less its mean
error (see :class:`InvariantStatistics`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from . import _core
from . import impacts as _impacts
from ._util import returned
from .derivatives import blame
from .integrate import integrate
from .model import Cyclic, Generator, Model, Rotation, Translation
from .trajectory import Trajectory

__all__ = [
    "FAILURE",
    "NOT_JUDGED",
    "ROUND_OFF",
    "TOO_COARSE",
    "VERDICTS",
    "ConservationReport",
    "InvariantStatistics",
    "check_conservation",
    "momentum",
]

#: The verdicts, best first: "conserved to round-off", "bounded", "too short to judge",
#: "secular drift", "too coarse", "failed".
VERDICTS: tuple[str, ...] = tuple(_core.VERDICTS)
#: An error this large against the scale (less the mean error) is a failure; also
#: ``integrate``'s default ``max_energy_error`` (against the running scale: beyond it, an error
#: stops a run beyond the method's stability limit, and one within it where it grows).
FAILURE: float = _core.FAILURE
#: An error this large against the scale (less the mean error) is of the order of the scale:
#: "too coarse", whatever its trend.
TOO_COARSE: float = _core.TOO_COARSE
#: Round-off is an error within ROUND_OFF · ε · (size of the terms) · √(1 + steps).
ROUND_OFF: float = _core.ROUND_OFF


def momentum(traj: Trajectory, generator: Generator) -> np.ndarray:
    """The Noether momentum J = p·ξ(q) at every saved state of ``traj``, shape (N,).

    Parameters
    ----------
    traj : Trajectory
        A run.
    generator : Translation, Rotation, Cyclic or callable
        The symmetry's generator: a :class:`~varmech.Translation`, :class:`~varmech.Rotation` or
        :class:`~varmech.Cyclic`, or a closure ``xi(q) -> array (n,)``.

    Returns
    -------
    ndarray, shape (N,)
        J at each saved state.

    Raises
    ------
    TypeError
        ``generator`` is none of these, or ``xi(q)`` returned something that is not numbers,
        naming it.
    ValueError
        ``xi(q)`` returned another shape than (n,).

    Examples
    --------
    >>> import varmech
    >>> traj = varmech.integrate(varmech.scenes.kepler(0.6), dt=0.01, steps=1000, save_every=500)
    >>> varmech.momentum(traj, varmech.Rotation(spatial_dim=2)).round(12)
    array([0.8, 0.8, 0.8])
    """
    return _momentum_terms(traj, generator)[0]


def _momentum_terms(
    traj: Trajectory, generator: Generator, argument: str = "generator", field: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """J = p·ξ(q) and its size at every saved state, by the core's rule (``Generator::momentum_terms``:
    the larger of Σ|pᵢξᵢ| and ‖p‖∞‖ξ‖∞); a generator that does not fit the model's coordinates
    is refused naming ``argument``. A closure's ξ at the states is ``field`` where given."""
    if isinstance(generator, (Translation, Rotation, Cyclic)):
        return _core.momentum(generator.spec(), *traj._arrays()[1:], argument=argument)
    if field is None:
        field = _field(traj, generator, argument)
    return _core.momentum_along(field, np.ascontiguousarray(traj.p, dtype=float))


def _field(traj: Trajectory, generator: Generator, argument: str = "generator") -> np.ndarray:
    """ξ(q) at every saved state of ``traj``, shape (N, n): a declared generator's from the core
    (p·ξ at the unit momenta), a closure's called at each state; one that does not fit the
    model is refused naming ``argument``."""
    q = np.ascontiguousarray(traj.q, dtype=float)
    n = q.shape[1]
    if isinstance(generator, (Translation, Rotation, Cyclic)):
        spec, columns = generator.spec(), []
        for i in range(n):
            unit = np.zeros_like(q)
            unit[:, i] = 1.0
            columns.append(_core.momentum(spec, q, unit, argument=argument)[0])
        return np.stack(columns, axis=1)
    if not callable(generator):
        raise TypeError(f"{argument}: expected a Translation, Rotation, Cyclic or a callable xi(q), got {generator!r}")
    xi = np.empty_like(q)
    for k, x in enumerate(q):
        row = returned(f"{argument}: xi(q)", generator(x.copy()))
        if row.shape != (n,):
            raise ValueError(f"{argument}: xi(q) must return shape ({n},), got {row.shape}")
        xi[k] = row
    return xi


def _acting(traj: Trajectory) -> list[tuple[str, np.ndarray | None]]:
    """What besides L pushes the run's states, and along which rows at each saved state (N, k, n):
    each contact's normal and friction (:func:`varmech.impacts.acting`) and the model's force
    Q = ṗ − ∂L/∂q; None where the rows cannot be had (a contact loaded as its name, a force
    that does not evaluate at a state alone)."""
    found: list[tuple[str, np.ndarray | None]] = []
    q = np.asarray(traj.q, dtype=float)
    for c in traj.contacts:
        if isinstance(c, _impacts.Contact):
            found += _impacts.acting(c, q)
        else:
            found.append((f"contact {c!r} (given by functions its file does not store)", None))
    if traj.model.forced:
        what = "the model's force (Q·ξ ≠ 0)"
        t, q, p = (np.ascontiguousarray(x, dtype=float) for x in traj._arrays())
        core = traj.model._core
        try:
            v = _core.derivative(core, "velocity", t, q, p)
            force = _core.derivative(core, "dp_dt", t, q, v) - _core.derivative(core, "dl_dq", t, q, v)
        except (ValueError, RuntimeError):  # delayed forces need the run's history
            found.append((what, None))
        else:
            found.append((what, force[:, None, :]))
    return found


def _broken(t: np.ndarray, xi: np.ndarray, acting: list[tuple[str, np.ndarray | None]]) -> str | None:
    """Why the momentum of ξ (at the states, (N, n)) is not conserved, if something in ``acting``
    has a component along it at a state: |row·ξ| beyond 10⁻⁹ of its terms' size."""
    for what, rows in acting:
        if rows is None:
            return f"not judged: {what} may act along ξ"
        value = np.einsum("skj,sj->sk", rows, xi)
        terms = np.einsum("skj,sj->sk", np.abs(rows), np.abs(xi))
        size = np.maximum(terms, np.max(np.abs(rows), axis=2) * np.max(np.abs(xi), axis=1)[:, None])
        off = np.any(np.abs(value) > 1e-9 * size, axis=1)
        if off.any():
            return f"not conserved: {what} can push along ξ (at t = {t[int(np.argmax(off))]:.6g})"
    return None


@dataclass(frozen=True)
class InvariantStatistics:
    """The error of one conserved quantity along a run, against its scale, and the verdict.

    A field of :class:`ConservationReport` (``report.energy``, ``report.momenta[k]``, …).

    The scale is measured on the run's own states, which the error shifts (an orbit that lost
    energy is deeper and faster: by Kepler's virial theorem its mean kinetic energy is −E), so
    the level of the error is judged against ``judged_scale``, the scale less the mean |error|.
    The verdict is the first that applies of:

    - ``"failed"``: a value is not finite (``first_non_finite`` is the first saved state where
      it is not), or max |error| reaches :data:`FAILURE` × ``judged_scale``: the quantity is
      wrong by its own size;
    - ``"too short to judge"``: the run took no step (there is nothing to judge);
    - ``"conserved to round-off"``: max |error| ≤ ``round_off`` = :data:`ROUND_OFF` · ε ·
      (largest size of the quantity's terms) · √(1 + steps), the rounding error of its terms
      grown as a random walk (Brouwer's law);
    - ``"too coarse"``: max |error| reaches :data:`TOO_COARSE` × ``judged_scale``, an error of
      the order of the scale, whatever its trend: the step does not resolve the motion;
    - ``"secular drift"``: the error grows. Over eight batches in time, the slope of the batch
      means differs from zero by more than four standard errors, the drift over the run exceeds
      round-off, the 4 ε of the terms a step that biased rounding (an implicit method's solve)
      can add, and the error's own oscillation (the median band within a batch: a bounded
      error that wanders with the state, as on a chaotic orbit, shifts by less than it
      oscillates), and the last batch's largest |error| is more than twice the first's. The
      run must span two oscillations of the motion or more (``oscillations``: half the
      crossings of the quantity's size through its mean), and the error must keep growing (over
      the run's second half its batch means move by a quarter of what the slope predicts or
      more); otherwise a bounded error's rise, or a transient's rise and plateau, cannot be told
      from a drift and the verdict is ``"too short to judge"``;
    - ``"bounded"``: otherwise, a band that does not grow and stays below the too-coarse level.

    A forced run's balance E − W is not conserved by any method: its error is the
    discretisation error of the work. When it would be "secular drift", :func:`check_conservation`
    runs the same motion again at h/2 and, if the error falls at the method's order, calls it
    "bounded" with the measured order in the advice.

    ``max_rel_error`` and ``band`` are relative to ``scale``; ``drift_rate`` and
    ``drift_rate_stderr`` are absolute, per unit time.

    Attributes
    ----------
    name : str
        The quantity: ``"energy"``, ``"Jacobi integral"``, ``"energy balance"``, a momentum (``"L"``, ``"P_x"``,
        ``"p[0]"``, ``"xi[k]"``) or a constraint level (``"|g(q)|"``, ``"|G q̇|"``, ``"|A q̇|"``).
    initial : float
        Its value at the first saved state (H₀, J₀; 0 for a constraint residual).
    scale : float
        What the error is measured against: the mean kinetic energy for the energy, the mean
        max(Σ|pᵢξᵢ|, ‖p‖∞‖ξ‖∞) for a momentum, the mean ‖G‖‖q‖ or ‖G‖‖q̇‖ for a constraint.
    scale_name : str
        What the scale is, in words: ``"mean kinetic energy"``, ``"mean max(Σ|pᵢξᵢ|, ‖p‖‖ξ‖)"``, …
    round_off : float
        The round-off level: 10 ε × (largest size of the terms) × √(1 + steps), absolute.
    max_abs_error : float
        The largest |error| over the saved states, absolute (max |ΔH| for the energy).
    max_rel_error : float
        ``max_abs_error / scale``.
    band : float
        The median oscillation of the error within a batch of the run, relative to the scale.
    drift_rate : float
        The slope of the error's batch means, absolute, per unit time.
    drift_rate_stderr : float
        The standard error of ``drift_rate``.
    first_non_finite : int or None
        The first saved state where the quantity is not finite (None: it is finite throughout).
    verdict : str
        One of :data:`VERDICTS`; :data:`NOT_JUDGED` for an energy that is not conserved and has
        no tracked balance to judge instead (affine velocity constraints), or a momentum that a
        contact, its friction or a force pushes (the advice names it).
    advice : str
        For a failure or a too coarse run, where and how large and what to do; for a run too
        short, why; for a coarse band, to reduce dt; for a forced balance, its measured order;
        otherwise empty.
    judged_scale : float
        The scale less the mean |error| over the run: what the error's level is judged against.
    oscillations : float
        How many times the motion oscillates over the run (half the crossings of the
        quantity's size through its mean; infinite when the size is constant).
    representative : bool
        Whether |initial| is of the order of the scale, so that an error relative to it means
        something.

    Examples
    --------
    >>> import varmech
    >>> traj = varmech.integrate(varmech.scenes.kepler(0.6), dt=0.01, steps=20_000, save_every=10)
    >>> energy = varmech.check_conservation(traj).energy
    >>> energy.verdict, energy.scale_name, energy.max_rel_error < 1e-2
    ('bounded', 'mean kinetic energy', True)
    """

    name: str
    initial: float
    scale: float
    #: What the scale is: "mean kinetic energy", "mean max(Σ|pᵢξᵢ|, ‖p‖‖ξ‖)", …
    scale_name: str
    round_off: float
    max_abs_error: float
    max_rel_error: float
    band: float
    drift_rate: float
    drift_rate_stderr: float
    first_non_finite: int | None
    verdict: str
    #: For a failure: where it happened, and what to do.
    advice: str = ""
    #: The scale less the mean |error|: what the error's level is judged against.
    judged_scale: float = math.nan
    #: How many times the motion oscillates over the run.
    oscillations: float = math.inf

    @property
    def representative(self) -> bool:
        """Whether |J₀| is of the order of the scale, so that an error relative to J₀ means
        something (it does not for an energy whose zero is at the initial state, nor for a
        J₀ of 0)."""
        return abs(self.initial) > 0 and abs(self.initial) >= 1e-2 * self.scale

    def describe(self, symbol: str, error: str | None = None) -> list[str]:
        """The lines of a report on this quantity: verdict, initial value, errors and drift.

        Parameters
        ----------
        symbol : str
            The quantity's symbol in the text (H, J, …).
        error : str, optional
            The symbol of its error (default Δ``symbol``).

        Returns
        -------
        list of str
            Three lines (four for an energy whose initial value is not representative of
            its size): the verdict and advice; the initial value and the largest error,
            absolute and against the scale; the round-off level and the drift rate.

        Examples
        --------
        >>> import varmech
        >>> traj = varmech.integrate(varmech.scenes.harmonic_oscillator(), dt=0.1, steps=1000)
        >>> lines = varmech.check_conservation(traj).energy.describe("H")
        >>> len(lines), lines[0]
        (3, 'energy      verdict: bounded')
        """
        error = error or f"Δ{symbol}"
        head = f"{self.name + ' ':<12}verdict: {self.verdict}"
        if self.advice:
            head += f" ({self.advice})"
        lines = [
            head,
            f"{'':12}{symbol}0 = {self.initial:.12g}   max |{error}| = {self.max_abs_error:.3e} = "
            f"{self.max_rel_error:.3e} × scale {self.scale:.3e} ({self.scale_name})",
            f"{'':12}round-off level {self.round_off:.3e}   drift rate {self.drift_rate:+.3e} ± "
            f"{self.drift_rate_stderr:.1e} per unit time",
        ]
        if self.representative:
            lines[1] += f"   (max |{error}/{symbol}0| = {self.max_abs_error / abs(self.initial):.3e})"
        elif self.name in _SYMBOLS:
            lines.append(f"{'':12}|{symbol}0| is not representative of the energy's size: errors are against the scale")
        return lines


#: A bounded band above this fraction of the scale is coarse, and the advice says so.
COARSE = 0.1


def _statistics(record: _core.Statistics, name: str, initial: float, scale_name: str, t: np.ndarray) -> InvariantStatistics:
    """The report of the core's statistics, with a failure located in time."""
    k = record.first_non_finite
    advice = ""
    judged = record.judged_scale
    level = (
        f"{record.max_abs_error / judged:.3g} × the scale less the mean error ({judged:.3g})"
        if judged > 0
        else f"{record.max_rel_error:.3g} × the scale {record.scale:.3g}, with a mean error beyond the scale"
    )
    if k is not None:
        advice = f"not finite from saved state {k} (t = {t[k]:.6g}) on"
    elif record.verdict == "failed":
        advice = f"the error reaches {level}"
    elif record.verdict == "too coarse":
        advice = f"the error reaches {level}: the step does not resolve the motion; reduce dt"
    elif record.verdict == "too short to judge":
        if len(t) < 2:
            advice = "nothing to judge: the run took no step"
        elif record.oscillations < 2:
            advice = (
                f"the error rises over {record.oscillations:.3g} oscillation(s) of the motion, too few to tell "
                f"a band from a drift: run longer"
            )
        else:
            advice = "the error rose, then levelled off over the run's second half: run longer to tell a transient from a drift"
    elif record.verdict == "bounded" and record.max_rel_error > COARSE:
        advice = f"coarse: the band reaches {record.max_rel_error:.2g} of the scale; reduce dt for accuracy"
    return InvariantStatistics(
        name,
        float(initial),
        record.scale,
        scale_name,
        record.round_off,
        record.max_abs_error,
        record.max_rel_error,
        record.band,
        record.drift_rate,
        record.drift_rate_stderr,
        k,
        record.verdict,
        advice,
        judged,
        record.oscillations,
    )


#: The verdict of an energy that is not conserved and has no tracked balance to judge instead.
NOT_JUDGED = "not judged"
#: Why: affine velocity constraints' forces do work.
AFFINE = "not conserved: the affine velocity constraints' moving surface does work, which the run does not track"
#: The name of ``report.energy`` where anything puts energy in or takes it out: E − W is judged.
BALANCE = "energy balance"
#: The names ``report.energy`` takes, and their symbols in the report's text.
_SYMBOLS = {"energy": "H", "Jacobi integral": "h", BALANCE: "(E − W)"}


@dataclass(frozen=True)
class ConservationReport:
    """What a run conserved: its energy (or a forced run's energy balance), its Noether
    momenta and its constraints, each with an :class:`InvariantStatistics` and its verdict.

    :func:`check_conservation` returns it; ``print(report)`` gives the table the user guide's verdicts page shows.

    Attributes
    ----------
    model : str
        The model's name.
    method : str
        The method's name.
    dt : float
        The step.
    t_end : float
        The last saved time.
    energy : InvariantStatistics
        Always present; its ``name`` says what it is. The energy function E = p·q̇ − L
        (``"energy"``; ``"Jacobi integral"`` for a model that names it so, such as an L from
        inertial coordinates whose t cancels: a moving frame); for forced systems and for an L
        that depends on t, the balance E(t) − W(t) (``"energy balance"``), W the energy put in
        (``traj.work``: the forces' work, the discrete Lagrange–d'Alembert energy balance, less
        ∫∂L/∂t dt on the method's quadrature), judged as the energy is; with affine velocity
        constraints, whose forces do work no run tracks, the energy's statistics with the
        verdict :data:`NOT_JUDGED` and the reason in ``advice`` (a non-finite energy still
        fails).
    momenta : tuple of InvariantStatistics
        Each Noether momentum judged, in the order of the generators.
    constraints : tuple of InvariantStatistics or None
        For constrained models: |g(q)|∞ and |G(q)M⁻¹p|∞ over the run; with velocity
        constraints |A(q)q̇ + b(q)|∞ alone; with both, |g(q)|∞ and |G(q)q̇, A(q)q̇ + b(q)|∞.
    affine : bool
        Whether the velocity constraints are affine (b ≠ 0, a moving surface): their forces do
        work, and the energy is not judged.
    constraint_power : InvariantStatistics or None
        For fixed constraints: the power Cᵀλ·q̇ of the constraint forces
        (:meth:`Trajectory.reactions`), which vanishes on the exact motion: a work-free check of
        the multipliers and of the velocities' constraint together, against Σ|(Cᵀλ)ᵢq̇ᵢ|.
        None without constraints, or with affine ones (their forces do work).
    time_dependent : bool
        Whether L depends on t: then its energy balance, not its energy, is judged.
    verdict : str
        ``energy.verdict``: the energy's, the Jacobi integral's or the balance's.
    constraint_residuals : tuple of float or None
        max |g(q)|∞ and max |G(q)M⁻¹p|∞ over the run, for constrained models (0 and max
        |A(q)q̇|∞ with velocity constraints); None without constraints.
    quantities : tuple of InvariantStatistics
        Every quantity judged: energy (or balance) unless not judged, momenta, constraints.

    Examples
    --------
    >>> import varmech
    >>> traj = varmech.integrate(varmech.scenes.kepler(0.6), dt=0.01, steps=20_000, save_every=10)
    >>> report = varmech.check_conservation(traj)
    >>> report.verdict, [m.name for m in report.momenta]
    ('bounded', ['L'])
    >>> f"{report.energy.max_abs_error:.1e}"
    '...e-0...'
    """

    model: str
    method: str
    dt: float
    t_end: float
    #: The energy, the Jacobi integral, or where anything puts energy in or takes it out the
    #: balance E(t) − W(t) (W as ``traj.work``): ``energy.name`` says which.
    energy: InvariantStatistics
    momenta: tuple[InvariantStatistics, ...]
    #: For constrained models: |g(q)|∞ and |G(q)M⁻¹p|∞ over the run; with velocity constraints
    #: |A(q)q̇ + b(q)|∞ alone; with both, |g(q)|∞ and |G(q)q̇, A(q)q̇ + b(q)|∞.
    constraints: tuple[InvariantStatistics, ...] | None = None
    #: Whether the velocity constraints are affine (b ≠ 0): then the energy is not judged.
    affine: bool = False
    #: For fixed constraints: the power Cᵀλ·q̇ of the constraint forces, 0 on the exact motion.
    constraint_power: InvariantStatistics | None = None
    #: Whether L depends on t (then the balance, not the energy, is judged).
    time_dependent: bool = False

    @property
    def verdict(self) -> str:
        """The verdict of ``energy`` (see :class:`InvariantStatistics`): the energy's, the Jacobi
        integral's or the balance's."""
        return self.energy.verdict

    @property
    def constraint_residuals(self) -> tuple[float, float] | None:
        """max |g(q)|∞ and max |G(q)M⁻¹p|∞ over the run, for constrained models (0 and max
        |A(q)q̇|∞ with velocity constraints)."""
        if self.constraints is None:
            return None
        if len(self.constraints) == 1:
            return 0.0, self.constraints[0].max_abs_error
        return self.constraints[0].max_abs_error, self.constraints[1].max_abs_error

    @property
    def quantities(self) -> tuple[InvariantStatistics, ...]:
        """Every quantity judged: energy (or balance) unless :data:`NOT_JUDGED`, momenta,
        constraints and their power."""
        energy = (self.energy,) if self.energy.verdict != NOT_JUDGED else ()
        momenta = tuple(m for m in self.momenta if m.verdict != NOT_JUDGED)
        power = (self.constraint_power,) if self.constraint_power is not None else ()
        return energy + momenta + (self.constraints or ()) + power

    def __str__(self) -> str:
        lines = [f"Conservation report: {self.model}, {self.method}, dt = {self.dt:g}, t = 0 … {self.t_end:g}"]
        lines += ["  " + line for line in self.energy.describe(_SYMBOLS.get(self.energy.name, "H"))]
        for m in self.momenta:
            lines += ["  " + line for line in m.describe("J")]
        residuals = ("g(q)", "G M⁻¹ p") if len(self.constraints or ()) == 2 else ("A q̇ + b" if self.affine else "A q̇",)
        if self.constraints and len(self.constraints) == 2 and self.constraints[1].name != "|G q̇|":
            residuals = ("g(q)", "G q̇, A q̇ + b")  # holonomic and velocity constraints together
        for c, error in zip(self.constraints or (), residuals):
            lines += ["  " + line for line in c.describe("r", error)]
        if self.constraint_power is not None:
            lines += ["  " + line for line in self.constraint_power.describe("P", "Cᵀλ·q̇")]
        return "\n".join(lines)


def check_conservation(traj: Trajectory, generators: Sequence[Generator] | None = None, *, refine: bool = True) -> ConservationReport:
    """Check the energy, the Noether momenta and the constraints of ``traj``, and the power of the constraint forces.

    The energy function E = p·q̇ − L is judged when nothing puts energy in or takes it out and
    no constraint does work (affine velocity constraints A(q)q̇ + b(q) = 0 do); where anything
    does, the report judges the balance E − W instead, W the energy put in as the run tracked
    it (``traj.work``): the forces' work less ∫∂L/∂t dt on the method's quadrature, the
    friction of held contacts, each impact's loss where e < 1 (its law's own; an elastic impact
    puts in none) and each impulse's energy change. A momentum is judged only where no
    contact's normal, friction slip row or force of the model pushes along its ξ at the run's
    states; otherwise it is :data:`NOT_JUDGED`, its advice naming what pushes it. An energy
    that is not finite at a saved state fails the report in every case. With velocity
    constraints the report judges the residuals |A(q)q̇ + b(q)| and only the momenta of the
    symmetries the model declares: a nonholonomic system need not conserve the momenta of the
    symmetries of its L (the native scenes declare those they conserve). Each quantity's error
    is measured against a scale (the mean kinetic energy for the energy), and judged by one of
    :data:`VERDICTS` (:class:`InvariantStatistics` says how).

    Parameters
    ----------
    traj : Trajectory
        A run, as :func:`varmech.integrate` returns it.
    generators : sequence of Translation, Rotation, Cyclic or callable, optional
        The symmetries whose momenta J = p·ξ(q) are judged. Default: those the model declares;
        a cyclic coordinate's momentum is named as the model names it (``p_phi``, from
        :attr:`Model.momentum_names`), a closure generator ``xi(q)`` ``xi[k]``.
    refine : bool, default True
        For a balance (forced, or L depending on t) that would be "secular drift": run the same motion again at
        h/2 and call the balance "bounded" when its error falls at the method's order (the
        discretisation error of the work, not a drift), with the measured order in the advice.
        This costs twice the run. For a conserved energy that would be "secular drift" or "too
        short to judge": judge it again over the run continued as long again, "bounded" where
        the error levels off there (a transient) or its rise stops there (a slow oscillation). This
        costs one more run. ``False`` skips both.

    Returns
    -------
    ConservationReport
        The energy (or balance), each momentum and each constraint level, with their
        statistics and verdicts; ``print(report)`` shows them.

    Raises
    ------
    TypeError, ValueError
        A generator that is not one, or whose ``xi(q)`` has the wrong shape (see :func:`momentum`).

    See Also
    --------
    ConservationReport : The report this returns, its fields and verdict.
    InvariantStatistics : The statistics of one invariant, with its verdict.

    Examples
    --------
    >>> import varmech
    >>> from varmech import scenes
    >>> traj = varmech.integrate(scenes.kepler(0.6), dt=0.01, steps=20_000, save_every=10)
    >>> report = varmech.check_conservation(traj)
    >>> report.verdict, report.momenta[0].verdict
    ('bounded', 'conserved to round-off')
    """
    if generators is None:
        generators = traj.model.symmetries
    model = traj.model
    t, steps = np.asarray(traj.t), int(traj.steps)
    affine = bool(model.velocity_constraints) and model.affine
    # Whether anything puts energy in or takes it out (forces, L's dependence on t, impacts,
    # friction, impulses): then the balance E − W is judged, W as the run recorded it.
    forced = _impacts.exchanges(model, traj.contacts, traj.impulses)
    work = np.zeros(len(t)) if traj.work is None else np.asarray(traj.work)
    if not affine:
        energy = energy_statistics(model, t, *traj._arrays()[1:], steps=steps, work=work if forced else None)
        if energy.verdict == "failed":
            energy = replace(energy, advice=f"{energy.advice}; {_failure_advice(traj)}")
        elif forced and energy.verdict == "secular drift" and refine:
            energy = _refined(traj, energy)
        elif not forced and energy.verdict in ("secular drift", "too short to judge") and refine:
            energy = _continued(traj, energy)
        if energy.verdict == "secular drift" and not energy.advice:
            energy = replace(energy, advice=_drift_advice(traj))
        if energy.verdict in ("secular drift", "too coarse", "failed") and energy.first_non_finite is None:
            # Wrong derivatives integrate other dynamics than the energy's: no step mends that.
            wrong = blame(model, traj.q[0], traj.v[0], float(traj.t[0]), "at the first state")
            energy = energy if wrong is None else replace(energy, advice=wrong)
    else:
        energy = energy_statistics(model, t, *traj._arrays()[1:], steps=steps)
        # Not conserved, so not judged; but a non-finite energy fails the run all the same.
        if energy.first_non_finite is None:
            energy = replace(energy, verdict=NOT_JUDGED, advice=AFFINE)
    if energy.first_non_finite is not None:
        energy = replace(energy, advice=f"{energy.advice}: the model's energy p·q̇ − L does not evaluate there")
    momenta = []
    # A momentum is judged where nothing pushes along its ξ: no contact's normal or friction,
    # no force of the model.
    acting = _acting(traj) if generators else []
    for k, xi in enumerate(generators):
        # Checked against the model's coordinates first: then a cyclic coordinate's momentum is
        # named as the model knows it (p_phi).
        argument = f"generators[{k}]"
        # ξ at the states, once, where a closure's J or the test of what acts along it needs it.
        builtin = isinstance(xi, (Translation, Rotation, Cyclic))
        field = _field(traj, xi, argument) if acting or not builtin else None
        j, size = _momentum_terms(traj, xi, argument, field)
        name = model.momentum_names[xi.index] if isinstance(xi, Cyclic) else xi.name if isinstance(xi, (Translation, Rotation)) else f"xi[{k}]"
        record = _core.statistics(t, j - j[0], size, size, steps)
        stats = _statistics(record, name, j[0], "mean max(Σ|pᵢξᵢ|, ‖p‖‖ξ‖)", t)
        why = _broken(t, field, acting) if acting and field is not None else None
        # Not conserved, so not judged; a non-finite momentum fails all the same.
        if why is not None and stats.first_non_finite is None:
            stats = replace(stats, verdict=NOT_JUDGED, advice=why)
        momenta.append(stats)
    constraints: tuple[InvariantStatistics, ...] | None = None
    if model.constraints:
        (g, v), (g_size, v_size) = _core.constraint_residuals(model._core, *traj._arrays()[1:])
        # With velocity constraints beside them, the velocities' residual holds both sets.
        name, scale = ("|G q̇, A q̇ + b|", "mean ‖[G; A]‖‖q̇‖ + |b|") if model.velocity_constraints else ("|G q̇|", "mean ‖G‖‖q̇‖")
        constraints = (
            _statistics(_core.statistics(t, g, g_size, g_size, steps), "|g(q)|", g[0], "mean ‖G‖‖q‖", t),
            _statistics(_core.statistics(t, v, v_size, v_size, steps), name, v[0], scale, t),
        )
    elif model.velocity_constraints:
        (_, v), (_, v_size) = _core.constraint_residuals(model._core, *traj._arrays()[1:])
        name, scale = ("|A q̇ + b|", "mean ‖A‖‖q̇‖ + |b|") if affine else ("|A q̇|", "mean ‖A‖‖q̇‖")
        constraints = (_statistics(_core.statistics(t, v, v_size, v_size, steps), name, v[0], scale, t),)
    power = None
    if constraints is not None and not affine:
        _, _, (p, p_size) = _core.reactions(model._core, *traj._arrays())
        power = _statistics(_core.statistics(t, p, p_size, p_size, steps), "power", p[0], "mean Σ|(Cᵀλ)ᵢq̇ᵢ|", t)
    return ConservationReport(
        model.name, traj.method, traj.dt, float(t[-1]), energy, tuple(momenta), constraints, affine, power, model.time_dependent
    )


def energy_statistics(
    model: Model, t: np.ndarray, q: np.ndarray, p: np.ndarray, *, steps: int, work: np.ndarray | None = None
) -> InvariantStatistics:
    """The statistics and verdict of the energy of ``model`` at states (t, q, p) sampled from
    a run of ``steps`` steps, by varmech or any other integrator; with ``work`` (the work of the
    forces up to each state), of the balance E − W."""
    t, q, p = (np.ascontiguousarray(x, dtype=float) for x in (t, q, p))
    return _energy_judged(model, t, _core.energy_terms(model._core, t, q, p), steps, work)


def _energy_judged(
    model: Model, t: np.ndarray, terms: tuple[np.ndarray, np.ndarray, np.ndarray], steps: int, work: np.ndarray | None = None
) -> InvariantStatistics:
    """:func:`energy_statistics` from the energy's terms (E, T, V) at times ``t``, evaluated."""
    e, kinetic, potential = terms
    w = np.zeros(len(t)) if work is None else np.ascontiguousarray(work, dtype=float)
    record = _core.energy_statistics(t, e, kinetic, potential, w, int(steps))
    return _statistics(record, model.energy_name if work is None else BALANCE, e[0] - w[0], "mean kinetic energy", t)


def _refined(traj: Trajectory, stats: InvariantStatistics) -> InvariantStatistics:
    """A forced run's drifting balance, judged by the same motion at h/2: "bounded" when its
    error falls at the method's order (discretisation error of the work), with the measured
    order; otherwise the drift stands, with the order measured. Unchanged for a run that did
    not reach its end (events or an error stopped it), saved states off its steps
    (``t_eval``), which the same motion at h/2 cannot be compared at, or a run with contacts,
    which the model alone would run without its impacts."""
    steps = (traj.t - traj.t[0]) / traj.dt
    at = np.rint(steps).astype(np.int64)
    gaps = np.diff(at)
    if traj.status != 0 or traj.contacts or len(gaps) == 0 or np.any(gaps <= 0) or not np.allclose(steps, at, rtol=0, atol=1e-6):
        return stats
    every = int(np.gcd.reduce(gaps))
    fine = integrate(
        traj.model,
        traj.q[0],
        traj.p[0],
        dt=traj.dt / 2,
        steps=2 * int(traj.steps),
        method=traj.method,
        t0=float(traj.t[0]),
        save_every=2 * every,
        max_energy_error=None,
        progress=False,
    )
    keep = at // every
    t, q, p, work = fine.t[keep], fine.q[keep], fine.p[keep], np.asarray(fine.work)[keep]
    halved = energy_statistics(traj.model, t, q, p, steps=int(fine.steps), work=work)
    order = {m.name: m for m in _core.methods()}[traj.method].order
    measured = math.log2(stats.max_abs_error / halved.max_abs_error) if halved.max_abs_error > 0 else math.inf
    if measured >= order - 0.5 or halved.verdict == "conserved to round-off":
        advice = (
            f"discretisation error of the work, not a drift: it falls as h^{measured:.2f} at h/2 "
            f"({traj.method} is of order {order})"
        )
        return replace(stats, verdict="bounded", advice=advice)
    return replace(stats, advice=f"it falls only as h^{measured:.2f} at h/2, not at {traj.method}'s order {order}")


def _continued(traj: Trajectory, stats: InvariantStatistics) -> InvariantStatistics:
    """An energy whose run rose too steadily to be called bounded ("secular drift", or "too short
    to judge"), judged again over the run and its continuation as long again: a transient (the
    Chaplygin sleigh's energy error rises while its spin decays, then stays) levels off there and
    is "bounded", as is a drift whose rate the continuation alone does not keep (a quarter of it,
    or the other sign: a slow oscillation's rise); a drift keeps growing, and a run too short now
    may not be. Unchanged for a run that did not reach its end, or saved off its steps."""
    steps = (traj.t - traj.t[0]) / traj.dt
    gaps = np.diff(np.rint(steps).astype(np.int64))
    if traj.status != 0 or len(gaps) == 0 or np.any(gaps <= 0) or not np.allclose(steps, np.rint(steps), rtol=0, atol=1e-6):
        return stats
    # Saved as the run was (its usual gap; the last one may be short), so that the batches of the
    # verdict's statistics span equal times: a finer continuation would outweigh the run.
    every = int(np.median(gaps))
    try:
        more = integrate(traj, steps=int(traj.steps), save_every=every, max_energy_error=None, progress=False)
    except _core.VarmechError:
        # A continuation that fails (a state no longer finite) tells no transient from a drift.
        return stats
    joined = ((traj.t, more.t), (traj.q, more.q), (traj.p, more.p))
    t, q, p = (np.ascontiguousarray(np.concatenate([a, b[1:]]), dtype=float) for a, b in joined)
    terms = _core.energy_terms(traj.model._core, t, q, p)
    longer = _energy_judged(traj.model, t, terms, int(more.steps))
    how = f"judged over the run continued as long again, to t = {t[-1]:.6g}"
    if stats.verdict == longer.verdict == "secular drift":
        # A drift keeps its rate over the continuation alone (from the run's last state, its
        # terms above); a slow oscillation's rise (energy passing between modes) stops there.
        k = len(traj.t) - 1
        ahead = _energy_judged(traj.model, t[k:], (terms[0][k:], terms[1][k:], terms[2][k:]), int(more.steps))
        rate, then = stats.drift_rate, ahead.drift_rate
        if not (then * rate > 0 and abs(then) >= abs(rate) / 4):
            return replace(stats, verdict="bounded", advice=f"{how}: its rise stops there (rate {then:.3g} after {rate:.3g}), no drift")
    if longer.verdict == stats.verdict or longer.verdict in ("failed", "too coarse"):
        return stats
    if longer.verdict in ("bounded", "conserved to round-off"):
        return replace(stats, verdict="bounded", advice=f"{how}: the error levels off, a transient")
    return replace(stats, verdict=longer.verdict, advice=f"{how}: {longer.advice}" if longer.advice else how)


def _drift_advice(traj: Trajectory) -> str:
    """What to do about a drifting energy: reduce dt, and why a smaller step helps."""
    info = {m.name: m for m in _core.methods()}.get(traj.method)
    if info is not None and not info.symplectic:
        return _not_symplectic(info)
    # Backward error analysis bounds the error over exponentially long times only for h·ω small
    # enough: near the stability limit, or at a resonance, the modified energy does not hold.
    return "a symplectic method drifts only at a step too coarse for the motion: reduce dt"


def _not_symplectic(info: _core.MethodInfo) -> str:
    """What helps the energy error of a method that is not symplectic, as a run's divergence
    says it: nothing bounds it, so a smaller step only slows its growth."""
    return (
        f"reduce dt ({info.name} is not symplectic: its energy error grows along the run, slower at a smaller "
        f"step, by order {info.order}), or take a symplectic method, whose error stays bounded: verlet (rattle on "
        "a constrained model)"
    )


def _failure_advice(traj: Trajectory) -> str:
    """What to do about a failed energy: reduce dt, and whether the step is past the method's
    linear stability limit h·ω_max when the linearisation at the initial state gives an estimate."""
    info = {m.name: m for m in _core.methods()}.get(traj.method)
    if info is not None and not info.symplectic:
        return _not_symplectic(info)
    advice = "reduce dt"
    h_omega = _h_omega(traj.model, traj.q[0], traj.dt, float(traj.t[0]))
    if h_omega is not None and info is not None and h_omega >= info.h_omega_max:
        advice += (
            f": h·ω ≈ {h_omega:.3g} at the initial state (linear estimate) is past {traj.method}'s "
            f"stability limit h·ω = {info.h_omega_max:.3g}"
        )
    return advice


def _h_omega(model: Model, q: np.ndarray, dt: float, t0: float) -> float | None:
    """dt times the largest frequency of the linearisation about q at rest, ω² the largest
    eigenvalue of M⁻¹K with M = ∂²L/∂q̇² and K = −∂²L/∂q², both by central differences; None
    for constrained or large models, or when no direction oscillates."""
    n = model.dim
    if model.constraints or n > 64:
        return None
    eye, zeros = np.eye(n), np.zeros((1, n))
    tt = np.full(1, t0)
    try:
        mass = np.stack([_core.derivative(model._core, "momentum", tt, q[None, :], eye[j][None, :])[0] for j in range(n)], axis=1)
        step = 1e-5 * max(1.0, float(np.max(np.abs(q))))
        stiffness = np.stack(
            [
                -(
                    _core.derivative(model._core, "dl_dq", tt, (q + step * eye[j])[None, :], zeros)[0]
                    - _core.derivative(model._core, "dl_dq", tt, (q - step * eye[j])[None, :], zeros)[0]
                )
                / (2 * step)
                for j in range(n)
            ],
            axis=1,
        )
        omega2 = np.linalg.eigvals(np.linalg.solve(mass, stiffness)).real.max()
    except Exception:  # the estimate only words advice: a model it cannot linearise gets none
        return None
    return dt * math.sqrt(omega2) if np.isfinite(omega2) and omega2 > 0 else None
