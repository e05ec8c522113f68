"""The README's code and the gallery's examples pass ``mypy --strict`` as a user would run it on
their own code: varmech's public API is typed (py.typed), its report's energy is never None."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# What the README's idiom reads off a report: typed, and never None.
PROBE = """import varmech

report = varmech.check_conservation(varmech.integrate(varmech.scenes.pendulum(), dt=0.1, steps=10))
reveal_type(report.energy)
largest: float = report.energy.max_rel_error
"""


def test_the_readme_and_the_gallery_pass_mypy_strict(tmp_path):
    pytest.importorskip("mypy")
    readme = (ROOT / "README.md").read_text()
    files = []
    for i, code in enumerate(re.findall(r"```python\n(.*?)```", readme, flags=re.S)):
        files.append(tmp_path / f"readme_{i}.py")
        files[-1].write_text(code)
    files += sorted((ROOT / "docs" / "examples").glob("*.py"))
    (tmp_path / "probe.py").write_text(PROBE)
    # Third-party libraries without types (SymPy, SciPy) are the user's to stub, not varmech's.
    command = [sys.executable, "-m", "mypy", "--strict", "--ignore-missing-imports", "--no-incremental",
               "--cache-dir", str(tmp_path / "cache"), "--config-file", "", *map(str, files), str(tmp_path / "probe.py")]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    # varmech itself was analysed, not taken as Any: the report's energy has its class.
    assert 'Revealed type is "varmech.conservation.InvariantStatistics"' in done.stdout, done.stdout
    assert len(files) >= 7
