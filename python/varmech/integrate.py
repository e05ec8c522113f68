"""Fixed-step integration: :func:`integrate` (its result, :class:`~varmech.trajectory.Trajectory`,
in :mod:`varmech.trajectory`)."""

from __future__ import annotations

import contextlib
import datetime
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from . import _core, files, streaming
from . import events as _events
from . import impacts as _impacts
from . import impulses as _impulses
from ._progress import progress_bar
from ._runspec import Jumps, RunSpec, continuing, energy_threshold, sample_times
from ._util import positive, positive_int, returned_scalar, step_count, vector
from .constraints import warn_if_integrable
from .derivatives import blame
from .model import Lagrangian, Model, check_delays, initial_state
from .modes import warn_if_unstable
from .scenes import Scene
from .scenes._scene import contacts_of, model_and_state

# Trajectory lives in varmech.trajectory; imported here, it is still found under its old name
# (varmech.integrate.Trajectory), which pickles made before the move refer to.
from .trajectory import Trajectory, going_on_from, load, of_record, take_partial

__all__ = [
    "integrate",
    "symplecticity_defect",
]


def _check_time_independent(
    model: Model, q: np.ndarray, p: np.ndarray, times: tuple[float, ...], names: str = "q0, p0"
) -> None:
    """Refuses a Lagrangian declared time-independent whose L(q0, q̇0, t) changes with t: its
    energy would be judged as conserved while it is not. ``names`` are the arguments (q, p)
    came from, for an error in finding q̇0."""
    if not isinstance(model, Lagrangian) or model.time_dependent:
        return
    t = np.array(times[:1])
    v = _core.derivative(model._core, "velocity", t, q[None, :], p[None, :], names=names)[0]
    values = [returned_scalar("lagrangian(q, v, t)", model.lagrangian(q.copy(), v.copy(), s)) for s in times]
    spread = max(values) - min(values)
    size = max(abs(x) for x in values) + float(np.abs(p * v).sum())
    if not spread <= 1e-12 * size:
        shown = ", ".join(f"L(t = {s:.6g}) = {x:.12g}" for s, x in zip(times, values))
        raise ValueError(
            f"time_dependent: L(q0, q̇0, t) changes with t ({shown}), but {model.name} was not declared "
            "time-dependent; pass time_dependent=True, or its energy would be judged as conserved"
        )


def integrate(
    model: Model | Scene | Trajectory,
    q0: ArrayLike | None = None,
    p0: ArrayLike | None = None,
    *,
    v0: ArrayLike | None = None,
    dt: float | None = None,
    steps: int | None = None,
    t_end: float | None = None,
    method: str | None = None,
    save_every: int = 1,
    compensated: bool = True,
    max_energy_error: float | None | Literal["auto"] = "auto",
    t0: float | None = None,
    newton_tolerance: float = 1e-14,
    newton_max_iterations: int = 50,
    parameters: Mapping[Any, float] | None = None,
    progress: bool | None = None,
    output: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
    checkpoint_every: int | datetime.timedelta | None = None,
    events: Sequence[_events.Event | _events.EventFunction] | None = None,
    t_eval: ArrayLike | None = None,
    impulses: Sequence[_impulses.Impulse] | None = None,
    contacts: Sequence[_impacts.Contact] | None = None,
) -> Trajectory:
    """Integrate ``model`` from (q0, p0) with a fixed step.

    Parameters
    ----------
    model
        A :class:`~varmech.MechanicalSystem`, a native model, or a :class:`~varmech.scenes.Scene`
        (whose initial state is then the default). Or a :class:`Trajectory`: the run goes on
        from its last state for ``steps`` more steps (or to ``t_end``), bit for bit as if it had
        never stopped (its checkpoint carries the compensated-summation carries, the Newton
        predictors and every other part of the method's state); the method, step, summation,
        Newton options and energy check are the trajectory's, and the result starts with its
        last state.
    q0, p0, v0
        Initial positions and momenta, arrays (n,); give the velocities ``v0`` instead of
        ``p0`` to start from p0 = ∂L/∂q̇(q0, v0, t0) (M v0 for mechanical systems).
    dt
        The step h > 0.
    steps, t_end
        How far: a number of steps, or a final time that is a whole number of steps.
    method
        A name from :func:`varmech.methods`. Default: ``"verlet"`` for separable mechanical
        systems, ``"midpoint"`` for general Lagrangians.
    save_every
        Keep every k-th state; the initial and final states are always kept.
    compensated
        Add the step increments with compensated summation (default), so that round-off grows
        like √N rather than N over N steps.
    max_energy_error
        Stop with :class:`~varmech.DivergenceError` when the energy error |E − E₀| at a saved
        state exceeds this times the energy's scale, the mean kinetic energy of the states saved
        so far (errors at round-off never stop a run; see
        :class:`~varmech.InvariantStatistics`): at once where the step is beyond the method's
        stability limit at the first state, and, within it, where the error grows (from the
        64th saved state on, at least twice the largest error while the run was half as long)
        or the state does (max |qᵢ|: an orbit thrown out of its well); the bounded offset of a
        symplectic method's modified energy at a coarse stable step, however large, runs to
        the end, its size the verdict's to judge; or when the energy is not finite. To stop at an error of a given size, use a terminal event,
        ``events=[varmech.events.energy_error(bound)]``. A forced run,
        or one of a Lagrangian that depends on t, checks its balance E − W instead, W the energy
        put in (the forces' work less ∫∂L/∂t dt, ``traj.work``). ``"auto"`` (default): 1
        (:data:`varmech.conservation.FAILURE`), the error at which the verdict is "failed"; no
        check where affine velocity constraints do work. ``None``: no energy check; non-finite
        states still stop the run. The check costs one energy evaluation per saved state. A
        continued run (``integrate(traj)``) keeps its run's check unless given one: a value
        sets its level (the run's first energy, scale and growth kept, or, where the run had
        no check, measured from the continuation's start), ``None`` lifts it.
    t0
        The initial time (default 0). It restarts a run from a state saved by hand: give that
        state's q, p and time, ``integrate(model, traj.q[-1], traj.p[-1], dt=dt, steps=n,
        t0=traj.t[-1])``, and the result's times go on from it (a time-dependent Lagrangian or
        forcing sees the right t). That is a new run, whose compensated-summation carries and
        Newton predictors start afresh, so it agrees with the unbroken run to round-off (the
        pendulum scene: 1e-16 after 100 + 100 Verlet steps); pass the :class:`Trajectory`
        itself (above) to go on bit for bit.
    newton_tolerance, newton_max_iterations
        The implicit methods' Newton iteration stops when its correction is below
        ``newton_tolerance``·‖δq‖∞ (δq the step's increment) or stalls at round-off, and fails
        with :class:`~varmech.ConvergenceError` after ``newton_max_iterations`` iterations.
    parameters
        For a symbolic model (:mod:`varmech.symbolic`), parameter values by name (or symbol)
        for this run:
        the model of ``model.with_parameters(**parameters)`` is integrated, with the same
        compiled code. Other models have none (TypeError naming ``parameters``).
    progress
        Show a progress bar (tqdm, on stderr: steps, steps/s, time left) once the run has taken a
        second. ``None`` (default): only on a terminal (stderr) or in a Jupyter notebook, unless TQDM_DISABLE is set. It is updated at the stride
        of the Ctrl-C check (every 10–40 ms), so it costs the step loop nothing measurable.
    output, overwrite
        Stream the saved states to the HDF5 file ``output`` (h5py, the extra ``io``; layout in
        :mod:`varmech.files`) as the run goes, in segments of about two seconds, each committed
        with its checkpoint; memory stays flat whatever the number of steps. The result is read
        back from the file: lazily (:func:`varmech.load` with ``lazy=True``) when it holds more
        than :data:`varmech.files.LAZY_BYTES`. A run stopped by Ctrl-C, an error or a kill leaves a valid file
        with every committed state, from which :func:`varmech.resume` goes on. An existing file
        is refused unless ``overwrite``.
    t_eval
        Keep the states at these times (increasing, within the run's span) instead of every
        ``save_every``-th: each is reached by one step of the same method of size τ < h from the
        grid state before it (or from the last jump, an impact or an impulse, between them), so
        it has the method's own error (order measured in ``tests/python/test_dense.py``), as
        ``solve_ivp(t_eval=)`` does with its dense output. At a jump's time it is the state just
        before. The run itself is unchanged (it ends on its grid, with its checkpoint, from which
        ``integrate(traj, steps=, t_eval=)`` goes on); not with ``save_every`` or ``output``,
        whose rows are the run's own states.
    impulses
        Blows (:class:`varmech.Impulse`) at their times ``impulse.t`` within the run: the momenta
        jump by P(q) there (on a constrained model, projected back on the constraints by their
        workless impulse). An impulse between grid points splits its step: a step of the same
        method to tₙ + τ, the jump, a step of h − τ back onto the grid, so the method keeps its
        order (``tests/python/test_impulses.py``). The saved states include those just before and
        just after each jump (one time, two rows). A continued run (``integrate(traj, steps=)``)
        goes on with the impulses still to come.
    contacts
        Unilateral constraints φ(q) ≥ 0 (:class:`varmech.Contact`): the run goes through their
        impacts, each step that crosses a surface split at the contact configuration (see
        :mod:`varmech.impacts`); the impacts are each contact's occurrences in ``traj.events``.
        Default: a scene's ``contacts`` (an impact scene's floor or wall); ``contacts=[]``
        runs without them. They compose with events, impulses, ``t_eval``, ``output`` and
        continued runs, which go on with them.
    checkpoint_every
        With ``output``: commit states and a checkpoint at least every this many steps (rounded
        down to whole ``save_every`` periods), or every :class:`datetime.timedelta` of run time.
    events
        Event functions g(t, q, p) whose zero crossings are located (``traj.events``), as in
        :func:`scipy.integrate.solve_ivp`: plain functions with optional ``direction`` and
        ``terminal`` attributes, :class:`varmech.events.Event` (which may take the velocities,
        g(t, q, v)), or the built-in helpers of :mod:`varmech.events` (evaluated natively).
        Each crossing is located by a partial step of the method, to round-off; a terminal event
        stops the run after the step of its crossing with ``status = 1``. The steps are then
        taken one at a time (a Wisdom–Holman method synchronises, and ``whc`` applies its
        corrector, at every step).

    Returns
    -------
    Trajectory
        The saved states (``t``, ``q``, ``p``; ``v`` on demand), the counts, ``status`` and
        ``message``, the located events, and the checkpoint to go on from.

    Raises
    ------
    ValueError
        Malformed arguments; the message starts with the argument's name (``output`` for a file
        that cannot be written or exists without ``overwrite``). Also a
        :class:`~varmech.Lagrangian` declared time-independent whose L changes with t at the
        initial state (probed at a few times), naming ``time_dependent``.
    DivergenceError
        The solution blew up; ``err.step``, ``err.time`` and ``err.partial`` (the trajectory up
        to the last good step) are attached.
    ConvergenceError
        An implicit method's Newton iteration failed; ``err.step``, ``err.time``,
        ``err.residual``, ``err.iterations`` and ``err.partial`` are attached. Its subclass
        :class:`~varmech.SpuriousBranchError` means Newton converged, but beyond a fold of the
        DEL map where the step's solution is not unique (the step is too large there).
    TypeError
        An event function that does not take (t, q, p), naming it (``events[i] (name)``).
    VarmechError
        An event function returned a value that is not finite (the message names it).
    Exception
        An exception raised by a closure or an event function (or KeyboardInterrupt) propagates
        unchanged, with ``err.partial``, ``err.step`` and ``err.time`` attached where the
        exception allows.

    See Also
    --------
    check_conservation : the verdict on what the run conserved.
    varmech.ensemble : many runs of one model at once.

    Examples
    --------
    Kepler's problem (e = 0.6) from closures, 10 periods at 200 steps a period:

    >>> import numpy as np
    >>> import varmech
    >>> kepler = varmech.MechanicalSystem(
    ...     2,
    ...     potential=lambda q: -1.0 / np.hypot(q[0], q[1]),
    ...     gradient=lambda q: q / np.hypot(q[0], q[1]) ** 3,
    ...     symmetries=[varmech.Rotation(spatial_dim=2)],
    ... )
    >>> traj = varmech.integrate(kepler, [0.4, 0.0], [0.0, 2.0], dt=2 * np.pi / 200, steps=2000,
    ...                          method="kahan_li8", save_every=100)
    >>> traj.q.shape, traj.nfev
    ((21, 2), 34001)
    >>> print(varmech.check_conservation(traj).verdict)
    bounded

    A built-in scene carries its initial state, and the default method is its kind's:

    >>> traj = varmech.integrate(varmech.scenes.double_pendulum(), dt=0.01, t_end=1.0)
    >>> traj.method, traj.t[-1]
    ('midpoint', np.float64(1.0))
    """
    if isinstance(model, Trajectory):
        given = {
            "q0": q0,
            "p0": p0,
            "v0": v0,
            "dt": dt,
            "method": method,
            "t0": t0,
            "parameters": parameters,
            "t_eval": t_eval,
            "impulses": impulses,
            "contacts": contacts,
        }
        named = [name for name, value in given.items() if value is not None and name != "t_eval"]
        if named:
            raise ValueError(f"{named[0]}: a continued run keeps its trajectory's {', '.join(named)}")
        # The run's own energy check goes on unless one is given.
        keep = max_energy_error == "auto"
        options = RunSpec(
            model.method,
            model.dt,
            save_every=save_every,
            max_energy_error=None if keep else energy_threshold(max_energy_error),
            keep_energy_check=keep,
            output=output,
            overwrite=overwrite,
            checkpoint_every=checkpoint_every,
            progress=progress,
        )
        return _go_on(model, steps, t_end, events, t_eval, options)
    contacts = contacts_of(model, contacts) or None
    model, q0, p0 = model_and_state(model, q0, p0, v0)
    if parameters is not None:
        if not isinstance(parameters, Mapping):
            raise TypeError(f"parameters: expected a dict {{name: value}}, got {type(parameters).__name__}")
        # Keys may be the model's SymPy symbols, whose str is the name.
        model = model.with_parameters(**{str(name): value for name, value in parameters.items()})
    spec = RunSpec.checked(
        model, dt=dt, steps=steps, t_end=t_end, method=method, save_every=save_every, compensated=compensated,
        max_energy_error=max_energy_error, t0=t0, newton_tolerance=newton_tolerance,
        newton_max_iterations=newton_max_iterations, events=events, contacts=contacts, impulses=impulses, t_eval=t_eval,
        output=output, overwrite=overwrite, checkpoint_every=checkpoint_every, progress=progress,
    )
    t0, duration = spec.t0, spec.steps * spec.dt
    q, p = initial_state(model, q0, p0, v0, t0)
    if model.velocity_constraints:
        warn_if_integrable(model, q)
    check_delays(model, bool(spec.jumps), duration)
    probes = (t0, t0 + spec.dt, t0 + 0.5, t0 + 1.0, t0 + 0.37 * duration, t0 + duration)
    starts = "q0, v0" if v0 is not None else "q0, p0"
    _check_time_independent(model, q, p, tuple(s for s in probes if math.isfinite(s)), starts)
    warn_if_unstable(model, spec.method, q, spec.dt, t0)
    return _run(model, spec, (q, p))


def _go_on(
    traj: Trajectory,
    steps: int | None,
    t_end: float | None,
    events: Sequence[_events.Event | _events.EventFunction] | None,
    t_eval: ArrayLike | None,
    options: RunSpec,
) -> Trajectory:
    """``integrate(traj, steps=)``: the run of ``traj`` continued from its checkpoint, watching
    ``events`` from there (terminal counts after ``traj``'s crossings of the same events, an
    energy error from ``traj``'s first energy), keeping the states at ``t_eval`` if given, with
    the saving period, energy check, output and progress of ``options`` (its arguments, not yet
    checked against the run)."""
    contacts = _impacts.going_on(traj.contacts)
    # The checkpoint's time: a trajectory of t_eval times ends at its last sample, not there.
    t_now = going_on_from(traj, "model", "this trajectory").t
    nsteps = step_count(traj.dt, t_now, steps, t_end)
    save_every = positive_int("save_every", options.save_every)
    times = sample_times(t_eval, t_now, t_now + nsteps * traj.dt, save_every, options.output, traj.model.dim)
    jumps = Jumps.of(traj.model, events, contacts, _impulses.going_on(traj.impulses, None, t_now))
    spec = replace(options, steps=nsteps, save_every=save_every, jumps=jumps, times=times, **continuing(traj, jumps))
    return _run(traj.model, spec)


def _run(model: Model, spec: RunSpec, state: tuple[np.ndarray, np.ndarray] | None = None) -> Trajectory:
    """Runs ``model`` as ``spec`` specifies: from ``state`` (q, p: a new run) or from
    ``spec.checkpoint`` (a continued run), in memory, or streamed to ``spec.output`` in
    segments (:mod:`varmech.streaming`). The result reports the crossings of the spec's events,
    then the impacts on its contacts."""
    bar = progress_bar(total=spec.steps, unit="step", desc=spec.method, enabled=spec.progress)
    try:
        if spec.output is not None:
            target = files.writable(spec.output, bool(spec.overwrite), "output")
            streaming.checkpoint_period(spec.checkpoint_every, spec.save_every)
            writer = files.Writer(target, model, spec, argument="output")
            try:
                streaming.stream(writer, model, spec, bar, state)
            except BaseException as err:
                # A file that cannot be read back (a disk that failed) leaves the error as it is.
                with contextlib.suppress(ValueError):
                    err.partial = load(target, model=model, lazy=True)  # type: ignore[attr-defined]
                raise
            return load(target, model=model, lazy=files.larger_than_memory(target))
        if spec.checkpoint_every is not None:
            raise ValueError("checkpoint_every: checkpoints are written to a file; pass output=")

        def report(steps: int) -> None:
            bar.update(steps - spec.base - bar.n)

        shown = None if bar.disable else report
        try:
            if spec.checkpoint is None:
                assert state is not None
                record = spec.start(model, *state, spec.steps, shown)
            else:
                going_on = spec.continued(spec.found, spec.initial_energy)
                record = _core.resume(model._core, spec.checkpoint, going_on, progress=shown)
            bar.update(record.steps - spec.base - bar.n)
        except BaseException as err:
            partial = take_partial(err)
            if partial is not None:
                err.partial = of_record(partial, model, spec, status=-1, message=str(err))  # type: ignore[attr-defined]
                if isinstance(err, _core.DivergenceError):
                    _blame_derivatives(err, model)
            raise
    finally:
        bar.close()
    return of_record(record, model, spec)


def symplecticity_defect(model: Model, method: str, q: ArrayLike, p: ArrayLike, dt: float) -> float:
    """‖ΨᵀJΨ − J‖_F for the Jacobian Ψ of one step of ``method`` from (q, p), J = [[0, I], [−I, 0]].

    Ψ comes from fourth-order central differences of the one-step map; a symplectic method
    gives round-off (≲1e-10 on problems of unit scale), a non-symplectic one O(h^{p+1}).

    Parameters
    ----------
    model
        An unconstrained model.
    method
        The method whose step is tested.
    q, p
        The state the step starts from, shape (n,) each.
    dt
        The step.

    Returns
    -------
    float
        The Frobenius norm of ΨᵀJΨ − J.

    Raises
    ------
    ValueError
        ``q``, ``p`` of the wrong shape or not finite, ``dt`` not positive, or a method that
        does not integrate the model, naming it.

    Examples
    --------
    >>> import varmech
    >>> pendulum = varmech.scenes.pendulum().model
    >>> bool(varmech.symplecticity_defect(pendulum, "verlet", [1.0], [0.5], 0.1) < 1e-10)
    True
    >>> bool(varmech.symplecticity_defect(pendulum, "rk4", [1.0], [0.5], 0.1) > 1e-9)  # O(h⁵): 2.8e-9
    True
    """
    n = model.dim
    return _core.symplecticity_defect(model._core, method, vector("q", q, n), vector("p", p, n), positive("dt", dt))


def _blame_derivatives(err: BaseException, model: Model) -> None:
    """A divergence that a closure model's wrong derivatives explain (:func:`derivatives.blame` at
    the run's last good state) says so, instead of advising to reduce dt."""
    last = err.partial  # type: ignore[attr-defined]
    t = float(last.t[-1])
    advice = blame(model, last.q[-1], last.v[-1], t, f"at the last good state (t = {t:g})")
    if advice is not None:
        err.args = (f"{str(err).replace('; reduce dt', '', 1)}; but {advice}",)
