"""The long campaign of the property tests (``make campaign``): many more random cases than CI's
(tests/python/test_properties.py), each in a process of its own with a time limit, and a count of
their outcomes: runs completed by verdict, typed errors by type, misfits, crashes and hangs, the
verdicts confirmed and not by refinement, and every case that broke a property, as a spec that
``property_oracle.examine`` reproduces.

Usage: ``python tests/python/property_campaign.py [--examples N] [--minutes M] [--seed S]
[--out FILE] [--families NAME ...]``; the cases that broke a property, and those of a kind
left open (``"known"``), are also written to FILE as JSON lines.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import re
import sys
import time
from collections import Counter
from pathlib import Path

from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parent))
import property_models as pm  # noqa: E402
import property_oracle as po  # noqa: E402

#: The campaign's own profile: many examples, new ones each seed, no shrinking (each case's
#: spec is the reproducer), no database.
settings.register_profile(
    "campaign",
    max_examples=100_000,
    deadline=None,
    database=None,
    phases=[settings.default.phases[1], settings.default.phases[2]],  # generate only: no explicit, no shrink
    suppress_health_check=list(HealthCheck),
)

class Done(Exception):
    """The campaign's time is up: ends the drawing (past its deadline a case returning at once
    would still have Hypothesis draw, and build, the rest of ``--examples``)."""


#: How often each family is drawn.
WEIGHTS = {"closures": 4, "symbolic": 3, "sphere": 2, "wall": 2}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--examples", type=int, default=2000)
    parser.add_argument("--minutes", type=float, default=15.0)
    parser.add_argument("--seed", type=int, default=int(time.time()))
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds a case may take before it counts as a hang")
    parser.add_argument("--out", type=Path, default=Path("campaign_failures.jsonl"))
    parser.add_argument("--families", nargs="+", choices=sorted(WEIGHTS), default=sorted(WEIGHTS), help="draw only these")
    args = parser.parse_args()
    families = pm.strategies()
    weights = {name: w for name, w in WEIGHTS.items() if name in args.families}
    draw = st.one_of(*[st.tuples(st.just(name), families[name]) for name, w in weights.items() for _ in range(w)])
    outcomes: Counter[str] = Counter()
    verdicts: Counter[str] = Counter()
    errors: Counter[str] = Counter()
    confirmed: Counter[str] = Counter()
    known: Counter[str] = Counter()
    by_family: Counter[str] = Counter()
    broken: list[tuple[str, pm.Spec, po.Outcome]] = []
    deadline = time.monotonic() + 60 * args.minutes
    args.out.write_text("")

    @settings(settings.get_profile("campaign"), max_examples=args.examples)
    @seed(args.seed)
    @given(draw)
    def case(drawn: tuple[str, pm.Spec]) -> None:
        if time.monotonic() > deadline:
            raise Done
        family, spec = drawn
        outcome = po.isolated(po.examine, spec, args.timeout)
        outcomes[outcome.kind] += 1
        by_family[family] += 1
        if outcome.kind == "completed":
            verdicts[str(outcome.verdict)] += 1
        elif outcome.kind not in ("misfit",):
            errors[outcome.kind] += 1
        confirmed[{True: "confirmed", False: "unconfirmed", None: "nothing to confirm"}[outcome.confirmed]] += 1
        for problem in outcome.known:
            known[next(k for pattern, k in po.KNOWN_OPEN.items() if re.search(pattern, problem))] += 1
        if outcome.problems:
            broken.append((family, spec, outcome))
        if outcome.problems or outcome.known:
            with args.out.open("a") as f:
                row = {"family": family, "spec": dataclasses.asdict(spec), "problems": outcome.problems, "known": outcome.known}
                f.write(json.dumps(row) + "\n")
        total = sum(outcomes.values())
        if total % 50 == 0:
            print(f"{total} cases, {len(broken)} broke a property", flush=True)

    started = time.monotonic()
    try:
        case()
    except Done:
        pass  # the time is up
    finally:
        _summary(args, outcomes, verdicts, errors, confirmed, known, by_family, broken, started)
    return 1 if broken else 0


def _summary(
    args: argparse.Namespace, outcomes: Counter[str], verdicts: Counter[str], errors: Counter[str],
    confirmed: Counter[str], known: Counter[str], by_family: Counter[str], broken: list[tuple[str, pm.Spec, po.Outcome]], started: float,
) -> None:
    """Prints the campaign's counts, also when it ends early."""
    total = sum(outcomes.values())
    print(f"\nCampaign: seed {args.seed}, {total} cases in {(time.monotonic() - started) / 60:.1f} min ({dict(by_family)})")
    print(f"  completed: {outcomes['completed']}, by verdict: {dict(verdicts.most_common())}")
    print(f"  typed errors and other outcomes: {dict(errors.most_common())}")
    print(f"  misfits refused by name: {outcomes['misfit']}")
    print(f"  refinement: {dict(confirmed.most_common())}")
    print(f"  known open (issue 64's list, oracle.KNOWN_OPEN): {dict(known.most_common())}")
    print(f"  broke a property: {len(broken)} (written to {args.out})")
    for family, spec, outcome in broken:
        print(f"\n- {family}: {outcome.kind}: {outcome.problems[0][:600]}\n  {spec!r}")


if __name__ == "__main__":
    raise SystemExit(main())
