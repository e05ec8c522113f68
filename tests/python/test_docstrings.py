"""The most-used public API has complete numpydoc docstrings: every parameter documented and no
unknown one, Returns, Raises and an Examples section (test_docs.py runs the examples), and every
field of a result record documented under Attributes. Rendered by the docs site (numpydoc)."""

import dataclasses
import importlib

import pytest

numpydoc_validate = pytest.importorskip("numpydoc.validate")
from numpydoc.docscrape import ClassDoc, FunctionDoc  # noqa: E402

FUNCTIONS = [
    "varmech.integrate.integrate",
    "varmech.conservation.check_conservation",
    "varmech.conservation.momentum",
    "varmech.constraints.project",
    "varmech.ensemble.ensemble",
    "varmech.analysis.work_precision.work_precision",
    "varmech.reduction.routh",
    "varmech.files.load",
    "varmech.streaming.resume",
    "varmech.scenes.get",
    "varmech.methods.methods",
    "varmech.events.crossing",
    "varmech.events.energy_error",
    "varmech.events.escape",
    "varmech.events.encounter",
    "varmech.constraints.integrable_near",
    "varmech.symbolic.lagrangian",
    "varmech.symbolic.mechanical",
    "varmech.symbolic.routh",
    "varmech.derivatives.check_derivatives",
    "varmech.integrate.symplecticity_defect",
]
#: Functions that raise nothing of their own.
NO_RAISES = {"varmech.methods.methods"}
MODELS = ["varmech.model.MechanicalSystem", "varmech.model.Lagrangian"]
RECORDS = [
    "varmech.integrate.Trajectory",
    "varmech.conservation.ConservationReport",
    "varmech.conservation.InvariantStatistics",
    "varmech.ensemble.Ensemble",
    "varmech.scenes.Scene",
]


def resolve(name: str):
    module, _, attr = name.rpartition(".")
    return getattr(importlib.import_module(module), attr)


def errors(name: str, codes: set[str]) -> list[tuple[str, str]]:
    return [(c, m) for c, m in numpydoc_validate.validate(name)["errors"] if c in codes]


@pytest.mark.parametrize("name", FUNCTIONS)
def test_functions_document_parameters_returns_raises_and_examples(name):
    assert errors(name, {"PR01", "PR02", "RT01", "EX01", "GL08"}) == []
    assert name in NO_RAISES or FunctionDoc(resolve(name))["Raises"], f"{name}: no Raises section"


@pytest.mark.parametrize("name", MODELS)
def test_model_classes_document_parameters_raises_and_examples(name):
    assert errors(name, {"PR01", "PR02", "EX01", "GL08"}) == []
    assert ClassDoc(resolve(name), config={"show_class_members": False})["Raises"]


@pytest.mark.parametrize("name", RECORDS)
def test_records_document_every_field_and_property(name):
    cls = resolve(name)
    documented = {
        n.strip() for p in ClassDoc(cls, config={"show_class_members": False})["Attributes"] for n in p.name.split(",")
    }
    fields = {f.name for f in dataclasses.fields(cls) if not f.name.startswith("_")}
    properties = {n for n, v in vars(cls).items() if isinstance(v, property) and not n.startswith("_")}
    assert fields | properties <= documented, f"{name}: undocumented {sorted((fields | properties) - documented)}"
    assert documented <= fields | properties, f"{name}: documents {sorted(documented - fields - properties)}"
    assert errors(name, {"EX01"}) == []
