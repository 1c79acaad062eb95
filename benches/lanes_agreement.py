"""How far granrs.sweep's lanes are from the scalar path, over random free-link scenes.

The lanes take ``sin``/``cos`` and ``pow`` from glibc's four-lane calls where the CPU has
AVX2 (within 4 ulp of libm's; the scalar path calls libm). Everything else is the scalar
path's arithmetic in its order. This draws random scenes under every law the lanes run (the
thesis's terms under each sign model, ``rft``, ``rft`` with its inertial term, ``poncelet``),
sweeps them in the lanes and on the scalar path (``lanes=False``), and prints, per law:

* how many rows agree to 1e-12 relative on every result (t_s, depth, the forces, energies
  and the tip's end position; a final spin near zero against 1e-12 of 10 rad/s);
* the rows where a decision was tipped (a stick-slip sign grazing zero within rounding: the
  paths locate a different number of events, or either counts an unresolved step or stop),
  and the largest relative difference of t_s and depth there, and of any result;
* the largest relative difference among the rows with no tipped decision.

    GRANRS_FAST_LANES=1 python benches/lanes_agreement.py [--scenes 500] [--seed 1]

Without ``GRANRS_FAST_LANES=1`` the lanes call libm lane by lane and every row agrees bit for
bit (a check of the harness).
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import granrs
from granrs import cases
from granrs.forces import gravity, poncelet, rft, rft_inertial, thesis

RESULTS = [
    "t_s", "depth", "dq", "F_d_max", "F_s_end", "F_r_end", "dKE", "dPE", "dE", "work_sand",
    "x_tip_end", "energy_end",
]  # fmt: skip
#: The scale below which a final spin is rounding about zero (1e-12 of 10 rad/s).
SPIN_SCALE = 10.0


def laws() -> dict[str, tuple[list, str]]:
    return {
        "thesis, modes": (list(thesis()), "modes"),
        "thesis, raw": (list(thesis()), "raw"),
        "thesis, smooth": (list(thesis()), "smooth"),
        "rft": ([gravity(), rft(zeta=1e6)], "modes"),
        "rft + rft_inertial": ([gravity(), rft(zeta=1e6), rft_inertial()], "modes"),
        "poncelet": ([gravity(), poncelet(c=0.8, k=150.0)], "modes"),
    }


def rel(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.abs(a - b) / np.maximum(np.abs(a), np.abs(b))
    d[(a == b) | (np.isnan(a) & np.isnan(b))] = 0.0
    return d


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=int, default=500, help="scenes per law")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    print(f"fast lanes (glibc's four-lane calls): {granrs.fast_lanes()}")
    n = args.scenes
    print(f"{n} random scenes per law (seed {args.seed}): q in [-85, 85] deg, v0 in [0.1, 4] m/s,")
    print("vx0 in [-1, 1] m/s, omega0 in [-15, 15] rad/s, at the tip or the centroid")
    print(f"{'law':<22}{'<=1e-12':>9}{'tipped':>8}{'tipped t_s/depth':>18}{'tipped any':>12}"
          f"{'others max':>12}")  # fmt: skip
    base = cases.free_link(q_deg=0.0, v0=1.0)
    for name, (law, sign) in laws().items():
        scenes = [
            base.replace(
                forces=law,
                sign_model=sign,
                q_deg=float(rng.uniform(-85, 85)),
                v0=float(rng.uniform(0.1, 4.0)),
                vx0=float(rng.uniform(-1, 1)),
                omega0=float(rng.uniform(-15, 15)),
                apply_at=str(rng.choice(["tip", "centroid"])),
            )
            for _ in range(n)
        ]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            a = granrs.sweep(scenes, progress=False)
            b = granrs.sweep(scenes, progress=False, lanes=False)
        flags = ["unresolved", "unresolved_stops"]
        tipped = (
            (a[flags].sum(axis=1) + b[flags].sum(axis=1) > 0) | (a["events"] != b["events"])
        ).to_numpy()
        d = rel(a[RESULTS].to_numpy(float), b[RESULTS].to_numpy(float))
        spin = np.abs(a["omega_end"].to_numpy() - b["omega_end"].to_numpy()) / np.maximum(
            np.maximum(np.abs(a["omega_end"].to_numpy()), np.abs(b["omega_end"].to_numpy())),
            SPIN_SCALE,
        )
        worst = np.maximum(d.max(axis=1), spin)
        ok = int((worst <= 1e-12).sum())
        ts_depth = d[tipped][:, :2].max() if tipped.any() else 0.0
        tipped_any = worst[tipped].max() if tipped.any() else 0.0
        others = worst[~tipped].max() if (~tipped).any() else 0.0
        print(
            f"{name:<22}{ok:>9}{int(tipped.sum()):>8}{ts_depth:>18.1e}{tipped_any:>12.1e}"
            f"{others:>12.1e}"
        )


if __name__ == "__main__":
    main()
