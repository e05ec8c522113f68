"""Charts in the user's own figures: every chart draws into given Axes (or a new Figure made
without pyplot), returns the figure, writes a file only when given a path, and never chooses or
changes matplotlib's backend."""

from __future__ import annotations

import math

import pytest

import varmech
from varmech import charts
from varmech.analysis.implicit import implicit_regions
from varmech.analysis.nonholonomic import nonholonomic_energy
from varmech.analysis.phase_portrait import phase_portrait
from varmech.analysis.sections import poincare_section
from varmech.analysis.stability import growth_table, spectrum

matplotlib = pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def drawings():
    """Each public chart with the smallest measurement it draws, as ``draw(**where)``."""
    driven = varmech.scenes.get("damped_driven_pendulum")
    oscillator = varmech.scenes.harmonic_oscillator()
    runs = {m: varmech.integrate(oscillator, dt=0.1, steps=100, method=m) for m in ("verlet", "rk4")}
    hh = varmech.scenes.henon_heiles()
    sections = [poincare_section(hh, e, orbits=2, dt=0.1, t_end=30.0, progress=False) for e in (1 / 12, 1 / 8)]
    regions = implicit_regions(("midpoint", "galerkin4"), h_values=(0.5, 3.0), q0_values=(1.0, 3.0))
    growth = varmech.energy_growth(oscillator, ["verlet"], t_end=50.0, samples=10, baselines=())
    lyapunov = varmech.lyapunov_spectrum(hh.model, [0.0, -0.25], [0.42, 0.0], dt=0.05, steps=400)
    portrait = phase_portrait(varmech.scenes.pendulum(), [-0.5, 2.0], dt=0.1, t_end=10.0, progress=False)
    tables = {
        "energy_error": lambda **k: charts.energy_error(runs, **k),
        "energy_growth_chart": (charts.energy_growth_chart, growth),
        "implicit_regions_chart": (charts.implicit_regions_chart, regions),
        "lyapunov_chart": (charts.lyapunov_chart, lyapunov),
        "nonholonomic_energy_chart": (charts.nonholonomic_energy_chart, nonholonomic_energy(steps=100, samples=5)),
        "orbit_diagram_chart": (charts.orbit_diagram_chart, varmech.orbit_diagram(
            driven, [-math.pi / 2], [0.0], parameter="amplitude", values=[1.06, 1.075], period=3 * math.pi, periods=4, transient=10)),
        "phase_portrait_chart": (charts.phase_portrait_chart, portrait),
        "poincare_chart": (charts.poincare_chart, sections),
        "spectrum_chart": (charts.spectrum_chart, spectrum(varmech.scenes.fermi_pasta_ulam(), ["verlet", "midpoint"])),
        "stability_chart": (charts.stability_chart, growth_table(["verlet", "rk4"], [0.5, 2.5], limits=False)),
        "strobe_chart": (charts.strobe_chart, varmech.stroboscopic_section(driven, [-math.pi / 2], [0.0], period=3 * math.pi, periods=20)),
        "work_precision_chart": (charts.work_precision_chart, varmech.work_precision(
            oscillator, ["verlet"], steps=[64, 128], baselines=(), rebound=(), repeat=1)),
    }
    return {name: t if callable(t) else (lambda f=t[0], table=t[1], **k: f(table, **k)) for name, t in tables.items()}


PANELS = {"poincare_chart": 2, "implicit_regions_chart": 2}


@pytest.fixture
def svg_backend():
    """The user's own backend, svg, put back as it was afterwards."""
    previous = matplotlib.get_backend()
    matplotlib.use("svg")
    yield "svg"
    matplotlib.use(previous)


def test_every_chart_is_covered(drawings):
    assert sorted(drawings) == sorted(charts.__all__)


@pytest.mark.parametrize("name", sorted(charts.__all__))
def test_a_chart_draws_into_the_users_axes_and_leaves_the_backend_alone(name, drawings, svg_backend):
    import matplotlib.pyplot as plt

    panels = PANELS.get(name, 1)
    fig, axes = plt.subplots(1, panels, squeeze=False)
    before = [len(ax.get_children()) for ax in axes.flat]
    ax = axes[0, 0] if panels == 1 else list(axes.flat)
    try:
        drawn = drawings[name](ax=ax)
        assert drawn is fig
        assert matplotlib.get_backend() == svg_backend
        # Its artists are in the user's axes: lines, dots, bars or images, each panel.
        for ax_, count in zip(axes.flat, before):
            artists = [*ax_.lines, *ax_.collections, *ax_.images, *ax_.patches]
            assert artists and len(ax_.get_children()) > count, name
        assert plt.get_fignums() == [fig.number]   # no figure of its own left open
    finally:
        plt.close(fig)


@pytest.mark.parametrize("name", sorted(charts.__all__))
def test_a_chart_without_axes_makes_a_figure_outside_pyplot_and_writes_only_when_asked(name, drawings, svg_backend, tmp_path):
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    open_before = plt.get_fignums()
    fig = drawings[name]()
    assert isinstance(fig, Figure) and fig.axes
    assert plt.get_fignums() == open_before and matplotlib.get_backend() == svg_backend
    assert list(tmp_path.iterdir()) == []
    path = tmp_path / "sub" / f"{name}.png"
    assert isinstance(drawings[name](path=path), Figure)
    # A PNG's signature, in a folder the chart made.
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_quick_measurement_says_so_in_the_users_axes_and_a_wrong_ax_is_named(drawings, svg_backend):
    import matplotlib.pyplot as plt

    table = varmech.work_precision(varmech.scenes.harmonic_oscillator(), ["verlet"], steps=[64], baselines=(), rebound=(), repeat=1)
    table.meta["quick"] = True
    fig, ax = plt.subplots()
    try:
        charts.work_precision_chart(table, ax=ax, title="mine")
        assert ax.get_title().startswith(charts._figure.QUICK_NOTE) and ax.get_title().endswith("mine")
        assert not fig.texts   # no suptitle put on the user's figure
        with pytest.raises(TypeError, match="^ax: expected a matplotlib Axes"):
            charts.work_precision_chart(table, ax=fig)
        with pytest.raises(ValueError, match="^ax: this chart draws 2 panels, got 1 Axes"):
            drawings["poincare_chart"](ax=ax)
        with pytest.raises(ValueError, match="^path: must end in .png or .svg"):
            charts.work_precision_chart(table, "chart.pdf", ax=ax)
    finally:
        plt.close(fig)
