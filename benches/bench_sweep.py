"""Benchmarks of issue 5: sweeps, call overhead, pruned scenes, the vectorized force.

One command, every ratio measured in the same run (absolute times on shared machines are
noisy; the ratios are what to quote)::

    python benches/bench_sweep.py            # 100,000-impact sweep; about two minutes
    python benches/bench_sweep.py --quick    # 10,000 impacts
    python benches/bench_sweep.py --part overhead --part prune

Parts:

* ``sweep``: a sweep of free-link impacts (angles x speeds x coefficient scales), summary
  only, on 1 and 2 threads, each in a fresh child process that reports its own peak
  resident memory (``ru_maxrss``), and once more on 1 thread asking only for the depth and
  t_s, and on 1 and 2 threads returning every column as numpy arrays (``as_frame=False``:
  no pandas). Targets: 2 threads >= 1.8x faster than 1; peak < 200 MB; at a million impacts
  (``--runs 1000000``) the sweep asking for the depth and t_s, and the sweep returning
  numpy arrays, each peak < 300 MB.
* ``overhead``: each ``granrs.simulate(scene)`` call timed whole, against the run inside
  it as the core times it. Target: overhead < 10 % of the call.
* ``prune``: the vertical drop with every effect and every series recorded, against the
  same drop with only ``gravity`` and ``static_v`` (summary only), and against every effect
  summary only. Both must be measurably faster than the full scene with full recording.
* ``force``: ``granrs.resistance_force`` on a million states against the same equations in
  numpy.
* ``fixed``: a sweep's fixed cost: a one-scene sweep on 1 and 2 threads, timed whole and as
  the core's call alone (``_granrs.sweep``: the pool's hand-off and the run, no DataFrame),
  against the run alone as the core times it, in the same loop. No target; it is what a
  small sweep pays beyond its runs (issue 22's two-thread line at 155 runs).
* ``lanes``: 1000 free links (40 angles x 25 speeds) on one thread under each sign model
  (``modes``, ``raw``, ``smooth``) and under ``rft``, ``rft`` + ``rft_inertial`` and
  ``poncelet``, with the SIMD lanes (``lanes=True``) and on the scalar path
  (``lanes=False``), taken in turn. No target; the lanes' gain over the scalar path
  (``docs/sweeps.md``).
* ``axis``: a sweep's validation before its first run (the Python-level checks of the
  axes and the core's check of every run, as ``granrs.sweep`` does them), for one axis of
  40,000 values against a 400 x 100 product of the same size. Target: under 1 s each; the
  two within a factor of a few of each other (the check of one long axis was quadratic:
  37.1 s against 2.8 s).

Build in release first: ``maturin develop --release``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import time
from collections.abc import Callable

import numpy as np

import granrs
from granrs import _granrs, cases
from granrs.forces import select, thesis

PARTS = ("sweep", "overhead", "prune", "force", "fixed", "lanes", "axis")
#: What the lean sweep asks for.
LEAN_OUTPUTS = ("depth", "t_s")
#: A million-impact sweep's peak memory target, judged on the lean sweep and on the sweep
#: returning every column as numpy arrays.
MILLION_PEAK_MB = 300


def _median_time(fn: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


# ---------------------------------------------------------------------------------- sweep
def _sweep_axes(n: int) -> dict[str, list[float]]:
    """About n free-link impacts: angle x speed x eta_v scale."""
    n_q = 100
    n_v = 20
    n_c = max(1, round(n / (n_q * n_v)))
    return {
        "q_deg": list(np.linspace(-85.0, 85.0, n_q)),
        "v0": list(np.linspace(0.5, 5.0, n_v)),
        "rho_g": list(np.linspace(1400.0, 1800.0, n_c)),
    }


def _child(n: int, threads: int, lean: int = 0, arrays: int = 0) -> None:
    """Run one sweep and print its time and this process's peak memory (JSON); ``lean``:
    the sweep asks only for the depth and t_s (``outputs=LEAN_OUTPUTS``); ``arrays``: it
    returns numpy arrays (``as_frame=False``), and the child reports whether pandas was
    loaded."""
    base = cases.free_link(q_deg=0.0, v0=2.0)
    axes = _sweep_axes(n)
    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.perf_counter()
    outputs = {"outputs": list(LEAN_OUTPUTS)} if lean else {}
    result = granrs.sweep(
        base, threads=threads, progress=False, as_frame=not arrays, **outputs, **axes
    )
    elapsed = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
    pandas_loaded = "pandas" in sys.modules
    if arrays:
        assert isinstance(result, dict)
        # The object column's strings are the five shared ones: 8 bytes a row each.
        result_mb = sum(column.nbytes for column in result.values()) / 2**20
    else:
        result_mb = result.memory_usage(deep=True).sum() / 2**20
    ok = bool((result["status"] == "stopped").all() and np.isfinite(result["depth"]).all())
    print(
        json.dumps(
            {
                "runs": len(result["status"]),
                "threads": threads,
                "lean": bool(lean),
                "arrays": bool(arrays),
                "seconds": elapsed,
                "peak_mb": peak / 1024,
                "before_mb": rss_before / 1024,
                "result_mb": result_mb,
                "pandas_loaded": pandas_loaded,
                "all_stopped_finite": ok,
            }
        )
    )


#: The sweep part's children: (threads, lean, arrays).
SWEEP_RUNS = ((1, 0, 0), (2, 0, 0), (1, 1, 0), (1, 0, 1), (2, 0, 1))


def part_sweep(n: int) -> list[str]:
    rows = {}
    for threads, lean, arrays in SWEEP_RUNS:
        out = subprocess.run(
            [sys.executable, __file__, "--child", str(n), str(threads), str(lean), str(arrays)],
            check=True,
            capture_output=True,
            text=True,
        )
        rows[threads, lean, arrays] = json.loads(out.stdout.strip().splitlines()[-1])
    one, two, lean_one = rows[1, 0, 0], rows[2, 0, 0], rows[1, 1, 0]
    arrays_peak = max(rows[1, 0, 1]["peak_mb"], rows[2, 0, 1]["peak_mb"])
    speedup = one["seconds"] / two["seconds"]
    lines = [
        f"### Sweep of {one['runs']:,} free-link impacts, summary only",
        "",
        "| threads | columns | returns | time [s] | per impact [us] | peak RSS [MB] "
        "| RSS after import [MB] | result [MB] | pandas loaded | all stopped, finite |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for key in SWEEP_RUNS:
        r = rows[key]
        columns = "depth, t_s" if r["lean"] else "default"
        returns = "numpy arrays" if r["arrays"] else "DataFrame"
        lines.append(
            f"| {r['threads']} | {columns} | {returns} | {r['seconds']:.2f} "
            f"| {r['seconds'] / r['runs'] * 1e6:.1f} "
            f"| {r['peak_mb']:.0f} | {r['before_mb']:.0f} | {r['result_mb']:.1f} "
            f"| {r['pandas_loaded']} | {r['all_stopped_finite']} |"
        )
    peak = max(one["peak_mb"], two["peak_mb"])

    def million(mb: float) -> str:
        met = "met" if mb < MILLION_PEAK_MB else "NOT met"
        return f"(a million-impact sweep's target < {MILLION_PEAK_MB} MB at --runs 1000000: {met})"

    lines += [
        "",
        f"2 threads / 1 thread speed-up: **{speedup:.2f}x** (target >= 1.8x: "
        f"{'met' if speedup >= 1.8 else 'NOT met'}); peak memory **{peak:.0f} MB** "
        f"(target < 200 MB: {'met' if peak < 200 else 'NOT met'}).",
        f"Asking only for the depth and t_s: peak **{lean_one['peak_mb']:.0f} MB** "
        f"{million(lean_one['peak_mb'])}.",
        f"Every column as numpy arrays (``as_frame=False``): peak **{arrays_peak:.0f} MB** "
        f"on 1 and 2 threads {million(arrays_peak)}.",
        "",
    ]
    return lines


# ------------------------------------------------------------------------------- overhead
def part_overhead(repeat: int) -> list[str]:
    """Each call of simulate() timed whole, and the core's run inside it timed by the core
    (``run_seconds``): the difference is the call's overhead, measured in the same call."""
    lines = ["### Python call overhead of `simulate`", ""]
    lines += [
        "| scene | simulate() [us] | the run in the core [us] | overhead [us] | share "
        "| a new Scene each call: overhead [us] | share |"
    ]
    lines += ["|---|---|---|---|---|---|---|"]
    worst = 0.0
    for name, scene in (
        ("free link q = 45, v0 = 2.27", cases.free_link(q_deg=45.0, v0=2.27)),
        ("free link q = 85, v0 = 2.257", cases.free_link(q_deg=85.0, v0=2.257)),
        ("vertical drop v0 = 2.214", cases.free_link(q_deg=0.0, v0=2.214)),
    ):
        n = 200 * repeat
        # Fresh copies (their construction is not timed): each call then converts and
        # validates its scene in the core, as a loop over scene.replace(...) does.
        fresh = [dataclasses.replace(scene) for _ in range(n)]
        stats: dict[str, tuple[float, float]] = {}
        for label, scenes in (("same", [scene] * n), ("fresh", fresh)):
            totals, cores = [], []
            for s in scenes:
                t0 = time.perf_counter()
                result = granrs.simulate(s)
                totals.append(time.perf_counter() - t0)
                # The core's own timing of the run inside that call.
                cores.append(result._core.run_seconds)
            stats[label] = (statistics.median(totals), statistics.median(cores))
        total, core = stats["same"]
        over = total - core
        f_total, f_core = stats["fresh"]
        f_over = f_total - f_core
        worst = max(worst, over / total, f_over / f_total)
        lines.append(
            f"| {name} | {total * 1e6:.1f} | {core * 1e6:.1f} | {over * 1e6:.1f} "
            f"| {over / total * 100:.1f} % | {f_over * 1e6:.1f} | {f_over / f_total * 100:.1f} % |"
        )
    lines += [
        "",
        f"Largest overhead: **{worst * 100:.1f} %** of a simulate() call (target < 10 %: "
        f"{'met' if worst < 0.10 else 'NOT met'}).",
        "",
    ]
    return lines


# ---------------------------------------------------------------------------------- fixed
def part_fixed(repeat: int) -> list[str]:
    """A one-scene sweep timed whole and as the core's call, against the run alone, each
    the best of ``300 * repeat`` tries taken in turn."""
    scene = cases.free_link(q_deg=45.0, v0=2.27)
    compiled = [scene._compiled()]
    todo: dict[str, Callable[[], object]] = {"run": lambda: None}
    for threads in (1, 2):
        todo[f"sweep {threads}"] = lambda t=threads: granrs.sweep(
            [scene], threads=t, progress=False
        )
        todo[f"core {threads}"] = lambda t=threads: _granrs.sweep(scenes=compiled, threads=t)
    best = dict.fromkeys(todo, math.inf)
    for _ in range(300 * repeat):
        for name, fn in todo.items():
            if name == "run":
                best[name] = min(best[name], _granrs.run(compiled[0]).run_seconds)
                continue
            t0 = time.perf_counter()
            fn()
            best[name] = min(best[name], time.perf_counter() - t0)
    run = best["run"]
    lines = ["### A sweep's fixed cost (one scene: free link q = 45, v0 = 2.27)", ""]
    lines += [
        f"The run alone, as the core times it: {run * 1e6:.1f} us (best of {300 * repeat}).",
        "",
        "| threads | sweep() [us] | the core's call [us] | fixed cost of sweep() [us] "
        "| of which the DataFrame and checks [us] | fixed cost / the run |",
        "|---|---|---|---|---|---|",
    ]
    for threads in (1, 2):
        whole, core = best[f"sweep {threads}"], best[f"core {threads}"]
        lines.append(
            f"| {threads} | {whole * 1e6:.0f} | {core * 1e6:.0f} | {(whole - run) * 1e6:.0f} "
            f"| {(whole - core) * 1e6:.0f} | {(whole - run) / run:.1f} |"
        )
    return [*lines, ""]


# ---------------------------------------------------------------------------------- axis
def part_axis(repeat: int, n: int = 40_000) -> list[str]:
    """Validation of a sweep of ``n`` runs before it starts: one axis of ``n`` values, and
    a product of two axes of the same size, each the median of ``repeat`` tries."""
    from granrs.batch import _axis_sweep, _threads

    scene = cases.free_link(q_deg=0.0, v0=2.0)
    n_q = 100
    shapes = {
        f"one axis of {n:,} values": {"v0": list(np.linspace(0.5, 5.0, n))},
        f"{n // n_q} x {n_q} product": {
            "v0": list(np.linspace(0.5, 5.0, n // n_q)),
            "q_deg": list(np.linspace(-85.0, 85.0, n_q)),
        },
    }

    def validate(axes: dict[str, list[float]]) -> None:
        kwargs, _ = _axis_sweep(scene, axes)
        _granrs.validate_sweep(**kwargs, threads=_threads(None))

    lines = [
        f"### A sweep's validation before its first run ({n:,} runs, median of {repeat})",
        "",
        "| axes | validation [s] | target |",
        "|---|---|---|",
    ]
    for label, axes in shapes.items():
        seconds = _median_time(lambda a=axes: validate(a), repeat)
        lines.append(f"| {label} | {seconds:.3f} | < 1 s: {'met' if seconds < 1 else 'MISSED'} |")
    return [*lines, ""]


# ---------------------------------------------------------------------------------- lanes
def part_lanes(repeat: int) -> list[str]:
    """1000 free links on one thread under each sign model the lanes cover, and under
    ``rft``, dynamic RFT and ``poncelet``, lanes and scalar path in turn, best of
    ``repeat``."""
    from granrs import forces

    axes = {"q_deg": np.linspace(0.0, 75.0, 40), "v0": np.linspace(0.5, 4.0, 25)}
    base = cases.free_link(q_deg=0.0, v0=2.0)
    laws = {m: base.replace(sign_model=m) for m in ("modes", "raw", "smooth")}
    g = forces.gravity()
    laws["rft (modes)"] = base.replace(forces=[g, forces.rft(zeta=1e6)])
    laws["rft + rft_inertial"] = base.replace(
        forces=[g, forces.rft(zeta=1e6), forces.rft_inertial()]
    )
    laws["poncelet"] = base.replace(forces=[g, forces.poncelet(c=0.8, k=150.0)])
    # Three laws in one sweep, each law's scenes together (as a calibration's vectors):
    # the lanes run one frame law at a time, so a scene waits for them to drain.
    grid = [(float(q), float(v)) for q in axes["q_deg"][::4] for v in axes["v0"][::3]]
    mixed = [
        base.replace(forces=law, q_deg=q, v0=v)
        for law in (laws["rft (modes)"].forces, laws["poncelet"].forces, base.forces)
        for q, v in grid
    ]
    mixed_name = f"rft, poncelet, thesis ({len(mixed)} in 3 blocks)"
    # `rft` with a zeta per scene: the lanes share its terms and element count only.
    zetas = np.linspace(3e5, 3e6, len(grid))
    swept = [
        base.replace(forces=[g, forces.rft(zeta=float(z))], q_deg=q, v0=v)
        for z, (q, v) in zip(zetas, grid, strict=True)
    ]
    swept_name = f"rft, a zeta per scene ({len(swept)})"
    lists = {mixed_name: mixed, swept_name: swept}
    best = {(m, lanes): math.inf for m in (*laws, *lists) for lanes in (True, False)}
    for _ in range(repeat):
        for m, lanes in best:
            t0 = time.perf_counter()
            if m in lists:
                granrs.sweep(lists[m], lanes=lanes, threads=1, progress=False)
            else:
                granrs.sweep(laws[m], lanes=lanes, threads=1, progress=False, **axes)
            best[(m, lanes)] = min(best[(m, lanes)], time.perf_counter() - t0)
    lines = [
        "### SIMD lanes against the scalar path (1000 free links, one thread)",
        "",
        "| law | lanes [ms] | scalar path [ms] | lanes / scalar |",
        "|---|---|---|---|",
    ]
    for m in (*laws, *lists):
        on, off = best[(m, True)], best[(m, False)]
        lines.append(f"| {m} | {on * 1e3:.1f} | {off * 1e3:.1f} | {on / off:.3f} |")
    return [
        *lines,
        "",
        f"Best of {repeat}; a sweep's ms are its us per impact (the last two rows': per "
        f"{len(mixed)} and {len(swept)} impacts).",
        "",
    ]


# ---------------------------------------------------------------------------------- prune
def part_prune(repeat: int) -> list[str]:
    base = cases.free_link(q_deg=0.0, v0=2.214)
    variants = {
        "every effect, every series recorded": base.replace(record=("state", "forces", "energy")),
        "every effect, summary only": base,
        "gravity + static_v, summary only": base.replace(
            forces=select(thesis(), *("gravity", "static_v"))
        ),
        "gravity + static_v, every series": base.replace(
            forces=select(thesis(), *("gravity", "static_v")), record=("state", "forces", "energy")
        ),
    }
    n = 200
    results = {k: [] for k in variants}
    for _ in range(repeat):
        for name, scene in variants.items():
            results[name].append(
                _median_time(lambda s=scene: [granrs.simulate(s) for _ in range(n)], 1) / n
            )
    full = statistics.median(results["every effect, every series recorded"])
    depth = {k: granrs.simulate(s).depth for k, s in variants.items()}
    lines = [
        "### Effects and outputs: the vertical drop (v0 = 2.214 m/s, 10 kHz)",
        "",
        "| scene | per impact [us] | full / this | depth [mm] |",
        "|---|---|---|---|",
    ]
    for name in variants:
        t = statistics.median(results[name])
        lines.append(f"| {name} | {t * 1e6:.1f} | {full / t:.2f}x | {depth[name] * 1e3:.4f} |")
    lines.append("")
    return lines


# ---------------------------------------------------------------------------------- force
def _numpy_force(depth, q_deg, vx, vy, omega, c, length=0.19, dc=0.0127, rho=1650.0, g=9.81):
    q = np.radians(q_deg)
    s, co = np.sin(q), np.cos(q)
    d = np.maximum(depth, 0.0)
    li = np.minimum(d / co, length)
    vex = vx + 0.5 * li * omega * co
    vey = vy - 0.5 * li * omega * s
    k = c["eta_d"] * rho * dc * li * np.abs(s * vey - co * vex)
    fsh = -np.sign(vex) * c["eta_h"] * g * rho * dc * d**2
    fsv = -np.sign(vey) * c["eta_v"] * (d / length) ** c["lam"] * g * rho * math.pi / 4 * dc**2 * li
    return -k * vex + fsh, -k * vey + fsv


def part_force(repeat: int, n: int = 1_000_000) -> list[str]:
    rng = np.random.default_rng(1)
    depth = rng.uniform(0, 0.1, n)
    q = rng.uniform(-80, 80, n)
    vx, vy, om = rng.normal(0, 1, n), rng.normal(-1, 1, n), rng.normal(0, 5, n)
    c = {"eta_h": 5.5, "eta_d": 11.0, "eta_v": 53.0, "lam": 0.25}
    ours = _median_time(
        lambda: granrs.resistance_force(depth, q, vx, vy, om, coefficients=c), repeat
    )
    theirs = _median_time(lambda: _numpy_force(depth, q, vx, vy, om, c), repeat)
    f = granrs.resistance_force(depth, q, vx, vy, om, coefficients=c)
    fx, fy = _numpy_force(depth, q, vx, vy, om, c)
    err = max(np.max(np.abs(f.F_x - fx)), np.max(np.abs(f.F_y - fy)))
    return [
        f"### `resistance_force` on {n:,} states",
        "",
        "| implementation | time [ms] | per state [ns] |",
        "|---|---|---|",
        f"| granrs (Rust; both cores above 16k states) | {ours * 1e3:.1f} | {ours / n * 1e9:.1f} |",
        f"| the same equations in numpy | {theirs * 1e3:.1f} | {theirs / n * 1e9:.1f} |",
        "",
        f"numpy / granrs: **{theirs / ours:.1f}x**; largest difference {err:.2e} N.",
        "",
    ]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--part", action="append", choices=PARTS, help="parts to run (all)")
    parser.add_argument("--quick", action="store_true", help="10,000-impact sweep, fewer repeats")
    parser.add_argument("--runs", type=int, default=None, help="impacts in the sweep")
    parser.add_argument("--out", help="also write the Markdown report here")
    parser.add_argument("--child", nargs="+", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        _child(*args.child)
        return 0
    parts = args.part or list(PARTS)
    n = args.runs or (10_000 if args.quick else 100_000)
    repeat = 3 if args.quick else 7
    lines = [
        f"## granrs {granrs.__version__}: sweeps, overhead, effects (cpus: {os.cpu_count()})",
        "",
    ]
    for part in parts:
        if part == "sweep":
            lines += part_sweep(n)
        elif part == "overhead":
            lines += part_overhead(repeat)
        elif part == "prune":
            lines += part_prune(repeat)
        elif part == "fixed":
            lines += part_fixed(repeat)
        elif part == "lanes":
            lines += part_lanes(repeat)
        elif part == "axis":
            lines += part_axis(repeat)
        else:
            lines += part_force(repeat)
    print("\n".join(lines), flush=True)
    if args.out:
        with open(args.out, "w", encoding="utf-8") as fh:
            fh.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
