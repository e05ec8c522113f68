"""A release wheel, as a user gets it: built here for manylinux2014 (maturin with zig, no
Docker), accepted by auditwheel with that tag, installed into a fresh venv with its extra
``symbolic`` from the index, and running the README's quickstart there, with the ``varmech``
command. The packaging check, marked ``wheel``: a release build of its own, then pip, minutes;
``make wheel-check`` runs it, ``make test`` (``pytest -m "not wheel"``) leaves it out."""

import os
import platform
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import varmech
from test_readme import quickstart

ROOT = Path(__file__).resolve().parents[2]

pytestmark = [
    pytest.mark.wheel,
    pytest.mark.skipif(
        sys.platform != "linux" or platform.machine() != "x86_64", reason="the manylinux wheel of this test is x86_64 Linux's"
    ),
]


def run(*args, **kwargs):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, check=True, **kwargs)


def test_a_manylinux2014_wheel_installs_in_a_fresh_venv_and_runs_the_quickstart(tmp_path):
    pytest.importorskip("ziglang")
    # The repository's target dir: the build is incremental after the first (minutes, then seconds).
    env = {**os.environ, "CARGO_TARGET_DIR": os.environ.get("CARGO_TARGET_DIR", str(ROOT / "target"))}
    run(
        sys.executable, "-m", "maturin", "build", "--release", "--zig", "--compatibility", "manylinux2014",
        "--interpreter", sys.executable, "--out", tmp_path / "dist", cwd=ROOT, env=env,
    )  # fmt: skip
    (wheel,) = (tmp_path / "dist").glob("*.whl")
    tag = f"cp{sys.version_info.major}{sys.version_info.minor}"
    version = varmech.__version__
    assert wheel.name.startswith(f"varmech-{version}-{tag}-{tag}-manylinux2014_x86_64.manylinux_2_17_x86_64")
    shown = run(sys.executable, "-m", "auditwheel", "show", wheel).stdout
    assert '"manylinux_2_17_x86_64"' in " ".join(shown.split()), shown
    names = zipfile.ZipFile(wheel).namelist()
    licenses = {f"varmech-{version}.dist-info/licenses/LICENSE-{kind}" for kind in ("MIT", "APACHE")}
    assert licenses <= set(names)
    # Stripped ([tool.maturin] strip): the module has no symbol table, whose section is named .symtab.
    (module,) = [name for name in names if name.startswith("varmech/_core")]
    assert b".symtab" not in zipfile.ZipFile(wheel).read(module)

    # A clean venv (no system site-packages): the wheel's dependencies come from the index.
    venv = tmp_path / "venv"
    run(sys.executable, "-m", "venv", venv)
    bin_dir = venv / "bin"
    run(bin_dir / "python", "-m", "pip", "install", "--quiet", f"{wheel}[symbolic]")
    # Away from the clone, and without its python/ on the path: the installed package alone.
    clean = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "CARGO_TARGET_DIR")}
    found = run(bin_dir / "python", "-c", "import varmech; print(varmech.__file__)", cwd=tmp_path, env=clean).stdout
    assert found.startswith(str(venv))
    assert "| `kahan_li8` | 8 | 17 |" in run(bin_dir / "varmech", "methods", cwd=tmp_path, env=clean).stdout

    # The quickstart's code blocks as one script, each block's output marked off, compared with
    # the verdicts of the output block that follows it in the README, as test_readme does.
    blocks = re.findall(r"```(python)?\n(.*?)```", quickstart(), flags=re.S)
    pairs = list(zip(blocks, [*blocks[1:], ("python", "")]))
    script = "".join(f"{code}\nprint('@@ block {i}')\n" for i, ((language, code), _) in enumerate(pairs) if language)
    out = run(bin_dir / "python", "-c", script, cwd=tmp_path, env=clean).stdout
    printed = dict(zip(re.findall(r"@@ block (\d+)", out), re.split(r"@@ block \d+\n", out)))
    compared = 0
    for i, ((language, _), (following, shown)) in enumerate(pairs):
        if language and not following:
            verdicts = re.findall(r"verdict: [a-z -]+", shown)
            assert re.findall(r"verdict: [a-z -]+", printed[str(i)]) == verdicts, i
            compared += len(verdicts)
    assert compared > 0
