"""Pickling and documentation of varmech's exceptions (defined in the core binding, module
``varmech``).

Pickling: an error keeps its message and its attributes (``step``, ``time``, ``residual``,
``iterations`` and the partial trajectory ``partial``), so that it crosses process boundaries
(multiprocessing, concurrent.futures). The partial trajectory travels without its model: models
hold native objects or closures, which do not pickle; its states, times and counts are all kept.

Documentation: the binding gives each class a one-line docstring; the numpydoc docstrings below
(attributes and a run that fails) replace them when :func:`install` runs, at import, and are
the doctests of this module (``__test__``).
"""

from __future__ import annotations

import dataclasses
from typing import Any

from ._core import ContactError, ConvergenceError, DivergenceError, SpuriousBranchError, VarmechError

_VARMECH_ERROR = """Base class of varmech's errors: catch it to catch any of them.

    A run that fails raises a subclass (:class:`DivergenceError`, :class:`ConvergenceError`,
    :class:`SpuriousBranchError`, :class:`ContactError`); a VarmechError itself means
    a model's evaluation failed in the core without a Python exception of its own, or an event
    function returned a value that is not finite. Bad arguments are ValueError or TypeError,
    never a VarmechError. It is a :class:`RuntimeError`.

    Attributes
    ----------
    step : int
        The step that failed (1 for the first), where a run failed.
    time : float
        The time tₙ at the start of that step.
    partial : Trajectory
        The run up to the last good step, with ``status`` -1 and the error's message as its
        ``message``.

    See Also
    --------
    varmech.integrate : what raises them, with the attributes each carries.

    Examples
    --------
    The pendulum with a step of half its period blows up at once:

    >>> import varmech
    >>> try:
    ...     varmech.integrate(varmech.scenes.pendulum(), dt=3.0, steps=100)
    ... except varmech.VarmechError as err:
    ...     print(type(err).__name__, err.step, err.partial.status, len(err.partial))
    DivergenceError 1 -1 2
    """

# The attributes that say where a run failed, as DivergenceError, ConvergenceError and
# SpuriousBranchError have them, put into their docstrings for ``{failed step}``.
_FAILED_STEP = """Attributes
    ----------
    step : int
        The step that failed (1 for the first).
    time : float
        The time tₙ at the start of that step."""

_DIVERGENCE_ERROR = """The solution blew up: a non-finite state, or an energy error beyond ``max_energy_error``.

    :func:`varmech.integrate` checks the energy error |E − E₀| at each saved state against
    ``max_energy_error`` times the energy's scale (the mean kinetic energy so far). Beyond it,
    the error stops the run at once where the step is beyond the method's stability limit at
    the first state, and, within the limit, where it grows (from the 64th saved state on, at
    least twice the largest error while the run was half as long), or the state does (max |qᵢ|,
    so judged): the bounded offset of a
    symplectic method's modified energy at a coarse stable step runs to the end, however
    large. A state that is not finite always stops the run. The usual cure is a smaller step.

    {failed step}
    partial : Trajectory
        The run up to the last good step (``status`` -1): the states before the blow-up, to
        look at or to go on from with a smaller step.

    See Also
    --------
    varmech.conservation.FAILURE : the default threshold, the error of a "failed" verdict.

    Examples
    --------
    Verlet at h = 3 on the pendulum (period ≈ 6.7), beyond its limit hω = 2: the energy error
    after one step is 4.4 times the kinetic energy.

    >>> import varmech
    >>> try:
    ...     varmech.integrate(varmech.scenes.pendulum(), dt=3.0, steps=100)
    ... except varmech.DivergenceError as err:
    ...     print(err.step, err.time, err.partial.t)
    1 3.0 [0. 3.]

    Released from rest with its rod horizontal (q = π/2, where it has no small oscillation to
    bound the step), the same pendulum swings through its bottom at hω = 3 and is thrown over
    its top: the check stops it while its angle grows.

    >>> import math
    >>> try:
    ...     varmech.integrate(varmech.scenes.pendulum(), [math.pi / 2], [0.0], dt=3.0, steps=1000)
    ... except varmech.DivergenceError as err:
    ...     print(err.step, "and the state growing" in str(err))
    107 True
    """

_CONVERGENCE_ERROR = """Newton's method did not solve a step's implicit equations; the message says what helps.

    The implicit methods (``midpoint``, ``trapezoid``, the Galerkin and constrained ones) solve
    each step's discrete Euler–Lagrange equations D₂L_d(qₙ₋₁, qₙ) + D₁L_d(qₙ, qₙ₊₁) = 0 by
    Newton's method; it fails after ``newton_max_iterations`` iterations without reaching
    ``newton_tolerance`` (arguments of :func:`varmech.integrate`) or the noise floor of the
    equations. The advice comes from the iteration's course: a smaller step where the
    predictor lies outside Newton's region, the model's second derivatives where they disagree
    with the first, its smoothness where the corrections stall far above the noise, more
    iterations where they were still falling.

    {failed step}
    residual : float
        ‖F‖∞, the max-norm of the step's equations F(qₙ₊₁) = 0 at the last iterate.
    iterations : int
        The iterations made.
    partial : Trajectory
        The run up to the last good step (``status`` -1).

    See Also
    --------
    SpuriousBranchError : Newton converged, but beyond a fold of the discrete map.

    Examples
    --------
    One Newton iteration a step is too few for the double pendulum:

    >>> import varmech
    >>> try:
    ...     varmech.integrate(varmech.scenes.double_pendulum(), dt=0.1, steps=10, newton_max_iterations=1)
    ... except varmech.ConvergenceError as err:
    ...     print(err.step, err.iterations, f"{err.residual:.1e}", len(err.partial))
    1 1 3.1e-02 1
    """

_SPURIOUS_BRANCH_ERROR = """A step's implicit equations were solved beyond a fold of the DEL map (take a smaller step).

    The solution found lies on a branch that need not continue the trajectory. Near a fold the
    derivative of the discrete Euler–Lagrange equations in qₙ₊₁ changes sign, and Newton's
    method can converge to a solution qₙ₊₁ that is not the continuation of the trajectory (a
    pendulum jumping over the top with too little energy). A subclass of
    :class:`ConvergenceError`, whose ``residual`` and ``iterations`` it does not set.

    {failed step}
    partial : Trajectory
        The run up to the last good step (``status`` -1).

    See Also
    --------
    ConvergenceError : Newton's method did not converge at all.

    Examples
    --------
    The pendulum from rest at q = 3 (E = −cos 3 < 1) with the midpoint rule at h = 3:

    >>> import varmech
    >>> try:
    ...     varmech.integrate(varmech.scenes.pendulum(), [3.0], [0.0], dt=3.0, steps=10, method="midpoint")
    ... except varmech.SpuriousBranchError as err:
    ...     print(err.step, err.time, len(err.partial))
    1 0.0 1
    """

_CONTACT_ERROR = """A contact could not be resolved: a non-finite state through an impact, a body that
    crosses the surface again at once after leaving it (a resting or grazing contact), more than
    64 impacts in one step (an accumulation of impacts, as of a ball coming to rest), or a held
    contact's solve that failed.

    A held contact's solves (its position constraint, momentum projection and friction) stop at
    the round-off floor of what they combine; one that fails says which, its residual against
    that floor, and what its diagnosis found: a step past the surface's curvature radius (a
    smaller step helps), a gradient that is not ∇φ, φ losing its precision, or dependent
    normals (a smaller step does not help).

    A ball with e < 1 bounces ever lower and faster, and its impacts accumulate at a finite
    time. Under verlet and its compositions the contact then closes and holds the ball (see
    :mod:`varmech.impacts`); other methods cannot hold it, and raise this error there: stop
    the run before it (a terminal event), or take such a method.

    Attributes
    ----------
    step : int
        The step in which the impact failed (1 for the first).
    time : float
        The time tₙ at the start of that step.
    partial : Trajectory
        The run up to the last good step (``status`` -1), with the impacts resolved so far in
        its ``events``.

    See Also
    --------
    varmech.Contact : the surfaces and their coefficients of restitution.

    Examples
    --------
    A ball with e = 0.5 comes to rest on the floor at t = (1 + 2e/(1 − e))√(2h₀/g) ≈ 1.35;
    rk4 cannot hold the floor:

    >>> import numpy as np, varmech
    >>> ball = varmech.MechanicalSystem(1, lambda q: 9.81 * q[0], lambda q: np.array([9.81]))
    >>> floor = varmech.Contact.wall(0, restitution=0.5, law="reflect")
    >>> try:
    ...     varmech.integrate(ball, [1.0], [0.0], dt=0.01, t_end=2.0, contacts=[floor], method="rk4")
    ... except varmech.ContactError as err:
    ...     print(err.step, round(err.time, 2), len(err.partial.events[0]), err.partial.status)
    136 1.35 8 -1
    """

#: The numpydoc docstrings of the binding's exceptions, which :func:`install` sets.
DOCSTRINGS: dict[type[BaseException], str] = {
    cls: doc.replace("{failed step}", _FAILED_STEP)
    for cls, doc in {
        VarmechError: _VARMECH_ERROR,
        DivergenceError: _DIVERGENCE_ERROR,
        ConvergenceError: _CONVERGENCE_ERROR,
        SpuriousBranchError: _SPURIOUS_BRANCH_ERROR,
        ContactError: _CONTACT_ERROR,
    }.items()
}

#: The docstrings' examples, for doctest (the classes belong to module ``varmech``).
__test__ = {cls.__name__: doc for cls, doc in DOCSTRINGS.items()}


def _reduce(error: BaseException) -> tuple[Any, ...]:
    state = dict(error.__dict__)
    partial = state.get("partial")
    if dataclasses.is_dataclass(partial) and not isinstance(partial, type):
        state["partial"] = dataclasses.replace(partial, model=None)
    return (type(error), error.args, state)


def install() -> None:
    """Makes VarmechError and its subclasses pickle with their attributes, and gives them their
    numpydoc docstrings."""
    VarmechError.__reduce__ = _reduce  # type: ignore[assignment,method-assign]
    for cls, doc in DOCSTRINGS.items():
        cls.__doc__ = doc
