"""The ensemble's parallel speed-up: a 256-member double-pendulum ensemble (native, ``midpoint``)
with ``workers`` = 1 and 2, through a Dask ``LocalCluster(n_workers=2, threads_per_worker=1,
processes=True)``, and a Python loop of ``integrate`` calls, in one run; and the closure twin of the
double pendulum (``varmech.examples.double_pendulum``, Python at every step), serially and in
two processes.

    PYTHONPATH=$PWD/python python benches/ensemble.py [--members 256] [--steps 10000] [--closure-members 32]
        [--closure-steps 4000] [--repeat 3] [--markdown FILE]

Every configuration is timed best of ``--repeat``, all interleaved so that machine noise hits
them alike; the ratios are what to read (the machine is shared). The load average before and
after the timing is printed with them. Every member of every configuration is checked bit for
bit against the loop's. Then the cluster's costs: the per-task overhead (256 one-step members,
one a task), and the bytes shipped per task and per result (cloudpickle, Dask's serialiser).
"""

from __future__ import annotations

import os

# OpenBLAS's idle worker threads spin on a core of their own; nothing here uses BLAS.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import time
from pathlib import Path

import numpy as np
from compare import best_times_interleaved

import varmech
from varmech import examples, scenes
from varmech.ensemble import _chunk


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--members", type=int, default=256)
    parser.add_argument("--steps", type=int, default=10_000)
    parser.add_argument("--closure-members", type=int, default=32)
    parser.add_argument("--closure-steps", type=int, default=4000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()

    scene = scenes.double_pendulum()
    rng = np.random.default_rng(19)
    q0 = scene.q0 + 0.1 * rng.standard_normal((args.members, 2))
    p0 = scene.p0 + 0.1 * rng.standard_normal((args.members, 2))
    run = dict(dt=1e-3, steps=args.steps, method="midpoint", save_every=100)
    results: dict[str, list] = {}

    def loop() -> None:
        results["loop"] = [varmech.integrate(scene.model, q0[i], p0[i], **run) for i in range(args.members)]

    def parallel(workers: int):
        def go() -> None:
            results[f"workers={workers}"] = list(varmech.ensemble(scene, q0, p0, workers=workers, progress=False, **run))

        return go

    import cloudpickle
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    client = Client(cluster)

    def dask() -> None:
        results["dask"] = list(varmech.ensemble(scene, q0, p0, client=client, progress=False, **run))

    closure = examples.double_pendulum()
    cq0, cp0 = q0[: args.closure_members], p0[: args.closure_members]
    crun = dict(run, steps=args.closure_steps)

    def closures(workers: int | None):
        def go() -> None:
            results[f"closure {workers}"] = list(varmech.ensemble(closure, cq0, cp0, workers=workers, progress=False, **crun))

        return go

    runs = {
        "closure model, serial (default)": closures(None),
        "closure model, workers = 2 (processes)": closures(2),
        "Python loop of integrate": loop,
        "ensemble, workers = 1": parallel(1),
        "ensemble, workers = 2": parallel(2),
        "ensemble, LocalCluster 2 processes × 1 thread": dask,
    }
    load_before = os.getloadavg()
    best = best_times_interleaved(runs, args.repeat)
    load_after = os.getloadavg()
    for a, b in zip(results["closure None"], results["closure 2"]):
        assert np.array_equal(a.q, b.q) and np.array_equal(a.p, b.p)
    for name, trajs in results.items():
        if name.startswith("closure"):
            continue
        assert all(np.array_equal(a.q, b.q) and np.array_equal(a.p, b.p) for a, b in zip(trajs, results["loop"])), name

    # The processes' start: a two-member closure ensemble of one step each, in two processes.
    started = np.inf
    for _ in range(args.repeat):
        start = time.perf_counter()
        varmech.ensemble(closure, cq0[:2], cp0[:2], workers=2, progress=False, **dict(crun, steps=1))
        started = min(started, time.perf_counter() - start)

    # The cluster's costs: one-step members one a task, and the bytes of a default chunk.
    tiny = dict(run, steps=1, save_every=1)
    overhead = np.inf
    for _ in range(args.repeat):
        start = time.perf_counter()
        varmech.ensemble(scene, q0, p0, client=client, chunk_size=1, progress=False, **tiny)
        overhead = min(overhead, (time.perf_counter() - start) / args.members)
    chunk = -(-args.members // 8)
    settings = dict(run, compensated=True, t0=0.0, newton_tolerance=1e-14, newton_max_iterations=50, max_energy_error="auto", workers=1)
    task = (scene.model, q0[:chunk], p0[:chunk], {}, settings)
    sent = len(cloudpickle.dumps(task))
    received = len(cloudpickle.dumps(_chunk(*task[:4], dict(settings, workers=1))))
    client.close()
    cluster.close()

    w1 = best["ensemble, workers = 1"]
    lines = [
        f"{args.members} members × {args.steps} steps of the native double pendulum (midpoint, dt = 1e-3, "
        f"save_every = 100), best of {args.repeat}, interleaved; every member bit for bit the loop's.",
        f"Load average (1, 5, 15 min) before: {load_before[0]:.2f} {load_before[1]:.2f} {load_before[2]:.2f}; "
        f"after: {load_after[0]:.2f} {load_after[1]:.2f} {load_after[2]:.2f}; cores: {os.cpu_count()}.",
        "",
        "| configuration | seconds (best) | speed-up over workers = 1 | loop time / this |",
        "|---|---:|---:|---:|",
    ]
    for name, seconds in best.items():
        if name.startswith("closure"):
            continue
        lines.append(f"| {name} | {seconds:.3f} | {w1 / seconds:.2f} | {best['Python loop of integrate'] / seconds:.2f} |")
    lines += [
        "",
        f"Dask time / local workers = 2: {best['ensemble, LocalCluster 2 processes × 1 thread'] / best['ensemble, workers = 2']:.3f} "
        f"(the default chunks: {chunk} members a task, 8 tasks).",
        f"Per-task overhead on the LocalCluster: {overhead * 1e3:.2f} ms (one-step members, one a task, best of {args.repeat}).",
        f"Bytes shipped per task of {chunk} members: {sent} (model, initial rows, settings); per result: {received} "
        f"({received / chunk:.0f} a member of {args.steps // 100 + 1} saved states of n = 2).",
        "",
        f"Closure model (the same double pendulum in Python closures), {args.closure_members} members × "
        f"{args.closure_steps} steps: serial {best['closure model, serial (default)']:.3f} s, "
        f"workers = 2 (processes) {best['closure model, workers = 2 (processes)']:.3f} s, speed-up "
        f"{best['closure model, serial (default)'] / best['closure model, workers = 2 (processes)']:.2f}; "
        f"starting the two processes and one step each: {started:.3f} s; bit for bit the same.",
    ]
    text = "\n".join(lines)
    print(text)
    if args.markdown:
        command = "PYTHONPATH=$PWD/python python benches/ensemble.py --markdown benches/ensemble_results.md"
        args.markdown.write_text(f"# benches/ensemble.py\n\nCommand: `{command}`\n\n{text}\n")


if __name__ == "__main__":
    main()
