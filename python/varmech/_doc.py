"""Numpydoc docstrings assembled from their parts, for the scenes and their twins: a function's own
docstring says what it is and shows it (its summary and Examples); :func:`documented` writes the
sections between from the signature and the scene's declaration (:mod:`varmech._catalogue`):
Parameters (types and defaults from the signature, descriptions from :data:`GLOSSARY` unless
given), Returns, Raises, See Also (the twins the declaration names) and References."""

from __future__ import annotations

import inspect
import textwrap
from collections.abc import Callable, Mapping, Sequence
from typing import Any, Literal, TypeVar

from ._catalogue import DECLARED, declared

F = TypeVar("F", bound=Callable[..., object])

#: What a parameter of these names is wherever a scene or a twin takes one.
GLOSSARY = {
    "m": "The mass.",
    "l": "The rod's length.",
    "g": "The gravitational acceleration.",
    "jit": "Compile the model's tapes (Cranelift), or interpret them.",
    "m0": "The initial mass m₀.",
    "k": "The strength of the attraction k/r.",
    "gamma": "The damping γ.",
    "amplitude": "The driving torque's amplitude A.",
    "drive": "The driving frequency Ω.",
    "inertia": "The moment of inertia I about the centre.",
    "blade": "The blade's distance b behind the centre.",
    "radius": "The ball's radius a.",
    "alpha": "The plane's inclination α.",
    "B": "The field at the origin.",
    "kappa": "Its growth κ with |q|²; 0 is the uniform field.",
    "spin": "The initial spin ω_z about the plane's normal.",
    "push": "The driving force F.",
    "l0": "The spring's rest length l₀.",
    "I3": "The moment of inertia about the symmetry axis.",
    "i3": "The moment of inertia about the symmetry axis.",
    "Mgl": "Mass × gravity × the pivot's distance to the centre of mass.",
    "mgl": "Mass × gravity × the pivot's distance to the centre of mass.",
}

_INDENT = "    "
_EXAMPLES = f"\n{_INDENT}Examples\n{_INDENT}--------\n"

#: The function families whose twins the See Also section names, and how it names each.
_TWINS = {
    "scene": "varmech.scenes.{} : the native scene it twins.",
    "closure": "varmech.examples.{} : its closure twin.",
    "symbolic": "varmech.symbolic.examples.{} : its symbolic twin.",
}


def hlw(section: str) -> str:
    """Hairer, Lubich and Wanner's book, at ``section``."""
    return f"E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed., Springer, 2006, Sec. {section}."


#: The variational collision integrators of the impact scenes.
FETECAU = (
    'R. C. Fetecau, J. E. Marsden, M. Ortiz and M. West, "Nonsmooth Lagrangian mechanics and variational collision '
    'integrators", *SIAM J. Appl. Dyn. Syst.* 2 (2003) 381–416.'
)


def bloch(section: str) -> str:
    """Bloch's book on nonholonomic mechanics, at ``section``."""
    return f"A. M. Bloch, *Nonholonomic Mechanics and Control*, Springer, 2003, Sec. {section}."


def _wrap(text: str, indent: str, then: str | None = None) -> list[str]:
    return textwrap.wrap(
        text, 100, initial_indent=indent, subsequent_indent=then or indent, break_long_words=False, break_on_hyphens=False
    )


def _section(title: str, entries: Sequence[tuple[str, str | None]]) -> str:
    """A numpydoc section of ``entries`` (a heading line, and its indented description)."""
    lines = [_INDENT + title, _INDENT + "-" * len(title)]
    for head, body in entries:
        lines += _wrap(head, _INDENT) if body is not None else [_INDENT + head]
        if body:
            lines += _wrap(body, 2 * _INDENT)
    return "\n".join(lines)


def _kind(annotation: object) -> str:
    """A parameter's type as numpydoc writes it, from its annotation (a string: annotations are
    postponed)."""
    text = str(annotation)
    return {"ArrayLike": "array_like", "np.ndarray": "array_like"}.get(text, text.replace(" | ", " or "))


def _parameters(f: Callable[..., object], given: Mapping[str, str | tuple[str, str]]) -> list[tuple[str, str | None]]:
    """The Parameters entries of ``f``, in its signature's order; a key of ``given`` may name
    several parameters that follow each other ("x0, y0"), described together."""
    signature = inspect.signature(f).parameters
    groups = {name: key for key in given for name in key.split(", ")}
    unknown = set(groups) - set(signature)
    if unknown:
        raise TypeError(f"{f.__qualname__}: documents parameters it does not take: {sorted(unknown)}")
    entries: list[tuple[str, str | None]] = []
    for name, parameter in signature.items():
        key = groups.get(name, name)
        if key != name and not key.startswith(name + ","):
            continue  # described with the group's first
        description = given.get(key, GLOSSARY.get(name))
        if description is None:
            raise TypeError(f"{f.__qualname__}: parameter {name} is described neither here nor in the glossary")
        if isinstance(description, tuple):
            kind, description = description
        else:
            kind = _kind(parameter.annotation)
            defaults = [signature[n].default for n in key.split(", ")]
            if parameter.default is not inspect.Parameter.empty:
                shown = [f'"{d}"' if isinstance(d, str) else repr(d) for d in defaults]
                kind += ", default " + " and ".join(shown)
        entries.append((f"{key} : {kind}", description))
    return entries


def documented(
    returns: str,
    *,
    twins: Literal["scene", "closure", "symbolic"] | None = None,
    parameters: Mapping[str, str | tuple[str, str]] | None = None,
    raises: str | Mapping[str, str] | None = None,
    see_also: Sequence[str] = (),
    references: Sequence[str] = (),
) -> Callable[[F], F]:
    """Completes the decorated function's docstring (its summary, then ``Examples``) with the
    sections between, in numpydoc's order.

    ``returns`` describes the returned object, whose type is the return annotation's. ``twins``
    is the function's family: the See Also section names the twins of the scene of the function's
    name in the other families, as its declaration has them, before ``see_also``. ``parameters``
    describes the parameters the glossary does not, or not so (a pair: (type, description)).
    ``raises``: a ValueError's description, or descriptions by exception. ``references``: the
    entries, numbered as the summary cites them ([1]_, …)."""

    def decorate(f: F) -> F:
        head, marker, examples = (f.__doc__ or "").partition(_EXAMPLES)
        if not marker:
            raise TypeError(f"{f.__qualname__}: its docstring needs an Examples section")
        sections = []
        entries = _parameters(f, parameters or {})
        if entries:
            sections.append(_section("Parameters", entries))
        kind = _kind(inspect.signature(f).return_annotation)
        sections.append(_section("Returns", [(kind, returns)]))
        if raises is not None:
            table = {"ValueError": raises} if isinstance(raises, str) else raises
            sections.append(_section("Raises", [(k, v) for k, v in table.items()]))
        name = f.__name__
        declaration = declared(name)
        if twins in ("closure", "symbolic") and name in DECLARED and not getattr(declaration, twins):
            raise TypeError(f"{f.__qualname__}: a {twins} twin of a scene declared without one (varmech._catalogue)")
        family = {"scene": True, "closure": declaration.closure, "symbolic": declaration.symbolic}
        related = [_TWINS[k].format(name) for k, has in family.items() if twins is not None and k != twins and has]
        if related or see_also:
            sections.append(_section("See Also", [(line, None) for line in [*related, *see_also]]))
        if references:
            cited = [line for i, text in enumerate(references, 1) for line in _wrap(f".. [{i}] {text}", _INDENT, _INDENT + "   ")]
            sections.append("\n".join([_INDENT + "References", _INDENT + "-" * 10, *cited]))
        f.__doc__ = head.rstrip() + "\n\n" + "\n\n".join(sections) + "\n" + _EXAMPLES + examples
        return f

    return decorate


def scene_doc(returns: str, **sections: Any) -> Callable[[F], F]:
    """:func:`documented` for a scene function of :mod:`varmech.scenes`."""
    return documented(returns, twins="scene", **sections)


def closure_doc(returns: str, **sections: Any) -> Callable[[F], F]:
    """:func:`documented` for a closure twin of :mod:`varmech.examples`."""
    return documented(returns, twins="closure", **sections)


def symbolic_doc(returns: str, **sections: Any) -> Callable[[F], F]:
    """:func:`documented` for a symbolic twin of :mod:`varmech.symbolic.examples`."""
    return documented(returns, twins="symbolic", **sections)
