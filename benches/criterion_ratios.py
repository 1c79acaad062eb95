"""Print the medians of the last ``cargo bench --bench bodies`` run and their ratios, and
the per-term table of ``cargo bench --bench free_link``.

Reads criterion's ``<dir>/<group>/<body>/new/estimates.json`` for the groups of
``benches/bodies.rs`` (``rhs_by_body``, ``step_by_body``, ``impact_by_body``) and prints, per
group, each body's median time with its 95 % interval and its ratio to the free link's median
in the same group. All the numbers come from one criterion run: the machines are shared and
noisy, so read the ratios, not the absolute times.

The free link's ``force`` group gives the cost of one evaluation of each force term and of
the thesis's set as a whole (``terms_on`` over drag, static_h and static_v; issue 16), next
to a whole right-hand-side evaluation (``rhs``), each with its ratio to the thesis's set.

Usage::

    cargo bench --bench bodies -- --warm-up-time 1 --measurement-time 3
    cargo bench --bench free_link -- "force|rhs" --warm-up-time 1 --measurement-time 3
    python benches/criterion_ratios.py [--dir target/criterion] [--baseline free_link_q45]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

#: The groups of benches/bodies.rs, in the order they are reported.
GROUPS = ("rhs_by_body", "step_by_body", "impact_by_body")

#: The bodies of benches/bodies.rs, in the order they are reported.
BODIES = (
    "free_link_q45",
    "chain_default",
    "chain_case1",
    "leg_locked",
    "leg_spring",
    "leg_free",
)


#: The free link's per-term table (benches/free_link.rs): (group, bench) in report order, and
#: the bench the ratios divide by.
TERM_BENCHES = (
    ("force", "term/drag"),
    ("force", "term/static_h"),
    ("force", "term/static_v"),
    ("force", "thesis_set"),
    ("rhs", "eval"),
    ("rhs", "eval_vertical_stick"),
)
TERM_BASELINE = ("force", "thesis_set")


def median_ns(path: Path) -> tuple[float, float, float]:
    """Median of one bench and its 95 % confidence interval [ns]."""
    median = json.loads(path.read_text())["median"]
    ci = median["confidence_interval"]
    return median["point_estimate"], ci["lower_bound"], ci["upper_bound"]


def format_ns(ns: float) -> str:
    """A time in ns, us or ms, four significant figures."""
    if ns >= 1e6:
        return f"{ns / 1e6:#.4g} ms"
    if ns >= 1e3:
        return f"{ns / 1e3:#.4g} us"
    return f"{ns:#.4g} ns"


def report(root: Path, baseline: str) -> str:
    """The table of every group found under ``root``."""
    lines = []
    for group in GROUPS:
        found = {}
        for body in BODIES:
            path = root / group / body / "new" / "estimates.json"
            if path.exists():
                found[body] = median_ns(path)
        if not found:
            continue
        base = found.get(baseline)
        lines.append(f"{group}: median [95 % interval], ratio to {baseline}")
        for body, (med, lo, hi) in found.items():
            ratio = f"{med / base[0]:6.2f}" if base else "     -"
            lines.append(
                f"  {body:<14} {format_ns(med):>10} [{format_ns(lo)} - {format_ns(hi)}]  {ratio}"
            )
    terms = {}
    for group, bench in TERM_BENCHES:
        # criterion writes a bench id's "/" as "_" in its directory name.
        path = root / group / bench.replace("/", "_") / "new" / "estimates.json"
        if path.exists():
            terms[(group, bench)] = median_ns(path)
    if terms:
        base = terms.get(TERM_BASELINE)
        lines.append("free link, one evaluation: median [95 % interval], ratio to force/thesis_set")
        for (group, bench), (med, lo, hi) in terms.items():
            ratio = f"{med / base[0]:6.2f}" if base else "     -"
            name = f"{group}/{bench}"
            lines.append(
                f"  {name:<26} {format_ns(med):>10} [{format_ns(lo)} - {format_ns(hi)}]  {ratio}"
            )
    if not lines:
        return f"no estimates of benches/bodies.rs or benches/free_link.rs under {root}"
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--dir",
        type=Path,
        default=Path(__file__).resolve().parent.parent / "target" / "criterion",
        help="criterion's output directory (default: target/criterion)",
    )
    parser.add_argument(
        "--baseline",
        default=BODIES[0],
        choices=BODIES,
        help="the body the ratios divide by (default: %(default)s)",
    )
    args = parser.parse_args(argv)
    print(report(args.dir, args.baseline))
    return 0


if __name__ == "__main__":
    sys.exit(main())
