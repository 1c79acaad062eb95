"""Does the step-size warning see every unresolved run, and only those?

A random set of free-link scenes under every law (the thesis's, ``rft``, ``rft_inertial``,
``poncelet`` and mixes of them, the force at the tip or at the immersed centroid; angle,
speeds, spin and mass drawn too) is run at dt = 1e-3 and 1e-4, and each again at dt / 10. A
scene *moved* at a dt when its ``t_s`` or its depth differs from the dt / 10 run's by more
than 1 % (or its status does); it *warned* when ``granrs.simulate`` warned
:class:`granrs.StepSizeWarning` or refused the run as diverged. The script prints, per dt,
the confusion counts (moved & warned, moved & silent, still & warned, still & silent), how
many runs ``granrs.simulate``'s step check ran again at a finer step (its cost), each
miss and false alarm with its ``h_lambda``, ``step_error`` and ``unresolved_stops``, and the
mirror count: each scene is run again as its mirror image (x -> -x: the angle q, vx0 and
omega0 -> -q, -vx0, -omega0); of the pairs where neither warns, how many differ by more
than 1e-9 (relative, in ``t_s`` and depth), and how many pairs only one of the two warns.

With ``--deep`` a run that agrees with dt / 10 is also compared with dt / 100 and counts as
moved if that differs: dt / 10 can be as wrong as dt (a stick that both steps' overshoot
decided, which only dt / 100 resolves).

Usage::

    python benches/step_warning.py [--scenes 200] [--seed 7] [--deep]
"""

from __future__ import annotations

import argparse
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

import granrs
from granrs import cases
from granrs import forces as f

#: The laws drawn from, each with its parameters drawn from `rng`.
LAWS: dict[str, Callable[[np.random.Generator], list[f.Term]]] = {
    "thesis": lambda r: list(f.thesis()),
    "rft": lambda r: [f.gravity(), f.rft(zeta=10 ** r.uniform(5.5, 6.5))],
    "rft_inertial": lambda r: [f.gravity(), f.rft_inertial(lam=r.uniform(0.5, 2.0))],
    "poncelet": lambda r: [f.gravity(), f.poncelet(c=r.uniform(0.3, 3.0), k=r.uniform(20, 500))],
    "rft+rft_inertial": lambda r: [
        f.gravity(),
        f.rft(zeta=10 ** r.uniform(5.5, 6.5)),
        f.rft_inertial(),
    ],
    "rft+poncelet": lambda r: [
        f.gravity(),
        f.rft(zeta=10 ** r.uniform(5.5, 6.5)),
        f.poncelet(c=r.uniform(0.3, 3.0), k=r.uniform(20, 500)),
    ],
    "rft_inertial+poncelet": lambda r: [
        f.gravity(),
        f.rft_inertial(),
        f.poncelet(c=r.uniform(0.3, 3.0), k=r.uniform(20, 500)),
    ],
    "thesis+rft": lambda r: [*f.thesis(), f.rft(zeta=10 ** r.uniform(5.5, 6.5))],
}
#: Relative change of t_s or depth at dt / 10 that counts as "moved".
MOVED = 0.01
T_END = 0.3


@dataclass
class Scene:
    """One drawn scene: its law's name and the free link's fields."""

    law: str
    fields: dict[str, Any]

    def at(self, dt: float, mirror: bool = False) -> granrs.Scene:
        s = -1.0 if mirror else 1.0
        p = self.fields
        return cases.free_link(s * p["q_deg"], p["v0"], dt=dt).replace(
            mass=p["mass"],
            vx0=s * p["vx0"],
            omega0=s * p["omega0"],
            forces=p["forces"],
            apply_at=p["apply_at"],
            t_end=T_END,
        )


def draw(rng: np.random.Generator) -> Scene:
    law = list(LAWS)[rng.integers(len(LAWS))]
    forces = LAWS[law](rng)
    return Scene(
        law,
        {
            "q_deg": rng.uniform(-85.0, 85.0),
            "v0": rng.uniform(0.1, 5.0),
            "vx0": rng.uniform(-1.0, 1.0),
            "omega0": rng.uniform(-10.0, 10.0),
            "mass": 10 ** rng.uniform(-2.0, 0.0),
            "apply_at": ("tip", "centroid")[rng.integers(2)],
            "forces": forces,
        },
    )


def scenes(n: int, seed: int) -> list[Scene]:
    rng = np.random.default_rng(seed)
    return [draw(rng) for _ in range(n)]


@dataclass
class Run:
    """A run's summary (None if refused as diverged), whether it warned, and whether
    ``granrs.simulate``'s step check ran it again at a finer step (its cost)."""

    summary: dict[str, Any] | None
    warned: bool
    checked: bool = False


def run(scene: granrs.Scene) -> Run:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            r = granrs.simulate(scene)
        except granrs.SimulationError:
            return Run(None, True)
    warned = any(issubclass(w.category, granrs.StepSizeWarning) for w in caught)
    return Run(dict(r.summary), warned, r.step_check is not None)


def moved(a: Run, b: Run) -> bool:
    """Whether the run `a` differs from the finer `b` by more than MOVED."""
    if a.summary is None or b.summary is None:
        return True
    if a.summary["status"] != b.summary["status"]:
        return True
    for key in ("t_s", "depth"):
        x, y = a.summary[key], b.summary[key]
        if math.isnan(x) and math.isnan(y):
            continue
        if not abs(x - y) <= MOVED * abs(y):
            return True
    return False


def mirror_gap(a: Run, b: Run) -> float:
    """Largest relative difference of t_s and depth between a run and its mirror image."""
    if a.summary is None or b.summary is None:
        return math.inf
    gap = 0.0
    for key in ("t_s", "depth"):
        x, y = a.summary[key], b.summary[key]
        if math.isnan(x) and math.isnan(y):
            continue
        gap = max(gap, abs(x - y) / max(abs(y), 1e-300))
    return gap


@dataclass
class Study:
    """The confusion counts per dt, the misses and false alarms, and the mirror gaps."""

    counts: dict[float, dict[str, int]] = field(default_factory=dict)
    #: Per dt, how many runs simulate's step check ran again (the check's cost).
    checked: dict[float, int] = field(default_factory=dict)
    misses: list[tuple[int, str, float, dict[str, Any]]] = field(default_factory=list)
    false_alarms: list[tuple[int, str, float, dict[str, Any]]] = field(default_factory=list)
    #: (scene, dt, gap) for every pair of silent runs (a scene and its mirror image).
    mirror: list[tuple[int, float, float]] = field(default_factory=list)
    #: (scene, dt) where only one of a scene and its mirror image warned.
    mirror_warned: list[tuple[int, float]] = field(default_factory=list)


def study(
    drawn: list[Scene],
    dts: tuple[float, ...] = (1e-3, 1e-4),
    mirrors: bool = True,
    deep: bool = False,
) -> Study:
    out = Study()
    for dt in dts:
        out.counts[dt] = dict.fromkeys(
            ("moved&warned", "moved&silent", "still&warned", "still&silent"), 0
        )
    for i, sc in enumerate(drawn):
        fine: dict[float, Run] = {}
        for dt in dts:
            coarse = fine.get(dt) or run(sc.at(dt))
            fine[dt / 10] = finer = run(sc.at(dt / 10))
            m = moved(coarse, finer)
            if deep and not m:
                # dt / 10 may be as unresolved as dt (a stick decided by both steps).
                m = moved(coarse, run(sc.at(dt / 100)))
            key = f"{'moved' if m else 'still'}&{'warned' if coarse.warned else 'silent'}"
            out.counts[dt][key] += 1
            out.checked[dt] = out.checked.get(dt, 0) + coarse.checked
            info = {
                k: (coarse.summary or {}).get(k, math.nan)
                for k in ("h_lambda", "unresolved_stops", "step_error", "t_s", "depth")
            }
            info["t_s_fine"] = (finer.summary or {}).get("t_s", math.nan)
            info["depth_fine"] = (finer.summary or {}).get("depth", math.nan)
            if m and not coarse.warned:
                out.misses.append((i, sc.law, dt, info))
            if coarse.warned and not m:
                out.false_alarms.append((i, sc.law, dt, info))
            if mirrors:
                image = run(sc.at(dt, mirror=True))
                if coarse.warned != image.warned:
                    out.mirror_warned.append((i, dt))
                elif not coarse.warned:
                    out.mirror.append((i, dt, mirror_gap(coarse, image)))
    return out


def report(s: Study, drawn: list[Scene]) -> str:
    lines = []
    for dt, c in s.counts.items():
        lines.append(
            f"dt = {dt:g}: moved&warned {c['moved&warned']}, moved&silent {c['moved&silent']}, "
            f"still&warned {c['still&warned']}, still&silent {c['still&silent']}; "
            f"checked again by simulate {s.checked.get(dt, 0)}"
        )
    for title, rows in (("moved & silent", s.misses), ("still & warned", s.false_alarms)):
        lines.append(f"{title}:")
        for i, law, dt, info in rows:
            sc = drawn[i]
            lines.append(
                f"  scene {i} ({law}, at the {sc.fields['apply_at']}) dt {dt:g}: "
                f"h_lambda {info['h_lambda']:.3g}, step_error {info['step_error']:.3g}, "
                f"unresolved_stops {info['unresolved_stops']}, "
                f"t_s {info['t_s']:.6g} against {info['t_s_fine']:.6g}, depth "
                f"{info['depth']:.6g} against {info['depth_fine']:.6g}"
            )
    if s.mirror or s.mirror_warned:
        over = sum(1 for _, _, g in s.mirror if g > 1e-9)
        line = (
            f"mirror images: {len(s.mirror)} silent pairs compared, {over} differ by more than 1e-9"
        )
        if s.mirror:
            worst = max(s.mirror, key=lambda r: r[2])
            line += f" (largest {worst[2]:.3g}: scene {worst[0]} at dt {worst[1]:g})"
        only = ", ".join(f"scene {i} at dt {dt:g}" for i, dt in s.mirror_warned)
        line += f"; {len(s.mirror_warned)} pairs where only one warns{': ' + only if only else ''}"
        lines.append(line)
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=200)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument(
        "--deep",
        action="store_true",
        help="a run that agrees with dt / 10 is also compared with dt / 100",
    )
    args = parser.parse_args(argv)
    drawn = scenes(args.scenes, args.seed)
    print(f"{args.scenes} scenes, seed {args.seed}{', deep' if args.deep else ''}")
    print(report(study(drawn, deep=args.deep), drawn))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
