"""Time the thesis's cases as built-in bodies and as plain linkages (issue 19), paired.

Every case of ``tests/record_thesis_cases.py`` (50 free links, 3 chains, 4 legs) runs through
``granrs.simulate`` twice: as ``granrs.cases`` builds it (the built-in body) and as
``scene.as_linkage()`` (its body detached into links, joints, contacts and a root, run through
the linkage path). The two are timed in turn within each repeat, so each ratio's two times come
from the same moment of a shared, noisy machine; the report is the median and the range of
the per-repeat ratios (linkage / built-in) per body. Build with ``maturin develop --release``
to time the engine rather than the dev profile.

To compare a build with another (say main), run this script (or ``--only built-in``) with each
build on ``PYTHONPATH`` in alternation and divide; the issue's goal is at most 10 % more.

Usage::

    python benches/bench_linkage.py [--repeats 9] [--rounds 5]
"""

from __future__ import annotations

import argparse
import pathlib
import statistics
import sys
import time

import granrs

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "tests"))
from record_thesis_cases import cases


def _time(scenes: list[granrs.Scene], rounds: int) -> float:
    best = float("inf")
    for _ in range(rounds):
        t0 = time.perf_counter()
        for s in scenes:
            granrs.simulate(s)
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    groups: dict[str, tuple[list[granrs.Scene], list[granrs.Scene]]] = {}
    for name, scene in cases():
        built_in, linkage = groups.setdefault(name.split()[0], ([], []))
        built_in.append(scene)
        linkage.append(scene.as_linkage())
    ratios: dict[str, list[float]] = {body: [] for body in groups}
    times: dict[str, list[float]] = {body: [] for body in groups}
    for body, (built_in, linkage) in groups.items():
        _time(built_in, 1)  # compile and warm up
        _time(linkage, 1)
        for _ in range(args.repeats):
            a = _time(built_in, args.rounds)
            b = _time(linkage, args.rounds)
            ratios[body].append(b / a)
            times[body].append(a)
    print(f"granrs {granrs.__version__} from {pathlib.Path(granrs.__file__).parent}")
    print(f"{'body':<10} {'cases':>5} {'built-in [ms]':>14} {'linkage / built-in':>30}")
    for body, r in ratios.items():
        n = len(groups[body][0])
        print(
            f"{body:<10} {n:>5} {1e3 * min(times[body]):>14.3f} "
            f"{statistics.median(r):>12.3f} (range {min(r):.3f} .. {max(r):.3f})"
        )


if __name__ == "__main__":
    main()
