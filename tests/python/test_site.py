"""The documentation site's own parts, checked without building it (``make test`` builds it
with -W): every formula of the pages converts to MathML, as the build renders math with no
script and no network, and the guide's inline names of public objects find their API pages."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = [*ROOT.glob("docs/*.md"), *ROOT.glob("docs/user_guide/*.md"), ROOT / "reference" / "theory.md"]


def formulas(text: str) -> list[str]:
    """The $…$ and $$…$$ formulas of a Markdown page, outside code."""
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    text = re.sub(r"`[^`\n]*`", "", text)
    display = re.findall(r"\$\$(.+?)\$\$", text, flags=re.S)
    text = re.sub(r"\$\$(.+?)\$\$", "", text, flags=re.S)
    return display + re.findall(r"(?<![\\$])\$([^$\n]+?)\$", text)


def test_every_formula_of_the_pages_converts_to_mathml():
    converter = pytest.importorskip("latex2mathml.converter")
    found = {page.name: formulas(page.read_text()) for page in PAGES}
    assert len(found["theory.md"]) >= 30
    for page, latex_list in found.items():
        for latex in latex_list:
            mathml = converter.convert(latex)
            assert mathml.startswith("<math") and "<merror" not in mathml, (page, latex)


def test_the_guides_inline_names_find_their_api_pages():
    sys.path.insert(0, str(ROOT / "docs" / "_ext"))
    try:
        from apilinks import api_name
    finally:
        sys.path.remove(str(ROOT / "docs" / "_ext"))
    objects = dict.fromkeys(
        ["varmech.integrate", "varmech.Trajectory.to_xarray", "varmech.symbolic.from_mechanics", "varmech.charts.strobe_chart"]
    )
    assert api_name("varmech.integrate", objects) == "varmech.integrate"
    assert api_name("integrate(model, q0, dt=0.1)", objects) == "varmech.integrate"
    assert api_name("Trajectory.to_xarray()", objects) == "varmech.Trajectory.to_xarray"
    assert api_name("symbolic.from_mechanics", objects) == "varmech.symbolic.from_mechanics"
    assert api_name("strobe_chart(table, path)", objects) == "varmech.charts.strobe_chart"
    # A variable's method, an argument, a shell command: text.
    assert [api_name(t, objects) for t in ("traj.to_xarray()", "dt=0.1", "python -m varmech tour")] == [None] * 3
