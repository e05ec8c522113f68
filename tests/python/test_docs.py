"""The docstring examples run as written (numpydoc ``Examples``): the symbolic front end, events,
files, long runs, dense output, impulses, impacts and their surfaces, the scenes, the stepper, the
conservation report, ensembles, constraints and small oscillations."""

import doctest
import importlib

import pytest

pytest.importorskip("sympy")


@pytest.mark.parametrize(
    "name",
    [
        "varmech.symbolic._constructors",
        "varmech.symbolic.examples",
        "varmech.symbolic._lower",
        "varmech.symbolic._derive",
        "varmech.symbolic._model",
        "varmech.symbolic._mass_flow",
        "varmech.symbolic._delays",
        "varmech.symbolic._mechanics",
        "varmech.events",
        "varmech.files",
        "varmech.streaming",
        "varmech.dense",
        "varmech.impulses",
        "varmech.impacts",
        "varmech.surfaces",
        "varmech.scenes._scene",
        "varmech.scenes._hamiltonian",
        "varmech.scenes._lagrangian",
        "varmech.scenes._constrained",
        "varmech.stepper",
        "varmech.conservation",
        "varmech.ensemble",
        "varmech.integrate",
        "varmech.trajectory",
        "varmech._model",
        "varmech._closures",
        "varmech._native",
        "varmech._symmetries",
        "varmech.constraints",
        "varmech.derivatives",
        "varmech.reduction",
        "varmech.modes",
        "varmech.methods",
        "varmech.analysis.work_precision",
        "varmech._errors",
        "varmech._warnings",
        "varmech.table",
        "varmech.analysis.energy_growth",
        "varmech.analysis.sections",
        "varmech.analysis.lyapunov",
        "varmech.analysis.strobe",
        "varmech.analysis.phase_portrait",
        "varmech.analysis.stability",
        "varmech.analysis.nonholonomic",
        "varmech.examples",
        "varmech.charts.recipes",
        "varmech.charts.energy",
        "varmech.charts.chaos",
        "varmech.charts.nonholonomic",
        "varmech.charts.sections",
        "varmech.charts.stability",
        "varmech.charts.work_precision",
        "varmech.pointers",
    ],
)
def test_examples_run(name):
    if name.startswith("varmech.charts"):
        pytest.importorskip("matplotlib")
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0, result
