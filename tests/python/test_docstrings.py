"""Every public object has a complete numpydoc docstring, found by walking the public namespaces
(not a hand-kept list, which goes stale): functions and scene constructors document every
parameter and no unknown one, Returns, Raises and an Examples section (test_docs.py runs the
examples); methods document their parameters, returns and raises; classes their parameters and
an example; every field and property of a result record is documented under Attributes.
Rendered by the docs site (numpydoc)."""

import dataclasses
import importlib
import inspect

import pytest

numpydoc_validate = pytest.importorskip("numpydoc.validate")
from numpydoc.docscrape import ClassDoc, FunctionDoc  # noqa: E402

#: The namespaces whose ``__all__`` is the public API.
NAMESPACES = [
    "varmech",
    "varmech.charts",
    "varmech.symbolic",
    "varmech.events",
    "varmech.impacts",
    "varmech.impulses",
    "varmech.surfaces",
    "varmech.pointers",
]
#: The modules without ``__all__`` whose every function and class not named ``_…`` is public.
MODULES = ["varmech.scenes"]
#: Functions and methods that raise nothing of their own (a Raises section would invent one),
#: besides those that take no arguments.
NO_RAISES = {
    "varmech.methods.methods",
    "varmech.pointers.is_pointer",
    "varmech.conservation.InvariantStatistics.describe",
    "varmech.ensemble.Ensemble.check_conservation",
    "varmech.ensemble.Ensemble.energy",
    "varmech.model.Translation.spec",
    "varmech.model.Rotation.spec",
    "varmech.model.Cyclic.spec",
    "varmech.stepper.Stepper.checkpoint",
    "varmech.surfaces.Wall.gradient",
    "varmech.surfaces.Ellipsoid.gradient",
    "varmech.symbolic._model.SymbolicModel.first_order",
    "varmech.symbolic._model.SymbolicModel.with_jit",
    "varmech.table.Table.format",
}
#: The model classes, which check what they are given, say what they raise.
MODELS = ["varmech.model.MechanicalSystem", "varmech.model.Lagrangian"]


def public_objects() -> dict[str, object]:
    """Qualified name → object: each namespace's ``__all__`` (modules aside, and the binding's own
    classes, which its stubs describe), the public functions and classes of the other modules,
    and the public methods of every public class."""
    found: dict[str, object] = {}

    def add(obj: object) -> None:
        module = getattr(obj, "__module__", "") or ""
        if module.startswith("varmech") and not module.startswith("varmech._core"):
            found[f"{module}.{obj.__qualname__}"] = obj  # type: ignore[attr-defined]

    for name in NAMESPACES:
        namespace = importlib.import_module(name)
        for attr in namespace.__all__:
            obj = getattr(namespace, attr)
            if not inspect.ismodule(obj):
                add(obj)
    for name in MODULES:
        for attr, obj in vars(importlib.import_module(name)).items():
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and obj.__module__ == name and not attr.startswith("_"):
                add(obj)
    for obj in list(found.values()):
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and (inspect.isfunction(member) or isinstance(member, (staticmethod, classmethod))):
                    add(getattr(obj, attr))
    return found


OBJECTS = public_objects()
FUNCTIONS = sorted(n for n, o in OBJECTS.items() if inspect.isfunction(o) or inspect.ismethod(o))
CLASSES = sorted(n for n, o in OBJECTS.items() if inspect.isclass(o))
RECORDS = sorted(n for n in CLASSES if dataclasses.is_dataclass(OBJECTS[n]))


def errors(name: str, codes: set[str]) -> list[tuple[str, str]]:
    return [(c, m) for c, m in numpydoc_validate.validate(name)["errors"] if c in codes]


def test_the_walk_finds_the_api():
    """The walk reaches the entry points, the scenes, the records and the methods."""
    for name in [
        *MODELS,
        "varmech.integrate.integrate",
        "varmech.scenes.kepler",
        "varmech.scenes.rolling_disk",
        "varmech.integrate.Trajectory",
        "varmech.integrate.Trajectory.save",
        "varmech.charts.work_precision.work_precision_chart",
        "varmech.symbolic.lagrangian",
    ]:
        assert name in OBJECTS, name
    assert len(FUNCTIONS) > 100 and len(RECORDS) > 10


@pytest.mark.parametrize("name", FUNCTIONS)
def test_functions_document_parameters_returns_raises_and_examples(name):
    method = "." in OBJECTS[name].__qualname__  # type: ignore[attr-defined]
    # A method's examples are its class's.
    codes = {"PR01", "PR02", "RT01", "GL08", "SA04"} | (set() if method else {"EX01"})
    assert errors(name, codes) == []
    takes = [p for p in inspect.signature(OBJECTS[name]).parameters if p not in ("self", "cls")]  # type: ignore[arg-type]
    assert name in NO_RAISES or not takes or FunctionDoc(OBJECTS[name])["Raises"], f"{name}: no Raises section"


@pytest.mark.parametrize("name", CLASSES)
def test_classes_document_parameters_and_examples(name):
    cls = OBJECTS[name]
    # A record's fields, and an error's attributes, are documented under Attributes.
    plain = not dataclasses.is_dataclass(cls) and not issubclass(cls, BaseException)  # type: ignore[arg-type]
    assert errors(name, {"PR02", "EX01", "GL08"} | ({"PR01"} if plain else set())) == []
    assert name not in MODELS or ClassDoc(cls, config={"show_class_members": False})["Raises"]


@pytest.mark.parametrize("name", RECORDS)
def test_records_document_every_field_and_property(name):
    cls = OBJECTS[name]
    documented = {
        n.strip() for p in ClassDoc(cls, config={"show_class_members": False})["Attributes"] for n in p.name.split(",")
    }
    fields = {f.name for f in dataclasses.fields(cls) if not f.name.startswith("_")}  # type: ignore[arg-type]
    properties = {n for n, v in vars(cls).items() if isinstance(v, property) and not n.startswith("_")}
    assert fields | properties <= documented, f"{name}: undocumented {sorted((fields | properties) - documented)}"
    assert documented <= fields | properties, f"{name}: documents {sorted(documented - fields - properties)}"


def test_the_exemptions_are_current():
    """Each exemption names a public function that indeed has no Raises section."""
    for name in NO_RAISES:
        assert name in FUNCTIONS, name
        assert not FunctionDoc(OBJECTS[name])["Raises"], f"{name} has a Raises section: drop its exemption"
