"""Re-runs every reproducer of a fuzz-signatures file (issue 32) and counts the unclean ones.

Each reproducer runs in its own process under a timeout. Its outcome is clean when it succeeds
(non-finite results aside: the verdicts' business), when it raises a ValueError, TypeError or
varmech error whose message starts by naming an argument (``name: ...``, as varmech's
messages do) or a closure (``gradient(q) must ...``), or when the exception comes from the
reproducer's own code (its innermost frame is not in varmech). Anything else is unclean: a
wrong exception type, a message naming nothing, a timeout.

Usage: ``PYTHONPATH=python python benches/fuzz_signatures.py [signatures.txt] [--timeout S]``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import textwrap
from concurrent.futures import ThreadPoolExecutor

DEFAULT = "/work/shared/reliability/fuzz-signatures.txt"

WRAPPER = r'''
import json, sys, time, traceback, numpy as np, varmech
_c = {}
code = sys.stdin.read()
try:
    exec(compile(code, "<case>", "exec"), {"np": np, "varmech": varmech, "time": time, "_c": _c})
    print(json.dumps({"outcome": "ok"}))
except BaseException as err:
    frames = traceback.extract_tb(err.__traceback__)
    inner = frames[-1].filename if frames else ""
    print(json.dumps({"outcome": "raised", "type": type(err).__module__ + "." + type(err).__qualname__,
                      "message": str(err), "where": inner,
                      "varmech": isinstance(err, (varmech.VarmechError,)),
                      "value_or_type": isinstance(err, (ValueError, TypeError))}))
'''

#: A message naming an argument (``q0: ...``, ``q0, p0: ...``) or a closure (``gradient(q) must``).
NAMED = re.compile(r"^(\w+(\[\w+\])?(, \w+)*: |\w+\([\w, ]*\) (must|returned))")


def reproducers(path: str) -> list[tuple[str, int, str]]:
    """(signature line, count, code) of each signature in the file."""
    out, lines = [], open(path, encoding="utf-8").read().splitlines()
    i = 0
    while i < len(lines):
        m = re.match(r"^\[(\d+)x\] (.*)$", lines[i])
        if not m:
            i += 1
            continue
        head, count = m.group(2), int(m.group(1))
        while not lines[i].strip() == "reproducer:":
            i += 1
        i += 1
        body = []
        while i < len(lines) and not lines[i].startswith("====="):
            body.append(lines[i])
            i += 1
        out.append((head, count, textwrap.dedent("\n".join(body)).strip() + "\n"))
    return out


def classify(code: str, timeout: float) -> tuple[str, str]:
    """(class, detail) of one reproducer run in its own process."""
    try:
        done = subprocess.run(
            [sys.executable, "-c", WRAPPER], input=code, capture_output=True, text=True, timeout=timeout,
            env=os.environ | {"PYTHONWARNINGS": "ignore"},
        )
    except subprocess.TimeoutExpired:
        return "unclean", f"timeout > {timeout} s"
    last = done.stdout.strip().splitlines()[-1:] or [""]
    try:
        r = json.loads(last[0])
    except json.JSONDecodeError:
        return "unclean", f"crashed (rc {done.returncode}): {done.stderr.strip()[-300:]}"
    if r["outcome"] == "ok":
        return "clean", "ok"
    detail = f"{r['type']}: {r['message'][:160]}"
    if "varmech" not in r["where"] and "<case>" in r["where"]:
        return "clean", "propagated from the reproducer's own code: " + detail
    if (r["value_or_type"] or r["varmech"]) and NAMED.match(r["message"]):
        return "clean", detail
    return "unclean", detail


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("path", nargs="?", default=DEFAULT)
    parser.add_argument("--timeout", type=float, default=20.0)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    cases = reproducers(args.path)
    with ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(lambda c: classify(c[2], args.timeout), cases))
    unclean = [(c, r) for c, r in zip(cases, results) if r[0] == "unclean"]
    for (head, count, _), (cls, detail) in zip(cases, results):
        print(f"{cls:8} [{count}x] {head[:110]}\n         -> {detail}")
    print(f"\n{len(cases)} signatures ({sum(c[1] for c in cases)} cases): {len(unclean)} unclean "
          f"({sum(c[1] for c, _ in unclean)} cases), {len(cases) - len(unclean)} clean")


if __name__ == "__main__":
    main()
