"""The base of varmech's warnings, and the warning of derivatives taken by differences.

Every warning varmech issues is a :class:`VarmechWarning`, so that one filter takes them all
(``warnings.simplefilter("ignore", varmech.VarmechWarning)``); each kind has its own class,
defined beside what issues it.
"""

from __future__ import annotations

__all__ = ["DerivativeWarning", "VarmechWarning"]


class VarmechWarning(UserWarning):
    """Base class of varmech's warnings: filter it to filter any of them.

    Its subclasses: :class:`DerivativeWarning`, :class:`StabilityWarning`,
    :class:`IntegrableConstraintsWarning`, :class:`ImpactWarning` and
    :class:`~varmech.analysis.reference.ReferenceWarning`. It is a :class:`UserWarning`.

    Examples
    --------
    >>> import warnings, varmech
    >>> issubclass(varmech.StabilityWarning, varmech.VarmechWarning)
    True
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("error", varmech.VarmechWarning)
    ...     try:
    ...         varmech.integrate(varmech.scenes.pendulum(), dt=2.5, steps=10, max_energy_error=None)
    ...     except varmech.StabilityWarning as w:
    ...         print(type(w).__name__)
    StabilityWarning
    """


class DerivativeWarning(VarmechWarning):
    """A derivative the model did not give is taken by central differences: about 1e-10
    relative accuracy, and two calls of the function a coordinate. Give the derivative (or use
    a SymPy model, whose derivatives are derived) to silence it.

    Examples
    --------
    >>> import warnings, varmech
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     model = varmech.Lagrangian(1, lambda q, v, t: 0.5 * v @ v - 0.5 * q @ q)
    >>> [type(w.message).__name__ for w in caught]
    ['DerivativeWarning']
    """
