"""SymPy expressions as plain data (JSON lists) and back, for files that must not run code.

A node is ``[class name, *arguments]``. Only the classes a compiled model is made of are
known (symbols, numbers, constants, sums, products, powers and the tape's functions): decoding
builds each with its class's constructor from already-decoded SymPy objects and with
``evaluate=False``, so that no string is ever parsed (:func:`sympy.sympify`, ``srepr`` and
``eval`` would run code) and no crafted power is ever computed.
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from ._lower import UNARY

#: The compound classes by name: built as ``cls(*arguments, evaluate=False)``.
COMPOUND: dict[str, type[sp.Basic]] = {
    cls.__name__: cls
    for cls in (sp.Add, sp.Mul, sp.Pow, sp.atan2, sp.DiracDelta, sp.Heaviside, *UNARY)
}
#: The constants without arguments by name (π, e, ...): SymPy's singletons.
CONSTANTS = {
    name: getattr(sp.S, name)
    for name in ("Pi", "Exp1", "EulerGamma", "Catalan", "GoldenRatio", "TribonacciConstant", "Infinity",
                 "NegativeInfinity", "NaN", "ComplexInfinity", "ImaginaryUnit")
}


def encode(expr: sp.Basic) -> list[Any]:
    """``expr`` as data; TypeError naming the first node of a class that is not known."""
    name = type(expr).__name__
    if isinstance(expr, sp.Dummy):
        return ["Dummy", expr.name, expr.dummy_index, _assumptions(expr)]
    if isinstance(expr, sp.Symbol) and type(expr) is sp.Symbol:
        return ["Symbol", expr.name, _assumptions(expr)]
    if isinstance(expr, sp.Integer):
        return ["Integer", int(expr)]
    if isinstance(expr, sp.Rational):
        return ["Rational", int(expr.p), int(expr.q)]
    if isinstance(expr, sp.Float):
        sign, mantissa, exponent, bits = expr._mpf_
        return ["Float", [int(sign), int(mantissa), int(exponent), int(bits)], int(expr._prec)]
    if name in CONSTANTS and expr is CONSTANTS[name]:
        return [name]
    if COMPOUND.get(name) is type(expr):
        return [name, *(encode(a) for a in expr.args)]
    raise TypeError(f"{expr}: a {name} is not stored as data")


def decode(data: Any) -> Any:
    """The expression of :func:`encode`'s ``data``; TypeError or ValueError when it is not one."""
    if not isinstance(data, list) or not data or not isinstance(data[0], str):
        raise TypeError(f"{str(data)[:80]} is not an expression node")
    name, arguments = data[0], data[1:]
    if name in ("Symbol", "Dummy"):
        *naming, assumptions = arguments
        if not isinstance(naming[0], str) or not isinstance(assumptions, dict):
            raise TypeError("a symbol is a name and its assumptions")
        if not all(isinstance(k, str) and type(v) is bool for k, v in assumptions.items()):
            raise TypeError("a symbol's assumptions are names and booleans")
        if name == "Dummy":
            return sp.Dummy(naming[0], dummy_index=_integer(naming[1]), **assumptions)
        return sp.Symbol(naming[0], **assumptions)
    if name == "Integer":
        return sp.Integer(_integer(arguments[0]))
    if name == "Rational":
        return sp.Rational(_integer(arguments[0]), _integer(arguments[1]))
    if name == "Float":
        sign, mantissa, exponent, bits = (_integer(x) for x in arguments[0])
        return sp.Float._new((sign, mantissa, exponent, bits), _integer(arguments[1]))
    if name in CONSTANTS and not arguments:
        return CONSTANTS[name]
    cls = COMPOUND.get(name)
    if cls is None:
        raise TypeError(f"{name!r} is not a known expression class")
    return cls(*(decode(a) for a in arguments), evaluate=False)


def _assumptions(symbol: sp.Symbol) -> dict[str, bool]:
    """The assumptions the symbol was made with (``Symbol("x", real=True)``'s)."""
    return {k: bool(v) for k, v in symbol._assumptions_orig.items() if v is not None}


def _integer(x: Any) -> int:
    if type(x) is not int:
        raise TypeError(f"{x!r} is not an integer")
    return x
