"""Lowering: SymPy expressions to one SSA instruction tape.

A tape is a list of instructions ``[code, a, b]``; instruction i defines register i from
earlier registers (or from a constant, an input slot or a parameter). The outputs of one
function share one tape: ``sympy.cse`` finds their common subexpressions first, and every
constant, input, parameter and instruction is emitted once (hash-consing), so a value used
twice is computed once.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import sympy as sp

#: The tape's operations in the order of the contract with the core (``_core.TAPE_OPS``): the
#: code of an operation is its index. Unary operations read register ``a``; binary ones
#: ``a`` and ``b``; ``const`` reads constant ``a``, ``input`` slot ``a``, ``param`` parameter
#: ``a``; ``powi`` raises register ``a`` to the integer ``b``.
TAPE_OPS: tuple[str, ...] = (
    "const",
    "input",
    "param",
    "neg",
    "sqrt",
    "exp",
    "log",
    "sin",
    "cos",
    "tan",
    "asin",
    "acos",
    "atan",
    "sinh",
    "cosh",
    "tanh",
    "asinh",
    "acosh",
    "atanh",
    "abs",
    "sign",
    "add",
    "sub",
    "mul",
    "div",
    "pow",
    "atan2",
    "powi",
)
CODE = {name: code for code, name in enumerate(TAPE_OPS)}

#: SymPy's functions of one argument that are tape operations.
UNARY: dict[type, str] = {
    sp.sin: "sin",
    sp.cos: "cos",
    sp.tan: "tan",
    sp.asin: "asin",
    sp.acos: "acos",
    sp.atan: "atan",
    sp.sinh: "sinh",
    sp.cosh: "cosh",
    sp.tanh: "tanh",
    sp.asinh: "asinh",
    sp.acosh: "acosh",
    sp.atanh: "atanh",
    sp.exp: "exp",
    sp.log: "log",
    sp.Abs: "abs",
    sp.sign: "sign",
}

Tape = tuple[np.ndarray, np.ndarray, np.ndarray]


class _Builder:
    """The tape of one function under construction: instructions, constants, and the register
    of every value already emitted."""

    def __init__(self, slots: Mapping[sp.Symbol, int], parameters: Mapping[sp.Symbol, int]):
        self.slots = slots
        self.parameters = parameters
        self.ops: list[tuple[int, int, int]] = []
        self.constants: list[float] = []
        self.rows: dict[tuple[int, int, int], int] = {}
        # Constants by their bits, so that −0.0 and 0.0 stay apart and NaN finds itself.
        self.constant_rows: dict[str, int] = {}
        self.values: dict[sp.Expr, int] = {}

    def emit(self, op: str, a: int, b: int = 0) -> int:
        """The register of ``op(a, b)``, emitted unless an equal instruction already was."""
        row = (CODE[op], a, b)
        register = self.rows.get(row)
        if register is None:
            register = self.rows[row] = len(self.ops)
            self.ops.append(row)
        return register

    def constant(self, value: float) -> int:
        register = self.constant_rows.get(value.hex())
        if register is None:
            self.constants.append(value)
            register = self.constant_rows[value.hex()] = self.emit("const", len(self.constants) - 1)
        return register

    def lower(self, expr: sp.Expr) -> int:
        """The register holding ``expr``."""
        register = self.values.get(expr)
        if register is None:
            register = self.values[expr] = self._lower(expr)
        return register

    def _lower(self, expr: sp.Expr) -> int:
        if expr.is_Symbol:
            return self._symbol(expr)
        if expr.is_Number or isinstance(expr, sp.NumberSymbol):
            return self.constant(_real(expr))
        if expr.is_Add:
            return self._add(expr)
        if expr.is_Mul:
            return self._mul(expr)
        if expr.is_Pow:
            return self._pow(expr.base, expr.exp)
        if isinstance(expr, sp.atan2):
            return self.emit("atan2", self.lower(expr.args[0]), self.lower(expr.args[1]))
        op = UNARY.get(type(expr))
        if op is not None and len(expr.args) == 1:
            return self.emit(op, self.lower(expr.args[0]))
        raise ValueError(f"{expr}: cannot be compiled: {unsupported(expr)}")

    def _symbol(self, symbol: sp.Symbol) -> int:
        if symbol in self.slots:
            return self.emit("input", self.slots[symbol])
        if symbol in self.parameters:
            return self.emit("param", self.parameters[symbol])
        raise ValueError(f"{symbol}: symbol is neither a coordinate, a velocity, t, nor a parameter")

    def _add(self, expr: sp.Expr) -> int:
        """A sum as a chain of add and sub, left to right: terms with a negative coefficient
        are subtracted, and a numeric term comes last (x − 1, not −1 + x)."""
        terms = sorted(expr.args, key=lambda term: (bool(term.is_number), _negative(term)))
        total = None
        for term in terms:
            negative = _negative(term)
            register = self.lower(-term if negative else term)
            if total is None:
                total = self.emit("neg", register) if negative else register
            else:
                total = self.emit("sub" if negative else "add", total, register)
        assert total is not None
        return total

    def _mul(self, expr: sp.Expr) -> int:
        """A product as numerator / denominator, each a chain of mul, the numeric coefficient
        first (−1 becomes neg)."""
        coefficient, rest = expr.as_coeff_Mul()
        numerator: list[sp.Expr] = []
        denominator: list[sp.Expr] = []
        for factor in sp.Mul.make_args(rest):
            if factor.is_Pow and factor.exp.is_Number and factor.exp < 0:
                denominator.append(sp.Pow(factor.base, -factor.exp))
            else:
                numerator.append(factor)
        negate = coefficient == -1
        if coefficient not in (1, -1) or not numerator:
            numerator.insert(0, abs(coefficient) if negate else coefficient)
        value = self._product(numerator)
        if denominator:
            value = self.emit("div", value, self._product(denominator))
        return self.emit("neg", value) if negate else value

    def _product(self, factors: Sequence[sp.Expr]) -> int:
        value = self.lower(factors[0])
        for factor in factors[1:]:
            value = self.emit("mul", value, self.lower(factor))
        return value

    def _pow(self, base: sp.Expr, exponent: sp.Expr) -> int:
        """bⁿ by powi, b^(k/2) by sqrt (times powi for k ≠ ±1), b^(−k/2) as 1/b^(k/2), and any
        other exponent by pow."""
        if exponent.is_Integer:
            return self.emit("powi", self.lower(base), int(exponent))
        if exponent.is_Rational and exponent.q == 2:
            if exponent < 0:
                return self.emit("div", self.constant(1.0), self._pow(base, -exponent))
            root = self.emit("sqrt", self.lower(base))
            whole = int(exponent.p) // 2
            if whole == 0:
                return root
            power = self.lower(base) if whole == 1 else self.emit("powi", self.lower(base), whole)
            return self.emit("mul", power, root)
        return self.emit("pow", self.lower(base), self.lower(exponent))

    def tape(self, outputs: Sequence[int]) -> Tape:
        ops = np.array(self.ops, dtype=np.int64).reshape(-1, 3)
        return ops, np.array(self.constants, dtype=np.float64), np.array(outputs, dtype=np.int64)


def _negative(term: sp.Expr) -> bool:
    """Whether a term of a sum carries a negative numeric coefficient."""
    coefficient, _ = term.as_coeff_Mul()
    return bool(coefficient.is_negative)


def _real(number: sp.Expr) -> float:
    """A SymPy number as a float; ValueError for a complex or infinite-complex one."""
    try:
        return float(number)
    except TypeError:
        raise ValueError(f"{number}: cannot be compiled: not a real number") from None


def unsupported(expr: sp.Expr) -> str:
    """Why the head of an expression cannot be compiled, for the error message."""
    if isinstance(expr, sp.Function):
        return f"unsupported function {expr.func.__name__}"
    if isinstance(expr, sp.Derivative):
        return "an unevaluated derivative (write it out, or use the velocity symbols)"
    return f"unsupported expression {type(expr).__name__}"


def _compilable(node: sp.Basic) -> bool:
    """Whether the head of ``node`` is a tape operation, a symbol or a real number."""
    if node.is_Atom:
        return bool(node.is_Symbol or node.is_Number or isinstance(node, sp.NumberSymbol))
    return bool(node.is_Add or node.is_Mul or node.is_Pow or isinstance(node, sp.atan2)) or (
        type(node) in UNARY and len(node.args) == 1
    )


def check_compilable(expr: sp.Expr, what: str) -> None:
    """ValueError naming ``what``, the offending subexpression and the reason, when ``expr``
    holds anything the tape cannot compute (checked before deriving, so that the message shows
    the user's expression rather than its derivative)."""
    for node in sp.preorder_traversal(expr):
        if not _compilable(node):
            raise ValueError(f"{what}: {node} cannot be compiled: {unsupported(node)}")


def _without_delta(expr: sp.Expr) -> sp.Expr:
    """``expr`` with every DiracDelta (and derivative of one) 0 (replace walks the whole tree
    and rebuilds it: only where one is found)."""
    if expr.is_Atom or not expr.has(sp.DiracDelta):
        return expr
    return expr.replace(sp.DiracDelta, lambda *args: sp.S.Zero)


def lower(expressions: Sequence[sp.Expr], slots: Mapping[sp.Symbol, int], parameters: Mapping[sp.Symbol, int]) -> Tape:
    """The tape of one function: ``(ops, constants, outputs)``, with ops an int64 array (k, 3)
    of rows ``[code, a, b]`` (codes from :data:`TAPE_OPS`), constants a float64 array and
    outputs the int64 registers of ``expressions`` in order.

    ``slots`` maps a symbol to its input slot (qᵢ → i, q̇ᵢ → n + i, t → 2n), ``parameters``
    to its index in the parameter vector. ``DiracDelta`` (the derivative of sign, and its
    derivatives) is 0: it vanishes almost everywhere. ValueError names an expression that cannot be
    compiled and the reason (an unsupported function, or a symbol that is neither an input nor
    a parameter).

    Examples
    --------
    >>> import sympy as sp
    >>> x, k = sp.symbols("x k")
    >>> ops, constants, outputs = lower([k * sp.sin(x) ** 2], {x: 0}, {k: 0})
    >>> [TAPE_OPS[code] for code in ops[:, 0]]
    ['param', 'input', 'sin', 'powi', 'mul']
    >>> outputs.tolist()
    [4]
    """
    # DiracDelta (sign' and |x|'', and its derivatives) vanishes wherever it is defined: 0, before
    # the common subexpressions, so that the terms it multiplies go too.
    expressions = [_without_delta(sp.sympify(e)) for e in expressions]
    # Only compound expressions go through cse: the zeros of a large Hessian (3n² outputs, nearly
    # all 0 for a chain) cost it time and share nothing.
    compound = [e for e in expressions if not e.is_Atom]
    replacements, reduced = sp.cse(compound, symbols=sp.numbered_symbols("_cse", cls=sp.Dummy), order="none")
    builder = _Builder(slots, parameters)
    for symbol, expr in replacements:
        builder.values[symbol] = builder.lower(expr)
    shared = iter(reduced)
    return builder.tape([builder.lower(expr if expr.is_Atom else next(shared)) for expr in expressions])
