"""Benchmarks of granrs: accuracy against time (a work-precision diagram).

:func:`work_precision` runs the free link of chapter 3 at three angles with every
integrator setting worth comparing (RK4 with each sign model over a sweep of ``dt``;
Dormand-Prince 5(4) over a sweep of ``rtol``), compares each run with a reference run of
RK4 (``"modes"``) at a very small step, and writes a CSV, a log-log plot and a short
Markdown summary. ``benches/accuracy.py`` and ``granrs bench accuracy`` both call it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from ._files import replacing, write_text
from .api import simulate
from .cases import free_link
from .result import Result
from .scene import Scene

__all__ = ["SCENES", "work_precision"]


@dataclass(frozen=True)
class BenchScene:
    """One benchmark scene: a free link dropped at ``q_deg`` [deg] with speed ``v0`` [m/s]."""

    name: str
    q_deg: float
    v0: float


#: The benchmark's scenes (Table 3.4 coefficients, the default of :func:`free_link`).
SCENES: tuple[BenchScene, ...] = (
    BenchScene("vertical", 0.0, 2.214),
    BenchScene("45 deg", 45.0, 2.27),
    BenchScene("85 deg", 85.0, 2.257),
)
#: Latest end time of every run [s] (every impact stops within about 30 ms).
T_END = 0.2
#: Step of the reference runs [s] (RK4, ``"modes"``); quick mode uses the second.
REFERENCE_DT = 1e-7
REFERENCE_DT_QUICK = 1e-6
#: RK4 steps [s]; quick mode keeps those >= 1e-5.
DTS = (1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6)
DTS_QUICK = (1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5)
#: Sign models run with RK4.
SIGN_MODELS = ("modes", "raw", "smooth")
#: Dormand-Prince relative tolerances (``atol = rtol * ATOL_FACTOR``); quick mode to 1e-8.
RTOLS = tuple(10.0**-k for k in range(3, 13))
RTOLS_QUICK = tuple(10.0**-k for k in range(3, 9))
ATOL_FACTOR = 1e-3
#: The step whose errors the Markdown summary tabulates [s].
SUMMARY_DT = 1e-4

COLUMNS = [
    "scene",
    "q_deg",
    "v0",
    "method",
    "sign_model",
    "label",
    "dt",
    "rtol",
    "atol",
    "status",
    "failed",
    "error",
    "t_s",
    "depth",
    "t_s_ref",
    "depth_ref",
    "depth_rel_err",
    "t_s_abs_err",
    "time_s",
    "rhs_evals",
    "steps",
]


def _settings(quick: bool) -> list[dict[str, Any]]:
    """Every integrator setting of the sweep, as keyword arguments of :func:`free_link`."""
    settings: list[dict[str, Any]] = []
    for sign_model in SIGN_MODELS:
        for dt in DTS_QUICK if quick else DTS:
            settings.append({"method": "rk4", "sign_model": sign_model, "dt": dt})
    for rtol in RTOLS_QUICK if quick else RTOLS:
        settings.append({"method": "dopri5", "rtol": rtol, "atol": rtol * ATOL_FACTOR})
    return settings


def _label(setting: dict[str, Any]) -> str:
    """The plot's line a setting belongs to."""
    if setting["method"] == "rk4":
        return f"rk4 {setting['sign_model']}"
    return "dopri5"


def _timed(scene: Scene, repeats: int) -> tuple[Result, float]:
    """The run of ``scene`` and its wall-clock time [s], the minimum of ``repeats`` runs."""
    best = math.inf
    result = None
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        result = simulate(scene)
        best = min(best, time.perf_counter() - start)
    assert result is not None
    return result, best


def _finite(*values: float) -> bool:
    return all(isinstance(v, (int, float)) and math.isfinite(v) for v in values)


def _run_setting(
    bench: BenchScene, setting: dict[str, Any], ref: Result, repeats: int
) -> dict[str, Any]:
    """One row of the table: the setting's run compared with the reference."""
    row: dict[str, Any] = {
        "scene": bench.name,
        "q_deg": bench.q_deg,
        "v0": bench.v0,
        "method": setting["method"],
        "sign_model": setting.get("sign_model", ""),
        "label": _label(setting),
        "dt": setting.get("dt", math.nan),
        "rtol": setting.get("rtol", math.nan),
        "atol": setting.get("atol", math.nan),
        "status": "",
        "failed": True,
        "error": "",
        "t_s": math.nan,
        "depth": math.nan,
        "t_s_ref": ref.t_s,
        "depth_ref": ref.depth,
        "depth_rel_err": math.nan,
        "t_s_abs_err": math.nan,
        "time_s": math.nan,
        "rhs_evals": math.nan,
        "steps": math.nan,
    }
    try:
        scene = free_link(bench.q_deg, bench.v0, t_end=T_END, **setting)
        result, seconds = _timed(scene, repeats)
    except Exception as exc:  # a setting that raises is a failed setting, not a crash
        row["status"] = "raised"
        row["error"] = " ".join(f"{type(exc).__name__}: {exc}".split())
        return row
    t_s = float(result.t_s) if result.t_s is not None else math.nan
    depth = float(result.depth) if result.depth is not None else math.nan
    row.update(
        status=result.status,
        t_s=t_s,
        depth=depth,
        time_s=seconds,
        rhs_evals=result.summary.get("rhs_evals", math.nan),
        steps=result.summary.get("steps", math.nan),
    )
    if _finite(t_s, depth):
        row["depth_rel_err"] = abs(depth - ref.depth) / abs(ref.depth)
        row["t_s_abs_err"] = abs(t_s - ref.t_s)
    row["failed"] = result.status != "stopped" or not _finite(t_s, depth)
    if row["failed"] and not row["error"]:
        row["error"] = (
            f"status {result.status}" if result.status != "stopped" else "non-finite result"
        )
    return row


def _reference(bench: BenchScene, dt: float) -> Result:
    """The scene's reference run: RK4, ``"modes"``, at step ``dt``; it must stop."""
    ref = simulate(free_link(bench.q_deg, bench.v0, dt=dt, t_end=T_END, sign_model="modes"))
    if ref.status != "stopped" or not _finite(float(ref.t_s), float(ref.depth)):
        raise RuntimeError(f"reference run of {bench.name} did not stop: {ref!r}")
    return ref


def _failed_lines(df: pd.DataFrame) -> list[str]:
    """One line per failed setting."""
    lines = []
    for _, r in df[df["failed"]].iterrows():
        what = f"dt={r['dt']:g}" if r["method"] == "rk4" else f"rtol={r['rtol']:g}"
        lines.append(f"{r['scene']}: {r['label']} {what} ({r['error'] or r['status']})")
    return lines


def _plot(df: pd.DataFrame, scenes: Sequence[BenchScene], tmp: Path) -> None:
    """One log-log panel per scene: relative depth error against time per run, saved to
    ``tmp`` (the temporary file of :func:`granrs._files.replacing`)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5.0 * len(scenes), 4.6), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(scenes), squeeze=False)[0]
    labels = list(dict.fromkeys(df["label"]))
    markers = dict(zip(labels, "osD^v<>", strict=False))
    for ax, bench in zip(axes, scenes, strict=True):
        sub = df[df["scene"] == bench.name]
        for label in labels:
            ok = sub[(sub["label"] == label) & ~sub["failed"]]
            # in sweep order (coarse to fine); a zero error has no place on a log axis
            ok = ok[ok["depth_rel_err"] > 0]
            if len(ok):
                ax.loglog(
                    ok["time_s"] * 1e3,
                    ok["depth_rel_err"],
                    marker=markers.get(label, "o"),
                    label=label,
                )
        failed = sub[sub["failed"]]
        title = f"{bench.name} (q = {bench.q_deg:g} deg, v0 = {bench.v0:g} m/s)"
        if len(failed):
            title += f"\nfailed: {len(failed)} (see accuracy.md)"
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("time per run [ms]")
        ax.set_ylabel("relative depth error")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.savefig(tmp, dpi=110)


def _fmt(value: Any, spec: str = ".2e") -> str:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return str(value)
    return "n/a" if not math.isfinite(v) else format(v, spec)


def _markdown(df: pd.DataFrame, scenes: Sequence[BenchScene], ref_dt: float, t_end: float) -> str:
    """The summary: per scene, the errors at ``SUMMARY_DT`` and the dopri5 rows; failures."""
    lines = [
        "# Accuracy against time (free link, Table 3.4 coefficients)",
        "",
        f"Reference per scene: RK4, sign model `modes`, dt = {ref_dt:g} s; t_end = {t_end:g} s.",
        "Depth error is relative, t_s error absolute. Times are the minimum of the repeats;",
        "compare them as ratios (the machines are shared and noisy). Data: `accuracy.csv`,",
        "plot: `accuracy.png`.",
        "",
    ]
    header = "| setting | status | depth error (rel) | t_s error [s] | time [ms] | rhs evals |"
    rule = "|---|---|---|---|---|---|"
    for bench in scenes:
        sub = df[df["scene"] == bench.name]
        lines += [f"## {bench.name} (q = {bench.q_deg:g} deg, v0 = {bench.v0:g} m/s)", ""]
        ref = sub.iloc[0]
        lines += [
            f"Reference: t_s = {ref['t_s_ref'] * 1e3:.4f} ms, "
            f"depth = {ref['depth_ref'] * 1e3:.4f} mm.",
            "",
            header,
            rule,
        ]
        at = sub[(sub["method"] == "rk4") & (sub["dt"] == SUMMARY_DT)]
        rows = [(f"rk4 {r['sign_model']}, dt = {SUMMARY_DT:g}", r) for _, r in at.iterrows()]
        rows += [
            (f"dopri5, rtol = {r['rtol']:g}", r)
            for _, r in sub[sub["method"] == "dopri5"].iterrows()
        ]
        for name, r in rows:
            lines.append(
                f"| {name} | {r['status']} | {_fmt(r['depth_rel_err'])} | "
                f"{_fmt(r['t_s_abs_err'])} | {_fmt(r['time_s'] * 1e3, '.3f')} | "
                f"{_fmt(r['rhs_evals'], '.0f')} |"
            )
        lines.append("")
    failed = _failed_lines(df)
    lines += ["## Failed settings", ""]
    lines += [f"- {line}" for line in failed] if failed else ["None."]
    lines.append("")
    return "\n".join(lines)


def work_precision(
    out_dir: str | Path,
    quick: bool = False,
    repeats: int = 3,
    progress: bool = True,
) -> pd.DataFrame:
    """Run the accuracy-against-time benchmark and write its outputs to ``out_dir``.

    For each scene of :data:`SCENES` a reference run (RK4, ``"modes"``, dt =
    :data:`REFERENCE_DT`, or :data:`REFERENCE_DT_QUICK` when ``quick``) is compared with RK4
    for each sign model over :data:`DTS` and with dopri5 over :data:`RTOLS` (``quick``
    shortens both sweeps). Each row holds the relative depth error, the absolute stop-time
    error [s], the time per run [s] (minimum of ``repeats`` wall-clock runs), the number of
    right-hand-side evaluations and the status. A setting fails if it did not stop, gave a
    non-finite result or raised; failed settings are listed, not plotted.

    Writes ``accuracy.csv``, ``accuracy.png`` and ``accuracy.md`` in ``out_dir`` (created
    if needed) and returns the table.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    ref_dt = REFERENCE_DT_QUICK if quick else REFERENCE_DT
    settings = _settings(quick)
    rows: list[dict[str, Any]] = []
    for bench in SCENES:
        start = time.perf_counter()
        ref = _reference(bench, ref_dt)
        if progress:
            print(
                f"[bench] {bench.name}: reference dt={ref_dt:g} s: t_s={ref.t_s * 1e3:.4f} ms, "
                f"depth={ref.depth * 1e3:.4f} mm ({time.perf_counter() - start:.2f} s)",
                flush=True,
            )
        for i, setting in enumerate(settings, 1):
            row = _run_setting(bench, setting, ref, repeats)
            rows.append(row)
            if progress:
                what = f"dt={row['dt']:g}" if row["method"] == "rk4" else f"rtol={row['rtol']:g}"
                print(
                    f"[bench] {bench.name} {i}/{len(settings)} {row['label']} {what}: "
                    f"depth err {_fmt(row['depth_rel_err'])}, t_s err "
                    f"{_fmt(row['t_s_abs_err'])} s, {_fmt(row['time_s'] * 1e3, '.3f')} ms"
                    + (f"  FAILED ({row['error']})" if row["failed"] else ""),
                    flush=True,
                )
    df = pd.DataFrame(rows, columns=COLUMNS)
    with replacing(out / "accuracy.csv") as tmp:
        df.to_csv(tmp, index=False)
    with replacing(out / "accuracy.png") as tmp:
        _plot(df, SCENES, tmp)
    write_text(out / "accuracy.md", _markdown(df, SCENES, ref_dt, T_END))
    if progress:
        print(f"[bench] wrote {out / 'accuracy.csv'}, accuracy.png, accuracy.md", flush=True)
    return df
