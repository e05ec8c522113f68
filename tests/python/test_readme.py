"""The README's code blocks run as they stand, each on its own, and print the verdicts the README
shows; the full quickstart (now the docs' getting-started page) runs as written too."""

import contextlib
import io
import re
from pathlib import Path

import pytest

pytest.importorskip("sympy")

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
GETTING_STARTED = ROOT / "docs" / "getting_started.md"


def blocks(text: str) -> list[tuple[str, str, str]]:
    """Each ```python block with the plain block right after it, if any (the output shown)."""
    found = re.findall(r"```(\w*)\n(.*?)```", text, flags=re.S)
    return [
        (code, following_lang, shown)
        for (lang, code), (following_lang, shown) in zip(found, [*found[1:], ("python", "")])
        if lang == "python"
    ]


def verdicts(text: str) -> list[str]:
    return re.findall(r"(?:verdict: |^\w+ +)(conserved to round-off|bounded|secular drift|failed)", text, flags=re.M)


def quickstart() -> str:
    text = GETTING_STARTED.read_text()
    return text[text.index("## Quickstart") : text.index("### API in brief")]


def test_the_quickstart_runs_and_prints_the_verdicts_shown():
    blocks = re.findall(r"```(python)?\n(.*?)```", quickstart(), flags=re.S)
    namespace: dict = {}
    compared = 0
    for (language, code), (following, shown) in zip(blocks, [*blocks[1:], ("python", "")]):
        if not language:
            continue
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(compile(code, str(GETTING_STARTED), "exec"), namespace)
        if not following:  # the output the README shows for this block
            verdicts = re.findall(r"verdict: [a-z -]+", shown)
            assert re.findall(r"verdict: [a-z -]+", out.getvalue()) == verdicts, code
            compared += len(verdicts)
    assert compared == 5


@pytest.mark.parametrize("index", range(len(blocks(README.read_text()))))
def test_every_readme_block_runs_as_it_stands(index, tmp_path, monkeypatch):
    code, following_lang, shown = blocks(README.read_text())[index]
    monkeypatch.chdir(tmp_path)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, f"{README}, python block {index}", "exec"), {"__name__": "__readme__"})
    if not following_lang:  # the output the README shows: the same verdicts, in order
        assert verdicts(out.getvalue()) == verdicts(shown), out.getvalue()


def test_the_readme_shows_output_for_its_blocks():
    shown = [verdicts(s) for _, lang, s in blocks(README.read_text()) if not lang]
    assert sum(len(v) for v in shown) == 8 and len(shown) == 4


def test_the_own_model_walkthrough_runs_and_prints_what_it_shows(tmp_path, monkeypatch):
    """The getting-started page's own model, from SymPy to a work–precision chart: the names,
    the step and the computed reference it prints are those the page shows."""
    pytest.importorskip("scipy")
    pytest.importorskip("matplotlib")
    text = GETTING_STARTED.read_text()
    section = text[text.index("## Your own model, measured against SciPy") :]
    code, shown = re.findall(r"```python\n(.*?)```\s*```text\n(.*?)```", section, flags=re.S)[0]
    monkeypatch.chdir(tmp_path)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, str(GETTING_STARTED), "exec"), {"__name__": "__walkthrough__"})
    assert out.getvalue() == shown
    assert (tmp_path / "elastic_pendulum_work_precision.png").exists()
