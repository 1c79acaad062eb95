"""Time two builds of granrs against each other on the thesis's free link and leg (issue 19,
arcs: the boundary's plates made as they are walked must not slow a rod or a box).

Each build is a directory holding an importable ``granrs`` package with its compiled core
(e.g. a release wheel unpacked: ``maturin build --release`` then ``unzip``). The script runs
a worker per build in turn, ``--rounds`` times: each worker times every scene ``--repeats``
times with the core's own timer (``_granrs.run(scene._compiled()).run_seconds``: the run
alone) and reports the best. The report is, per scene, the best time of each build over all
rounds and their ratio (B / A), so both builds' times come from the same stretch of a shared
machine.

Usage::

    python benches/bench_plates.py DIR_A DIR_B [--rounds 5] [--repeats 20]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

WORKER = r"""
import json, sys
import granrs
from granrs import _granrs, cases, forces

def scenes():
    rft = [forces.gravity(), forces.rft(zeta=1e6)]
    return {
        "free link, thesis law (q 45, v0 2.27)": cases.free_link(q_deg=45.0, v0=2.27),
        "leg, thesis law, locked (v0 3.28)": cases.leg(v0=3.28),
        "leg, thesis law, sprung (v0 3.28)": cases.leg(v0=3.28, joints={"k": 300.0, "c": 5.0}),
        "free link, rft (q 30, v0 2)": cases.free_link(q_deg=30.0, v0=2.0, forces=rft),
        "leg, rft (v0 2)": cases.leg(v0=2.0, forces=rft),
        "free link, rft + rft_inertial": cases.free_link(
            q_deg=30.0, v0=2.0, forces=[*rft, forces.rft_inertial()]
        ),
        "leg, rft + rft_inertial": cases.leg(v0=2.0, forces=[*rft, forces.rft_inertial()]),
    }

repeats = int(sys.argv[1])
best = {}
for name, scene in scenes().items():
    c = scene._compiled()
    _granrs.run(c)
    best[name] = min(_granrs.run(c).run_seconds for _ in range(repeats))
print(json.dumps(best))
"""


def run(build: str, repeats: int) -> dict[str, float]:
    env = {**os.environ, "PYTHONPATH": build}
    out = subprocess.run(
        [sys.executable, "-c", WORKER, str(repeats)],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        cwd=build,
    )
    return json.loads(out.stdout)  # type: ignore[no-any-return]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    best: dict[str, dict[str, float]] = {"a": {}, "b": {}}
    for _ in range(args.rounds):
        for key, build in (("a", args.a), ("b", args.b)):
            for name, t in run(build, args.repeats).items():
                best[key][name] = min(best[key].get(name, float("inf")), t)
    print(f"{'scene':40s} {'A [ms]':>9s} {'B [ms]':>9s} {'B / A':>7s}")
    for name, a in best["a"].items():
        b = best["b"][name]
        print(f"{name:40s} {a * 1e3:9.3f} {b * 1e3:9.3f} {b / a:7.3f}")


if __name__ == "__main__":
    main()
