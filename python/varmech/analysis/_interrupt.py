"""Ctrl-C in a sweep: the rows measured so far travel with the KeyboardInterrupt."""

from __future__ import annotations

from collections.abc import Callable

from ..table import Table


def interruptible(table: Table, body: Callable[[], None]) -> Table:
    """Runs ``body``, which fills ``table``, and returns the table; a KeyboardInterrupt
    propagates with the rows so far as ``err.partial``."""
    try:
        body()
    except KeyboardInterrupt as err:
        err.partial = table  # type: ignore[attr-defined]
        raise
    return table
