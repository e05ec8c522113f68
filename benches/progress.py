"""The cost of integrate(progress=True) on the native step loop: Kepler Verlet, 3·10⁷ steps, with
the bar drawn (to a discarded stream) and without, interleaved, best of 7.

    python benches/progress.py
"""

from __future__ import annotations

import importlib
import io

from compare import best_times_interleaved

import varmech

# The module (the package's name `integrate` is the function).
integrate_module = importlib.import_module("varmech.integrate")


def main() -> None:
    s = varmech.scenes.kepler()
    steps = 30_000_000
    shown = integrate_module.progress_bar

    def drawn(**kwargs):
        return shown(**{**kwargs, "enabled": True}, file=io.StringIO())

    def run(progress: bool) -> None:
        integrate_module.progress_bar = drawn if progress else shown
        try:
            varmech.integrate(s, dt=s.dt, steps=steps, save_every=steps, progress=progress)
        finally:
            integrate_module.progress_bar = shown

    best = best_times_interleaved({"without": lambda: run(False), "with": lambda: run(True)}, repeat=7)
    print(f"Kepler verlet, {steps:,} steps: without a bar {best['without']:.3f} s, with {best['with']:.3f} s")
    print(f"time with / without: {best['with'] / best['without']:.4f}")


if __name__ == "__main__":
    main()
