"""Long runs (issue 16): the cost of streaming to HDF5 (against the same run in memory) and of
checkpoints every 10⁶ steps (against the default, a segment of about 2 s) on the native Kepler
Verlet loop, interleaved, best of 5, as ratios; the bytes a saved
state takes in a file; and a 10⁹-step run streamed to disk, with its peak memory and verdict.

    python benches/long_runs.py            # the ratios and bytes per state
    python benches/long_runs.py --billion  # and the 10⁹-step run (about a minute)
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

from compare import best_times_interleaved

import varmech
from varmech import _core, streaming


def ratios(steps: int) -> None:
    s = varmech.scenes.kepler()
    folder = Path(tempfile.mkdtemp())

    def memory(every: int):
        return lambda: varmech.integrate(s, dt=s.dt, steps=steps, save_every=every)

    def streamed(every: int, **kwargs):
        return lambda: varmech.integrate(s, dt=s.dt, steps=steps, save_every=every, output=folder / "run.h5", overwrite=True, **kwargs)

    runs = {
        "memory, save_every=100": memory(100),
        "file, save_every=100": streamed(100),
        "file, save_every=10⁴": streamed(10_000),
        "file, checkpoint every 10⁶": streamed(10_000, checkpoint_every=10**6),
    }
    best = best_times_interleaved(runs, repeat=5)
    for name, seconds in best.items():
        print(f"{name:30s} {seconds:.3f} s  ({steps / seconds / 1e6:.1f} M steps/s)")
    print(f"streaming to HDF5 (save_every = 100) / in memory: {best['file, save_every=100'] / best['memory, save_every=100']:.3f}")
    print(
        "checkpoints every 10⁶ steps / every 2 s (both streamed, save_every = 10⁴): "
        f"{best['file, checkpoint every 10⁶'] / best['file, save_every=10⁴']:.3f}"
    )


def gaps(steps: int) -> None:
    """The main thread's time between two segments' core runs (checkpoints every 10⁶ steps):
    what a checkpoint adds to the run's time when the commit thread has a core of its own. The
    core runs are timed by wrapping ``_core.resume`` as ``streaming`` calls it."""
    s = varmech.scenes.kepler()
    path = Path(tempfile.mkdtemp()) / "run.h5"
    spans: list[tuple[float, float]] = []

    class Timed:
        def __getattr__(self, name: str) -> object:
            return getattr(_core, name)

        def resume(self, *args: object, **kwargs: object) -> object:
            started = time.perf_counter()
            record = _core.resume(*args, **kwargs)
            spans.append((started, time.perf_counter()))
            return record

    streaming._core = Timed()  # type: ignore[assignment]
    try:
        medians = []
        for _ in range(3):
            spans.clear()
            varmech.integrate(s, dt=s.dt, steps=steps, save_every=10_000, output=path, overwrite=True, checkpoint_every=10**6)
            between = sorted(b[0] - a[1] for a, b in zip(spans, spans[1:]))
            segment = sorted(b - a for a, b in spans)
            medians.append((between[len(between) // 2], segment[len(segment) // 2]))
    finally:
        streaming._core = _core
    gap, segment = min(medians)
    print(f"main thread between segments: {gap * 1e3:.3f} ms against {segment * 1e3:.1f} ms a segment of 10⁶ steps ({gap / segment:.2%})")


def bytes_per_state() -> None:
    folder = Path(tempfile.mkdtemp())
    cases = [
        ("kepler", "verlet", varmech.scenes.kepler()),
        ("double_pendulum", "midpoint", varmech.scenes.double_pendulum()),
        ("outer_solar_system", "whc", varmech.scenes.outer_solar_system()),
    ]
    for name, method, scene in cases:
        path = folder / f"{name}.h5"
        traj = varmech.integrate(scene, dt=scene.dt, steps=200_000, save_every=10, method=method, output=path)
        size = path.stat().st_size
        n = scene.model.dim
        data = 8 * (2 * n + 1) + 8 * (traj.newton is not None)
        print(f"{name} ({method}, n = {n}): {size / len(traj.t):.1f} bytes per saved state over {len(traj.t)} states (data: {data})")


BILLION = """
import resource, sys, time, h5py, varmech  # h5py first: the baseline holds the library the run loads
s = varmech.scenes.kepler()
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
start = time.perf_counter()
traj = varmech.integrate(s, dt=s.dt, steps=10**9, save_every=10**4, output=sys.argv[1], overwrite=True)
seconds = time.perf_counter() - start
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
report = varmech.check_conservation(traj)
print(f"10⁹ steps in {seconds:.1f} s ({1e3 / seconds:.1f} M steps/s), {len(traj.t)} states on disk")
print(f"peak RSS {peak / 1024:.1f} MiB (after import {before / 1024:.1f} MiB)")
print(report)
"""


def billion() -> None:
    path = Path(tempfile.mkdtemp()) / "billion.h5"
    subprocess.run([sys.executable, "-c", textwrap.dedent(BILLION), str(path)], check=True)
    print(f"file: {path.stat().st_size / 2**20:.1f} MiB")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=100_000_000)
    parser.add_argument("--billion", action="store_true")
    args = parser.parse_args()
    ratios(args.steps)
    gaps(min(args.steps, 30_000_000))
    bytes_per_state()
    if args.billion:
        billion()


if __name__ == "__main__":
    main()
