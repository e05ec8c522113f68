"""Compiled functions from elsewhere: model functions given as native function pointers.

Every pointer has the one C signature :data:`C_SIGNATURE`::

    int32_t f(const double *q, const double *v, double t, int64_t n, double *out)

It reads q and q̇ (``n`` numbers each) at time ``t``, writes its outputs to ``out`` and returns
0; any other status stops the run with a :class:`varmech.VarmechError` naming the function and
the status. Functions of q alone (the potential and its gradient) get ``v`` pointing at n zeros
and ``t = 0``. The core calls them with no Python in the loop and the GIL released.

Accepted are a ``numba.cfunc`` compiled with :data:`SIGNATURE`, a ctypes function pointer of
the prototype :data:`CFUNCTYPE`, a cffi function pointer, and a ``scipy.LowLevelCallable``; the
signature of each is checked when the model is built, before any step.

Examples
--------
>>> import ctypes, math
>>> import varmech
>>> @varmech.pointers.CFUNCTYPE
... def potential(q, v, t, n, out):
...     out[0] = 0.5 * q[0] * q[0]
...     return 0
>>> @varmech.pointers.CFUNCTYPE
... def gradient(q, v, t, n, out):
...     out[0] = q[0]
...     return 0
>>> oscillator = varmech.MechanicalSystem(1, potential, gradient)
>>> traj = varmech.integrate(oscillator, [1.0], [0.0], dt=0.01, steps=100)
>>> bool(abs(traj.q[-1, 0] - math.cos(1.0)) < 1e-5)
True

(A ctypes callback of a Python function runs Python per call; compile it with numba for speed.)
"""

from __future__ import annotations

import ctypes
import re
import sys
from collections.abc import Callable
from typing import Any

import numpy as np

from ._core import VarmechError

__all__ = ["CFUNCTYPE", "C_SIGNATURE", "SIGNATURE", "Function", "address", "functions", "is_pointer"]

#: The numba signature of every pointer: ``@numba.cfunc(varmech.pointers.SIGNATURE)``.
SIGNATURE = "int32(CPointer(float64), CPointer(float64), float64, int64, CPointer(float64))"

#: The same signature in C.
C_SIGNATURE = "int32_t f(const double *q, const double *v, double t, int64_t n, double *out)"

_DOUBLE_P = ctypes.POINTER(ctypes.c_double)

#: The ctypes prototype of every pointer; ``CFUNCTYPE(python_function)`` or
#: ``CFUNCTYPE(address)`` makes one.
CFUNCTYPE = ctypes.CFUNCTYPE(ctypes.c_int32, _DOUBLE_P, _DOUBLE_P, ctypes.c_double, ctypes.c_int64, _DOUBLE_P)

# The base class of ctypes function pointers.
_FUNCTION_POINTER = CFUNCTYPE.__bases__[0]

# The C type names a signature string may spell each parameter with (sizes as on this platform).
_INT32 = {"int32_t"} | ({"int"} if ctypes.sizeof(ctypes.c_int) == 4 else set())
_INT64 = {"int64_t", "long long"} | ({"long"} if ctypes.sizeof(ctypes.c_long) == 8 else set())
_PARAMETERS = ({"double*"}, {"double*"}, {"double"}, _INT64, {"double*"})


def _expected(name: str) -> str:
    return f"{name}: expected a function pointer of signature {C_SIGNATURE} (numba: @cfunc({SIGNATURE!r}))"


def _pointer_kind(obj: Any) -> str | None:
    """Which kind of function pointer ``obj`` is meant to be, or None for anything else."""
    if isinstance(obj, int) and not isinstance(obj, bool):
        return "int"
    if isinstance(obj, _FUNCTION_POINTER):
        return "ctypes"
    if isinstance(obj, Function):
        return "varmech"
    module = type(obj).__module__
    if module.startswith("numba") and type(obj).__name__ == "CFunc":
        return "numba"
    if module == "scipy._lib._ccallback" and type(obj).__name__ == "LowLevelCallable":
        return "scipy"
    if module == "_cffi_backend":
        return "cffi"
    return None


def is_pointer(obj: Any) -> bool:
    """Whether ``obj`` is meant as a function pointer (a numba cfunc, a ctypes or cffi function
    pointer, a ``scipy.LowLevelCallable``, or a raw int address, which is refused) rather than a
    Python closure.

    Only the kind of object is looked at, not its signature (:func:`address` checks that).

    Parameters
    ----------
    obj : object
        A model function as given.

    Returns
    -------
    bool
        True for the kinds of function pointer above (and :class:`Function`).

    Examples
    --------
    >>> import ctypes
    >>> from varmech import pointers
    >>> @pointers.CFUNCTYPE
    ... def gradient(q, v, t, n, out):
    ...     out[0] = q[0]
    ...     return 0
    >>> pointers.is_pointer(gradient), pointers.is_pointer(lambda q: q)
    (True, False)
    """
    return _pointer_kind(obj) is not None


def _same_prototype(pointer: Any) -> bool:
    """Whether a ctypes function pointer has exactly the types of :data:`CFUNCTYPE`."""
    argtypes = tuple(getattr(pointer, "argtypes", None) or ())
    return argtypes == tuple(CFUNCTYPE._argtypes_) and getattr(pointer, "restype", None) is CFUNCTYPE._restype_


def _c_signature_matches(signature: str) -> bool:
    """Whether a C signature string ``"int (double *, double *, double, long, double *)"`` (the
    form of scipy's capsule names and cffi's types) is :data:`C_SIGNATURE`; ``const`` is allowed
    on q and v."""
    match = re.fullmatch(r"\s*([\w ]+?)\s*(?:\(\s*\*\s*\))?\s*\((.*)\)\s*", signature)
    if match is None:
        return False
    params = [re.sub(r"\bconst\b", "", p) if i < 2 else p for i, p in enumerate(match[2].split(","))]
    params = [" ".join(p.split()).replace(" *", "*") for p in params]
    return match[1].strip() in _INT32 and len(params) == 5 and all(p in ok for p, ok in zip(params, _PARAMETERS))


def _capsule_pointer(capsule: Any, name: str) -> int:
    get = ctypes.pythonapi.PyCapsule_GetPointer
    get.restype, get.argtypes = ctypes.c_void_p, [ctypes.py_object, ctypes.c_char_p]
    return int(get(capsule, name.encode()) or 0)


def _cffi_signature(obj: Any) -> str | None:
    """The C signature of a cffi function pointer, or None for another cffi object."""
    ffi = sys.modules["cffi"].FFI()
    try:
        kind = ffi.typeof(obj)
    except TypeError:
        return None
    return ffi.getctype(kind) if kind.kind == "function" else None


def address(obj: Any, name: str) -> int:
    """The address of the function pointer ``obj``, after checking its signature.

    Parameters
    ----------
    obj : object
        A numba cfunc, a ctypes or cffi function pointer, a ``scipy.LowLevelCallable`` or a
        :class:`Function`, of signature :data:`C_SIGNATURE`.
    name : str
        The argument it was given as, for the message.

    Returns
    -------
    int
        The address of its code.

    Raises
    ------
    TypeError
        ``obj`` is not such a pointer, or its signature is not :data:`C_SIGNATURE` (a raw int
        address, whose signature cannot be checked, included); the message names ``name``
        and shows the expected signature.

    Examples
    --------
    >>> import ctypes
    >>> from varmech import pointers
    >>> @pointers.CFUNCTYPE
    ... def gradient(q, v, t, n, out):
    ...     out[0] = q[0]
    ...     return 0
    >>> pointers.address(gradient, "gradient") == ctypes.cast(gradient, ctypes.c_void_p).value
    True
    >>> pointers.address(12345, "gradient")
    Traceback (most recent call last):
        ...
    TypeError: gradient: expected a function pointer of signature ... got a raw address 12345, whose signature cannot be checked
    """
    kind = _pointer_kind(obj)
    if kind == "varmech":
        return int(obj.address)
    if kind == "numba" and _same_prototype(obj.ctypes):
        return int(obj.address)
    if kind == "ctypes" and _same_prototype(obj):
        return int(ctypes.cast(obj, ctypes.c_void_p).value or 0)
    if kind == "scipy" and _c_signature_matches(obj.signature):
        # scipy keeps the function as a capsule named by its signature in the tuple's item 0
        # (as its own `signature` property reads it), whatever it was made from.
        return _capsule_pointer(tuple.__getitem__(obj, 0), obj.signature)
    if kind == "cffi" and _c_signature_matches(_cffi_signature(obj) or ""):
        return int(sys.modules["cffi"].FFI().cast("uintptr_t", obj))
    got = {
        "numba": lambda: f"a numba cfunc of signature {obj._sig}",
        "ctypes": lambda: f"a ctypes pointer of ({obj.restype}, {obj.argtypes})",
        "scipy": lambda: f"a LowLevelCallable of signature {obj.signature!r}",
        "cffi": lambda: f"a cffi object of type {_cffi_signature(obj) or obj!r}",
        "int": lambda: f"a raw address {obj}, whose signature cannot be checked",
    }.get(kind or "", lambda: f"{type(obj).__name__} {obj!r}")()
    raise TypeError(f"{_expected(name)}, got {got}")


def functions(entries: dict[str, Any], dim: int) -> dict[str, Function] | None:
    """The model functions ``entries`` (name → function or None) of a model with ``dim``
    coordinates as :class:`Function` objects when every given one is a pointer, or None when none
    is.

    Parameters
    ----------
    entries : dict of str to object
        The model's functions by name (``"potential"``, ``"gradient"``, ``"lagrangian"``,
        ``"dl_dq"``, ``"dl_dv"``, ``"hessians"``, ``"force"``), None for one not given.
    dim : int
        The number of coordinates n.

    Returns
    -------
    dict of str to Function, or None
        Every given function wrapped, or None when they are all Python closures.

    Raises
    ------
    TypeError
        Pointers and Python closures are mixed (naming both), or a pointer's signature is wrong
        (naming it).

    Examples
    --------
    >>> import ctypes
    >>> from varmech import pointers
    >>> @pointers.CFUNCTYPE
    ... def gradient(q, v, t, n, out):
    ...     out[0] = q[0]
    ...     return 0
    >>> wrapped = pointers.functions({"potential": None, "gradient": gradient}, 1)
    >>> wrapped
    {'gradient': Function('gradient', <CFunctionType object at ...>)}
    >>> wrapped["gradient"]([2.0]).tolist()
    [2.0]
    >>> pointers.functions({"gradient": lambda q: q}, 1) is None
    True
    """
    given = {k: f for k, f in entries.items() if f is not None}
    pointers = [k for k, f in given.items() if is_pointer(f)]
    if not pointers:
        return None
    closures = [k for k in given if k not in pointers]
    if closures:
        raise TypeError(
            f"{', '.join(pointers)}: function pointers cannot be mixed with Python closures "
            f"({', '.join(closures)}); give all of them as pointers or all as closures"
        )
    return {k: Function(k, f, address(f, k), dim) for k, f in given.items()}


#: The shape of each model function's result for n coordinates.
_RESULTS: dict[str, Callable[[int], tuple[int, ...]]] = {
    "potential": lambda n: (),
    "gradient": lambda n: (n,),
    "lagrangian": lambda n: (),
    "dl_dq": lambda n: (n,),
    "dl_dv": lambda n: (n,),
    "hessians": lambda n: (3, n, n),
    "force": lambda n: (n,),
}



class Function:
    """A model function given by a pointer, callable from Python as the closure it stands for:
    ``f(q)`` for the potential and its gradient, ``f(q, v, t)`` for the others, returning a
    float, an array (n,) or, for ``hessians``, the three arrays (n, n). The Python layer
    (:func:`varmech.check_derivatives`, the time-dependence probe) calls it; the core calls
    the pointer itself. A nonzero status is a :class:`varmech.VarmechError` naming the function.

    Parameters
    ----------
    name : str
        The model function it stands for (``"potential"``, ``"gradient"``, ``"lagrangian"``,
        ``"dl_dq"``, ``"dl_dv"``, ``"hessians"`` or ``"force"``), which fixes its result's shape.
    pointer : object
        The object the user gave (kept alive with the model).
    address : int
        Its code's address (:func:`address`).
    dim : int
        The number of coordinates n.

    See Also
    --------
    functions : Wraps a model's functions.

    Examples
    --------
    >>> import ctypes
    >>> from varmech import pointers
    >>> @pointers.CFUNCTYPE
    ... def potential(q, v, t, n, out):
    ...     out[0] = 0.5 * q[0] * q[0]
    ...     return 0
    >>> f = pointers.Function("potential", potential, pointers.address(potential, "potential"), 1)
    >>> f([3.0])
    4.5
    """

    def __init__(self, name: str, pointer: Any, address: int, dim: int):
        self.name, self.pointer, self.address, self.dim = name, pointer, address, dim
        self._shape = _RESULTS[name](dim)
        self._function = CFUNCTYPE(address)

    def __call__(self, q: Any, v: Any = None, t: float = 0.0) -> Any:
        n = self.dim
        x = [np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype=float), (n,))) for a in (q, np.zeros(n) if v is None else v)]
        out = np.zeros(self._shape)
        status = self._function(*(a.ctypes.data_as(_DOUBLE_P) for a in x), float(t), n, out.ctypes.data_as(_DOUBLE_P))
        if status != 0:
            raise VarmechError(f"the function pointer {self.name} returned status {status}")
        return float(out) if out.ndim == 0 else tuple(out) if self.name == "hessians" else out

    def __repr__(self) -> str:
        return f"Function({self.name!r}, {self.pointer!r})"
