"""The README's quickstart runs as written, and prints the verdicts the README shows."""

import contextlib
import io
import re
from pathlib import Path

import pytest

pytest.importorskip("sympy")

README = Path(__file__).resolve().parents[2] / "README.md"


def quickstart() -> str:
    text = README.read_text()
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
            exec(compile(code, str(README), "exec"), namespace)
        if not following:  # the output the README shows for this block
            verdicts = re.findall(r"verdict: [a-z -]+", shown)
            assert re.findall(r"verdict: [a-z -]+", out.getvalue()) == verdicts, code
            compared += len(verdicts)
    assert compared == 5
