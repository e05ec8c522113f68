"""The code's shape (docs/development.md): no source file over 800 lines, and the core's
layers, solve → model → discrete → integrators → diagnostics, no module using one above it;
scenes use the model (and their catalogue hands them out as the integrators' Dynamics). Read
from the `crate::` paths of each Rust file.

The modules inside integrators/ still use each other both ways in one place (issue 65): their
mutual pairs are counted here, so that a change can lower the count but not raise it.
"""

import re
import shutil
import subprocess
from pathlib import Path

import pytest

CORE = Path(__file__).resolve().parents[2] / "rust" / "core" / "src"
LAYERS = ["solve", "model", "discrete", "integrators", "diagnostics"]

#: Mutual module pairs inside integrators/, at most: dynamics and stepper alone, whose model kinds
#: pick the loop their steps run in (``Dynamics::advance``) and whose loop steps them.
MUTUAL_PAIRS = 1


def _code(path: Path) -> str:
    return "\n".join(line.split("//")[0] for line in path.read_text().splitlines())


def test_no_layer_of_the_core_uses_one_above_it():
    rank = {layer: i for i, layer in enumerate(LAYERS)}
    upward = []
    for path in CORE.rglob("*.rs"):
        top = path.relative_to(CORE).parts[0].removesuffix(".rs")
        for used in set(re.findall(r"crate::(\w+)", _code(path))):
            if top in rank and used in rank and rank[used] > rank[top]:
                upward.append(f"{path.relative_to(CORE)} uses {used}")
            if top == "scenes" and used in ("discrete", "diagnostics"):
                upward.append(f"{path.relative_to(CORE)} uses {used}")
    assert not upward, upward


def _integrators_graph() -> dict[str, set[str]]:
    root = CORE / "integrators"
    modules: dict[str, list[Path]] = {}
    for path in root.rglob("*.rs"):
        parts = path.relative_to(root).parts
        name = parts[0].removesuffix(".rs")
        if name != "mod":
            modules.setdefault(name, []).append(path)
    # What integrators/mod.rs re-exports, by the module that defines it.
    owner = {}
    for module, items in re.findall(r"pub(?:\([^)]*\))? use (\w+)::(\{[^}]*\}|\w+);", (root / "mod.rs").read_text(), re.S):
        for item in re.split(r"[,\s]+", items.strip("{}")):
            if item and item != "self":
                owner[item] = module
    graph: dict[str, set[str]] = {}
    for name, paths in modules.items():
        used: set[str] = set()
        for path in paths:
            code = _code(path)
            direct = path.parent == root
            for match in re.finditer(r"(crate::integrators::|super::)(\w+)", code):
                target = match.group(2)
                if target in modules:
                    used.add(target)
                elif target in owner and (direct or match.group(1) == "crate::integrators::"):
                    used.add(owner[target])
            for group in re.findall(r"use (?:crate::integrators|super)::\{([^}]*)\}", code, re.S):
                for item in re.split(r"[,\s]+", group):
                    item = item.split("::")[0]
                    used.add(owner.get(item, item) if item in owner or item in modules else name)
        graph[name] = used - {name}
    return graph


def test_the_integrators_modules_use_each_other_both_ways_no_more_than_now():
    graph = _integrators_graph()
    mutual = sorted((a, b) for a in graph for b in graph[a] if a < b and a in graph.get(b, ()))
    assert len(mutual) <= MUTUAL_PAIRS, mutual


def test_no_source_file_is_over_800_lines():
    root = CORE.parents[2]
    files = [*root.glob("rust/**/*.rs"), *root.glob("python/**/*.py")]
    long = {str(f.relative_to(root)): n for f in files if (n := len(f.read_text().splitlines())) > 800}
    assert len(files) > 100 and not long, long


def test_the_guides_new_impact_law_applies_and_touches_three_files():
    """docs/development.md's example diff of a new impact law applies to this tree as written
    and touches three files outside tests and docs (issue 65's measure of a jump kind)."""
    root = CORE.parents[2]
    if shutil.which("git") is None or not (root / ".git").exists():
        pytest.skip("needs the git checkout")
    guide = (root / "docs" / "development.md").read_text()
    diff = re.search(r"### Example: a new impact law.*?```diff\n(.*?)```", guide, re.S)
    assert diff is not None
    files = set(re.findall(r"^\+\+\+ b/(\S+)", diff.group(1), re.M))
    assert len(files) == 3 and not any(f.startswith(("tests/", "docs/")) for f in files), files
    check = subprocess.run(
        ["git", "apply", "--check", "-"], cwd=root, input=diff.group(1), text=True, capture_output=True
    )
    assert check.returncode == 0, check.stderr
