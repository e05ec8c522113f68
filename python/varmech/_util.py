"""Argument checks shared by the public functions, and the filling of shared docstring sections."""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike

#: The largest count (steps, dimensions, indices) the core's unsigned integers take.
MAX_COUNT = 2**63 - 1

_F = TypeVar("_F", bound=Callable[..., Any])


def with_sections(f: _F, sections: Mapping[str, str]) -> _F:
    """``f`` with ``sections`` (by placeholder, e.g. ``{returns}``) put into its docstring for
    their placeholders, as matplotlib's and SciPy's docstring templates do: the sections a
    family of functions shares, written once."""
    doc = f.__doc__ or ""
    for placeholder, section in sections.items():
        doc = doc.replace(placeholder, section)
    f.__doc__ = doc
    return f


def _shown(x: Any) -> str:
    """``x`` for a message, cut short (an int of 10**400 has 401 digits)."""
    text = repr(x)
    return text if len(text) <= 80 else f"{text[:60]}... ({type(x).__name__})"


def floats(name: str, x: Any) -> np.ndarray:
    """``x`` as a float64 array of its own shape, or an error naming ``name``: numbers only
    (bools and ints included), never strings or bytes read as numbers (TypeError, as NumPy's
    ufuncs refuse them), none beyond a float's range (ValueError)."""
    if type(x) is np.ndarray and x.dtype == np.float64:
        return x
    try:
        a = np.asarray(x)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: must be an array of numbers ({e})") from None
    if a.dtype.kind in "biuf":
        return a.astype(float, copy=False)
    # An object array holds ints too large for int64, Fractions, or a mix that includes strings.
    if a.dtype.kind in "USV" or any(isinstance(e, (str, bytes)) or e is None for e in a.flat):
        raise TypeError(f"{name}: must be numbers, not strings or None, got {_shown(x)}")
    if a.dtype.kind != "O":
        raise ValueError(f"{name}: must be numbers, got {_shown(x)}")
    try:
        return a.astype(float)
    except OverflowError:
        raise ValueError(f"{name}: must be finite, got a number beyond the float range in {_shown(x)}") from None
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: must be numbers, got {_shown(x)} ({e})") from None


def callable_as(name: str, f: Any, arguments: str) -> None:
    """TypeError naming ``name`` unless ``f`` is a callable that takes the positional
    ``arguments`` (their names, comma-separated, as the message shows them): a closure of
    another signature would fail at its first call with Python's bare message, naming no
    argument. A callable whose signature Python cannot read (a builtin) is taken as it is."""
    if not callable(f):
        raise TypeError(f"{name}: must be callable as {name}({arguments}), got {type(f).__name__}: {_shown(f)}")
    try:
        signature = inspect.signature(f)
    except (TypeError, ValueError):
        return
    try:
        signature.bind(*arguments.split(","))
    except TypeError:
        raise TypeError(f"{name}: must be callable as {name}({arguments}), but it takes {signature}") from None


def vector(name: str, x: ArrayLike, n: int) -> np.ndarray:
    """``x`` as a contiguous float64 array (n,), or ValueError naming ``name``."""
    a = floats(name, x)
    if a.shape != (n,):
        raise ValueError(f"{name}: must have shape ({n},), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: must be finite, got {a}")
    return np.ascontiguousarray(a)


def number(name: str, x: float) -> float:
    """``x`` as a float, or an error naming ``name``: TypeError for what is not a number (a
    string is not read as one), ValueError for an int beyond the float range."""
    if isinstance(x, (str, bytes)) or x is None:
        raise TypeError(f"{name}: must be a number, not {type(x).__name__}, got {_shown(x)}")
    try:
        return float(x)
    except OverflowError:
        raise ValueError(f"{name}: must be finite, got {_shown(x)}") from None
    except TypeError:
        raise TypeError(f"{name}: must be a number, got {_shown(x)}") from None
    except ValueError:
        raise ValueError(f"{name}: must be a number, got {_shown(x)}") from None


def positive(name: str, x: float) -> float:
    """``x`` as a finite positive float, or ValueError naming ``name``."""
    v = number(name, x)
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name}: must be finite and positive, got {_shown(x)}")
    return v


def finite(name: str, x: float) -> float:
    """``x`` as a finite float, or ValueError naming ``name``."""
    v = number(name, x)
    if not math.isfinite(v):
        raise ValueError(f"{name}: must be finite, got {v}")
    return v


def integer(name: str, x: int, least: int = 0) -> int:
    """``x`` as an int from ``least`` to :data:`MAX_COUNT`, or ValueError naming ``name`` (a
    float, even a whole one, or a bool is not taken for an integer)."""
    what = "a positive integer" if least == 1 else f"an integer ≥ {least}"
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)) or x < least:
        raise ValueError(f"{name}: must be {what}, got {_shown(x)}")
    if x > MAX_COUNT:
        raise ValueError(f"{name}: must be at most 2**63 - 1, got {_shown(x)}")
    return int(x)


def positive_int(name: str, x: int) -> int:
    """``x`` as a positive int (at most :data:`MAX_COUNT`), or ValueError naming ``name``."""
    return integer(name, x, 1)


def returned(call: str, x: Any) -> np.ndarray:
    """A closure's result as a float64 array of its own shape, read as the core reads one
    (a float, an int, or an array of ints or floats): anything else is a TypeError naming
    ``call`` (``"gradient(q)"``), as the core's own readers raise."""
    if type(x) is np.ndarray and x.dtype == np.float64:
        return x
    if isinstance(x, (float, int)) and not isinstance(x, bool):
        try:
            return np.asarray(float(x))
        except OverflowError:
            raise ValueError(f"{call} returned {_shown(x)}, beyond the float range") from None
    try:
        a = None if isinstance(x, np.ma.MaskedArray) else np.asarray(x)
    except (TypeError, ValueError):
        a = None
    if a is None or a.dtype.kind not in "iuf" or (a.dtype.kind == "f" and a.dtype.itemsize > 8):
        what = f"a {a.dtype} array" if isinstance(x, np.ndarray) and a is not None else type(x).__name__
        raise TypeError(f"{call} must return numbers (a float or an array of floats), got {what}")
    return a.astype(float, copy=False)


def returned_scalar(call: str, x: Any) -> float:
    """A closure's result that must be one float, read as :func:`returned` reads one."""
    a = returned(call, x)
    if a.shape != ():
        raise TypeError(f"{call} must return a float, got an array of shape {a.shape}")
    return float(a)


def step_count(dt: float, t0: float, steps: int | None, t_end: float | None) -> int:
    """The steps of a run from ``t0``: ``steps``, or those of ``dt`` to ``t_end`` (exactly one given,
    a whole number of steps)."""
    if (steps is None) == (t_end is None):
        raise ValueError("steps, t_end: give exactly one of them")
    if steps is not None:
        if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or not 0 <= steps < 2**63:
            raise ValueError(f"steps: must be an integer from 0 to 2**63 - 1, got {steps!r}")
        return int(steps)
    t_end = number("t_end", t_end)  # type: ignore[arg-type]
    if not math.isfinite(t_end) or t_end < t0:
        raise ValueError(f"t_end: must be finite and not before t0 = {t0}, got {t_end}")
    if not (t_end - t0) / dt <= MAX_COUNT:
        raise ValueError(
            f"t_end: {t_end} is more than 2**63 - 1 steps of dt = {dt} from t0 = {t0} "
            f"((t_end - t0)/dt = {(t_end - t0) / dt:.3g}); take a larger dt or a nearer t_end"
        )
    n = round((t_end - t0) / dt)
    if abs(n * dt - (t_end - t0)) > 1e-9 * max(abs(t_end - t0), dt):
        raise ValueError(
            f"t_end: {t_end} is not a whole number of steps dt = {dt} from t0 = {t0} "
            f"({(t_end - t0) / dt:.6g} steps); adjust dt or pass steps"
        )
    return n
