"""Criterion benches of two builds side by side: the same bench functions of two sets of bench
executables, interleaved, best of several rounds, reported as ratios.

    cargo bench --no-run                       # in each checkout; note the executables it prints
    python benches/criterion_ab.py --before DIR --after DIR [--rounds 5]

DIR holds the bench executables `steps`, `implicit`, `constraints` and `impacts` of one build
(copied out of target/release/deps). Each round runs every selected bench once in each build, alternating,
so that the noise of a shared machine falls on both alike; a bench's figure is its best
(smallest) criterion estimate over the rounds.

With --instructions, the figure is instead the instructions of one iteration of the bench,
counted by callgrind (valgrind): criterion's --test mode runs it once, and a run that selects
no bench gives the executable's set-up to subtract. Repeatable to a few thousand
instructions (0.5% of the smallest bench), so a change of a few percent shows where a shared
machine's timings scatter by tens.
"""

from __future__ import annotations

import argparse
import functools
import re
import subprocess
import tempfile
from pathlib import Path

#: (executable, criterion filter): the step loops issue 12 promised to keep as fast, and the
#: impacts' resolution (a billiard by each law, and a contact never hit).
BENCHES = [
    ("steps", "^kepler/verlet$"),
    ("steps", "^kepler/kahan_li8$"),
    ("steps", "^outer_solar_system/verlet$"),
    ("steps", "^outer_solar_system/kahan_li8$"),
    ("implicit", "^double_pendulum/midpoint$"),
    ("implicit", "^double_pendulum/galerkin4$"),
    ("constraints", "^rattle_chain/8$"),
    ("impacts", "^billiard/reflect$"),
    ("impacts", "^billiard/variational$"),
    ("impacts", "^billiard/never_hit$"),
]

UNITS = {"ps": 1e-12, "ns": 1e-9, "µs": 1e-6, "us": 1e-6, "ms": 1e-3, "s": 1.0}
TIME = re.compile(r"time:\s+\[\S+ \S+ (\S+) (\S+) \S+ \S+\]")


def seconds(executable: Path, pattern: str) -> float:
    out = subprocess.run(
        [str(executable), "--bench", pattern, "--warm-up-time", "0.5", "--measurement-time", "2", "--noplot"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    match = TIME.search(out)
    if match is None:
        raise RuntimeError(f"{executable.name} {pattern}: no criterion estimate in\n{out}")
    value, unit = match.groups()
    return float(value) * UNITS[unit]


@functools.cache
def counted(executable: Path, selected: str) -> int:
    """Instructions of `executable` run once in criterion's --test mode on the benches
    `selected` (callgrind); cached, so that each executable's set-up is counted once."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "callgrind.out"
        command = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(executable), "--bench", "--test", selected]
        subprocess.run(command, capture_output=True, check=True)
        summary = re.search(r"^summary: (\d+)", out.read_text(), re.M)
    if summary is None:
        raise RuntimeError(f"{executable.name}: no callgrind summary")
    return int(summary.group(1))


def instructions(executable: Path, pattern: str) -> int:
    """Instructions of one iteration of the bench `pattern` of `executable`: its run less the
    executable's set-up (a run that selects no bench)."""
    return counted(executable, pattern) - counted(executable, "^no bench$")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--before", type=Path, required=True)
    parser.add_argument("--after", type=Path, required=True)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--instructions", action="store_true", help="count instructions (callgrind) instead of timing")
    args = parser.parse_args()
    if args.instructions:
        print("| bench | before | after | instructions after / before |")
        print("|---|---:|---:|---:|")
        for exe, pattern in BENCHES:
            before, after = (instructions(folder / exe, pattern) for folder in (args.before, args.after))
            print(f"| {pattern.strip('^$')} | {before:,} | {after:,} | {after / before:.3f} |", flush=True)
        return
    best: dict[tuple[str, str], float] = {}
    for _ in range(args.rounds):
        for exe, pattern in BENCHES:
            for side, folder in (("before", args.before), ("after", args.after)):
                t = seconds(folder / exe, pattern)
                best[pattern, side] = min(best.get((pattern, side), float("inf")), t)
    print("| bench | before | after | speed after / before |")
    print("|---|---:|---:|---:|")
    for _, pattern in BENCHES:
        before, after = best[pattern, "before"], best[pattern, "after"]
        print(f"| {pattern.strip('^$')} | {before * 1e6:.2f} µs | {after * 1e6:.2f} µs | {before / after:.3f} |")


if __name__ == "__main__":
    main()
