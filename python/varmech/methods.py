"""The catalogue of integration methods."""

from __future__ import annotations

from dataclasses import dataclass

from . import _core


@dataclass(frozen=True)
class MethodInfo:
    """Facts about one fixed-step method.

    ``h_omega_max`` is the linear stability limit: the method is stable on q'' = -ω²q exactly
    when hω < h_omega_max (0 for explicit Euler, which is never stable).
    ``force_evaluations`` counts gradient evaluations per step, first-same-as-last reused (0 for
    the implicit methods, whose cost depends on their Newton iterations). ``implicit`` methods
    solve each step by Newton's method; ``constrained`` ones (RATTLE, SHAKE) integrate systems
    on holonomic constraints, and only those.
    """

    name: str
    order: int
    stages: int
    force_evaluations: int
    implicit: bool
    constrained: bool
    symplectic: bool
    symmetric: bool
    h_omega_max: float
    reference: str


def methods() -> list[MethodInfo]:
    """Every method varmech integrates with, from the simplest."""
    return [MethodInfo(**d) for d in _core.methods()]


def format_table() -> str:
    """The methods as a Markdown table."""
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
