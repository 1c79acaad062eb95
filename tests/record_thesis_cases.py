"""Record every thesis case's results (depth, t_s, energies, forces) as the regression
record of issue 16 ("An open model ... changes no result").

Run once on the code before a redesign; ``tests/test_thesis_regression.py`` then holds every
later version to this record at 1e-9 relative. Usage::

    python tests/record_thesis_cases.py > tests/data/thesis_cases.json
"""

from __future__ import annotations

import json
import math
import sys

import granrs

#: Table 3.4's angles from the vertical (alpha = 90 - q in {90, 85, ..., 5}).
ANGLES = (0.0, 5.0, 15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0, 85.0)
SPEEDS = (0.5, 1.0, 2.0, 3.0, 4.0)
#: The summary keys compared (per contact).
KEYS = ("t_s", "depth", "dq", "omega_end", "F_d_max", "F_s_end", "F_r_end", "dKE", "dPE", "dE")


def cases() -> list[tuple[str, granrs.Scene]]:
    out = []
    for q in ANGLES:
        for v in SPEEDS:
            out.append((f"free_link q={q:g} v0={v:g}", granrs.cases.free_link(q_deg=q, v0=v)))
    for c in (1, 2, 3):
        out.append((f"chain case={c}", granrs.cases.chain(case=c, end="all_stops")))
    for v in (2.0, 3.28):
        for name, j in (("locked", "locked"), ("spring", {"k": 300.0, "c": 5.0})):
            out.append((f"leg v0={v:g} joints={name}", granrs.cases.leg(v0=v, joints=j)))
    return out


def record(scene: granrs.Scene) -> list[dict[str, float | None]]:
    result = granrs.simulate(scene)
    rows = []
    for c in result.contacts:
        row = {}
        for k in KEYS:
            v = c.summary.get(k)
            row[k] = None if v is None or not math.isfinite(float(v)) else float(v)
        rows.append(row)
    return rows


def main() -> None:
    json.dump({name: record(s) for name, s in cases()}, sys.stdout, indent=1, sort_keys=True)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
