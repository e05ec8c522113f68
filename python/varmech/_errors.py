"""Pickling of varmech's exceptions (defined in the core binding, module ``varmech``): an error
keeps its message and its attributes (``step``, ``time``, ``residual``, ``iterations`` and the
partial trajectory ``partial``), so that it crosses process boundaries (multiprocessing,
concurrent.futures). The partial trajectory travels without its model: models hold native
objects or closures, which do not pickle; its states, times and counts are all kept."""

from __future__ import annotations

import dataclasses
from typing import Any

from ._core import VarmechError


def _reduce(error: BaseException) -> tuple[Any, ...]:
    state = dict(error.__dict__)
    partial = state.get("partial")
    if dataclasses.is_dataclass(partial) and not isinstance(partial, type):
        state["partial"] = dataclasses.replace(partial, model=None)
    return (type(error), error.args, state)


def install() -> None:
    """Makes VarmechError and its subclasses pickle with their attributes."""
    VarmechError.__reduce__ = _reduce  # type: ignore[assignment,method-assign]
