"""Cost per impact of each force law on the free link, against the thesis's law (issue 17).

The free link is dropped at the Table 3.1 angles (0, 15, ..., 75 deg) at v0 = 2 m/s under
each law. Each scene runs ``--repeats`` times, interleaved with the others, and its cost is
the minimum of the core's own timer (``_granrs.run(...).run_seconds``: the run alone, no
Python around it); a law's cost is the sum over the angles. The ratios come from one run of
this script (absolute times on a shared machine are noisy). Use a release build.

An impact's cost is its evaluations times their cost, and the evaluations follow how long
the impact lasts: a stiffer sand stops the rod sooner. ``zeta = 1e6`` (the examples' scale)
makes this sand softer than the thesis's law does, so the ``rft`` rows are also run at
``zeta`` fitted to Table 3.1 (``granrs.calibrate``, fitted here at the start: the same sand
as the thesis's row; the ``thesis_sand`` medium card of ``granrs.media`` keeps the value).

Usage::

    python benches/bench_laws.py [--repeats 300] [--out results.md]
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

import granrs
from granrs import _granrs
from granrs import forces as f

ANGLES = (0.0, 15.0, 25.0, 45.0, 65.0, 75.0)
V0 = 2.0

#: The laws timed, by name: the thesis's law first (the reference of the ratios).
LAWS: dict[str, Callable[[], list[f.Term]]] = {
    "thesis": lambda: list(f.thesis()),
    "poncelet": lambda: [f.gravity(), f.poncelet(c=0.8, k=150.0)],
    "rft (8 elements)": lambda: [f.gravity(), f.rft(zeta=1e6)],
    "rft (2 elements)": lambda: [f.gravity(), f.rft(zeta=1e6, elements=2)],
    "rft (32 elements)": lambda: [f.gravity(), f.rft(zeta=1e6, elements=32)],
    "rft + rft_inertial": lambda: [f.gravity(), f.rft(zeta=1e6), f.rft_inertial()],
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=300)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args(argv)
    fit = granrs.calibrate(
        "free_link",
        "table_3_1",
        ["rft.zeta"],
        forces=[f.gravity(), f.rft(zeta=1e6)],
        bounds={"rft.zeta": (1e5, 1e8)},
    )
    zeta = fit.values["rft.zeta"]
    laws = dict(LAWS)
    laws[f"rft (8 elements, zeta fitted: {zeta:.3g})"] = lambda: [f.gravity(), f.rft(zeta=zeta)]
    compiled = {
        (law, q): granrs.cases.free_link(q, V0).replace(forces=make())._compiled()
        for law, make in laws.items()
        for q in ANGLES
    }
    evals = {
        key: granrs.simulate(
            granrs.cases.free_link(key[1], V0).replace(forces=laws[key[0]]())
        ).summary["rhs_evals"]
        for key in compiled
    }
    best = dict.fromkeys(compiled, float("inf"))
    for _ in range(args.repeats):
        for key, c in compiled.items():
            best[key] = min(best[key], _granrs.run(c).run_seconds)
    base = sum(best[("thesis", q)] for q in ANGLES)
    lines = [
        f"Free link at q = {', '.join(f'{q:g}' for q in ANGLES)} deg, v0 = {V0} m/s; "
        f"min of {args.repeats} runs each (`python benches/bench_laws.py`).",
        "",
        "| law | us per impact (mean over the angles) | evaluations per impact | ns per "
        "evaluation | cost / thesis |",
        "|---|---:|---:|---:|---:|",
    ]
    for law in laws:
        total = sum(best[(law, q)] for q in ANGLES)
        n_eval = sum(evals[(law, q)] for q in ANGLES)
        lines.append(
            f"| {law} | {1e6 * total / len(ANGLES):.1f} | {n_eval / len(ANGLES):.0f} | "
            f"{1e9 * total / n_eval:.0f} | {total / base:.2f} |"
        )
    text = "\n".join(lines)
    print(text)
    if args.out:
        args.out.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
