"""Fingerprint of granrs's results, to hold a redesign to them: every thesis body (the free
link at six angles and two speeds, the chain's three cases free, with a spring-damper pin and
locked with a pin mass, the leg locked, free, with spring-dampers, the thesis's sole, at the
centroid and started in the sand), other laws (``rft`` with its inertial term, ``poncelet``),
every shipped scene file and three sweeps (the free link's in the SIMD lanes, the chain's and
the leg's), each summary and each recorded series (its sum, its sum of magnitudes and its
length).

Usage::

    python benches/fingerprint.py before.json       # with the code before the change
    python benches/fingerprint.py after.json        # with the code after it
    python benches/fingerprint.py --compare before.json after.json

``--compare`` prints every value that moved by more than 1e-9 (relative to the larger of 1
and the value) and the count; it exits 1 when anything moved.
"""

from __future__ import annotations

import dataclasses
import glob
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

import granrs
from granrs import cases, forces, scenefile, space

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "scenes"


def fingerprint() -> dict[str, Any]:
    """The fingerprint of this build: one entry a run, each a dict of numbers."""
    out: dict[str, Any] = {}

    def summ(res: Any) -> dict[str, Any]:
        d: dict[str, Any] = {}
        for k, v in res.summary.items():
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                d[k] = float(v)
        if res.series is not None:
            for k in sorted(res.series):
                a = np.asarray(res.series[k], dtype=float)
                d["series." + k] = [float(np.nansum(a)), float(np.nansum(np.abs(a))), a.size]
        for i, c in enumerate(getattr(res, "contacts", ())):  # none in space
            for k, v in dataclasses.asdict(c).items():
                if isinstance(v, (int, float)) and not isinstance(v, bool):
                    d[f"c{i}.{k}"] = float(v)
        for joint, values in getattr(res, "joints", {}).items():
            for k, v in values.items():
                if isinstance(v, (int, float)) and not isinstance(v, bool):
                    d[f"{joint}.{k}"] = float(v)
        return d

    def run(name: str, scene: Any) -> None:
        try:
            out[name] = summ(granrs.simulate(scene()))
        except Exception as e:  # a run that fails is part of the fingerprint
            out[name] = {"error": f"{type(e).__name__}: {e}"}

    rec = ("state", "forces", "energy")

    def recorded(scene: Any) -> Any:
        """The scene recording every series: a planar scene names its series, a scene in
        space records all of them (``record=True``)."""
        return scene.replace(record=True if isinstance(scene, space.Scene) else rec)

    for q in [-60, -30, 0, 15, 45, 75]:
        for v0 in [0.5, 2.27]:
            run(
                f"free link q{q} v{v0}",
                lambda q=q, v0=v0: cases.free_link(q_deg=q, v0=v0).replace(
                    record=rec, end="all_stops"
                ),
            )
    laws = {
        "rft": (forces.gravity(), forces.rft(zeta=1e6), forces.rft_inertial()),
        "poncelet": (forces.gravity(), forces.poncelet(c=0.8, k=150.0)),
    }
    for law, fs in laws.items():
        run(
            f"free link {law}",
            lambda fs=fs: cases.free_link(q_deg=30, v0=2.0).replace(
                forces=fs, record=rec, omega0=2.0, vx0=0.3
            ),
        )
        run(f"chain {law}", lambda fs=fs: cases.chain(case=1).replace(forces=fs, record=rec))
    for c in [1, 2, 3]:
        run(f"chain{c}", lambda c=c: cases.chain(case=c).replace(record=rec))

        def spring(c: int = c) -> Any:
            base = cases.chain(case=c)
            fs = tuple(t for t in base.forces if t.name != "joint_springs")
            return base.replace(
                pin_joint={"k": 0.5, "c": 0.001}, forces=(*fs, forces.joint_springs()), record=rec
            )

        run(f"chain{c} spring", spring)
        run(
            f"chain{c} locked pin mass",
            lambda c=c: cases.chain(case=c).replace(pin_joint="locked", pin_mass=0.01, record=rec),
        )
    legs: list[dict[str, Any]] = [
        {},
        {"knee": "free"},
        {"ankle": {"k": 300.0, "c": 5.0}, "knee": {"k": 300.0, "c": 5.0}, "hip": "free"},
        {"sole_model": "thesis"},
        {"depth0": 0.01, "vx0": 0.4},
        {"apply_at": "centroid"},
    ]
    for kw in legs:

        def leg(kw: dict[str, Any] = kw) -> Any:
            sc = cases.leg().replace(record=rec, **kw)
            springs = any(isinstance(v, dict) for v in kw.values())
            if springs and "joint_springs" not in [t.name for t in sc.forces]:
                sc = sc.replace(forces=(*sc.forces, forces.joint_springs()))
            return sc

        run(f"leg {sorted(kw)}", leg)
    for f in sorted(glob.glob(str(EXAMPLES / "*.toml"))):
        run("file " + Path(f).name, lambda f=f: recorded(scenefile.load(f)))
    sweeps = [
        (
            "free link",
            cases.free_link(q_deg=0, v0=2.0),
            {"q_deg": [-30.0, 0.0, 20.0, 45.0, 70.0], "v0": [0.5, 1.5, 3.0]},
        ),
        ("chain", cases.chain(case=1), {"v0": [1.0, 2.0, 3.0]}),
        ("leg", cases.leg(), {"v0": [2.0, 3.28]}),
    ]
    for name, scene, axes in sweeps:
        table = granrs.sweep(scene, **axes)
        out["sweep " + name] = {
            f"{k}[{i}]": float(x)
            for k in table.columns
            if np.asarray(table[k]).dtype.kind in "fiu"
            for i, x in enumerate(np.asarray(table[k], dtype=float))
        }
    return out


def compare(before: dict[str, Any], after: dict[str, Any]) -> int:
    """Print what moved by more than 1e-9 between two fingerprints; the count."""
    moved = 0
    for name in sorted(set(before) | set(after)):
        x, y = before.get(name), after.get(name)
        if x is None or y is None:
            print(f"{name}: only in {'after' if x is None else 'before'}")
            moved += 1
            continue
        for field in sorted(set(x) | set(y)):
            u, v = x.get(field), y.get(field)
            if u is None or v is None or isinstance(u, str) or isinstance(v, str):
                if u != v:
                    print(f"{name} {field}: {u!r} -> {v!r}")
                    moved += 1
                continue
            us, vs = (w if isinstance(w, list) else [w] for w in (u, v))
            if len(us) != len(vs):
                print(f"{name} {field}: {u!r} -> {v!r}")
                moved += 1
                continue
            for p, q in zip(us, vs, strict=True):
                if math.isnan(p) and math.isnan(q):
                    continue
                if abs(p - q) > 1e-9 * max(1.0, abs(p), abs(q)):
                    print(f"{name} {field}: {p!r} -> {q!r}")
                    moved += 1
                    break
    print(f"{moved} values moved by more than 1e-9 over {len(before)} runs")
    return moved


def main() -> None:
    args = sys.argv[1:]
    if len(args) == 3 and args[0] == "--compare":
        a, b = (json.loads(Path(p).read_text()) for p in args[1:])
        sys.exit(1 if compare(a, b) else 0)
    if len(args) != 1:
        sys.exit(__doc__)
    result = fingerprint()
    Path(args[0]).write_text(json.dumps(result, indent=0, sort_keys=True))
    print(f"{len(result)} runs, {sum('error' in v for v in result.values())} failed")


if __name__ == "__main__":
    main()
