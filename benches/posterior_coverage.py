"""Synthetic recovery: do the posterior's 90 % intervals cover the truth 90 % of the time?

Each trial draws a medium's parameters at random (the thesis law's vertical static and drag
coefficients as factors on its published ones, log-uniform in [0.5, 2]), makes Table 3.1's
twelve drops under them with granrs with Gaussian noise (sd a fixed fraction of each value,
which is also the row's sd), fits them with ``granrs.calibrate(..., posterior=...)`` and
counts whether each parameter's central 90 % interval holds its true value. The target is
85-95 % of the intervals over 200 trials.

Usage::

    python benches/posterior_coverage.py [--trials 200] [--steps 120] [--walkers 8]
        [--rel-sd 0.03] [--seed 0]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import granrs
from granrs.compare import Law, synthetic

PARAMS = ("scale.static_v.eta_v", "scale.drag.eta_d")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=200)
    ap.add_argument("--steps", type=int, default=120)
    ap.add_argument("--walkers", type=int, default=8)
    ap.add_argument("--rel-sd", type=float, default=0.03)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()

    law = Law(
        "two_scales",
        "the thesis's law with its vertical static and drag coefficients scaled",
        thesis=True,
        fit={p: (1.0, 0.02, 50.0) for p in PARAMS},
        body_unknowns=False,
    )
    rng = np.random.default_rng(args.seed)
    covered = {p: 0 for p in PARAMS}
    done = 0
    converged = 0
    t0 = time.perf_counter()
    for trial in range(args.trials):
        truth = {p: float(math.exp(rng.uniform(math.log(0.5), math.log(2.0)))) for p in PARAMS}
        data = synthetic(law, truth, "table_3_1", rel_sd=args.rel_sd, seed=args.seed + trial)
        fit = granrs.calibrate(
            "free_link",
            data,
            list(PARAMS),
            bounds={p: (0.02, 50.0) for p in PARAMS},
            posterior=args.steps,
            walkers=args.walkers,
            seed=trial,
        )
        assert fit.posterior is not None
        interval = fit.posterior.interval(0.9)
        for p in PARAMS:
            lo, hi = interval[p]
            covered[p] += int(lo <= truth[p] <= hi)
        converged += int(fit.posterior.converged)
        done += 1
        if (trial + 1) % 10 == 0:
            share = sum(covered.values()) / (len(PARAMS) * done)
            print(
                f"{done} trials, {time.perf_counter() - t0:.0f} s: 90 % intervals cover the "
                f"truth in {100 * share:.1f} % ({', '.join(f'{p} {covered[p]}' for p in PARAMS)})",
                flush=True,
            )
    share = sum(covered.values()) / (len(PARAMS) * done)
    print(
        f"coverage {100 * share:.1f} % of {len(PARAMS) * done} intervals over {done} trials "
        f"(target 85-95 %); chains longer than 50 autocorrelation times in {converged} trials; "
        f"{time.perf_counter() - t0:.0f} s"
    )


if __name__ == "__main__":
    main()
