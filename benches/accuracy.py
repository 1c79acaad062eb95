"""Accuracy against time of granrs's integrators (a work-precision diagram).

Usage::

    python benches/accuracy.py [--out DIR] [--quick] [--repeats N]

The same as ``granrs bench accuracy``; the implementation is
:func:`granrs.bench.work_precision`.
"""

from __future__ import annotations

import argparse

from granrs.bench import work_precision


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="bench-accuracy", help="output directory")
    parser.add_argument("--quick", action="store_true", help="shorter sweeps, coarser reference")
    parser.add_argument("--repeats", type=int, default=3, help="timing repeats (default: 3)")
    args = parser.parse_args()
    work_precision(args.out, quick=args.quick, repeats=args.repeats)


if __name__ == "__main__":
    main()
