"""The command line: ``python -m varmech tour | methods | scenes | run SCENE | chart KIND [SCENE]``.

SCENE is a scene's name (``varmech scenes`` lists them) or one's own: FILE.py:NAME or
MODULE:NAME naming a varmech Scene, a Model (with --q0, --p0 or --v0, and --t-end), a function
that returns one of them, or a SymPy Lagrangian L (the file defines its coordinates as ``q``, their
velocities as ``v`` unless q are dynamicsymbols, and may define ``parameters``)."""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import math
import os
import sys
import time
from pathlib import Path
from typing import Any

from . import _core, charts, scenes
from ._catalogue import declared
from ._version import __version__
from .charts.recipes import KINDS, chart
from .conservation import check_conservation
from .integrate import integrate
from .methods import format_table
from .model import Model
from .reduction import routh
from .table import Table

__all__: list[str] = []  # internal: importable, not part of the public API

def tour_runs() -> list[tuple[scenes.Scene, tuple[str, ...], float]]:
    """(scene, methods, horizon) for every scene of the catalogue, in its order: its showcase
    run, as declared with it (``tour``, :mod:`varmech._catalogue`: each over a horizon long
    enough to tell bounded from drifting, None for the scene's t_end), or the kind's default and
    accurate methods over the scene's t_end."""
    runs = []
    for name in scenes.CATALOGUE:
        scene = scenes.get(name)
        kind = scene.model.kind
        methods, horizon = declared(name).tour or (tuple(dict.fromkeys((kind.default_method, kind.accurate_method))), None)
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
    the reports only). Its exit status: 0, or 1 where a run or a chart failed (a varmech error,
    which the tour says and goes on past) or a run's verdict is "failed"."""
    problems: list[str] = []
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
            try:
                traj = integrate(scene, dt=scene.dt, steps=steps, method=method, save_every=save_every)
            except _core.VarmechError as e:
                problems.append(f"{name}, {method}: {type(e).__name__}: {e}")
                print(f"--- {method}: failed: {e}")
                continue
            elapsed = time.perf_counter() - start
            runs[method] = traj
            print(f"--- {method}: {traj.nfev} force evaluations in {elapsed:.3f} s")
            report = check_conservation(traj)
            print(report)
            stats = report.energy
            verdict = report.verdict if stats.name == "energy" else f"{stats.name} {report.verdict}"
            summary.append(name, method, steps, elapsed, stats.max_rel_error, verdict)
            if report.verdict == "failed":
                problems.append(f"{name}, {method}: the verdict is failed")
        if plots and runs:
            try:
                path = out / f"{name}_energy.png"
                charts.energy_error(runs, path, title=f"{name}: energy error, dt = {scene.dt:g} {scene.time_unit}", time_unit=scene.time_unit)
                print(f"wrote {path}")
            except ImportError as e:
                print(f"(no plots: {e})")
                plots = False
    tour_reduced(quick, summary)
    if plots:
        print("\n=== charts: accuracy against cost, energy over long runs, stability, sections")
        for kind in TOUR_CHARTS:
            try:
                for path in chart(kind, out=out, quick=quick, say=_note):
                    print(f"wrote {path}")
            except _core.VarmechError as e:
                problems.append(f"chart {kind}: {type(e).__name__}: {e}")
    # The summary last, where the reader's eye lands, and what went wrong under it.
    print()
    print(summary.format(max_rows=None))
    for problem in problems:
        print(f"tour: {problem}", file=sys.stderr)
    return 1 if problems else 0


def _note(note: str) -> None:
    """Say a measurement's note (a skipped baseline, a stopped sweep) on standard error, apart
    from the output."""
    print(f"note: {note}", file=sys.stderr)


def _module(where: str) -> Any:
    """The module of FILE.py (run as a script's module) or of an importable MODULE name."""
    if where.endswith(".py"):
        path = Path(where)
        if not path.is_file():
            raise ValueError(f"scene: no file {where}")
        spec = importlib.util.spec_from_file_location(path.stem, path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module
    try:
        return importlib.import_module(where)
    except ModuleNotFoundError as e:
        raise ValueError(f"scene: no module {where!r} ({e}); give FILE.py:NAME or an importable MODULE:NAME") from None


def load_subject(text: str) -> scenes.Scene | Model:
    """The Scene or Model that ``FILE.py:NAME`` or ``MODULE:NAME`` names: the object itself, what
    a function of that name returns, or a SymPy Lagrangian compiled (the module's ``q`` its
    coordinates, ``v`` their velocities, ``parameters`` the values of its symbols)."""
    where, _, name = text.rpartition(":")
    if not where or not name:
        raise ValueError(f"scene: expected a scene's name, FILE.py:NAME or MODULE:NAME, got {text!r}")
    module = _module(where)
    if not hasattr(module, name):
        public = sorted(k for k in vars(module) if not k.startswith("_"))
        raise ValueError(f"scene: {where} defines no {name!r}; it defines {', '.join(public)}")
    obj = getattr(module, name)
    if callable(obj) and not isinstance(obj, (scenes.Scene, Model)):
        obj = obj()
    if type(obj).__module__.startswith("sympy"):
        if not hasattr(module, "q"):
            raise ValueError(f"scene: {where} gives the Lagrangian {name} but no coordinates: define q = [the coordinates]")
        from .symbolic import lagrangian

        obj = lagrangian(obj, module.q, getattr(module, "v", None), parameters=getattr(module, "parameters", None), name=name)
    if not isinstance(obj, (scenes.Scene, Model)):
        raise ValueError(f"scene: {text} is a {type(obj).__name__}, not a varmech Scene, Model or SymPy Lagrangian")
    return obj


def _scene(args: argparse.Namespace) -> scenes.Scene | str | None:
    """The scene the command line names: a name as it is (the recipes know the catalogue), or the
    user's own object, a Model made a Scene with --q0, --p0/--v0, --t-end and --dt."""
    if args.scene is None or ":" not in args.scene:
        given = [flag for flag, value in (("--q0", args.q0), ("--p0", args.p0), ("--v0", args.v0)) if value is not None]
        if given and args.scene is not None:
            raise ValueError(f"{', '.join(given)}: a built-in scene has its own initial state; these are for a model of one's own")
        return args.scene
    subject = load_subject(args.scene)
    if isinstance(subject, scenes.Scene):
        return subject
    missing = [flag for flag, value in (("--q0", args.q0), ("--t-end", args.t_end)) if value is None]
    if missing:
        raise ValueError(f"{' and '.join(missing)}: {args.scene} is a model; give its initial state and horizon (--q0, --p0 or --v0, --t-end)")
    # From rest unless momenta or velocities are given.
    v0 = (0.0,) * len(args.q0) if args.p0 is None and args.v0 is None else args.v0
    return scenes.Scene.of(subject, args.q0, args.p0, v0=v0, t_end=args.t_end, dt=args.dt, name=args.scene.rpartition(":")[2])


def _run(args: argparse.Namespace) -> int:
    """One integration of a scene, its conservation report, and its final state."""
    subject = _scene(args)
    assert subject is not None  # run's SCENE is a required argument
    scene = scenes.as_scene(subject)
    method = args.method or scene.model.kind.default_method
    t_end = args.t_end or scene.t_end
    # The scene's step fitted to the horizon, or the step given (the horizon then rounded to it).
    steps = max(1, round(t_end / args.dt) if args.dt else math.ceil(t_end / scene.dt - 1e-9))
    dt = args.dt or t_end / steps
    print(f"{scene.name}: {scene.description or scene.model.name}; {method}, dt = {dt:g}, {steps} steps to t = {steps * dt:g} {scene.time_unit}")
    try:
        traj = integrate(scene, dt=dt, steps=steps, method=method, save_every=max(1, steps // 20000))
    except _core.VarmechError as e:
        print(f"error: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    print(check_conservation(traj))
    names = (*scene.model.coordinates, *scene.model.momentum_names)
    values = (*traj.q[-1], *traj.p[-1])
    print("final state: " + ", ".join(f"{n} = {v:.12g}" for n, v in zip(names, values)))
    return 0


def _scenes_table() -> Table:
    """The scenes by name: degrees of freedom, model kind, description."""
    table = Table(("scene", "dof", "kind", "description"), title="Scenes (varmech.scenes.get(name); python -m varmech run NAME)")
    for name in (*scenes.CATALOGUE, *scenes.SYMBOLIC):
        try:
            scene = scenes.get(name)
        except ImportError:
            continue
        table.append(name, scene.model.dim, scene.model.kind.name, scene.description)
    return table


def _floats(text: str) -> tuple[float, ...]:
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") from None


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return value


def _state_arguments(parser: argparse.ArgumentParser) -> None:
    """--q0, --p0, --v0: the initial state of one's own model."""
    for flag, what in (("--q0", "positions"), ("--p0", "momenta"), ("--v0", "velocities (default: at rest)")):
        parser.add_argument(flag, type=_floats, metavar="X,Y,...", help=f"one's own model: the initial {what}")


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
    sub.add_parser("scenes", help="print the table of scenes")
    r = sub.add_parser("run", help="integrate one scene (or one's own model) and print its conservation report")
    r.add_argument("scene", help="a scene name, or FILE.py:NAME / MODULE:NAME naming one's own Scene, Model or SymPy L")
    r.add_argument("--method", help="the method (default: the model's kind's default)")
    r.add_argument("--dt", type=_positive, help="the step (default: the scene's)")
    r.add_argument("--t-end", type=_positive, help="the horizon (default: the scene's; required for a model)")
    _state_arguments(r)
    c = sub.add_parser("chart", help="measure and write a chart (PNG or SVG) with its data (CSV)")
    c.add_argument("kind", choices=sorted(KINDS), help="; ".join(f"{k}: {v.description}" for k, v in KINDS.items()))
    c.add_argument(
        "scene", nargs="?", help="a scene name (default: the kind's own; varmech.charts.recipes.scenes_for(kind) lists those it takes), "
        "or FILE.py:NAME / MODULE:NAME naming one's own Scene, Model or SymPy L",
    )  # fmt: skip
    c.add_argument("--dt", type=_positive, help="one's own model: a step that resolves it (default: from its fastest frequency)")
    c.add_argument("--t-end", type=_positive, help="one's own model: the horizon (required)")
    _state_arguments(c)
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
    if args.command == "scenes":
        print(_scenes_table().format(max_rows=None))
        return 0
    if args.command == "run":
        try:
            return _run(args)
        except (ValueError, TypeError) as e:
            parser.error(str(e))
    if args.command == "chart":
        methods = tuple(args.methods.split(",")) if args.methods else None
        try:
            subject = _scene(args)
            if not isinstance(subject, scenes.Scene) and (args.dt or args.t_end):
                raise ValueError("--dt, --t-end: for one's own model; a chart of a built-in scene follows its own protocol")
            paths = chart(
                args.kind, subject, methods=methods, out=args.out, fmt=args.format, quick=args.quick, energies=args.energy,
                box=args.box, say=_note,
            )  # fmt: skip
        except (ValueError, TypeError) as e:
            parser.error(str(e))
        except _core.VarmechError as e:
            # A run of the measurement failed: said on one line, as ``run`` says it.
            print(f"error: {type(e).__name__}: {e}", file=sys.stderr)
            return 1
        for path in paths:
            print(f"wrote {path}")
        return 0
    print(format_table())
    return 0
