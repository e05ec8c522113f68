"""Progress bars for long sweeps (tqdm), off when asked or when the output is not a terminal."""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterable, Iterator
from typing import TextIO, TypeVar

from tqdm.auto import tqdm

T = TypeVar("T")


def _shown(enabled: bool | None) -> bool:
    """Whether to draw a bar: as asked, or (None) when stderr is a terminal."""
    return sys.stderr.isatty() if enabled is None else enabled


def progress(items: Iterable[T], *, total: int | None = None, desc: str = "", enabled: bool | None = None) -> Iterator[T]:
    """Iterate over ``items`` with a progress bar on stderr. ``enabled=None`` shows it only on a
    terminal. Ctrl-C stops the sweep: KeyboardInterrupt propagates from the running item."""
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
    (a short run shows none). ``enabled=None`` shows it only on a terminal."""
    return tqdm(total=total, unit=unit, desc=desc, disable=not _shown(enabled), delay=delay, leave=False, file=file)


def thread_lock() -> None:
    """Gives tqdm a thread lock instead of its default process lock, a named semaphore: for a
    worker process, which draws no bar, and whose semaphore would leak when its pool terminates
    it (the resource tracker's "leaked semaphore objects" at exit)."""
    tqdm.set_lock(threading.RLock())
