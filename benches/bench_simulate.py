"""Time ``granrs.simulate`` over the scenes of thesis Table 3.5 and over every body, from Python.

Each row of Table 3.5 (``granrs.data.load("table_3_5")``) becomes a free-link scene with its
Table 3.4 coefficients (``granrs.cases.free_link(q_deg, v0)``); the scenes are built once.
For every scene the script takes the minimum over ``--repeats`` runs of

* one ``granrs.simulate(scene)`` call (validation, the Rust run, the Result);
* the Python-side conversion alone: ``Scene.to_dict`` plus ``_granrs.validate``, which does
  the same dict-to-Rust conversion and validation as the simulate call without running;

and reports the right-hand-side evaluations of the run (``summary["rhs_evals"]``), the time
per evaluation (simulate time / rhs_evals: an upper bound on the Rust cost of one evaluation,
since it includes the overhead), and the overhead as a fraction of the simulate call. The
machines are shared and noisy: read the ratios, not the absolute times. The Rust-only times
are in ``cargo bench --bench free_link``; to compare with them, build the extension with
``maturin develop --release`` (a plain ``maturin develop`` builds the dev profile, about 1.5x
slower per evaluation).

The bodies part times one scene per body model, the scenes of ``cargo bench --bench bodies``
(same names, same work counters):

* ``free_link_q45``: ``granrs.cases.free_link(45, 2.27)``, the Table 3.5 row;
* ``chain_case1``: ``granrs.cases.chain(1, end="all_stops")``, the thesis's chain case 1 until
  both links stop;
* ``leg_locked``, ``leg_spring``, ``leg_free``: ``granrs.cases.leg(3.28)`` with ankle, knee
  and hip locked (the default), spring-dampers (``joints={"k": 300, "c": 5}``) or free.

It reports the same columns per body (simulate time, work counters, time per evaluation, the
to_dict + validate overhead) and the ratios to the free link's simulate time and time per
evaluation. The bodies are timed in turn within each repeat, so a ratio's two times come from
the same stretch of the run. Compare the ratios with those of ``cargo bench --bench bodies``
(``python benches/criterion_ratios.py``), not the times: the two are separate runs.

Usage::

    python benches/bench_simulate.py [--repeats 7] [--part all|table|bodies] [--csv PATH]
        [--bodies-csv PATH]
"""

from __future__ import annotations

import argparse
import csv
import statistics
import sys
import time
from dataclasses import asdict, dataclass

import granrs
from granrs import _granrs

#: Inner loop of the overhead timing: to_dict + validate take microseconds, so time a batch.
OVERHEAD_INNER = 20


@dataclass
class Row:
    """One Table 3.5 scene's timings (seconds are minima over the repeats)."""

    q_deg: float
    v0: float
    simulate_us: float
    rhs_evals: int
    steps: int
    ns_per_rhs: float
    overhead_us: float
    overhead_frac: float


@dataclass
class BodyRow:
    """One body's timings (seconds are minima over the repeats; ratios to the free link)."""

    name: str
    body: str
    status: str
    simulate_us: float
    rhs_evals: int
    steps: int
    ns_per_rhs: float
    overhead_us: float
    overhead_frac: float
    sim_ratio: float
    rhs_ratio: float


def build_bodies() -> dict[str, granrs.Scene]:
    """One scene per body, named as in ``benches/bodies.rs``; the free link first."""
    return {
        "free_link_q45": granrs.cases.free_link(45.0, 2.27),
        "chain_case1": granrs.cases.chain(1, end="all_stops"),
        "leg_locked": granrs.cases.leg(3.28),
        "leg_spring": granrs.cases.leg(3.28, joints={"k": 300.0, "c": 5.0}),
        "leg_free": granrs.cases.leg(3.28, joints="free"),
    }


def build_scenes() -> list[granrs.Scene]:
    """The Table 3.5 scenes, each with its Table 3.4 coefficients (nearest |q|, ties up)."""
    table = granrs.data.load("table_3_5")
    return [
        granrs.cases.free_link(float(q), float(v0))
        for q, v0 in zip(table["q_deg"], table["v0"], strict=True)
    ]


def time_simulate(scene: granrs.Scene) -> float:
    """Seconds of one simulate() call."""
    t0 = time.perf_counter()
    granrs.simulate(scene)
    return time.perf_counter() - t0


def time_overhead(scene: granrs.Scene) -> float:
    """Seconds of one Scene.to_dict + _granrs.validate (mean of a short batch)."""
    t0 = time.perf_counter()
    for _ in range(OVERHEAD_INNER):
        _granrs.validate(scene.to_dict())
    return (time.perf_counter() - t0) / OVERHEAD_INNER


def measure(scenes: list[granrs.Scene], repeats: int) -> tuple[list[Row], float]:
    """Per-scene rows and the minimum over repeats of the whole batch [s]."""
    results = [granrs.simulate(s) for s in scenes]  # warm-up, and the work counters
    for s, r in zip(scenes, results, strict=True):
        if r.status != "stopped":
            raise RuntimeError(f"q = {s.q_deg}, v0 = {s.v0}: {r.status}")
    best_sim = [float("inf")] * len(scenes)
    best_over = [float("inf")] * len(scenes)
    best_batch = float("inf")
    for _ in range(repeats):
        t_batch = time.perf_counter()
        for i, s in enumerate(scenes):
            best_sim[i] = min(best_sim[i], time_simulate(s))
        best_batch = min(best_batch, time.perf_counter() - t_batch)
        for i, s in enumerate(scenes):
            best_over[i] = min(best_over[i], time_overhead(s))
    rows = []
    for s, r, t_sim, t_over in zip(scenes, results, best_sim, best_over, strict=True):
        evals = int(r.summary["rhs_evals"])
        rows.append(
            Row(
                q_deg=s.q_deg,
                v0=s.v0,
                simulate_us=t_sim * 1e6,
                rhs_evals=evals,
                steps=int(r.summary["steps"]),
                ns_per_rhs=t_sim * 1e9 / evals,
                overhead_us=t_over * 1e6,
                overhead_frac=t_over / t_sim,
            )
        )
    return rows, best_batch


def measure_bodies(scenes: dict[str, granrs.Scene], repeats: int) -> list[BodyRow]:
    """Per-body rows; ratios to the first scene (the free link)."""
    results = {name: granrs.simulate(s) for name, s in scenes.items()}  # warm-up, counters
    for name, r in results.items():
        if r.status != "stopped":
            raise RuntimeError(f"{name}: {r.status}")
    best_sim = dict.fromkeys(scenes, float("inf"))
    best_over = dict.fromkeys(scenes, float("inf"))
    for _ in range(repeats):
        for name, s in scenes.items():
            best_sim[name] = min(best_sim[name], time_simulate(s))
        for name, s in scenes.items():
            best_over[name] = min(best_over[name], time_overhead(s))
    base = next(iter(scenes))
    base_evals = int(results[base].summary["rhs_evals"])
    base_ns_per_rhs = best_sim[base] * 1e9 / base_evals
    rows = []
    for name, s in scenes.items():
        r, t_sim, t_over = results[name], best_sim[name], best_over[name]
        evals = int(r.summary["rhs_evals"])
        ns_per_rhs = t_sim * 1e9 / evals
        rows.append(
            BodyRow(
                name=name,
                body=s.body,
                status=r.status,
                simulate_us=t_sim * 1e6,
                rhs_evals=evals,
                steps=int(r.summary["steps"]),
                ns_per_rhs=ns_per_rhs,
                overhead_us=t_over * 1e6,
                overhead_frac=t_over / t_sim,
                sim_ratio=t_sim / best_sim[base],
                rhs_ratio=ns_per_rhs / base_ns_per_rhs,
            )
        )
    return rows


def report_bodies(rows: list[BodyRow], repeats: int) -> str:
    """The per-body table as text."""
    base = rows[0].name
    lines = [
        f"granrs {granrs.__version__}: simulate() per body, min of {repeats} repeats; "
        f"x_sim, x_rhs: ratios to {base}",
        f"{'name':<14} {'sim_us':>9} {'x_sim':>6} {'steps':>6} {'rhs':>6} {'rhs/step':>8} "
        f"{'ns/rhs':>8} {'x_rhs':>6} {'ovh_us':>7} {'ovh_%':>6}",
    ]
    for r in rows:
        lines.append(
            f"{r.name:<14} {r.simulate_us:>9.1f} {r.sim_ratio:>6.2f} {r.steps:>6d} "
            f"{r.rhs_evals:>6d} {r.rhs_evals / r.steps:>8.2f} {r.ns_per_rhs:>8.1f} "
            f"{r.rhs_ratio:>6.2f} {r.overhead_us:>7.1f} {100 * r.overhead_frac:>6.2f}"
        )
    return "\n".join(lines)


def report(rows: list[Row], batch_s: float, repeats: int) -> str:
    """The table and the summary as text."""
    med_ns = statistics.median(r.ns_per_rhs for r in rows)
    lines = [
        f"granrs {granrs.__version__}: simulate() over {len(rows)} Table 3.5 scenes, "
        f"min of {repeats} repeats",
        f"{'q_deg':>6} {'v0':>6} {'sim_us':>9} {'steps':>6} {'rhs':>6} {'ns/rhs':>8} "
        f"{'x_med':>6} {'ovh_us':>7} {'ovh_%':>6}",
    ]
    for r in rows:
        lines.append(
            f"{r.q_deg:>6g} {r.v0:>6.3f} {r.simulate_us:>9.1f} {r.steps:>6d} {r.rhs_evals:>6d} "
            f"{r.ns_per_rhs:>8.1f} {r.ns_per_rhs / med_ns:>6.2f} {r.overhead_us:>7.1f} "
            f"{100 * r.overhead_frac:>6.2f}"
        )
    n = len(rows)
    mean_sim = statistics.fmean(r.simulate_us for r in rows)
    mean_rhs = statistics.fmean(r.rhs_evals for r in rows)
    total_sim = sum(r.simulate_us for r in rows)
    total_rhs = sum(r.rhs_evals for r in rows)
    mean_over = statistics.fmean(r.overhead_us for r in rows)
    vertical = [r for r in rows if r.q_deg == 0.0]
    slanted = [r for r in rows if r.q_deg != 0.0]
    lines += [
        "",
        f"per impact (mean of {n}):       {mean_sim:9.1f} us per simulate() call",
        f"rhs evaluations per impact:     {mean_rhs:9.1f}",
        f"ns per rhs evaluation:          {1e3 * total_sim / total_rhs:9.1f} "
        f"(batch total / total evals; median over rows {med_ns:.1f})",
        f"Python overhead per call:       {mean_over:9.1f} us "
        f"(to_dict + validate) = {100 * mean_over / mean_sim:.2f} % of a simulate() call "
        f"(rows {100 * min(r.overhead_frac for r in rows):.2f}-"
        f"{100 * max(r.overhead_frac for r in rows):.2f} %)",
        f"batch (loop of {n} calls):       {batch_s * 1e3:9.2f} ms "
        f"= {batch_s * 1e6 / n:.1f} us per impact "
        f"(sum of per-row minima / batch minimum = {total_sim / (batch_s * 1e6):.3f})",
    ]
    if vertical and slanted:
        v_ns = statistics.fmean(r.ns_per_rhs for r in vertical)
        s_ns = statistics.fmean(r.ns_per_rhs for r in slanted)
        lines.append(
            f"ns/rhs vertical (q = 0) / slanted (q != 0): {v_ns:.1f} / {s_ns:.1f} "
            f"= {v_ns / s_ns:.2f}"
        )
    return "\n".join(lines)


def write_csv(rows: list[Row] | list[BodyRow], path: str) -> None:
    """One line per scene, the columns of :class:`Row` (or :class:`BodyRow`)."""
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(asdict(rows[0])))
        writer.writeheader()
        for r in rows:
            writer.writerow(asdict(r))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=7, help="repeats (minimum taken)")
    parser.add_argument(
        "--part",
        choices=("all", "table", "bodies"),
        default="all",
        help="Table 3.5 scenes, one scene per body, or both (default: all)",
    )
    parser.add_argument("--csv", metavar="PATH", help="write the Table 3.5 table as CSV")
    parser.add_argument("--bodies-csv", metavar="PATH", help="write the per-body table as CSV")
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    if args.part in ("all", "table"):
        scenes = build_scenes()
        rows, batch_s = measure(scenes, args.repeats)
        print(report(rows, batch_s, args.repeats))
        if args.csv:
            write_csv(rows, args.csv)
            print(f"wrote {args.csv}")
    if args.part in ("all", "bodies"):
        if args.part == "all":
            print()
        body_rows = measure_bodies(build_bodies(), args.repeats)
        print(report_bodies(body_rows, args.repeats))
        if args.bodies_csv:
            write_csv(body_rows, args.bodies_csv)
            print(f"wrote {args.bodies_csv}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
