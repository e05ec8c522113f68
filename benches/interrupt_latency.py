"""How quickly Ctrl-C stops a long run: SIGINT is sent 0.2 s into a run of 10^10 steps, and the
time from the signal to the KeyboardInterrupt is measured, five times each for a native and a
closure model.

    python benches/interrupt_latency.py
"""

import os
import signal
import threading
import time

import varmech
from varmech import examples, scenes


def latency(model, q0, p0) -> float:
    sent = {}

    def fire():
        sent["t"] = time.perf_counter()
        os.kill(os.getpid(), signal.SIGINT)

    threading.Timer(0.2, fire).start()
    try:
        varmech.integrate(model, q0, p0, dt=1e-3, steps=10**10, save_every=10**7)
    except KeyboardInterrupt:
        return time.perf_counter() - sent["t"]
    raise RuntimeError("the run was not interrupted")


def main() -> None:
    sun, kepler = scenes.outer_solar_system(), scenes.kepler()
    for label, model, scene in (("native (outer solar system)", sun.model, sun), ("closure (Kepler)", examples.kepler(), kepler)):
        worst = max(latency(model, scene.q0, scene.p0) for _ in range(5))
        print(f"{label}: worst of 5, {worst * 1e3:.1f} ms from SIGINT to KeyboardInterrupt")


if __name__ == "__main__":
    main()
