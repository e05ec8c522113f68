"""The catalogue of integration methods."""

from __future__ import annotations

from . import _core

__all__ = [
    "MethodInfo",
    "method_info",
    "methods",
]

#: Facts about one fixed-step method (name, order, stages, force_evaluations, implicit,
#: constrained, symplectic, symmetric, h_omega_max, reference, splitting, features): see
#: ``_core.MethodInfo``.
MethodInfo = _core.MethodInfo


def methods() -> list[MethodInfo]:
    """Every method varmech integrates with, from the simplest.

    Returns
    -------
    list of MethodInfo
        One record a method: ``name``, ``order``, ``stages``, ``force_evaluations`` a step,
        ``implicit``, ``constrained``, ``nbody``, ``symplectic``, ``symmetric``, the linear
        stability limit ``h_omega_max`` on q̈ = −ω²q (inf: none; nan: not defined), its
        ``reference``, and ``features``, what its step offers beyond the models it integrates
        (``"discrete_energy"``, ``"tangent_map"``, ``"held_step"``, ``"delayed_forces"``).

    Examples
    --------
    >>> import varmech
    >>> verlet = {m.name: m for m in varmech.methods()}["verlet"]
    >>> verlet.order, verlet.force_evaluations, verlet.symplectic, verlet.h_omega_max
    (2, 1, True, 2.0)
    >>> [m.name for m in varmech.methods() if "delayed_forces" in m.features]
    ['midpoint', 'trapezoid']
    """
    return _core.methods()


def method_info(name: str) -> MethodInfo:
    """The facts of the method called ``name``.

    Parameters
    ----------
    name : str
        A method's name, as in :func:`methods`.

    Returns
    -------
    MethodInfo
        Its record.

    Raises
    ------
    ValueError
        No method has that name (the message names the argument ``method``).

    Examples
    --------
    >>> from varmech.methods import method_info
    >>> info = method_info("kahan_li8")
    >>> info.order, info.symplectic, info.implicit
    (8, True, False)
    """
    for m in _core.methods():
        if m.name == name:
            return m
    raise ValueError(f"method: no method {name!r}; see varmech.methods()")


def format_table() -> str:
    """The methods as a Markdown table.

    Returns
    -------
    str
        A header row, a separator, then one row a method: order, force evaluations a step
        ("Newton" for implicit methods), symplectic, symmetric and hω_max.

    Examples
    --------
    >>> from varmech.methods import format_table
    >>> for line in format_table().splitlines()[:3]:
    ...     print(line)
    | method | order | force evaluations / step | symplectic | symmetric | hω_max |
    |---|---|---|---|---|---|
    | `explicit_euler` | 1 | 1 | no | no | 0 |
    """
    rows = [
        "| method | order | force evaluations / step | symplectic | symmetric | hω_max |",
        "|---|---|---|---|---|---|",
    ]
    for m in methods():
        yes = lambda b: "yes" if b else "no"  # noqa: E731
        rows.append(
            f"| `{m.name}` | {m.order} | {'Newton' if m.implicit else m.force_evaluations} | {yes(m.symplectic)} | "
            f"{yes(m.symmetric)} | {m.h_omega_max:.4g} |"
        )
    return "\n".join(rows)
