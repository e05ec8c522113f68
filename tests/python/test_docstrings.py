"""Every public object has a complete numpydoc docstring, found by walking the public namespaces
(not a hand-kept list, which goes stale): functions and scene constructors document every
parameter and no unknown one, Returns, Raises and an Examples section (test_docs.py runs the
examples), and so do methods, each with an example of its own; classes document their parameters
and an example; every field and property of a result record is documented under Attributes.
Rendered by the docs site (numpydoc)."""

import dataclasses
import importlib
import inspect
import pkgutil

import pytest

import varmech

numpydoc_validate = pytest.importorskip("numpydoc.validate")
from numpydoc.docscrape import ClassDoc, FunctionDoc  # noqa: E402

#: The public modules: every module of the package with no ``_`` part in its name, each of
#: which declares its public API in ``__all__``.
MODULES = ["varmech"] + sorted(
    m.name for m in pkgutil.walk_packages(varmech.__path__, "varmech.") if not any(p.startswith("_") for p in m.name.split("."))
)
#: Functions and methods that raise nothing of their own (a Raises section would invent one),
#: besides those that take no arguments.
NO_RAISES = {
    "varmech.analysis.energy_growth.verdicts",
    "varmech.analysis.sections.covered_cells",
    "varmech.analysis.stability.relative_difference",
    "varmech.examples.harmonic_oscillator",
    "varmech.examples.double_pendulum",
    "varmech.examples.spherical_pendulum",
    "varmech.examples.heavy_top",
    "varmech.examples.kepler_polar",
    "varmech.examples.charged_particle",
    "varmech.examples.damped_driven_pendulum",
    "varmech.examples.rigid_body",
    "varmech.examples.bouncing_ball",
    "varmech.examples.rolling_sphere",
    "varmech.examples.ball_on_turntable",
    "varmech.symbolic.examples.charged_particle_nonuniform",
    "varmech.symbolic.examples.double_pendulum",
    "varmech.symbolic.examples.spherical_pendulum",
    "varmech.symbolic.examples.heavy_top",
    "varmech.symbolic.examples.kepler",
    "varmech.symbolic.examples.kepler_polar",
    "varmech.symbolic.examples.charged_particle",
    "varmech.symbolic.examples.damped_driven_pendulum",
    "varmech.symbolic.examples.elastic_pendulum",
    "varmech.symbolic.examples.rotating_hoop",
    "varmech.symbolic.examples.rocket",
    "varmech.symbolic.examples.falling_chain",
    "varmech.symbolic.examples.snowplough",
    "varmech.symbolic.examples.conveyor_belt",
    "varmech.methods.methods",
    "varmech.pointers.is_pointer",
    "varmech.conservation.InvariantStatistics.describe",
    "varmech.ensemble.Ensemble.check_conservation",
    "varmech.ensemble.Ensemble.energy",
    "varmech._symmetries.Translation.spec",
    "varmech._symmetries.Rotation.spec",
    "varmech._symmetries.Cyclic.spec",
    "varmech.stepper.Stepper.checkpoint",
    "varmech.surfaces.Wall.gradient",
    "varmech.surfaces.Ellipsoid.gradient",
    "varmech.symbolic._model.SymbolicModel.first_order",
    "varmech.symbolic._model.SymbolicModel.with_jit",
    "varmech.table.Table.format",
}
#: The model classes, which check what they are given, say what they raise.
MODELS = ["varmech._closures.MechanicalSystem", "varmech._closures.Lagrangian"]


def public_objects() -> dict[str, object]:
    """Qualified name → object: each public module's ``__all__`` (modules aside, and the binding's
    own classes, which its stubs describe), and the public methods of every public class."""
    found: dict[str, object] = {}

    def add(obj: object) -> None:
        module = getattr(obj, "__module__", "") or ""
        if module.startswith("varmech") and not module.startswith("varmech._core"):
            found[f"{module}.{obj.__qualname__}"] = obj  # type: ignore[attr-defined]

    for name in MODULES:
        module = importlib.import_module(name)
        for attr in getattr(module, "__all__", ()):
            obj = getattr(module, attr)
            if not inspect.ismodule(obj):
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


@pytest.mark.parametrize("name", MODULES)
def test_every_public_module_declares_its_api(name):
    """A public module says what is public (PEP 8), so the walk above cannot miss a new one."""
    module = importlib.import_module(name)
    assert isinstance(getattr(module, "__all__", None), list), f"{name}: no __all__"
    assert all(hasattr(module, attr) for attr in module.__all__), name


def test_the_walk_finds_the_api():
    """The walk reaches the entry points, the scenes, the records and the methods."""
    for name in [
        *MODELS,
        "varmech.integrate.integrate",
        "varmech.scenes._hamiltonian.kepler",
        "varmech.scenes._constrained.rolling_disk",
        "varmech.trajectory.Trajectory",
        "varmech.trajectory.Trajectory.save",
        "varmech.trajectory.load",
        "varmech.charts.work_precision.work_precision_chart",
        "varmech.symbolic._constructors.lagrangian",
    ]:
        assert name in OBJECTS, name
    assert len(FUNCTIONS) > 100 and len(RECORDS) > 10


@pytest.mark.parametrize("name", FUNCTIONS)
def test_functions_document_parameters_returns_raises_and_examples(name):
    assert errors(name, {"PR01", "PR02", "RT01", "GL08", "SA04", "EX01"}) == []
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
