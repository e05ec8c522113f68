"""Progress bars for long sweeps (tqdm): a widget in Jupyter, text on a terminal, none in log
files and pipes unless asked for."""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Iterable, Iterator
from typing import TextIO, TypeVar

from tqdm.auto import tqdm

T = TypeVar("T")


def _in_notebook() -> bool:
    """Whether this runs in a Jupyter kernel (IPython's ZMQ shell), where tqdm.auto draws a
    widget; IPython is not imported to find out."""
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None and hasattr(ipython, "get_ipython") else None
    return type(shell).__name__ == "ZMQInteractiveShell"


def _shown(enabled: bool | None) -> bool:
    """Whether to draw a bar: as asked, or (None) as tqdm's conventions have it: not where
    ``TQDM_DISABLE`` is set, else in a Jupyter notebook or when stderr is a terminal, so that
    log files and pipes get none."""
    if enabled is not None:
        return enabled
    if os.environ.get("TQDM_DISABLE", "").strip().lower() not in ("", "0", "false"):
        return False
    return _in_notebook() or sys.stderr.isatty()


def progress(items: Iterable[T], *, total: int | None = None, desc: str = "", enabled: bool | None = None) -> Iterator[T]:
    """Iterate over ``items`` with a progress bar on stderr. ``enabled=None`` shows it only on a
    terminal or in a notebook. Ctrl-C stops the sweep: KeyboardInterrupt propagates from the running item."""
    return iter(tqdm(items, total=total, desc=desc, disable=not _shown(enabled), leave=False))


def progress_bar(
    *,
    total: int,
    unit: str,
    desc: str = "",
    enabled: bool | None = None,
    file: TextIO | None = None,
    delay: float = 1.0,
) -> tqdm:
    """A progress bar on ``file`` (stderr) that appears once its run has taken ``delay`` seconds
    (a short run shows none). ``enabled=None`` shows it only on a terminal or in a notebook."""
    return tqdm(total=total, unit=unit, desc=desc, disable=not _shown(enabled), delay=delay, leave=False, file=file)


def thread_lock() -> None:
    """Gives tqdm a thread lock instead of its default process lock, a named semaphore: for a
    worker process, which draws no bar, and whose semaphore would leak when its pool terminates
    it (the resource tracker's "leaked semaphore objects" at exit)."""
    tqdm.set_lock(threading.RLock())
