"""The package's metadata agrees with itself: one version (the Cargo workspace's, which maturin
gives the installed metadata and ``varmech.__version__`` reads), CITATION.cff and
``varmech.cite()`` saying the same, the extra ``test`` exactly the dependency groups ``test`` and
``dev``, and a README whose links work on a package index page (absolute, to files that exist)."""

import doctest
import importlib.metadata
import re
import sys
from pathlib import Path

import pytest

import varmech
from varmech import _cite

ROOT = Path(__file__).resolve().parents[2]
REPOSITORY = "https://github.com/varmech/varmech"

needs_tomllib = pytest.mark.skipif(sys.version_info < (3, 11), reason="tomllib is Python 3.11+")


def toml(name: str) -> dict:
    import tomllib

    with open(ROOT / name, "rb") as f:
        return tomllib.load(f)


def cargo_version() -> str:
    """The workspace's version, which both crates take."""
    return toml("Cargo.toml")["workspace"]["package"]["version"]


@needs_tomllib
def test_one_version_from_cargo():
    version = cargo_version()
    assert toml("Cargo.toml")["package"]["version"] == {"workspace": True}
    assert toml("rust/python/Cargo.toml")["package"]["version"] == {"workspace": True}
    project = toml("pyproject.toml")["project"]
    assert "version" not in project and "version" in project["dynamic"]
    # A version bump shows here only once the package is built again (make install).
    assert importlib.metadata.version("varmech") == version
    assert varmech.__version__ == version


def test_cite_is_one_bibtex_entry_of_this_version():
    text = varmech.cite()
    entry = re.fullmatch(r"@software\{varmech,\n((?:  [a-z]+ = \{.*\},\n)+)\}", text)
    assert entry is not None, text
    fields = dict(re.findall(r"  ([a-z]+) = \{(.*)\},\n", entry.group(1)))
    assert fields["version"] == varmech.__version__
    assert fields["url"] == REPOSITORY
    assert {"author", "title", "year"} <= set(fields)
    assert text.count("{") == text.count("}")


def test_cite_example_runs():
    result = doctest.testmod(_cite, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0, result


def cff(key: str) -> str:
    """A top-level scalar of CITATION.cff (read with a pattern: no YAML library needed)."""
    found = re.search(
        rf'^{re.escape(key)}:[ \t]*"?([^"\n]*?)"?[ \t]*$', (ROOT / "CITATION.cff").read_text(), flags=re.M
    )
    assert found is not None, key
    return found.group(1)


def test_citation_cff_agrees_with_the_package():
    assert cff("cff-version") == "1.2.0"
    assert cff("version") == varmech.__version__
    assert cff("date-released").startswith(f"{_cite.YEAR}-")
    assert cff("title") == _cite.TITLE
    assert cff("repository-code") == _cite.URL == REPOSITORY


def requirements(entries: list, groups: dict) -> list[str]:
    """A dependency group's requirements, its included groups' spelled out (PEP 735)."""
    found: list[str] = []
    for entry in entries:
        found += requirements(groups[entry["include-group"]], groups) if isinstance(entry, dict) else [entry]
    return found


@needs_tomllib
def test_the_test_extra_is_the_groups_test_and_dev():
    """``make install`` installs the extra (pip < 25.1 has no ``--group``); it must install what
    the groups list, no more and no less."""
    pyproject = toml("pyproject.toml")
    groups = pyproject["dependency-groups"]
    dev = requirements(groups["dev"], groups)
    assert set(requirements(groups["test"], groups)) <= set(dev)
    assert len(dev) == len(set(dev)), "a requirement listed twice"
    assert sorted(pyproject["project"]["optional-dependencies"]["test"]) == sorted(dev)


def test_readme_links_are_absolute_and_exist():
    """The README is the package index's page too, where a relative link leads nowhere: every link
    and image is absolute (or an in-page anchor), and those into this repository name a file or
    folder that exists."""
    targets = re.findall(r"\]\(([^)\s]+)\)", (ROOT / "README.md").read_text())
    assert targets
    for target in targets:
        assert target.startswith(("https://", "#")), f"relative link {target}"
        own = re.match(
            rf"(?:{re.escape(REPOSITORY)}/(?:blob|tree)/main|https://raw\.githubusercontent\.com/varmech/varmech/main)/([^#]+)",
            target,
        )
        if own:
            assert (ROOT / own.group(1)).exists(), f"{target}: no {own.group(1)} in the repository"
