"""The package's import structure: its modules' imports form no cycle, no function imports a
varmech module (the way a cycle is dodged), each module imports on its own in a fresh
interpreter, and all but the symbolic front end without the optional extras. The graph is read
from the source (the AST), so it holds for every module, tested or not."""

import ast
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

import varmech

PACKAGE = Path(varmech.__file__).resolve().parent

#: Function-local imports of varmech modules that stay, each with why (module, imported module).
LAZY = {
    # SymPy is an optional extra: scenes.get imports the symbolic examples only for a symbolic
    # scene, so that the scenes (and the whole package) import without SymPy.
    ("varmech.scenes._scene", "varmech.symbolic.examples"),
    # The command line compiles a SymPy Lagrangian that a user's file names, and only then.
    ("varmech.cli", "varmech.symbolic"),
}


def lazy(name: str, target: str) -> bool:
    """Whether ``target`` (or a package above it) is what an import of :data:`LAZY` in ``name``
    brings in."""
    return any(name == m and (t == target or t.startswith(target + ".")) for m, t in LAZY)


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


SOURCES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}
#: Every module of the package, the binding's (``_core``, an extension with a stub) included.
MODULES = set(SOURCES) | {module_name(p) for p in PACKAGE.rglob("*.pyi")}


def is_package(name: str) -> bool:
    return SOURCES.get(name, Path()).name == "__init__.py"


def under_type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def targets(name: str, node: ast.Import | ast.ImportFrom) -> list[str]:
    """The varmech modules that the import statement ``node`` of module ``name`` depends on: the
    one named (a name imported from a package: the submodule of that name if there is one, the
    package otherwise), and the packages above it (whose ``__init__`` runs first) that are not
    above ``name`` too."""
    if isinstance(node, ast.Import):
        named = [alias.name for alias in node.names]
    else:
        if node.level:
            package = name if is_package(name) else name.rpartition(".")[0]
            base = package.split(".")[: len(package.split(".")) - node.level + 1]
            origin = ".".join(base + ([node.module] if node.module else []))
        else:
            origin = node.module or ""
        named = [f"{origin}.{a.name}" if f"{origin}.{a.name}" in MODULES else origin for a in node.names]
    found = []
    own = {".".join(name.split(".")[:k]) for k in range(1, name.count(".") + 2)}
    for target in named:
        parts = target.split(".")
        above = [".".join(parts[:k]) for k in range(1, len(parts))]
        # A package above the module is imported before it: only an import that names it (its
        # names, ``from . import x``) depends on it.
        for module in [m for m in above if m not in own] + [target]:
            if module in MODULES and module != name and module not in found:
                found.append(module)
    return found


def imports(name: str) -> tuple[set[str], list[tuple[str, int]]]:
    """Module ``name``'s module-level imports of varmech modules (those only for the type
    checker, under ``if TYPE_CHECKING:``, left out), and its imports inside functions
    (module, line)."""
    tree = ast.parse(SOURCES[name].read_text(encoding="utf-8"))
    top: set[str] = set()
    local: list[tuple[str, int]] = []

    def visit(node: ast.AST, in_function: bool) -> None:
        if isinstance(node, ast.If) and under_type_checking(node) and not in_function:
            for child in node.orelse:
                visit(child, in_function)
            return
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            for target in targets(name, node):
                if in_function:
                    local.append((target, node.lineno))
                else:
                    top.add(target)
            return
        inside = in_function or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
        for child in ast.iter_child_nodes(node):
            visit(child, inside)

    visit(tree, False)
    return top, local


GRAPH = {name: imports(name)[0] for name in SOURCES}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """A cycle of ``graph`` (its modules in import order, the first repeated), or None."""
    state: dict[str, int] = {}  # 1: on the path being walked, 2: done
    path: list[str] = []

    def walk(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return path[path.index(nxt) :] + [nxt]
            if nxt not in state and (cycle := walk(nxt)) is not None:
                return cycle
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (cycle := walk(node)) is not None:
            return cycle
    return None


def test_the_graph_is_read_from_the_source():
    """The reader finds the imports it must (the check below is not vacuous): relative,
    absolute, a submodule imported by name, the packages above it, and not what only the type
    checker sees."""
    assert {"varmech.trajectory", "varmech.model", "varmech.scenes", "varmech.streaming"} <= GRAPH["varmech.integrate"]
    assert "varmech._core" in GRAPH["varmech._model"]  # from . import _core, pointers
    assert {"varmech.analysis", "varmech.analysis.energy_growth"} <= GRAPH["varmech"]
    assert "varmech.trajectory" not in GRAPH["varmech.dense"]  # under TYPE_CHECKING there
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b", "c"}, "b": {"c"}, "c": set()}) is None


def test_the_package_has_no_import_cycle():
    """Dependencies point one way: no module imports (at module level, type checking aside) one
    that imports it back, directly or through others."""
    cycle = find_cycle(GRAPH)
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_no_function_imports_a_varmech_module():
    """No import of a varmech module inside a function (the way a cycle is kept importable),
    but those of :data:`LAZY`, each there for an optional dependency."""
    local = {(name, target, line) for name in SOURCES for target, line in imports(name)[1] if not lazy(name, target)}
    assert not local, "function-local imports: " + ", ".join(f"{n}:{line} imports {t}" for n, t, line in sorted(local))
    # Each one allowed is still there (an allow-list that outlives its reason goes stale).
    for name, target in LAZY:
        assert target in {t for t, _ in imports(name)[1]}, (name, target)


#: Underscored names imported from another module that stay, each with why (module, name).
PRIVATE = {
    # Pickles made before model.py was split name the reconstructors by this module's name.
    ("varmech.model", "_rebuild"),
    ("varmech.model", "_nbody_model"),
    ("varmech.model", "_scene_model"),
}


def private_imports(name: str) -> list[tuple[str, int]]:
    """The underscored names (not modules, not dunders) that module ``name`` imports from other
    varmech modules: (name, line)."""
    found = []
    for node in ast.walk(ast.parse(SOURCES[name].read_text(encoding="utf-8"))):
        if not isinstance(node, ast.ImportFrom) or not (node.level or (node.module or "").startswith("varmech")):
            continue
        origin = targets(name, node)
        for alias in node.names:
            private = alias.name.startswith("_") and not alias.name.startswith("__")
            if private and not any(t.endswith("." + alias.name) for t in origin):
                found.append((alias.name, node.lineno))
    return found


def test_no_module_imports_another_modules_private_names():
    """What modules share is a public name of the module that owns it (python/varmech/_runspec.py
    holds the run's checks that integrate, ensemble and Stepper share), never another module's
    underscored helper, but those of :data:`PRIVATE`."""
    found = {(name, n, line) for name in SOURCES for n, line in private_imports(name) if (name, n) not in PRIVATE}
    assert not found, "private imports: " + ", ".join(f"{m}:{line} imports {n}" for m, n, line in sorted(found))
    # Each one allowed is still there.
    for name, n in PRIVATE:
        assert n in {x for x, _ in private_imports(name)}, (name, n)


#: The optional extras' packages (pyproject's optional-dependencies, the benchmarks' included).
EXTRAS = ("sympy", "matplotlib", "h5py", "xarray", "dask", "distributed", "scipy", "rebound")


def run_python(code: str) -> subprocess.CompletedProcess:
    """``code`` run by a fresh interpreter that imports this varmech."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(PACKAGE.parent), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)


def test_the_package_imports_without_its_optional_extras():
    """The extras are imported where they are used: with none of them importable, every module
    but the symbolic front end (SymPy's) imports, and so does scenes, by the lazy import that
    :data:`LAZY` allows, while a symbolic scene names the extra to install."""
    modules = sorted(m for m in MODULES - {"varmech.__main__"} if not m.startswith("varmech.symbolic"))
    code = (
        f"import sys\nsys.modules.update(dict.fromkeys({EXTRAS!r}))\n"
        + "".join(f"import {m}\n" for m in modules)
        + "import varmech.scenes\ntry:\n    varmech.scenes.get('elastic_pendulum')\nexcept ImportError as e:\n    print(e)\n"
    )
    done = run_python(code)
    assert done.returncode == 0, done.stderr
    assert "pip install varmech[symbolic]" in done.stdout


# varmech.__main__ is the command line (importing it runs it); its imports are in the graph above.
@pytest.mark.parametrize("name", sorted(MODULES - {"varmech.__main__"}))
def test_each_module_imports_first_in_a_fresh_interpreter(name):
    """Imported first and alone, each module loads: no import works only because another module
    happened to be imported before it."""
    if name.startswith("varmech.symbolic") and importlib.util.find_spec("sympy") is None:
        pytest.skip("SymPy (the extra symbolic) is not installed")
    done = run_python(f"import {name}")
    assert done.returncode == 0, done.stderr


def test_the_top_level_shows_the_public_api_and_its_modules_and_nothing_else():
    import varmech

    shown = set(dir(varmech))
    assert shown == set(varmech.__all__) | set(varmech._MODULES)
    assert not any(name.startswith("_") for name in shown)
    for name in shown:
        assert getattr(varmech, name) is not None, name
