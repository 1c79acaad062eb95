"""Where a scene and its mirror image part: the first recorded sample at which any series
differs from its mirror's beyond negation.

A mirror image is a free-link scene of ``benches/step_warning.py`` with q, vx0 and omega0 ->
-q, -vx0, -omega0. IEEE negation is exact, so where every operation is mirror-symmetric the
two runs' series agree in magnitude bit for bit (x-like series negated, z-like ones equal).
The script runs each pair with every series recorded and prints, per series, the first
sample that differs (and the two values); the earliest of them is where to read the code.

Usage::

    python benches/mirror_trace.py 11:82 11:181 3:59 3:102 [--dt 1e-4] [--scenes 200]

(each argument is seed:scene of ``benches/step_warning.py --scenes 200 --seed seed``).
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np

import granrs

try:
    import step_warning
except ImportError:  # run from elsewhere than benches/
    import importlib.util
    import sys

    _path = Path(__file__).resolve().parent / "step_warning.py"
    _spec = importlib.util.spec_from_file_location("step_warning", _path)
    assert _spec is not None and _spec.loader is not None
    step_warning = importlib.util.module_from_spec(_spec)
    sys.modules["step_warning"] = step_warning
    _spec.loader.exec_module(step_warning)


def first_gaps(a: granrs.Result, b: granrs.Result) -> dict[str, tuple[int, float, float]]:
    """Per series, the first sample where `a` and its mirror `b` differ in magnitude."""
    out = {}
    for key in sorted(a.series or {}):
        x = np.asarray(a.series[key], dtype=float)
        y = np.asarray(b.series[key], dtype=float)
        n = min(len(x), len(y))
        same = (np.abs(x[:n]) == np.abs(y[:n])) | (np.isnan(x[:n]) & np.isnan(y[:n]))
        bad = np.flatnonzero(~same)
        if len(bad):
            out[key] = (int(bad[0]), float(x[bad[0]]), float(y[bad[0]]))
        elif len(x) != len(y):
            out[key] = (n, float("nan"), float("nan"))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("pairs", nargs="+", help="seed:scene")
    parser.add_argument("--dt", type=float, default=1e-4)
    parser.add_argument("--scenes", type=int, default=200)
    args = parser.parse_args(argv)
    for pair in args.pairs:
        seed, index = (int(s) for s in pair.split(":"))
        scene = step_warning.scenes(args.scenes, seed)[index]
        runs = []
        for mirror in (False, True):
            s = scene.at(args.dt, mirror=mirror).replace(record=("state", "forces"))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                runs.append(granrs.simulate(s))
        a, b = runs
        print(
            f"seed {seed} scene {index} ({scene.law}, at the {scene.fields['apply_at']}): "
            f"t_s {a.t_s!r} / {b.t_s!r}, depth {a.depth!r} / {b.depth!r}"
        )
        gaps = first_gaps(a, b)
        if not gaps:
            print("  every series the mirror's, bit for bit")
        for key, (i, x, y) in sorted(gaps.items(), key=lambda kv: kv[1][0]):
            print(f"  {key}: sample {i}, {x!r} against {y!r}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
