"""Time the thesis cases of two or more builds of granrs, each installed in its own venv
(issue 19's speed line: the cases through ``Linkage`` at most 10 % above the build before
the linkage work).

The cases are those of the last measurements: the free link at 45 deg, chain cases 1 and 3
to all stops, the leg at 2 m/s locked and at 3.28 m/s sprung. Each case's time is the core's
``run_seconds`` of ``granrs._granrs.run`` on a compiled scene (no Python around the run).
The builds run in rounds, in alternating order (interleaved pairs: a shared machine's load
reaches each build alike); each round a worker process per venv takes the best of
``--per`` runs of every case, and the report is each build's best over all rounds, with its
difference to the first build, and the load average.

Usage::

    python benches/bench_builds.py /path/to/venv_base /path/to/venv_new [--rounds 8] [--per 10]

Build each venv from a release wheel (``maturin build --release``, each with its own
``CARGO_TARGET_DIR``), e.g. ``git archive cd377ae`` for the build before the linkage work.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys


def worker(per: int) -> None:
    import granrs
    from granrs import _granrs

    scenes = {
        "free_link 45": granrs.cases.free_link(45.0, 2.27),
        "chain 1": granrs.cases.chain(case=1, end="all_stops"),
        "chain 3": granrs.cases.chain(case=3, end="all_stops"),
        "leg 2.0 locked": granrs.cases.leg(v0=2.0),
        "leg 3.28 sprung": granrs.cases.leg(v0=3.28, joints={"k": 300.0, "c": 5.0}),
    }
    compiled = {k: s._compiled() for k, s in scenes.items()}
    best = dict.fromkeys(compiled, float("inf"))
    for _ in range(per):
        for k, c in compiled.items():
            best[k] = min(best[k], _granrs.run(c).run_seconds)
    print(json.dumps(best))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("venvs", nargs="*", help="venvs, the first the reference")
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--per", type=int, default=10, help="runs per case per round")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker(args.per)
        return 0
    best: dict[str, dict[str, float]] = {v: {} for v in args.venvs}
    for r in range(args.rounds):
        for v in args.venvs if r % 2 == 0 else args.venvs[::-1]:
            cmd = [f"{v}/bin/python", __file__, "--worker", "--per", str(args.per)]
            out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
            for k, x in json.loads(out).items():
                best[v][k] = min(best[v].get(k, float("inf")), x)
    print("load average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    print(f"best of {args.rounds * args.per} runs per case and build, run_seconds [us]")
    ref = best[args.venvs[0]]
    for v in args.venvs:
        cells = (f"{k}: {x * 1e6:.0f} ({x / ref[k] - 1:+.1%})" for k, x in best[v].items())
        print(f"{v}: " + " | ".join(cells))
    return 0


if __name__ == "__main__":
    sys.exit(main())
