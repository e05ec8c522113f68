"""The README's gallery: every chart of ``python -m varmech chart``, at full settings, written to
docs/gallery/ (PNG) with its data (CSV).

    python benches/gallery.py [--out docs/gallery] [--quick] [--only KIND[:SCENE] ...]

``--only`` redraws the named charts alone (``--only work-precision:kepler``; a kind without a
scene selects every chart of that kind). Needs the ``bench`` extra (matplotlib, scipy, rebound).
Takes a few minutes; each chart's sweep shows a progress bar and Ctrl-C stops it. The impact
chart (``--only impacts``) races a rival that is no library code, so benches/impacts.py draws it;
benches/reactions.py draws the tension of a pendulum (``--only reactions``), benches/modes.py the
triatomic molecule's spectrum against the stability intervals (``--only spectrum``),
benches/holds.py the particle leaving the sphere (``--figure``), benches/variable_mass.py the
rocket and Cayley's chain (``--only variable-mass``), benches/delays.py the delayed feedback
oscillator's stability boundary (``--only delays``).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from delays import delays_figure
from impacts import billiard_chart
from modes import spectrum_figure
from reactions import tension_chart
from variable_mass import variable_mass_figure

from varmech.charts.recipes import KINDS, chart

#: (kind, scene, methods): the charts of the gallery, with the kind's default methods where
#: None. The work–precision charts of Kepler and the outer solar system add varmech's fastest
#: splittings at matched error (benches/splitting.py), and on the outer solar system its
#: Wisdom–Holman methods, against REBOUND's baselines (leapfrog order=8 on both; WHFast with and
#: without corrector=11, and IAS15, on the N-body scene); the elastic pendulum's is against
#: SciPy on its lambdified equations.
GALLERY = [
    ("work-precision", "kepler", ("verlet", "yoshida4", "kahan_li8", "blanes_moan6", "mclachlan8_dkd", "rk4")),
    ("work-precision", "outer_solar_system", ("verlet", "kahan_li8", "blanes_moan6", "mclachlan8_dkd", "whc", "whckl")),
    ("work-precision", "elastic_pendulum", None),
    ("energy", "kepler", None),
    ("stability", None, None),
    ("implicit-regions", "pendulum", None),
    ("poincare", "henon_heiles", None),
    ("phase", "pendulum", None),
    ("nonholonomic", None, None),
]
#: (kind, scene, draw(out, quick) → paths): charts drawn by a bench script, for their rival is
#: no library code (the naive "reflect at the end of the step" scheme) or their model no scene.
BENCHED = [
    ("impacts", "billiard", billiard_chart),
    ("reactions", "pendulum", tension_chart),
    ("spectrum", "triatomic", spectrum_figure),
    ("variable-mass", "rocket", variable_mass_figure),
    ("delays", "oscillator", delays_figure),
]


def selected(kind: str, scene: str | None, only: list[str]) -> bool:
    """Whether ``--only`` picks the chart (kind, scene): every chart when ``only`` is empty."""
    return not only or kind in only or f"{kind}:{scene}" in only


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("docs/gallery"))
    parser.add_argument("--quick", action="store_true", help="the tour's short sweeps")
    parser.add_argument("--only", nargs="+", default=[], metavar="KIND[:SCENE]", help="redraw these charts alone")
    args = parser.parse_args()
    known = {kind for kind, _, _ in GALLERY + BENCHED} | {f"{kind}:{scene}" for kind, scene, _ in GALLERY + BENCHED}
    unknown = [name for name in args.only if name not in known]
    if unknown:
        parser.error(f"--only: no gallery chart {', '.join(unknown)}; choose from {', '.join(sorted(known))}")
    for kind, scene, methods in GALLERY:
        assert kind in KINDS
        if not selected(kind, scene, args.only):
            continue
        start = time.perf_counter()
        report(kind, scene, start, chart(kind, scene, methods=methods, out=args.out, quick=args.quick, progress=True))
    for kind, scene, draw in BENCHED:
        if selected(kind, scene, args.only):
            start = time.perf_counter()
            report(kind, scene, start, draw(args.out, args.quick))


def report(kind: str, scene: str | None, start: float, paths: list[Path]) -> None:
    """Print a chart's time since ``start`` and the files it wrote."""
    print(f"{kind} {scene or ''}: {time.perf_counter() - start:.1f} s")
    for path in paths:
        print(f"  wrote {path}")


if __name__ == "__main__":
    main()
