"""The chart recipes: for each kind of chart, what to measure (:mod:`varmech.analysis`) with which
defaults, and which figures to draw from it. :func:`chart` runs one and writes the figures and
their data (CSV); ``python -m varmech chart <kind> [scene]`` (:mod:`varmech.cli`) and the tour
call it."""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import scenes
from ..analysis import energy_growth, implicit, sections, stability, work_precision
from ..analysis._orbits import energy_at
from ..analysis.baselines import REBOUND_METHODS
from ..analysis.nonholonomic import nonholonomic_energy
from ..analysis.phase_portrait import phase_portrait
from ..analysis.strobe import orbit_diagram, stroboscopic_section
from ..table import Table
from .chaos import orbit_diagram_chart, strobe_chart
from .nonholonomic import nonholonomic_energy_chart
from .sections import phase_portrait_chart, poincare_chart
from .stability import implicit_regions_chart, spectrum_chart, stability_chart
from .work_precision import energy_growth_chart, work_precision_chart

__all__ = [
    "chart",
    "scenes_for",
]


@dataclass(frozen=True)
class ChartKind:
    """A chart the command line draws: its default scene and methods, and what it shows."""

    scene: str | None
    methods: tuple[str, ...]
    description: str
    #: (scene, methods, quick, progress, options) → [(CSV name, table, {figure name: chart function})].
    draw: Callable[..., list[tuple[str, Table, dict[str, Callable]]]]
    #: Whether the chart applies to a scene: None if it does, else why not.
    refuses: Callable[[scenes.Scene], str | None] = lambda scene: None


def fitting_methods(methods: tuple[str, ...], scene: scenes.Scene) -> tuple[str, ...]:
    """The methods of ``methods`` that integrate ``scene``'s model, or, if none does, its kind's
    accurate and default methods (the core's table, :class:`varmech.ModelKind`)."""
    kind = scene.model.kind
    return tuple(m for m in methods if kind.admits(m)) or tuple(dict.fromkeys((kind.accurate_method, kind.default_method)))


def _unconstrained(scene: scenes.Scene) -> str | None:
    model = scene.model
    if model.kind.name.startswith("constrained") or model.kind.name == "nonholonomic" or scene.contacts:
        return f"{scene.name} is a {model.kind.name} model{' with contacts' if scene.contacts else ''}; the sections need a free one"
    if model.forced or model.time_dependent:
        return f"{scene.name} has no conserved energy; the sections need one"
    return None


def _one_freedom(scene: scenes.Scene) -> str | None:
    if scene.model.dim != 1:
        return f"a phase portrait needs one degree of freedom, {scene.name} has {scene.model.dim}; use poincare"
    return _unconstrained(scene)


def _implicit(scene: scenes.Scene) -> str | None:
    if scene.model.kind.name.startswith("constrained") or scene.model.velocity_constraints:
        return f"{scene.name} is a {scene.model.kind.name} model: the map's initial states would leave its constraints"
    if not any(scene.model.kind.admits(m) for m in stability.IMPLICIT_METHODS):
        methods = ", ".join(stability.IMPLICIT_METHODS)
        return f"{scene.name} is a {scene.model.kind.name} model, which none of the implicit methods {methods} integrates"
    return None


def _no_scene(scene: scenes.Scene) -> str | None:
    return "the stability chart is of the linear test equation q'' = −ω²q; it takes no scene"


def _two_freedoms(scene: scenes.Scene) -> str | None:
    if scene.model.dim != 2:
        return f"a Poincaré section in a plane needs two degrees of freedom, {scene.name} has {scene.model.dim}"
    return _unconstrained(scene)


def _work_precision(sc, methods, quick, progress, options):
    # Every REBOUND baseline that applies to the scene (none but leapfrog order=8 on Kepler).
    table = work_precision.work_precision(
        sc, methods, rebound=REBOUND_METHODS, repeat=1 if quick else 3, sweep_length=4 if quick else 11,
        max_seconds=1.0 if quick else 5.0, progress=progress,
    )
    horizon = f"{table.meta.get('t_end', sc.t_end):g} {sc.time_unit}"
    title = f"{sc.name}: error in (q, p) at t = {horizon} against cost"
    energy_title = f"{sc.name}: max energy error over t = 0 … {horizon} against cost"
    figures = {
        "work_precision": lambda t, p: work_precision_chart(t, p, x="seconds", title=title),
        "work_precision_evaluations": lambda t, p: work_precision_chart(t, p, x="evaluations", title=title),
        "work_precision_energy": lambda t, p: work_precision_chart(t, p, y="max_energy_error", title=energy_title),
    }
    if table.meta["reference"] is None:
        # No reference solution (a computed one could not be had): only the energy error is
        # measured, so only its chart is drawn.
        figures = {"work_precision_energy": figures["work_precision_energy"]}
    return [("work_precision", table, figures)]


def _energy(sc, methods, quick, progress, options):
    t_end = sc.long_run / (10 if quick else 1)
    table = energy_growth.energy_growth(sc, methods, t_end=t_end, samples=500 if quick else 2000, progress=progress)
    title = f"{sc.name}: max energy error up to t, over t = 0 … {t_end:g} {sc.time_unit}"
    return [
        ("energy_growth", table, {"energy_growth": lambda t, p: energy_growth_chart(t, p, title=title)}),
        ("energy_verdicts", energy_growth.verdicts(table), {}),
    ]


def _stability(sc, methods, quick, progress, options):
    table = stability.growth_table(methods, progress=progress)
    return [
        ("stability", table, {"stability": lambda t, p: stability_chart(t, p)}),
        ("stability_limits", stability.stability_table(methods, progress=progress), {}),
    ]


def _linearizable(scene: scenes.Scene) -> str | None:
    if scene.model.velocity_constraints:
        return f"{scene.name} has velocity constraints, whose small oscillations are not a Lagrangian's on a manifold"
    return None


def _spectrum(sc, methods, quick, progress, options):
    table = stability.spectrum(sc, methods)
    return [("spectrum", table, {"spectrum": lambda t, p: spectrum_chart(t, p)})]


def _implicit_regions(sc, methods, quick, progress, options):
    table = implicit.implicit_regions(methods, scene=sc, progress=progress)
    draw = lambda t, p: implicit_regions_chart(t, p, title=f"{sc.name}: outcome of the implicit steps by step and initial angle")  # noqa: E731
    return [("implicit_regions", table, {"implicit_regions": draw})]


def _poincare(sc, methods, quick, progress, options):
    henon_heiles = sc.name == "henon_heiles"
    out = []
    box = options.get("box")
    section = (0, 0.0, 1)
    if not henon_heiles:
        # The section through the scene's own state, q₀ = q₀(0), and a box about the state's
        # (q₁, p₁), a quarter of its size: the seeds find the energy shell there.
        section = (0, float(sc.q0[0]), 1)
        if box is None:
            q, p = float(sc.q0[1]), float(sc.p0[1])
            dq, dp = max(0.05, abs(q) / 4), max(0.05, abs(p) / 4)
            box = ((q - dq, q + dq), (p - dp, p + dp))
    energies = options.get("energies")
    if energies is None:
        energies = sections.HENON_HEILES_ENERGIES if henon_heiles else (float(energy_at(sc.model, sc.q0, sc.p0)[0]),)
    dt = 0.05 if henon_heiles else sc.dt
    t_end = dt * round((300.0 if quick else 2000.0) / dt)
    x, p_x = sc.model.coordinates[section[0]], sc.model.momentum_names[section[0]]
    for energy in energies:
        table = sections.poincare_section(
            sc, energy, orbits=12 if quick else 40, t_end=t_end, dt=dt, method=methods[0], box=box, section=section,
            progress=progress,
        )  # fmt: skip
        label = f"{energy:.4f}".rstrip("0")
        title = f"{sc.name}: Poincaré section {x} = {section[1]:.4g} ({p_x} > 0), {sc.model.energy_name} = {label}"
        name = f"poincare_H{label.replace('.', '_')}"
        out.append((name, table, {name: lambda t, p, title=title: poincare_chart(t, p, title=title)}))
    return out


def _phase(sc, methods, quick, progress, options):
    energies = options.get("energies")
    if energies is None and sc.name != "pendulum":
        # Orbits about the scene's own, from a quarter of its energy to four times it.
        e0 = float(energy_at(sc.model, sc.q0, sc.p0)[0])
        energies = tuple(e0 * f for f in (0.25, 0.5, 1.0, 2.0, 4.0)) if e0 > 0 else (e0,)
    table = phase_portrait(sc, energies=energies, method=methods[0], progress=progress)
    draw = lambda t, p: phase_portrait_chart(t, p, title=f"{sc.name}: phase portrait")  # noqa: E731
    return [("phase_portrait", table, {"phase_portrait": draw})]


def _driven_only(scene: scenes.Scene) -> str | None:
    if scene.name == "damped_driven_pendulum":
        return None
    return "the orbit diagram and the strobe are of the damped, driven pendulum, strobed at its drive's period"


def _orbit_diagram(sc, methods, quick, progress, options):
    # Taylor's cascade (§12.5): γ from 1.06 to 1.09, from φ = −π/2 at rest.
    period = 2 * math.pi / sc.parameters["drive"]
    values = np.linspace(1.06, 1.09, 31 if quick else 301)
    table = orbit_diagram(
        sc, [-math.pi / 2], [0.0], parameter="amplitude", values=values, period=period, periods=16 if quick else 64,
        transient=100 if quick else 300, method=methods[0],
    )  # fmt: skip
    title = f"{sc.name}: φ̇ strobed at the drive's period"
    draw = lambda t, p: orbit_diagram_chart(t, p, title=title)  # noqa: E731
    return [("orbit_diagram", table, {"orbit_diagram": draw})]


def _strobe(sc, methods, quick, progress, options):
    # The scene's own drive (Baker & Gollub's chaotic γ = 1.5 by default), from φ = −π/2 at rest.
    period = 2 * math.pi / sc.parameters["drive"]
    table = stroboscopic_section(
        sc, [-math.pi / 2], [0.0], period=period, periods=1_000 if quick else 20_000, transient=100, method=methods[0]
    )
    title = f"{sc.name}: the attractor strobed at the drive's period"
    draw = lambda t, p: strobe_chart(t, p, wrap=2 * math.pi, title=title)  # noqa: E731
    return [("strobe", table, {"strobe": draw})]


def _disk_only(scene: scenes.Scene) -> str | None:
    return "the nonholonomic chart is of the rolling disk (its closure model and RK4 with a projection); it takes no scene"


def _nonholonomic(sc, methods, quick, progress, options):
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
        "growth factor against hω with each stability limit", _stability, _no_scene,
    ),
    "spectrum": ChartKind(
        "fermi_pasta_ulam", ("verlet", "yoshida4", "mclachlan4", "kahan_li8", "rk4", "midpoint"),
        "the scene's normal-mode frequencies hω at its q0 and dt against each method's stability interval",
        _spectrum, _linearizable,
    ),
    "implicit-regions": ChartKind(
        "pendulum", ("midpoint", "trapezoid", "galerkin4", "galerkin6"),
        "where the implicit methods' Newton iterations fail or jump branches", _implicit_regions, _implicit,
    ),
    "poincare": ChartKind(
        "henon_heiles", ("kahan_li6",), "Poincaré sections (Hénon–Heiles: at H = 1/12 and 1/8; else the scene's energy)", _poincare,
        _two_freedoms,
    ),
    "phase": ChartKind("pendulum", ("kahan_li6",), "phase portrait: librations, separatrix, rotations", _phase, _one_freedom),
    "orbit-diagram": ChartKind(
        "damped_driven_pendulum", ("galerkin6",),
        "the strobe's attractor over the drive's amplitude: Taylor's period-doubling cascade into chaos", _orbit_diagram,
        _driven_only,
    ),
    "strobe": ChartKind(
        "damped_driven_pendulum", ("galerkin6",),
        "the state at each period of the drive, φ mod 2π against φ̇: the strange attractor of the chaotic pendulum",
        _strobe, _driven_only,
    ),
    "nonholonomic": ChartKind(
        None, ("midpoint", "cortes_martinez", "rk4_projection"),
        "a rolling disk's energy error against time: the discrete Lagrange–d'Alembert integrators and RK4 with a "
        "velocity projection", _nonholonomic, _disk_only,
    ),
}


def chart(
    kind: str,
    scene: str | scenes.Scene | None = None,
    *,
    methods: tuple[str, ...] | None = None,
    out: Path = Path("out/charts"),
    fmt: str = "png",
    quick: bool = False,
    progress: bool | None = None,
    energies: tuple[float, ...] | None = None,
    box: tuple[tuple[float, float], tuple[float, float]] | None = None,
    say: Callable[[str], object] | None = None,
) -> list[Path]:
    """Measure chart ``kind`` on ``scene`` and write its figures and data: the Python form of
    ``python -m varmech chart KIND [SCENE]``.

    For each figure, ``<out>/<name>_<scene>.<fmt>`` is written (the scene's name, its spaces and
    punctuation as ``_``), and the measured table as ``.csv``; with ``quick``, the tables say so
    (``meta["quick"]``) and the figures too. ``methods`` default to the kind's own that integrate the scene, or else the
    scene's kind's accurate and default methods.

    Parameters
    ----------
    kind : str
        One of ``work-precision``, ``energy``, ``stability``, ``spectrum``,
        ``implicit-regions``, ``poincare``, ``phase``, ``orbit-diagram``, ``strobe``,
        ``nonholonomic``.
    scene : str or Scene, optional
        A scene of :data:`varmech.scenes.CATALOGUE` or a symbolic one by name, or a
        :class:`~varmech.Scene` (one's own model: :meth:`varmech.Scene.of`); default: the kind's
        own (:func:`scenes_for` lists the named ones the kind applies to).
    methods : tuple of str, optional
        The methods to measure; default as above.
    out : pathlib.Path, default Path("out/charts")
        The folder written to.
    fmt : {"png", "svg"}, default "png"
        The figures' format.
    quick : bool, default False
        A short measurement (fewer steps, orbits and tolerances), for a first look and tests.
    progress : bool, optional
        Show progress bars; default: on a terminal (stderr) or in a Jupyter notebook, unless TQDM_DISABLE is set.
    energies : tuple of float, optional
        The Poincaré sections' energy shells (default: Hénon–Heiles' 1/12 and 1/8, another
        scene's own energy) or the phase portrait's orbits (default: the pendulum's own, another
        scene's energy times 1/4 … 4).
    box : ((float, float), (float, float)), optional
        The sections' seeding box (Hénon–Heiles: its allowed region; another scene: a box twice
        its initial state's size).
    say : callable, optional
        Called with each note of the measurements (skipped baselines, stopped sweeps), which
        the charts draw too.

    Returns
    -------
    list of pathlib.Path
        The files written, each table's CSV before its figures.

    Raises
    ------
    ValueError
        Naming ``kind`` for an unknown chart, ``format`` for a format other than png or svg,
        ``scene`` for an unknown scene or one the kind does not apply to.

    See Also
    --------
    scenes_for : the scenes a chart kind applies to.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from varmech.charts.recipes import chart
    >>> paths = chart("implicit-regions", out=pathlib.Path(tempfile.mkdtemp()), quick=True, progress=False)
    >>> [path.name for path in paths]
    ['implicit_regions_pendulum.csv', 'implicit_regions_pendulum.png']
    """
    if kind not in KINDS:
        raise ValueError(f"kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    if fmt not in ("png", "svg"):
        raise ValueError(f"format: expected png or svg, got {fmt!r}")
    spec = KINDS[kind]
    sc = None
    if isinstance(scene, scenes.Scene):
        sc = scene
    elif scene is not None or spec.scene is not None:
        name = scene or spec.scene
        known = (*scenes.CATALOGUE, *scenes.SYMBOLIC)
        if name not in known:
            raise ValueError(f"scene: expected one of {', '.join(known)}, or a varmech.Scene, got {name!r}")
        sc = scenes.get(name)
    if sc is not None:
        why = spec.refuses(sc)
        if why is not None:
            raise ValueError(f"scene: {why}")
        methods = methods or fitting_methods(spec.methods, sc)
    stem = "_" + re.sub(r"[^A-Za-z0-9_.-]+", "_", sc.name).strip("_") if sc is not None else ""
    written = []
    options = {"energies": energies, "box": box}
    for name, table, figures in spec.draw(sc, tuple(methods or spec.methods), quick, progress, options):
        table.meta["quick"] = quick
        if say is not None:
            for note in table.meta.get("notes", []):
                say(note)
        written.append(table.to_csv(out / f"{name}{stem}.csv"))
        for figure, draw in figures.items():
            written.append(out / f"{figure}{stem}.{fmt}")
            draw(table, written[-1])
    return written


def scenes_for(kind: str) -> list[str]:
    """The scenes chart ``kind`` applies to: every scene of the catalogue and the symbolic ones,
    less those it refuses, such as a phase portrait of two degrees of freedom.

    Parameters
    ----------
    kind : str
        A chart kind, as :func:`chart` takes it.

    Returns
    -------
    list of str
        The scenes' names, in the catalogue's order.

    Raises
    ------
    ValueError
        Naming ``kind`` for an unknown chart.

    See Also
    --------
    chart : measures and draws a chart kind on one of these scenes.

    Examples
    --------
    >>> from varmech.charts.recipes import scenes_for
    >>> scenes_for("phase")
    ['harmonic_oscillator', 'pendulum']
    """
    if kind not in KINDS:
        raise ValueError(f"kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    refuses = KINDS[kind].refuses
    return [name for name in (*scenes.CATALOGUE, *scenes.SYMBOLIC) if refuses(scenes.get(name)) is None]
