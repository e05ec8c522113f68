"""The chart recipes: for each kind of chart, what to measure (:mod:`varmech.analysis`) with which
defaults, and which figures to draw from it. :func:`chart` runs one and writes the figures and
their data (CSV); ``python -m varmech chart <kind> [scene]`` (:mod:`varmech.cli`) and the tour
call it."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .. import scenes
from ..analysis import energy_growth, sections, stability, work_precision
from ..analysis.baselines import REBOUND_METHODS
from ..analysis.nonholonomic import nonholonomic_energy
from ..analysis.phase_portrait import phase_portrait
from ..table import Table
from .nonholonomic import nonholonomic_energy_chart
from .sections import phase_portrait_chart, poincare_chart
from .stability import implicit_regions_chart, stability_chart
from .work_precision import energy_growth_chart, work_precision_chart


@dataclass(frozen=True)
class ChartKind:
    """A chart the command line draws: its default scene and methods, and what it shows."""

    scene: str | None
    methods: tuple[str, ...]
    description: str
    #: (scene, methods, quick, progress) → [(CSV name, table, {figure name: chart function})].
    draw: Callable[[str | None, tuple[str, ...], bool, bool | None], list[tuple[str, Table, dict[str, Callable]]]]


def _work_precision(scene, methods, quick, progress):
    sc = scenes.get(scene)
    # Every REBOUND baseline that applies to the scene (none but leapfrog order=8 on Kepler).
    table = work_precision.work_precision(
        sc, methods, rebound=REBOUND_METHODS, repeat=1 if quick else 3, sweep_length=4 if quick else 11,
        max_seconds=1.0 if quick else 5.0, progress=progress,
    )
    title = f"{scene}: error at t = {table.meta.get('t_end', sc.t_end):g} against cost"
    energy_title = f"{scene}: max energy error over t = 0 … {table.meta.get('t_end', sc.t_end):g} against cost"
    figures = {
        "work_precision": lambda t, p: work_precision_chart(t, p, x="seconds", title=title),
        "work_precision_evaluations": lambda t, p: work_precision_chart(t, p, x="evaluations", title=title),
        "work_precision_energy": lambda t, p: work_precision_chart(t, p, y="max_energy_error", title=energy_title),
    }
    if table.meta["reference"] is None:
        # No reference solution (a chaotic scene has none at long times): only the energy error
        # is measured, so only its chart is drawn.
        figures = {"work_precision_energy": figures["work_precision_energy"]}
    return [("work_precision", table, figures)]


def _energy(scene, methods, quick, progress):
    sc = scenes.get(scene)
    t_end = (5 if quick else 50) * sc.t_end
    table = energy_growth.energy_growth(sc, methods, t_end=t_end, samples=500 if quick else 2000, progress=progress)
    title = f"{scene}: energy error over t = {t_end:g}"
    return [
        ("energy_growth", table, {"energy_growth": lambda t, p: energy_growth_chart(t, p, title=title)}),
        ("energy_verdicts", energy_growth.verdicts(table), {}),
    ]


def _stability(scene, methods, quick, progress):
    table = stability.growth_table(methods, progress=progress)
    return [
        ("stability", table, {"stability": lambda t, p: stability_chart(t, p, title="growth factor on q'' = -ω²q")}),
        ("stability_limits", stability.stability_table(methods, progress=progress), {}),
    ]


def _implicit_regions(scene, methods, quick, progress):
    table = stability.implicit_regions(methods, scene=scene, progress=progress)
    draw = lambda t, p: implicit_regions_chart(t, p, title=f"{scene}: implicit steps")  # noqa: E731
    return [("implicit_regions", table, {"implicit_regions": draw})]


def _poincare(scene, methods, quick, progress):
    sc = scenes.get(scene)
    out = []
    for energy in sections.HENON_HEILES_ENERGIES:
        table = sections.poincare_section(
            sc, energy, orbits=12 if quick else 40, t_end=300.0 if quick else 2000.0, method=methods[0], progress=progress
        )
        label = f"{energy:.4f}".rstrip("0")
        title = f"{scene}: Poincaré section x = 0, H = {label}"
        name = f"poincare_H{label.replace('.', '_')}"
        out.append((name, table, {name: lambda t, p, title=title: poincare_chart(t, p, title=title)}))
    return out


def _phase(scene, methods, quick, progress):
    table = phase_portrait(scenes.get(scene), method=methods[0], progress=progress)
    draw = lambda t, p: phase_portrait_chart(t, p, title=f"{scene}: phase portrait")  # noqa: E731
    return [("phase_portrait", table, {"phase_portrait": draw})]


def _nonholonomic(scene, methods, quick, progress):
    table = nonholonomic_energy(methods, steps=5_000 if quick else 100_000, progress=progress)
    draw = lambda t, p: nonholonomic_energy_chart(t, p)  # noqa: E731
    return [("nonholonomic_energy", table, {"nonholonomic_energy": draw})]


KINDS: dict[str, ChartKind] = {
    "work-precision": ChartKind(
        "kepler", ("verlet", "yoshida4", "kahan_li8", "rk4"),
        "error at the final time (and max energy error) against wall time and force evaluations; scipy and REBOUND baselines",
        _work_precision,
    ),
    "energy": ChartKind(
        "kepler", ("verlet", "kahan_li8", "rk4"), "energy error against time, log–log, with a √t line", _energy
    ),
    "stability": ChartKind(
        None, ("symplectic_euler", "verlet", "yoshida4", "mclachlan4", "kahan_li8", "rk4", "midpoint"),
        "growth factor against hω with each stability limit", _stability,
    ),
    "implicit-regions": ChartKind(
        "pendulum", ("midpoint", "trapezoid", "galerkin4", "galerkin6"),
        "where the implicit methods' Newton iterations fail or jump branches", _implicit_regions,
    ),
    "poincare": ChartKind("henon_heiles", ("kahan_li6",), "Poincaré sections at H = 1/12 and 1/8", _poincare),
    "phase": ChartKind("pendulum", ("kahan_li6",), "phase portrait: librations, separatrix, rotations", _phase),
    "nonholonomic": ChartKind(
        None, ("midpoint", "cortes_martinez", "rk4_projection"),
        "a rolling disk's energy error against time: the discrete Lagrange–d'Alembert integrators and RK4 with a "
        "velocity projection", _nonholonomic,
    ),
}


def chart(
    kind: str,
    scene: str | None = None,
    *,
    methods: tuple[str, ...] | None = None,
    out: Path = Path("out/charts"),
    fmt: str = "png",
    quick: bool = False,
    progress: bool | None = None,
) -> list[Path]:
    """Measure chart ``kind`` on ``scene`` (its default when None) and write, for each figure,
    ``<out>/<name>_<scene>.<fmt>`` and the data as ``.csv``; returns the paths written."""
    if kind not in KINDS:
        raise ValueError(f"kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    if fmt not in ("png", "svg"):
        raise ValueError(f"format: expected png or svg, got {fmt!r}")
    spec = KINDS[kind]
    scene = scene or spec.scene
    known = (*scenes.CATALOGUE, *scenes.SYMBOLIC)
    if scene is not None and scene not in known:
        raise ValueError(f"scene: expected one of {', '.join(known)}, got {scene!r}")
    stem = f"_{scene}" if scene else ""
    written = []
    for name, table, figures in spec.draw(scene, tuple(methods or spec.methods), quick, progress):
        written.append(table.to_csv(out / f"{name}{stem}.csv"))
        written += [draw(table, out / f"{figure}{stem}.{fmt}") for figure, draw in figures.items()]
    return written
