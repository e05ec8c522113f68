"""The README's gallery: every chart of ``python -m varmech chart``, at full settings, written to
docs/gallery/ (PNG) with its data (CSV).

    python benches/gallery.py [--out docs/gallery] [--quick]

Needs the ``bench`` extra (matplotlib, scipy, rebound). Takes a few minutes; each chart's sweep
shows a progress bar and Ctrl-C stops it.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from varmech.charts.recipes import KINDS, chart

#: (kind, scene): the charts of the gallery; the work–precision chart also on the outer solar
#: system, where REBOUND is the baseline, and on the symbolic elastic pendulum, against SciPy on
#: its lambdified equations.
GALLERY = [
    ("work-precision", "kepler"),
    ("work-precision", "outer_solar_system"),
    ("work-precision", "elastic_pendulum"),
    ("energy", "kepler"),
    ("stability", None),
    ("implicit-regions", "pendulum"),
    ("poincare", "henon_heiles"),
    ("phase", "pendulum"),
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("docs/gallery"))
    parser.add_argument("--quick", action="store_true", help="the tour's short sweeps")
    args = parser.parse_args()
    for kind, scene in GALLERY:
        assert kind in KINDS
        start = time.perf_counter()
        paths = chart(kind, scene, out=args.out, quick=args.quick, progress=True)
        print(f"{kind} {scene or ''}: {time.perf_counter() - start:.1f} s")
        for path in paths:
            print(f"  wrote {path}")


if __name__ == "__main__":
    main()
