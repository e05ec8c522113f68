"""The command line: ``python -m varmech tour | methods | chart <kind> [scene]``."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from . import charts, scenes
from ._version import __version__
from .charts.recipes import KINDS, chart
from .conservation import check_conservation
from .integrate import integrate
from .methods import format_table
from .reduction import routh
from .table import Table

__all__: list[str] = []  # internal: importable, not part of the public API

#: Showcase runs of the tour, scene → (methods, horizon) with None for the scene's t_end: each
#: over a horizon long enough to tell bounded from drifting. A scene without one runs with its
#: kind's default and accurate methods over its t_end (see :func:`tour_runs`).
TOUR: dict[str, tuple[tuple[str, ...], float | None]] = {
    "harmonic_oscillator": (("verlet", "rk4", "symplectic_euler"), 1000.0),
    "pendulum": (("verlet", "yoshida4", "rk4"), 2000.0),
    "kepler": (("verlet", "kahan_li8", "rk4"), None),
    "henon_heiles": (("verlet", "kahan_li6", "rk4"), 5000.0),
    "fermi_pasta_ulam": (("verlet", "mclachlan4", "rk4"), 200.0),
    "outer_solar_system": (("verlet", "kahan_li8", "rk4"), None),
    "double_pendulum": (("midpoint", "trapezoid"), 100.0),
    "spherical_pendulum": (("midpoint", "trapezoid"), 1000.0),
    "heavy_top": (("midpoint", "galerkin4"), None),
    "kepler_polar": (("midpoint", "galerkin4"), None),
    "charged_particle": (("midpoint", "galerkin4"), 1000.0),
    "charged_particle_nonuniform": (("midpoint", "trapezoid"), 1000.0),
    "cartesian_pendulum": (("rattle", "shake"), 1000.0),
    "planar_chain": (("rattle", "rattle4"), 100.0),
    "rigid_body": (("trapezoid", "midpoint"), 100.0),
    # A hundred bounces and more, where the variational impacts' O(h²) energy jumps stay bounded.
    "bouncing_ball": (("verlet", "kahan_li6"), 1000.0),
}


def tour_runs() -> list[tuple[scenes.Scene, tuple[str, ...], float]]:
    """(scene, methods, horizon) for every scene of the catalogue, in its order: the showcase
    of :data:`TOUR`, or the kind's default and accurate methods over the scene's t_end."""
    runs = []
    for name in scenes.CATALOGUE:
        scene = scenes.get(name)
        kind = scene.model.kind
        methods, horizon = TOUR.get(name, (tuple(dict.fromkeys((kind.default_method, kind.accurate_method))), None))
        runs.append((scene, methods, horizon if horizon is not None else scene.t_end))
    return runs


#: The charts the tour draws, each with its default scene and methods (``python -m varmech chart``).
TOUR_CHARTS = ("work-precision", "energy", "stability", "implicit-regions", "poincare", "phase")

#: (scene, ignored coordinates, methods): Routh-reduced runs, reconstructed to the full model.
TOUR_REDUCED = [
    ("spherical_pendulum", (1,), ("midpoint", "galerkin4")),
    ("heavy_top", (1, 2), ("midpoint", "galerkin4")),
]


def tour_reduced(quick: bool, summary: Table) -> None:
    """Integrate the Routh-reduced scenes, report on the reconstructed full motion, and add
    the reduced runs' energy verdicts to ``summary``."""
    for name, cyclic, methods in TOUR_REDUCED:
        scene = scenes.get(name)
        reduced = routh(scene, cyclic)
        x0, px0 = reduced.reduce(scene.q0, scene.p0)
        t_end = scene.t_end / (10 if quick else 1)
        steps = round(t_end / scene.dt)
        print(f"\n=== {reduced.name}: {reduced.dim} coordinate(s) left; dt = {scene.dt:g}, {steps} steps")
        for method in methods:
            start = time.perf_counter()
            traj = integrate(reduced, x0, px0, dt=scene.dt, steps=steps, method=method)
            full = reduced.reconstruct(traj, c0=scene.q0[list(cyclic)])
            elapsed = time.perf_counter() - start
            lo, hi = traj.q.min(axis=0), traj.q.max(axis=0)
            print(f"--- {method}: {elapsed:.3f} s with reconstruction; x ranges over {lo} … {hi}")
            print(check_conservation(full))
            reduced_report = check_conservation(traj)
            summary.append(reduced.name, method, steps, elapsed, reduced_report.energy.max_rel_error, reduced_report.verdict)


def tour(out: Path, quick: bool) -> int:
    """Integrate every scene with a few methods, print their conservation reports, and write
    energy-error plots and the charts of :data:`TOUR_CHARTS` to ``out`` (without matplotlib,
    the reports only)."""
    plots = True
    summary = Table(
        ("scene", "method", "steps", "seconds", "max_error", "verdict"),
        title="Tour: energy error against its scale (the mean kinetic energy), and the verdict",
    )
    for scene, methods, horizon in tour_runs():
        name = scene.name
        t_end = horizon / 10 if quick else horizon
        steps = round(t_end / scene.dt)
        save_every = max(1, steps // 20000)
        print(f"\n=== {name}: {scene.description}; dt = {scene.dt:g}, {steps} steps to t = {steps * scene.dt:g}")
        runs = {}
        for method in methods:
            start = time.perf_counter()
            traj = integrate(scene, dt=scene.dt, steps=steps, method=method, save_every=save_every)
            elapsed = time.perf_counter() - start
            runs[method] = traj
            print(f"--- {method}: {traj.nfev} force evaluations in {elapsed:.3f} s")
            report = check_conservation(traj)
            print(report)
            stats = report.energy
            verdict = report.verdict if stats.name == "energy" else f"{stats.name} {report.verdict}"
            summary.append(name, method, steps, elapsed, stats.max_rel_error, verdict)
        if plots:
            try:
                path = charts.energy_error(
                    runs, out / f"{name}_energy.png", title=f"{name}: energy error, dt = {scene.dt:g} {scene.time_unit}", time_unit=scene.time_unit
                )
                print(f"wrote {path}")
            except ImportError as e:
                print(f"(no plots: {e})")
                plots = False
    tour_reduced(quick, summary)
    if plots:
        print("\n=== charts: accuracy against cost, energy over long runs, stability, sections")
        for kind in TOUR_CHARTS:
            for path in chart(kind, out=out, quick=quick, say=_note):
                print(f"wrote {path}")
    # The summary last, where the reader's eye lands.
    print()
    print(summary.format(max_rows=None))
    return 0


def _note(note: str) -> None:
    """Say a measurement's note (a skipped baseline, a stopped sweep) on screen."""
    print(f"note: {note}")


def _floats(text: str) -> tuple[float, ...]:
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") from None


def _box(text: str) -> tuple[tuple[float, float], tuple[float, float]]:
    values = _floats(text)
    if len(values) != 4:
        raise argparse.ArgumentTypeError(f"expected QMIN,QMAX,PMIN,PMAX, got {text!r}")
    return (values[0], values[1]), (values[2], values[3])


def main(argv: list[str] | None = None) -> int:
    """The command line's entry (``varmech`` and ``python -m varmech``): its exit status."""
    try:
        status = _main(argv)
        sys.stdout.flush()
        return status
    except BrokenPipeError:
        # The reader closed the pipe (`varmech methods | head`): stop quietly, as Unix tools do
        # (status 128 + SIGPIPE), with the interpreter's last flush sent nowhere.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


def _prog() -> str:
    """The name the command was run by: ``varmech`` (the script) or ``python -m varmech``."""
    name = Path(sys.argv[0]).name if sys.argv and sys.argv[0] else ""
    return "python -m varmech" if name in ("__main__.py", "-m", "") else name


def _main(argv: list[str] | None) -> int:
    # The module's docstring is reStructuredText; the help shows it as plain text.
    parser = argparse.ArgumentParser(prog=_prog(), description=(__doc__ or "").replace("``", ""))
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    t = sub.add_parser("tour", help="integrate every scene, print conservation reports, plot energy errors")
    t.add_argument("--out", type=Path, default=Path("out/tour"), help="folder for the plots (default out/tour)")
    t.add_argument("--quick", action="store_true", help="a tenth of each horizon")
    sub.add_parser("methods", help="print the table of methods")
    c = sub.add_parser("chart", help="measure and write a chart (PNG or SVG) with its data (CSV)")
    c.add_argument("kind", choices=sorted(KINDS), help="; ".join(f"{k}: {v.description}" for k, v in KINDS.items()))
    c.add_argument(
        "scene", nargs="?", help="a scene name (default: the kind's own; varmech.charts.recipes.scenes_for(kind) lists those it takes)"
    )
    c.add_argument(
        "--methods", help="comma-separated method names (default: the kind's own that fit the scene, else the scene's kind's)"
    )
    c.add_argument(
        "--energy", type=_floats, help="poincare: energy shells (default 1/12,1/8 on henon_heiles, else the scene's); phase: the orbits' energies"
    )
    c.add_argument(
        "--box",
        type=_box,
        metavar="QMIN,QMAX,PMIN,PMAX",
        help="poincare: the plane box to seed orbits in (default: about the scene's state); --box=-1,… below 0",
    )
    c.add_argument("--out", type=Path, default=Path("out/charts"), help="folder (default out/charts)")
    c.add_argument("--format", default="png", choices=("png", "svg"))
    c.add_argument("--quick", action="store_true", help="shorter sweeps and horizons")
    args = parser.parse_args(argv)
    if args.command == "tour":
        return tour(args.out, args.quick)
    if args.command == "chart":
        methods = tuple(args.methods.split(",")) if args.methods else None
        try:
            paths = chart(
                args.kind, args.scene, methods=methods, out=args.out, fmt=args.format, quick=args.quick, energies=args.energy,
                box=args.box, say=_note,
            )  # fmt: skip
        except ValueError as e:
            parser.error(str(e))
        for path in paths:
            print(f"wrote {path}")
        return 0
    print(format_table())
    return 0
