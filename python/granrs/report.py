"""The reproduction report: run the thesis's cases and compare them with its tables.

:func:`reproduce` runs the chapters asked for, writes ``README.md`` (the report, Markdown)
and its PNG figures under ``figures/`` in an output directory, and returns the path of the
report. The command line ``granrs reproduce --out DIR`` calls it (see :mod:`granrs.cli`).

Chapters form a registry (:data:`CHAPTERS`): a chapter is a function that takes a
:class:`ReportContext`, runs its simulations through it, adds its figures and headline
numbers to it, and returns its Markdown text. :func:`register_chapter` adds one; the free
link (chapter 3), the chain (chapter 4) and the leg (chapter 5) are registered here.

Chapter 3 (the free link) compares granrs with:

* Table 3.1 (the experiments: mean and sd of five drops), with Table 3.4 coefficients and
  the force applied at the tip, as the thesis's CAD runs did (sec. 3.3.2);
* Table 3.5 (the thesis's own simulation), every row, with the relative error of eq. 3.21;
  and the same with the Table 3.2 closed-form coefficients;
* Tables 3.6 (forces) and 3.7 (energies) at the speeds of sec. 3.4 (``sweep_3_4``);
* Figs. 3.15-3.20 (depth and tip velocity against time) and 3.22-3.23 (depth and stopping
  time against the impact angle alpha).

Chapter 4 (the two-link chain) compares granrs with Table 4.2 (the experiments) per link at
two link masses (the thesis does not give it: solid steel, 0.0341 kg, and half of it), with
Tables 4.5-4.6 (the thesis's simulation and its errors), sweeps the link mass for the best
fit to the measured depths, asks whether the links stop together, sets the forces and
energies quoted in sec. 4.3 beside granrs's, and draws Figs. 4.7-4.16 and the pin force.

Chapter 5 (the leg) compares granrs with Table 5.1 (per subject and height, and the mean)
and the thesis's simulation (sec. 5.3.2), then runs a joint study (locked, free,
spring-dampers over a sweep of stiffness, the thesis's sole) to show which settings come
closest to the thesis and to the experiments, and draws Fig. 5.10.

Relative errors follow the thesis's eq. 3.21, epsilon = |reference - granrs| / |reference|,
the reference being the experiment or the thesis's table. Every granrs number in the report
is computed at run time; nothing is edited to fit. Reference numbers come from the shipped
tables (:mod:`granrs.data`), except the few the thesis gives only in its text (secs. 4.2.2,
4.3 and 5.2.2), which are constants here citing their section.

Writing is all-or-nothing: every simulation and figure is produced in memory first, then
the files are written to a temporary directory next to the output directory and moved into
place, so an error leaves no half-written report.
"""

from __future__ import annotations

import math
import os
import platform
import shutil
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np

from . import __version__, cases, data
from .api import simulate
from .coefficients import Coefficients
from .errors import InvalidParameterError, UnknownNameError
from .result import Result
from .scene import Scene

__all__ = [
    "CHAPTERS",
    "Chapter",
    "ChapterBuilder",
    "ReportContext",
    "register_chapter",
    "relative_error",
    "reproduce",
]

#: The file name of the report inside the output directory.
REPORT_NAME = "README.md"
#: The folder of the figures inside the output directory.
FIGURES_DIR = "figures"

ChapterBuilder = Callable[["ReportContext"], str]


@dataclass(frozen=True)
class Chapter:
    """A chapter of the report.

    Attributes:
        key: the name used to ask for it (``"3"``).
        title: its heading, e.g. ``"Chapter 3: the free link"``.
        build: the function that runs it and returns its Markdown (headings from ``##``).
    """

    key: str
    title: str
    build: ChapterBuilder


#: The chapters :func:`reproduce` knows, by key, in registration order.
CHAPTERS: dict[str, Chapter] = {}


def register_chapter(key: str, title: str) -> Callable[[ChapterBuilder], ChapterBuilder]:
    """Decorator: register ``build`` as the chapter ``key`` of the report."""

    def decorator(build: ChapterBuilder) -> ChapterBuilder:
        """Register ``build`` and return it unchanged."""
        if key in CHAPTERS:
            raise ValueError(f"chapter {key!r} is already registered")
        CHAPTERS[key] = Chapter(key=key, title=title, build=build)
        return build

    return decorator


@dataclass
class ReportContext:
    """What a chapter works with: the run settings, and where its outputs go.

    Attributes:
        dt: the integration step of every scene [s].
        progress: whether to print progress lines (to stderr).
        figures: PNG bytes by file name (relative to ``figures/``), filled by
            :meth:`add_figure`.
        headlines: one-line findings for the report's summary, filled by
            :meth:`add_headline`.
        runs: the number of simulations run so far.
        sim_seconds: wall time spent in :func:`granrs.simulate` [s].
        settings: every (sign model, point of application) pair that was run.
    """

    dt: float
    progress: bool = True
    figures: dict[str, bytes] = field(default_factory=dict)
    headlines: list[str] = field(default_factory=list)
    runs: int = 0
    sim_seconds: float = 0.0
    settings: set[tuple[str, str]] = field(default_factory=set)

    def log(self, message: str) -> None:
        """Print one progress line to stderr (nothing when ``progress`` is False)."""
        if self.progress:
            print(f"granrs reproduce: {message}", file=sys.stderr, flush=True)

    @contextmanager
    def step(self, label: str) -> Iterator[None]:
        """Time a step of a chapter and log ``label`` with its run count and duration."""
        runs, start = self.runs, time.perf_counter()
        yield
        n = self.runs - runs
        what = f"{n} run{'s' if n != 1 else ''}, " if n else ""
        self.log(f"{label} ({what}{time.perf_counter() - start:.2f} s)")

    def run(self, scene: Scene) -> Result:
        """Simulate ``scene`` and count it."""
        start = time.perf_counter()
        result = simulate(scene)
        self.sim_seconds += time.perf_counter() - start
        self.runs += 1
        self.settings.add((scene.sign_model, scene.apply_at))
        return result

    def free_link(self, q_deg: float, v0: float, **kwargs: Any) -> Result:
        """Run :func:`granrs.cases.free_link` at the context's ``dt``."""
        return self.run(cases.free_link(q_deg=q_deg, v0=v0, dt=self.dt, **kwargs))

    def chain(self, case: int, **kwargs: Any) -> Result:
        """Run :func:`granrs.cases.chain` case ``case`` at the context's ``dt``, until both
        links have stopped (``end="all_stops"`` unless ``kwargs`` says otherwise)."""
        kwargs.setdefault("end", "all_stops")
        return self.run(cases.chain(case=case, dt=self.dt, **kwargs))

    def leg(self, v0: float, **kwargs: Any) -> Result:
        """Run :func:`granrs.cases.leg` at ``v0`` [m/s] and the context's ``dt``."""
        return self.run(cases.leg(v0=v0, dt=self.dt, **kwargs))

    def add_figure(self, name: str, png: bytes, alt: str) -> str:
        """Keep the PNG ``png`` as ``figures/name``; return its Markdown image link."""
        if name in self.figures:
            raise ValueError(f"figure {name!r} was added twice")
        self.figures[name] = png
        self.log(f"figure {FIGURES_DIR}/{name}")
        return f"![{alt}]({FIGURES_DIR}/{name})"

    def add_headline(self, text: str) -> None:
        """Add a one-line finding to the report's summary."""
        self.headlines.append(text)


# --------------------------------------------------------------------------------------
# Numbers and Markdown
# --------------------------------------------------------------------------------------


def relative_error(reference: float, value: float) -> float:
    """The thesis's relative error (eq. 3.21): |reference - value| / |reference|.

    NaN when either is not finite or the reference is zero.
    """
    if not (math.isfinite(reference) and math.isfinite(value)) or reference == 0.0:
        return math.nan
    return abs(reference - value) / abs(reference)


def _median(values: Iterable[float]) -> tuple[float, int]:
    """Median of the finite values and their count (NaN, 0 when there are none)."""
    finite = [v for v in values if math.isfinite(v)]
    return (statistics.median(finite), len(finite)) if finite else (math.nan, 0)


def _fmt(value: float, spec: str, scale: float = 1.0) -> str:
    """``value * scale`` formatted with ``spec``; ``n/a`` for NaN or infinity."""
    if value is None or not math.isfinite(value):
        return "n/a"
    return format(value * scale, spec)


def _pct(value: float) -> str:
    """A fraction as a percentage with one decimal."""
    return _fmt(value, ".1f", 100.0)


def _pm(mean: float, sd: float, spec: str, scale: float = 1.0) -> str:
    """``mean ± sd``."""
    return f"{_fmt(mean, spec, scale)} ± {_fmt(sd, spec, scale)}"


def _cell(text: str) -> str:
    """Escape a Markdown table cell (pipes, newlines)."""
    return str(text).replace("|", "\\|").replace("\n", " ")


def md_table(header: Sequence[str], rows: Iterable[Sequence[str]], align: str = "") -> str:
    """A Markdown (GitHub) table; ``align`` holds one of ``l``/``r``/``c`` per column."""
    marks = {"l": ":--", "r": "--:", "c": ":-:"}
    align = align.ljust(len(header), "r")
    lines = [
        "| " + " | ".join(_cell(h) for h in header) + " |",
        "|" + "|".join(marks[a] for a in align) + "|",
    ]
    lines += ["| " + " | ".join(_cell(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def _median_sentence(label: str, values: Sequence[float]) -> str:
    """``label: **median %** (n = count)`` over the finite values."""
    median, n = _median(values)
    return f"{label}: **{_pct(median)} %** (n = {n})"


# --------------------------------------------------------------------------------------
# Chapter 3: the free link
# --------------------------------------------------------------------------------------

#: Table 3.1 angles shown in Figs. 3.15-3.20, with the thesis's figure numbers
#: (depth, velocity).
_FIGS_3_15_3_20: dict[float, tuple[str, str]] = {
    0.0: ("3.15", "3.16"),
    45.0: ("3.17", "3.18"),
    75.0: ("3.19", "3.20"),
}
#: Tables 3.6-3.7 list their speeds by nominal value; the runs use the sweep_3_4 speeds
#: (v01, v02, v03) at each angle.
_NOMINAL_TO_SWEEP: dict[float, str] = {2.24: "v01", 1.77: "v02", 1.15: "v03"}
_SWEEP_COLUMNS: tuple[str, ...] = ("v01", "v02", "v03")
#: Largest speed difference [m/s] at which a Table 3.5 row is taken as the thesis's run of a
#: Table 3.1 experiment (the thesis rounded its speeds, e.g. 1.19 for 1.264 +- 0.035 at 45 deg).
_MATCH_V0_TOL = 0.1
_RECORD = ("state", "forces")


def _rows(name: str) -> list[dict[str, Any]]:
    """The rows of a shipped table as dicts (numbers as float, text as str)."""
    frame = data.load(name, as_="numpy")
    columns = list(frame)
    n = len(frame[columns[0]]) if columns else 0
    return [
        {c: v.item() if isinstance(v, np.generic) else v for c in columns for v in [frame[c][i]]}
        for i in range(n)
    ]


def _table_3_4_row(result: Result) -> str:
    """The coefficient source of a run, shortened for a table cell."""
    return result.scene.coefficients_source.removeprefix("Table 3.4, ")


def _thesis_match(
    thesis_rows: Sequence[dict[str, Any]], q: float, v0: float
) -> dict[str, Any] | None:
    """The Table 3.5 row at angle q whose speed is nearest v0 (within _MATCH_V0_TOL)."""
    candidates = [r for r in thesis_rows if r["q_deg"] == q]
    if not candidates:
        return None
    best = min(candidates, key=lambda r: abs(r["v0"] - v0))
    return best if abs(best["v0"] - v0) <= _MATCH_V0_TOL else None


def _status_note(result: Result) -> str:
    """`` (status)`` for a run that did not stop, else empty."""
    return "" if result.stopped else f" ({result.status})"


def _ch3_table_3_1(ctx: ReportContext) -> tuple[str, list[tuple[dict[str, Any], Result]]]:
    """Table 3.1 (experiments) against granrs; also the thesis's own Table 3.5 errors."""
    experiments = _rows("table_3_1")
    thesis_rows = _rows("table_3_5")
    runs: list[tuple[dict[str, Any], Result]] = []
    with ctx.step("chapter 3: Table 3.1 (experiments) vs granrs"):
        for row in experiments:
            result = ctx.free_link(row["q_deg"], row["v0_mean"], record=_RECORD)
            runs.append((row, result))

    table = []
    eps_t, eps_d, signed_t, thesis_eps_t, thesis_eps_d = [], [], [], [], []
    for row, r in runs:
        e_t = relative_error(row["t_s_mean"], r.t_s)
        e_d = relative_error(row["depth_mean"], r.depth)
        eps_t.append(e_t)
        eps_d.append(e_d)
        signed_t.append((r.t_s - row["t_s_mean"]) / row["t_s_mean"])
        match = _thesis_match(thesis_rows, row["q_deg"], row["v0_mean"])
        if match is not None:
            thesis_eps_t.append(relative_error(row["t_s_mean"], match["t_s"]))
            thesis_eps_d.append(relative_error(row["depth_mean"], match["depth"]))
        table.append(
            [
                f"{row['q_deg']:g}",
                _pm(row["v0_mean"], row["v0_sd"], ".3f"),
                _table_3_4_row(r),
                _pm(row["t_s_mean"], row["t_s_sd"], ".0f", 1e3),
                _fmt(r.t_s, ".1f", 1e3) + _status_note(r),
                _pct(e_t),
                _fmt((r.t_s - row["t_s_mean"]) / row["t_s_sd"], "+.1f"),
                _pm(row["depth_mean"], row["depth_sd"], ".0f", 1e3),
                _fmt(r.depth, ".1f", 1e3),
                _pct(e_d),
                _fmt((r.depth - row["depth_mean"]) / row["depth_sd"], "+.1f"),
            ]
        )
    header = [
        "q [deg]",
        "v0 [m/s] (exp. mean ± sd)",
        "Table 3.4 row used",
        "t_s exp. [ms]",
        "t_s granrs [ms]",
        "ε t_s [%]",
        "Δt_s / sd",
        "depth exp. [mm]",
        "depth granrs [mm]",
        "ε depth [%]",
        "Δdepth / sd",
    ]
    med_d, _ = _median(eps_d)
    med_t, n_t = _median(eps_t)
    med_signed, _ = _median(signed_t)
    earlier = sum(1 for s in signed_t if math.isfinite(s) and s < 0)
    th_d, n_th = _median(thesis_eps_d)
    th_t, _ = _median(thesis_eps_t)
    n_rows = len(runs)
    ctx.add_headline(
        f"Depth vs the experiments (Table 3.1, {n_rows} drops): median relative error "
        f"{_pct(med_d)} % (granrs, Table 3.4 coefficients at the tip); the thesis's own "
        f"simulation: {_pct(th_d)} % (n = {n_th})."
    )
    ctx.add_headline(
        f"**Known gap: stopping times.** The thesis itself says its simulated stopping times "
        f"do not match the experiments (sec. 3.3.2, Figs. 3.15-3.20). granrs has the same "
        f"gap: median relative t_s error vs Table 3.1 **{_pct(med_t)} %** (n = {n_t}); "
        f"granrs stops earlier than the experiment in {earlier} of {n_t} drops (median "
        f"signed error {_fmt(med_signed, '+.1f', 100.0)} %). The thesis's own Table 3.5 "
        f"t_s are off by a median {_pct(th_t)} % (n = {n_th})."
    )
    text = f"""### Table 3.1: the experiments against granrs

Each row of Table 3.1 (mean and sd of five drops, sec. 3.2.2) simulated at the measured mean
speed and angle, with the Table 3.4 coefficients of the nearest tabulated angle (the column
"Table 3.4 row used"; q = 60 deg, halfway between rows, takes the 65 deg row) and the force
applied at the tip. ε is eq. 3.21 with the experiment as reference; Δ/sd is
(granrs - experiment mean) / experiment sd.

{md_table(header, table, "rrl")}

- {_median_sentence("Median relative depth error vs Table 3.1 (eq. 3.21)", eps_d)}
- {_median_sentence("Median relative t_s error vs Table 3.1", eps_t)}; granrs stops earlier
  than the experiment in {earlier} of {n_t} drops.
- For comparison, the thesis's own simulation (Table 3.5 rows at the same angle and within
  {_MATCH_V0_TOL} m/s of the experiment's speed, n = {n_th}): median relative depth error
  **{_pct(th_d)} %**, median relative t_s error **{_pct(th_t)} %**.
"""
    return text, runs


def _ch3_table_3_5(ctx: ReportContext) -> str:
    """Table 3.5 (the thesis's simulation) against granrs, with Table 3.4 and Table 3.2."""
    thesis_rows = _rows("table_3_5")
    runs: dict[str, list[Result]] = {"table_3_4": [], "table_3_2": []}
    for coefficients, results in runs.items():
        label = coefficients.replace("table_", "Table ").replace("_", ".")
        with ctx.step(f"chapter 3: Table 3.5 (thesis simulation), {label} coefficients"):
            for row in thesis_rows:
                results.append(ctx.free_link(row["q_deg"], row["v0"], coefficients=coefficients))

    def errors(results: Sequence[Result]) -> tuple[list[float], list[float]]:
        """Relative depth and t_s errors (eq. 3.21) of ``results`` vs Table 3.5, per row."""
        pairs = list(zip(thesis_rows, results, strict=True))
        e_d = [relative_error(row["depth"], r.depth) for row, r in pairs]
        e_t = [relative_error(row["t_s"], r.t_s) for row, r in pairs]
        return e_d, e_t

    clean = [not row["note"] for row in thesis_rows]

    def clean_median(values: Sequence[float]) -> tuple[float, int]:
        """Median over the rows without a note."""
        return _median(e for e, ok in zip(values, clean, strict=True) if ok)

    table = []
    eps_d, eps_t = errors(runs["table_3_4"])
    for row, r, e_d, e_t in zip(thesis_rows, runs["table_3_4"], eps_d, eps_t, strict=True):
        table.append(
            [
                f"{row['q_deg']:g}",
                f"{row['v0']:.3f}",
                _fmt(row["t_s"], ".0f", 1e3),
                _fmt(r.t_s, ".1f", 1e3) + _status_note(r),
                _pct(e_t),
                _fmt(row["depth"], ".1f", 1e3),
                _fmt(r.depth, ".1f", 1e3),
                _pct(e_d),
                _table_3_4_row(r),
                row["note"],
            ]
        )
    header = [
        "q [deg]",
        "v0 [m/s]",
        "t_s thesis [ms]",
        "t_s granrs [ms]",
        "ε t_s [%]",
        "depth thesis [mm]",
        "depth granrs [mm]",
        "ε depth [%]",
        "Table 3.4 row used",
        "note (doubtful source row)",
    ]
    med_clean, n_clean = clean_median(eps_d)
    med_all, n_all = _median(eps_d)
    med_t_clean, _ = clean_median(eps_t)

    variant_rows = []
    for coefficients, label in (
        ("table_3_4", "Table 3.4 (hand-tuned values; as above)"),
        ("table_3_2", "Table 3.2 (closed forms at q, rho_g = 1650 kg/m³)"),
    ):
        variant_d, variant_t = errors(runs[coefficients])
        variant_rows.append(
            [
                label,
                _pct(clean_median(variant_d)[0]),
                _pct(_median(variant_d)[0]),
                _pct(clean_median(variant_t)[0]),
                _pct(_median(variant_t)[0]),
            ]
        )
    variant_header = [
        "coefficients",
        "median ε depth, rows without a note [%]",
        "median ε depth, all rows [%]",
        "median ε t_s, rows without a note [%]",
        "median ε t_s, all rows [%]",
    ]
    e32_clean, _ = clean_median(errors(runs["table_3_2"])[0])
    ctx.add_headline(
        f"Depth vs the thesis's simulation (Table 3.5, {n_all} rows): median relative error "
        f"{_pct(med_clean)} % over the {n_clean} rows without a note, {_pct(med_all)} % over "
        f"all rows (Table 3.4 coefficients); {_pct(e32_clean)} % without a note with the "
        f"Table 3.2 closed forms."
    )
    worst = sorted(
        (pair for pair in zip(eps_d, thesis_rows, strict=True) if pair[0] > 0.1),
        key=lambda pair: -pair[0],
    )
    worst_text = (
        "; ".join(
            f"q = {row['q_deg']:g}°, v0 = {row['v0']:.3f} m/s: {_pct(e)} %"
            + (" (doubtful row)" if row["note"] else "")
            for e, row in worst
        )
        or "none"
    )
    median_line = (
        f"**Median relative depth error (eq. 3.21) vs Table 3.5: {_pct(med_clean)} % over the "
        f"{n_clean} rows without a note; {_pct(med_all)} % over all {n_all} rows.**"
    )
    return f"""### Table 3.5: the thesis's simulation against granrs

Every row of Table 3.5 (the thesis's CAD runs at 10 kHz), including the ones whose source is
doubtful (a non-empty note; they are shown, and counted separately in the medians). granrs
uses the Table 3.4 coefficients of the nearest tabulated angle and the force at the tip.
ε is eq. 3.21 with the thesis's value as reference.

{md_table(header, table, "rrrrrrrrll")}

{median_line}

Median relative t_s error over the rows without a note: {_pct(med_t_clean)} %.

Rows with a depth error above 10 %: {worst_text}.

#### Table 3.2 variant (closed-form coefficients instead of Table 3.4)

The same {n_all} rows with the coefficients of the thesis's Table 3.2 closed forms evaluated
at each angle (instead of the hand-tuned Table 3.4 values), for comparison:

{md_table(variant_header, variant_rows, "lrrrr")}
"""


def _ch3_sweep(ctx: ReportContext) -> dict[tuple[float, str], Result]:
    """The sec. 3.4 sweep: 10 angles x 3 speeds (sweep_3_4), Table 3.4 coefficients."""
    runs: dict[tuple[float, str], Result] = {}
    with ctx.step("chapter 3: sec. 3.4 sweep (10 angles x 3 speeds)"):
        for row in _rows("sweep_3_4"):
            for column in _SWEEP_COLUMNS:
                runs[(row["q_deg"], column)] = ctx.free_link(row["q_deg"], row[column])
    return runs


def _sweep_result(
    sweep: Mapping[tuple[float, str], Result], q: float, nominal: float
) -> Result | None:
    """The sweep run at angle q for a Table 3.6/3.7 nominal speed (None if there is none)."""
    column = _NOMINAL_TO_SWEEP.get(round(nominal, 2))
    return None if column is None else sweep.get((q, column))


def _ch3_side_by_side(
    sweep: Mapping[tuple[float, str], Result],
    table: str,
    quantities: Sequence[tuple[str, str, str, str, str]],
) -> tuple[str, str]:
    """A thesis table (3.6 or 3.7) and granrs side by side; returns (table, medians).

    ``quantities`` holds (thesis column, granrs summary key, name, unit, format) per
    quantity.
    """
    rows = _rows(table)
    body = []
    errs: dict[str, list[float]] = {name: [] for _, _, name, _, _ in quantities}
    for row in rows:
        r = _sweep_result(sweep, row["q_deg"], row["v0_nominal"])
        cells = [f"{row['q_deg']:g}", f"{row['v0_nominal']:.2f}"]
        cells.append("n/a" if r is None else f"{r.scene.v0:.2f}" + _status_note(r))
        for column, key, name, _, spec in quantities:
            value = math.nan if r is None else float(r.summary[key])
            e = relative_error(row[column], value)
            errs[name].append(e)
            cells += [_fmt(row[column], spec), _fmt(value, spec), _pct(e)]
        body.append(cells)
    header = ["q [deg]", "v0 nominal [m/s]", "v0 run [m/s]"]
    for _, _, name, unit, _ in quantities:
        header += [f"{name} thesis [{unit}]", f"{name} granrs [{unit}]", f"ε {name} [%]"]
    medians = "\n".join(
        f"- {_median_sentence(f'Median relative error of {name}', e)}" for name, e in errs.items()
    )
    return md_table(header, body), medians


def _ch3_tables_3_6_3_7(ctx: ReportContext, sweep: Mapping[tuple[float, str], Result]) -> str:
    """Tables 3.6 (forces) and 3.7 (energies) against granrs."""
    with ctx.step("chapter 3: Tables 3.6 and 3.7"):
        forces, forces_median = _ch3_side_by_side(
            sweep,
            "table_3_6",
            [
                ("F_d_max_N", "F_d_max", "F_d,max", "N", ".2f"),
                ("F_s_end_N", "F_s_end", "F_s,end", "N", ".2f"),
                ("F_r_end_N", "F_r_end", "F_r,end", "N", ".2f"),
            ],
        )
        energy, energy_median = _ch3_side_by_side(
            sweep,
            "table_3_7",
            [
                ("dKE_J", "dKE", "ΔKE", "J", ".3f"),
                ("dPE_J", "dPE", "ΔPE", "J", ".3f"),
                ("dE_J", "dE", "ΔE", "J", ".3f"),
            ],
        )
    return f"""### Table 3.6: resistance forces

The thesis lists its speeds by nominal value (2.24, 1.77, 1.15 m/s); granrs runs each angle
at the speeds of sec. 3.4 (v01, v02, v03 of `sweep_3_4`, column "v0 run"), Table 3.4
coefficients, force at the tip. F_d,max is the largest |F_d| (eq. 3.23) during the
penetration phase, F_s,end and F_r,end the static and total force (eq. 3.24) at the stop.
ε is eq. 3.21 with the thesis's value as reference (n/a where the thesis's value is zero);
relative errors of small values are large by construction.

{forces}

{forces_median}

### Table 3.7: energy

ΔKE, ΔPE and ΔE = ΔKE + ΔPE from the first contact to the stop (eqs. 3.25-3.26), positive
when lost, as in the thesis.

{energy}

{energy_median}
"""


def _ch3_figs_3_15_3_20(
    ctx: ReportContext, runs_3_1: Sequence[tuple[dict[str, Any], Result]]
) -> str:
    """Figs. 3.15-3.20: depth and tip velocity against time at q = 0, 45, 75 deg."""
    from . import plots

    thesis_rows = _rows("table_3_5")
    links = []
    with ctx.step("chapter 3: Figs. 3.15-3.20"):
        for q, numbers in _FIGS_3_15_3_20.items():
            curves = []
            for row, r in sorted(
                ((row, r) for row, r in runs_3_1 if row["q_deg"] == q),
                key=lambda item: -item[0]["v0_mean"],
            ):
                if r.series is None:  # pragma: no cover - recorded above
                    raise RuntimeError("Table 3.1 runs must record their series")
                match = _thesis_match(thesis_rows, q, row["v0_mean"])
                curves.append(
                    plots.SpeedCurve(
                        v0=row["v0_mean"],
                        t=r.series["t"],
                        depth=r.series["depth"],
                        v_tip_y=r.series["v_tip_y"],
                        experiment=plots.EndPoint(
                            row["t_s_mean"], row["depth_mean"], row["t_s_sd"], row["depth_sd"]
                        ),
                        thesis=None
                        if match is None
                        else plots.EndPoint(match["t_s"], match["depth"]),
                    )
                )
            fig = plots.impact_figure(q, curves, numbers)
            links.append(
                ctx.add_figure(
                    f"fig_{numbers[0].replace('.', '_')}_{numbers[1].replace('.', '_')}_q{q:g}.png",
                    plots.png_bytes(fig),
                    f"Fig. {numbers[0]} (depth) and Fig. {numbers[1]} (tip velocity) at "
                    f"q = {q:g} deg",
                )
                + f"\n\n*Left: Fig. {numbers[0]}, tip depth against time; right: Fig. "
                f"{numbers[1]}, downward tip velocity against time; q = {q:g} deg.*"
            )
    figures = "\n\n".join(links)
    return f"""### Figs. 3.15-3.20: depth and tip velocity against time

granrs curves (Table 3.4 coefficients, force at the tip) at the Table 3.1 speeds for
q = 0, 45 and 75 deg; filled circles: the experiments' end points (Table 3.1: t_s and depth,
mean ± sd of five drops; on the velocity panel at zero velocity, with the t_s sd as the
horizontal bar); hollow squares: the thesis's simulated end points (Table 3.5, the row within
{_MATCH_V0_TOL} m/s of the experiment's speed; at q = 45 deg the 1.88 m/s row is missing in
the source). The thesis's own curves are not reproduced (its figures are images).

{figures}
"""


def _ch3_figs_3_22_3_23(ctx: ReportContext, sweep: Mapping[tuple[float, str], Result]) -> str:
    """Figs. 3.22-3.23: depth and stopping time against alpha for the three speeds."""
    from . import plots

    sweep_rows = _rows("sweep_3_4")
    thesis_rows = _rows("table_3_5")
    sweep_by_q = {row["q_deg"]: row for row in sweep_rows}
    links = []
    with ctx.step("chapter 3: Figs. 3.22-3.23"):
        for number, key, quantity, title in (
            ("3.22", "depth", "tip depth at the stop d", "penetration depth"),
            ("3.23", "t_s", "stopping time t_s", "stopping time"),
        ):
            series = []
            for column in _SWEEP_COLUMNS:
                speeds = [row[column] for row in sweep_rows]
                series.append(
                    plots.AlphaSeries(
                        label=f"granrs, {column} = {min(speeds):.2f}-{max(speeds):.2f} m/s",
                        alpha_deg=np.array([row["alpha_deg"] for row in sweep_rows]),
                        values=np.array(
                            [getattr(sweep[(row["q_deg"], column)], key) for row in sweep_rows]
                        ),
                    )
                )
            points = []
            for row in thesis_rows:
                srow = sweep_by_q.get(row["q_deg"])
                index = None
                if srow is not None:
                    index = min(
                        range(len(_SWEEP_COLUMNS)),
                        key=lambda i: abs(srow[_SWEEP_COLUMNS[i]] - row["v0"]),
                    )
                points.append(
                    plots.AlphaPoint(
                        alpha_deg=90.0 - row["q_deg"],
                        value=row[key],
                        series=index,
                        doubtful=bool(row["note"]),
                    )
                )
            fig = plots.alpha_figure(
                series,
                points,
                quantity=quantity,
                unit_scale=1e3,
                unit="mm" if key == "depth" else "ms",
                title=f"Fig. {number}: {title} against the impact angle",
                other_label="thesis, q = 60° (Table 3.1 speeds, not in sec. 3.4)",
            )
            links.append(
                ctx.add_figure(
                    f"fig_{number.replace('.', '_')}_{key}_vs_alpha.png",
                    plots.png_bytes(fig),
                    f"Fig. {number}: {title} against alpha",
                )
            )
    figures = "\n\n".join(links)
    return f"""### Figs. 3.22-3.23: depth and stopping time against the impact angle

granrs at the ten angles and three speeds of sec. 3.4 (lines; the colour is the speed), the
thesis's Table 3.5 values as diamonds in the colour of the nearest speed (hollow: a row
with a note; grey triangles: the q = 60 deg rows, run at the Table 3.1 speeds).

{figures}
"""


@register_chapter("3", "Chapter 3: the free link")
def chapter_3(ctx: ReportContext) -> str:
    """Chapter 3: the free link against Tables 3.1 and 3.5-3.7 and Figs. 3.15-3.23."""
    table_3_1, runs_3_1 = _ch3_table_3_1(ctx)
    table_3_5 = _ch3_table_3_5(ctx)
    sweep = _ch3_sweep(ctx)
    tables_3_6_3_7 = _ch3_tables_3_6_3_7(ctx, sweep)
    figs_3_15 = _ch3_figs_3_15_3_20(ctx, runs_3_1)
    figs_3_22 = _ch3_figs_3_22_3_23(ctx, sweep)
    return "\n".join(
        [
            "The thesis's steel rod (L = 0.190 m, d_c = 0.0127 m, m = 0.184 kg; sand "
            "rho_g = 1650 kg/m³) dropped tip first at an angle q from the vertical "
            "(alpha = 90° - q from the horizontal), moving straight down at v0.",
            "",
            table_3_1,
            table_3_5,
            tables_3_6_3_7,
            figs_3_15,
            figs_3_22,
        ]
    )


# --------------------------------------------------------------------------------------
# Chapter 4: the two-link chain
# --------------------------------------------------------------------------------------

_CHAIN_CASES: tuple[int, ...] = (1, 2, 3)
_CHAIN_LINKS: tuple[int, ...] = (1, 2)
#: The link masses reported side by side [kg], with what each stands for. The thesis does
#: not give the mass: the granrs default is a solid steel link of the stated size
#: (``cases.CHAIN``, ``bodies.csv``); the other is half of it.
_CHAIN_MASSES: tuple[tuple[float, str], ...] = (
    (cases.CHAIN["mass"], "solid steel, the granrs default"),
    (0.017, "half the solid-steel mass"),
)
#: The coarse link-mass sweep [kg]; then a fine one of :data:`_MASS_FINE_POINTS` masses
#: within one coarse step of the coarse best.
_MASS_SWEEP: tuple[float, ...] = tuple(round(float(m), 6) for m in np.linspace(0.010, 0.040, 13))
_MASS_FINE_POINTS = 11
_CHAIN_RECORD = ("state", "forces", "energy")

#: Numbers quoted in the text of sec. 4.3 (no table holds them; also listed in the data's
#: PROVENANCE.md): the largest |F_d| per (link, case) (Fig. 4.9 text) and |F_s| at the stop
#: (Fig. 4.10 text) [N]; the total energy dissipated per case (Fig. 4.15 text) [J].
_THESIS_FD_MAX: dict[tuple[int, int], float] = {
    (1, 1): 3.5,
    (1, 2): 3.25,
    (1, 3): 1.4,
    (2, 1): 2.5,
    (2, 2): 1.7,
    (2, 3): 0.85,
}
_THESIS_FS_END: dict[tuple[int, int], float] = {
    (1, 1): 3.1,
    (1, 2): 2.8,
    (1, 3): 2.6,
    (2, 1): 4.0,
    (2, 2): 3.7,
    (2, 3): 2.8,
}
_THESIS_DE: dict[int, float] = {1: 0.24, 2: 0.18, 3: 0.10}
#: The measured entry offsets Delta t(0) = t1(0) - t2(0) of sec. 4.2.2 [s], by case.
_THESIS_ENTRY_OFFSET: dict[int, float] = {1: 0.0013, 2: 0.0005, 3: 0.0003}

ChainRuns = Mapping[int, Result]


def _rms(values: Iterable[float]) -> tuple[float, int]:
    """Root mean square of the finite values and their count (NaN, 0 when there are none)."""
    finite = [v for v in values if math.isfinite(v)]
    if not finite:
        return math.nan, 0
    return math.sqrt(sum(v * v for v in finite) / len(finite)), len(finite)


def _link_case(row: Mapping[str, Any]) -> tuple[int, int]:
    """(link, case) of a chapter 4 table row."""
    return int(row["link"]), int(row["v0_case"])


def _link_stop(result: Result, link: int) -> tuple[float, float]:
    """Link ``link``'s (1 or 2) stopping time [s] and tip depth at its stop [m].

    The thesis counts each link's impact from the moment its own tip is at the surface
    (sec. 4.2.2); a granrs contact's ``t_s`` counts from the start of the run (the first
    tip's entry), so the link's entry time is subtracted. NaN time if the link did not stop.
    """
    contact = result.contacts[link - 1]
    t_s = contact.t_s - float(contact.summary["t_entry"]) if contact.stopped else math.nan
    return t_s, contact.depth


def _link_note(result: Result, link: int) -> str:
    """`` (not stopped)`` for a link that did not stop, else empty."""
    return "" if result.contacts[link - 1].stopped else " (not stopped)"


def _chain_errors(
    experiments: Sequence[Mapping[str, Any]], runs: ChainRuns
) -> tuple[list[float], list[float]]:
    """Relative depth (eq. 4.8) and t_s errors vs Table 4.2, one per link-case row."""
    e_d, e_t = [], []
    for row in experiments:
        link, case = _link_case(row)
        t_s, depth = _link_stop(runs[case], link)
        stopped = runs[case].contacts[link - 1].stopped
        e_d.append(relative_error(row["depth_mean"], depth) if stopped else math.nan)
        e_t.append(relative_error(row["t_s_mean"], t_s))
    return e_d, e_t


def _chain_depth_rms(experiments: Sequence[Mapping[str, Any]], runs: ChainRuns) -> float:
    """RMS relative depth error over every link-case; infinite if a link did not stop."""
    e_d, _ = _chain_errors(experiments, runs)
    rms, n = _rms(e_d)
    return rms if n == len(experiments) else math.inf


def _chain_energy(result: Result) -> float:
    """Energy the two links lost, each from the start to its own stop (eqs. 4.9-4.10) [J]."""
    return sum(float(c.summary["link_dE"]) for c in result.contacts)


def _chain_energy_rms(runs: ChainRuns) -> float:
    """RMS relative error of the links' total energy lost vs the sec. 4.3 numbers."""
    rms, n = _rms(relative_error(_THESIS_DE[c], _chain_energy(runs[c])) for c in _CHAIN_CASES)
    return rms if n == len(_CHAIN_CASES) else math.inf


def _grams(mass: float) -> str:
    """A mass [kg] in grams for the text."""
    return f"{mass * 1e3:.1f} g"


def _ch4_table_4_2(
    experiments: Sequence[Mapping[str, Any]], runs_by_mass: Mapping[float, ChainRuns]
) -> tuple[str, dict[float, float]]:
    """Table 4.2 (experiments) against granrs at each of :data:`_CHAIN_MASSES`.

    Returns the Markdown and the RMS relative depth error per mass.
    """
    header = [
        "link",
        "case",
        "q0 [deg] (Table 4.1)",
        "v0 exp. [m/s]",
        "v0 run [m/s]",
        "t_s exp. [ms]",
        "t_s granrs [ms]",
        "Δt_s granrs - exp. [ms]",
        "depth exp. [mm]",
        "depth granrs [mm]",
        "ε depth (eq. 4.8) [%]",
    ]
    parts, rms_by_mass = [], {}
    for mass, label in _CHAIN_MASSES:
        runs = runs_by_mass[mass]
        body = []
        for row in experiments:
            link, case = _link_case(row)
            r = runs[case]
            t_s, depth = _link_stop(r, link)
            body.append(
                [
                    str(link),
                    str(case),
                    f"{row['q0_deg']:+.2f}",
                    _pm(row["v0_mean"], row["v0_sd"], ".2f"),
                    f"{r.scene.v0:.3f}",
                    _pm(row["t_s_mean"], row["t_s_sd"], ".0f", 1e3),
                    _fmt(t_s, ".1f", 1e3) + _link_note(r, link),
                    _fmt(t_s - row["t_s_mean"], "+.1f", 1e3),
                    _pm(row["depth_mean"], row["depth_sd"], ".1f", 1e3),
                    _fmt(depth, ".1f", 1e3),
                    _pct(relative_error(row["depth_mean"], depth)),
                ]
            )
        e_d, e_t = _chain_errors(experiments, runs)
        rms_d, n_d = _rms(e_d)
        rms_t, n_t = _rms(e_t)
        med_dt, _ = _median(
            abs(_link_stop(runs[_link_case(row)[1]], _link_case(row)[0])[0] - row["t_s_mean"])
            for row in experiments
        )
        rms_by_mass[mass] = rms_d
        parts.append(
            f"""#### Link mass {mass:g} kg ({label})

{md_table(header, body)}

- RMS relative depth error (eq. 4.8) over the {n_d} link-cases: **{_pct(rms_d)} %**
  (largest {_pct(max((e for e in e_d if math.isfinite(e)), default=math.nan))} %).
- RMS relative t_s error: {_pct(rms_t)} % (n = {n_t}); median |Δt_s|
  {_fmt(med_dt, ".1f", 1e3)} ms.
"""
        )
    masses = ", ".join(f"{m:g} kg ({label})" for m, label in _CHAIN_MASSES)
    text = f"""### Table 4.2: the experiments against granrs

Each link of each case of Table 4.2 (mean ± sd of four drops): granrs runs the chain at the
case's measured angles (Table 4.1) and the mean of the two links' measured speeds (the chain
falls as one body; column "v0 run"), Table 4.4 coefficients per link, force at the tip, until
both links have stopped. A link's t_s counts from its own tip's entry, as in the thesis
(sec. 4.2.2). ε is eq. 4.8 with the experiment as reference. The link mass is not in the
thesis, and the result hangs on it; two masses are shown: {masses}.

{chr(10).join(parts)}"""
    return text, rms_by_mass


def _ch4_table_4_5(experiments: Sequence[Mapping[str, Any]]) -> str:
    """Tables 4.5 and 4.6: the thesis's own simulation and its depth errors."""
    thesis = {_link_case(row): row for row in _rows("chain_coefficients")}
    missing = "n/a (missing in thesis)"
    body, recomputed = [], []
    for row in experiments:
        key = _link_case(row)
        th = thesis[key]
        has_row = math.isfinite(th["depth_sim"])
        eps = relative_error(row["depth_mean"], th["depth_sim"]) if has_row else math.nan
        recomputed.append(eps)
        body.append(
            [
                str(key[0]),
                str(key[1]),
                f"{th['v0_sim']:.2f}",
                _fmt(th["t_s_sim"], ".0f", 1e3) if has_row else missing,
                _fmt(row["t_s_mean"], ".0f", 1e3),
                _fmt(th["depth_sim"], ".0f", 1e3) if has_row else missing,
                _fmt(row["depth_mean"], ".1f", 1e3),
                _fmt(th["depth_rel_err_pct"], ".2f") if has_row else missing,
                _pct(eps) if has_row else missing,
            ]
        )
    header = [
        "link",
        "case",
        "v0 thesis sim. [m/s]",
        "t_s thesis sim. (Table 4.5) [ms]",
        "t_s exp. (Table 4.2) [ms]",
        "depth thesis sim. (Table 4.5) [mm]",
        "depth exp. (Table 4.2) [mm]",
        "ε depth as printed (Table 4.6) [%]",
        "ε depth recomputed (eq. 4.8) [%]",
    ]
    rms, n = _rms(recomputed)
    return f"""### Tables 4.5-4.6: the thesis's own simulation

The thesis's SolidWorks runs (Table 4.5) and the depth errors it printed (Table 4.6), beside
eq. 4.8 recomputed from the rounded values of Tables 4.2 and 4.5 (the printed errors were
presumably computed from unrounded values; they do not follow from the tables). The case 3,
link 2 row is missing in the source.

{md_table(header, body)}

RMS of the recomputed depth errors: {_pct(rms)} % (n = {n}).
"""


def _ch4_mass_sweep(
    ctx: ReportContext,
    experiments: Sequence[Mapping[str, Any]],
    rms_by_mass: Mapping[float, float],
) -> tuple[str, float, dict[float, dict[int, Result]]]:
    """The link-mass sweep: the mass that best fits the Table 4.2 depths.

    ``rms_by_mass`` holds the RMS depth errors of the masses of :data:`_CHAIN_MASSES` (marked
    on the figure). Returns the Markdown, the best-fit mass [kg] and every run by mass and
    case.
    """
    from . import plots

    runs: dict[float, dict[int, Result]] = {}
    with ctx.step(f"chapter 4: link mass sweep ({len(_MASS_SWEEP)} masses x 3 cases)"):
        for mass in _MASS_SWEEP:
            runs[mass] = {case: ctx.chain(case, mass=mass) for case in _CHAIN_CASES}

    def objective(mass: float) -> float:
        """RMS relative depth error over the six link-cases at ``mass``."""
        return _chain_depth_rms(experiments, runs[mass])

    coarse_best = min(_MASS_SWEEP, key=objective)
    step = _MASS_SWEEP[1] - _MASS_SWEEP[0]
    lo, hi = max(_MASS_SWEEP[0], coarse_best - step), min(_MASS_SWEEP[-1], coarse_best + step)
    fine = [round(float(m), 6) for m in np.linspace(lo, hi, _MASS_FINE_POINTS)]
    with ctx.step(f"chapter 4: link mass sweep, fine grid ({_grams(lo)}-{_grams(hi)})"):
        for mass in fine:
            if mass not in runs:
                runs[mass] = {case: ctx.chain(case, mass=mass) for case in _CHAIN_CASES}
    best = min(runs, key=objective)
    best_energy = min(runs, key=lambda m: _chain_energy_rms(runs[m]))

    rows = sorted(set(_MASS_SWEEP) | {best, best_energy})
    body = []
    for mass in rows:
        _, e_t = _chain_errors(experiments, runs[mass])
        depths = {
            link: " / ".join(
                _fmt(_link_stop(runs[mass][case], link)[1], ".1f", 1e3) for case in _CHAIN_CASES
            )
            for link in _CHAIN_LINKS
        }
        notes = []
        if mass == best:
            notes.append("best fit to the depths")
        if mass == best_energy:
            notes.append("best fit to the sec. 4.3 energies")
        if mass not in _MASS_SWEEP:
            notes.append("fine grid")
        body.append(
            [
                f"{mass * 1e3:.2f}",
                depths[1],
                depths[2],
                _pct(objective(mass)),
                _pct(_rms(e_t)[0]),
                " / ".join(_fmt(_chain_energy(runs[mass][c]), ".3f") for c in _CHAIN_CASES),
                _pct(_chain_energy_rms(runs[mass])),
                "; ".join(notes),
            ]
        )
    header = [
        "link mass [g]",
        "depth link 1, cases 1 / 2 / 3 [mm]",
        "depth link 2, cases 1 / 2 / 3 [mm]",
        "RMS ε depth vs Table 4.2 [%]",
        "RMS ε t_s vs Table 4.2 [%]",
        "ΔE1 + ΔE2, cases 1 / 2 / 3 [J]",
        "RMS ε ΔE vs sec. 4.3 [%]",
        "note",
    ]
    exp_depths = {
        link: " / ".join(
            _fmt(row["depth_mean"], ".1f", 1e3) for row in experiments if _link_case(row)[0] == link
        )
        for link in _CHAIN_LINKS
    }
    best_e, best_t = _chain_errors(experiments, runs[best])
    agree = (
        ": the thesis's depths and its energies point at different masses."
        if abs(best - best_energy) > step
        else ", within one coarse step of the depth fit."
    )
    ctx.add_headline(
        f"Chain (chapter 4): the link mass is not in the thesis and the depths hang on it. "
        f"Best fit to the Table 4.2 depths over {_grams(_MASS_SWEEP[0])}-"
        f"{_grams(_MASS_SWEEP[-1])}: m = {_grams(best)} per link, RMS relative depth error "
        f"{_pct(objective(best))} % over the 6 link-cases (RMS t_s error "
        f"{_pct(_rms(best_t)[0])} %); the energies the thesis quotes (sec. 4.3) fit "
        f"m = {_grams(best_energy)} best."
    )
    masses = sorted(runs)
    depth_rms = [objective(m) for m in masses]
    time_rms = [_rms(_chain_errors(experiments, runs[m])[1])[0] for m in masses]
    energy_rms = [_chain_energy_rms(runs[m]) for m in masses]
    with ctx.step("chapter 4: link mass figure"):
        panel = plots.Panel(
            "RMS relative errors of the chain against the link mass",
            "RMS relative error [%]",
            [
                plots.Curve(
                    np.array(masses), np.array(depth_rms), 0, "depth vs Table 4.2", marker="."
                ),
                plots.Curve(
                    np.array(masses), np.array(time_rms), 1, "t_s vs Table 4.2", marker="."
                ),
                plots.Curve(
                    np.array(masses), np.array(energy_rms), 2, "ΔE1 + ΔE2 vs sec. 4.3", marker="."
                ),
            ],
            [
                plots.Point(best, objective(best), 0, "chosen"),
                plots.Point(best_energy, _chain_energy_rms(runs[best_energy]), 2, "chosen"),
                *(plots.Point(m, rms_by_mass[m], 0, "other") for m, _ in _CHAIN_MASSES),
            ],
            xlabel="link mass m [g]",
            x_scale=1e3,
            y_scale=100.0,
            legend=True,
        )
        figure = ctx.add_figure(
            "fig_4_link_mass.png",
            plots.png_bytes(
                plots.panel_grid(
                    [[panel]],
                    point_labels={
                        "chosen": "best fit",
                        "other": "depth error at "
                        + " and ".join(_grams(m) for m, _ in _CHAIN_MASSES),
                    },
                    width=8.0,
                    row_height=4.8,
                )
            ),
            "RMS relative errors against the link mass",
        )
    text = f"""### Link mass: which mass fits the experiments?

The chain's depths hang on the link mass, which the thesis does not give. granrs runs the
three cases at {len(_MASS_SWEEP)} masses from {_grams(_MASS_SWEEP[0])} to
{_grams(_MASS_SWEEP[-1])} ({_grams(step)} apart), then at {_MASS_FINE_POINTS} masses within
one step of the best of those ({_grams(lo)}-{_grams(hi)}), and takes the mass with the
smallest RMS relative depth error (eq. 4.8) over the six link-cases of Table 4.2. The
experiments' depths are {exp_depths[1]} mm (link 1) and {exp_depths[2]} mm (link 2). The
last columns compare the energy the two links lose (each from the start to its own stop,
eqs. 4.9-4.10) with the totals the thesis quotes in sec. 4.3 (0.24, 0.18, 0.10 J; whether
they are per link or for the chain is not said: they are taken as the chain's). Shown: the
coarse grid, and the best masses.

{md_table(header, body, "rllrrlrl")}

**Best-fit link mass: {_grams(best)} per link (chain {_grams(2 * best)}), RMS relative depth
error {_pct(objective(best))} % (largest {_pct(max(best_e))} %), RMS relative t_s error
{_pct(_rms(best_t)[0])} %.** The solid-steel default ({_grams(cases.CHAIN["mass"])}) is
{cases.CHAIN["mass"] / best:.2f} times the best fit. The energies quoted in sec. 4.3 are
fitted best at {_grams(best_energy)} (RMS {_pct(_chain_energy_rms(runs[best_energy]))} %){agree}

{figure}
"""
    return text, best, runs


def _ch4_stop_times(
    ctx: ReportContext,
    experiments: Sequence[Mapping[str, Any]],
    runs_by_mass: Mapping[float, ChainRuns],
) -> str:
    """Do the two links stop at the same time? Experiments, thesis and granrs per case."""
    exp = {_link_case(row): row for row in experiments}
    thesis = {_link_case(row): row for row in _rows("chain_coefficients")}
    header = [
        "case",
        "exp. t_s link 1 / 2 [ms]",
        "exp. link 2 - link 1 [ms]",
        "thesis sim. t_s link 1 / 2 [ms]",
        "thesis link 2 - link 1 [ms]",
        "entry offset t1(0) - t2(0), exp. / granrs [ms]",
    ]
    for mass in runs_by_mass:
        header += [f"granrs {_grams(mass)}: t_s link 1 / 2 [ms]", "link 2 - link 1 [ms]"]
    body = []
    later: dict[float, list[float]] = {mass: [] for mass in runs_by_mass}
    for case in _CHAIN_CASES:
        e1, e2 = exp[(1, case)]["t_s_mean"], exp[(2, case)]["t_s_mean"]
        t1, t2 = thesis[(1, case)]["t_s_sim"], thesis[(2, case)]["t_s_sim"]
        first = next(iter(runs_by_mass.values()))[case]
        entry = first.contacts[0].summary["t_entry"] - first.contacts[1].summary["t_entry"]
        cells = [
            str(case),
            f"{_fmt(e1, '.0f', 1e3)} / {_fmt(e2, '.0f', 1e3)}",
            _fmt(e2 - e1, "+.0f", 1e3),
            f"{_fmt(t1, '.0f', 1e3)} / {_fmt(t2, '.0f', 1e3)}",
            _fmt(t2 - t1, "+.0f", 1e3),
            f"{_fmt(_THESIS_ENTRY_OFFSET[case], '+.1f', 1e3)} / {_fmt(entry, '+.2f', 1e3)}",
        ]
        for mass, runs in runs_by_mass.items():
            s1, _ = _link_stop(runs[case], 1)
            s2, _ = _link_stop(runs[case], 2)
            later[mass].append(s2 - s1)
            cells += [
                f"{_fmt(s1, '.1f', 1e3)} / {_fmt(s2, '.1f', 1e3)}",
                _fmt(s2 - s1, "+.1f", 1e3),
            ]
        body.append(cells)

    def order(diffs: Sequence[float]) -> str:
        """Which link stops later, by how much, over the cases."""
        finite = [d for d in diffs if math.isfinite(d)]
        if not finite:
            return "no case has both stops"
        low, high = min(abs(d) for d in finite), max(abs(d) for d in finite)
        spread = (
            f"{_fmt(low, '.1f', 1e3)} ms"
            if math.isclose(low, high, abs_tol=5e-5)
            else f"{_fmt(low, '.1f', 1e3)}-{_fmt(high, '.1f', 1e3)} ms"
        )
        if all(d > 0 for d in finite):
            return f"link 2 stops after link 1 in every case (n = {len(finite)}), by {spread}"
        if all(d < 0 for d in finite):
            return f"link 1 stops after link 2 in every case (n = {len(finite)}), by {spread}"
        return f"the order changes between cases (differences {spread})"

    exp_diffs = [exp[(2, c)]["t_s_mean"] - exp[(1, c)]["t_s_mean"] for c in _CHAIN_CASES]
    thesis_diffs = [thesis[(2, c)]["t_s_sim"] - thesis[(1, c)]["t_s_sim"] for c in _CHAIN_CASES]
    best_mass, best_diffs = list(later.items())[-1]
    ctx.add_headline(
        f"Chain stop times per link (each from its own entry). Experiments (Table 4.2): "
        f"{order(exp_diffs)}; the thesis's simulation: {order(thesis_diffs)}; granrs at "
        f"{_grams(best_mass)}: {order(best_diffs)}."
    )
    granrs_lines = "\n".join(
        f"- granrs, link mass {_grams(mass)}: {order(diffs)}." for mass, diffs in later.items()
    )
    return f"""### Do the two links stop at the same time?

The cases are asymmetric (q1 and q2 of opposite sign and unequal size, different
coefficients per link), so the links need not stop together. Times are per link from its own
tip's entry; the entry offset t1(0) - t2(0) is the measured one (sec. 4.2.2) against the
one granrs gets from the measured angles (the lower tip starts at the surface).

{md_table(header, body)}

- Experiments (Table 4.2): {order(exp_diffs)}.
- The thesis's simulation (Table 4.5): {order(thesis_diffs)}.
{granrs_lines}
"""


def _ch4_quoted(
    experiments: Sequence[Mapping[str, Any]], runs_by_mass: Mapping[float, ChainRuns]
) -> str:
    """The forces and energies quoted in the text of sec. 4.3 against granrs."""
    masses = list(runs_by_mass)
    f_header = ["link", "case", "F_d,max thesis [N]"]
    f_header += [f"F_d,max granrs {_grams(m)} [N]" for m in masses]
    f_header += ["F_s,end thesis [N]"] + [f"F_s,end granrs {_grams(m)} [N]" for m in masses]
    f_body = []
    for row in experiments:
        key = _link_case(row)
        link, case = key
        cells = [str(link), str(case), f"{_THESIS_FD_MAX[key]:g}"]
        cells += [
            _fmt(runs_by_mass[m][case].contacts[link - 1].summary["F_d_max"], ".2f") for m in masses
        ]
        cells.append(f"{_THESIS_FS_END[key]:g}")
        cells += [
            _fmt(runs_by_mass[m][case].contacts[link - 1].summary["F_s_end"], ".2f") for m in masses
        ]
        f_body.append(cells)
    e_header = ["case", "ΔE thesis (sec. 4.3) [J]"]
    e_header += [f"ΔE1 + ΔE2 granrs {_grams(m)} [J]" for m in masses]
    e_header += [f"ΔE1 / ΔE2 granrs {_grams(m)} [J]" for m in masses[:1]]
    e_body = []
    for case in _CHAIN_CASES:
        cells = [str(case), f"{_THESIS_DE[case]:g}"]
        cells += [_fmt(_chain_energy(runs_by_mass[m][case]), ".3f") for m in masses]
        contacts = runs_by_mass[masses[0]][case].contacts
        cells.append(" / ".join(_fmt(c.summary["link_dE"], ".3f") for c in contacts))
        e_body.append(cells)
    return f"""### Forces and energy: the numbers quoted in sec. 4.3

The thesis gives its chain forces and energies only in the text beside Figs. 4.9, 4.10 and
4.15 (its Appendix H plots are images). F_d,max is the largest |F_d| of the link during its
penetration phase, F_s,end |F_s| at its stop; ΔE is the mechanical energy the links lose
from the start of the run to their own stops (eqs. 4.9-4.10), summed over the two links.

{md_table(f_header, f_body)}

{md_table(e_header, e_body)}
"""


def _link_series(result: Result, link: int) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
    """Time since link ``link``'s entry [s], the mask of its penetration phase (entry to
    its stop) and its series by short name (``depth``, ``v_tip_y``, ``F_dx``, ``KE``...)."""
    if result.series is None:  # pragma: no cover - the figure runs record
        raise RuntimeError("chapter 4 figure runs must record their series")
    contact = result.contacts[link - 1]
    t_entry = float(contact.summary["t_entry"])
    t = result.series["t"] - t_entry
    end = contact.t_s - t_entry if contact.stopped else math.inf
    phase = (t >= -1e-12) & (t <= end + 1e-12)
    prefix = f"c{link - 1}."
    named = {k[len(prefix) :]: v for k, v in result.series.items() if k.startswith(prefix)}
    named["KE"] = result.series[f"link{link}.KE"]
    named["PE"] = result.series[f"link{link}.PE"]
    return t, phase, named


def _case_label(runs: ChainRuns, case: int) -> str:
    """``case k (v0 = x m/s)``."""
    return f"case {case} (v0 = {runs[case].scene.v0:.2f} m/s)"


def _ch4_figures(
    ctx: ReportContext,
    experiments: Sequence[Mapping[str, Any]],
    best: float,
    best_runs: ChainRuns,
    steel_runs: ChainRuns,
) -> str:
    """Figs. 4.7-4.16 analogues and the pin force, at the best-fit mass."""
    from . import plots

    exp = {_link_case(row): row for row in experiments}
    thesis = {_link_case(row): row for row in _rows("chain_coefficients")}
    steel = cases.CHAIN["mass"]
    steel_label = f"granrs, {_grams(steel)} (solid steel)"
    links = []
    with ctx.step("chapter 4: Figs. 4.7-4.16 and the pin force"):
        # Figs. 4.7-4.8: depth and downward tip velocity per link.
        depth_panels, velocity_panels = [], []
        for link in _CHAIN_LINKS:
            d_curves, v_curves, d_points, v_points = [], [], [], []
            for i, case in enumerate(_CHAIN_CASES):
                for runs, style, label in (
                    (best_runs, "-", f"granrs {_case_label(best_runs, case)}, {_grams(best)}"),
                    (steel_runs, "--", steel_label if case == _CHAIN_CASES[-1] else None),
                ):
                    t, _, named = _link_series(runs[case], link)
                    keep = t >= -1e-12
                    d_curves.append(
                        plots.Curve(t[keep], named["depth"][keep], i, label, style, width=1.4)
                    )
                    v_curves.append(
                        plots.Curve(t[keep], -named["v_tip_y"][keep], i, label, style, width=1.4)
                    )
                row = exp[(link, case)]
                e = {"x_sd": row["t_s_sd"]}
                d_points.append(
                    plots.Point(row["t_s_mean"], row["depth_mean"], i, y_sd=row["depth_sd"], **e)
                )
                v_points.append(plots.Point(row["t_s_mean"], 0.0, i, **e))
                th = thesis[(link, case)]
                if math.isfinite(th["t_s_sim"]):
                    d_points.append(plots.Point(th["t_s_sim"], th["depth_sim"], i, "thesis"))
                    v_points.append(plots.Point(th["t_s_sim"], 0.0, i, "thesis"))
                t_s, depth = _link_stop(best_runs[case], link)
                if math.isfinite(t_s):
                    d_points.append(plots.Point(t_s, depth, i, "stop"))
                    v_points.append(plots.Point(t_s, 0.0, i, "stop"))
            depth_panels.append(
                plots.Panel(
                    f"Fig. 4.7 ({'ab'[link - 1]}): tip depth, link {link}",
                    "tip depth d [mm]",
                    d_curves,
                    d_points,
                    y_scale=1e3,
                    xlabel="time since the link's entry [ms]",
                    legend=link == 1,
                )
            )
            velocity_panels.append(
                plots.Panel(
                    f"Fig. 4.8 ({'ab'[link - 1]}): tip vertical velocity, link {link}",
                    r"downward tip velocity $-v_{y,T}$ [m/s]",
                    v_curves,
                    v_points,
                    xlabel="time since the link's entry [ms]",
                    y_from_zero=False,
                    zero_line=True,
                )
            )
        labels = {
            "experiment": "experiment end (Table 4.2, mean ± sd)",
            "thesis": "thesis simulation end (Table 4.5)",
            "stop": f"granrs stop, {_grams(best)}",
        }
        fig = plots.panel_grid(
            [depth_panels, velocity_panels],
            title=f"Figs. 4.7-4.8: the chain's tips, link mass {_grams(best)} (best fit; "
            f"dashed: {_grams(steel)})",
            point_labels=labels,
            row_height=4.6,
        )
        links.append(
            ctx.add_figure(
                "fig_4_7_4_8_depth_velocity.png",
                plots.png_bytes(fig),
                "Figs. 4.7-4.8: tip depth and velocity per link",
            )
            + "\n\n*Top: Fig. 4.7, tip depth against time, (a) link 1, (b) link 2; bottom: "
            "Fig. 4.8, downward tip velocity against time.*"
        )

        # Figs. 4.9-4.12: |F_d|, |F_s|, |F_r| and the dynamic / static shares.
        force_rows: list[list[Any]] = [[], [], [], []]
        for link in _CHAIN_LINKS:
            curves: list[list[Any]] = [[], [], [], []]
            for i, case in enumerate(_CHAIN_CASES):
                t, phase, n = _link_series(best_runs[case], link)
                f_d = np.hypot(n["F_dx"], n["F_dy"])[phase]
                f_s = np.hypot(n["F_sh"], n["F_sv"])[phase]
                f_r = np.hypot(n["F_dx"] + n["F_sh"], n["F_dy"] + n["F_sv"])[phase]
                total = f_d + f_s
                share = np.divide(f_d, total, out=np.full_like(total, np.nan), where=total > 0)
                tp = t[phase]
                label = f"granrs {_case_label(best_runs, case)}"
                curves[0].append(plots.Curve(tp, f_d, i, label))
                curves[1].append(plots.Curve(tp, f_s, i, label))
                curves[2].append(plots.Curve(tp, f_r, i, label))
                curves[3].append(plots.Curve(tp, share, i, f"dynamic, case {case}"))
                curves[3].append(plots.Curve(tp, 1.0 - share, i, f"static, case {case}", ":"))
            ab = "ab"[link - 1]
            for r, (number, name, symbol) in enumerate(
                (
                    ("4.9", "dynamic force", "|F_d|"),
                    ("4.10", "static force", "|F_s|"),
                    ("4.11", "resistance force", "|F_r|"),
                )
            ):
                force_rows[r].append(
                    plots.Panel(
                        f"Fig. {number} ({ab}): {name} {symbol}, link {link}",
                        f"{symbol} [N]",
                        curves[r],
                        xlabel="time since the link's entry [ms]",
                        legend=link == 1 and r == 0,
                    )
                )
            force_rows[3].append(
                plots.Panel(
                    f"Fig. 4.12 ({ab}): dynamic and static share, link {link}",
                    "share of |F_d| + |F_s| [%]",
                    curves[3],
                    y_scale=100.0,
                    xlabel="time since the link's entry [ms]",
                    legend=link == 1,
                )
            )
        fig = plots.panel_grid(
            force_rows,
            title=f"Figs. 4.9-4.12: resistance forces per link during the penetration phase, "
            f"link mass {_grams(best)}",
            row_height=3.6,
        )
        links.append(
            ctx.add_figure(
                "fig_4_9_4_12_forces.png",
                plots.png_bytes(fig),
                "Figs. 4.9-4.12: forces per link",
            )
            + "\n\n*Rows: Fig. 4.9, |F_d|; Fig. 4.10, |F_s|; Fig. 4.11, |F_r|; Fig. 4.12, "
            "the dynamic and static shares; left: link 1, right: link 2.*"
        )

        # Figs. 4.13-4.16: KE, PE and E lost per link and the KE / PE shares.
        energy_rows: list[list[Any]] = [[], [], [], []]
        for link in _CHAIN_LINKS:
            curves = [[], [], [], []]
            for i, case in enumerate(_CHAIN_CASES):
                t, phase, n = _link_series(best_runs[case], link)
                tp = t[phase]
                ke0 = float(np.interp(0.0, t, n["KE"]))
                pe0 = float(np.interp(0.0, t, n["PE"]))
                ke_lost = ke0 - n["KE"][phase]
                pe_lost = pe0 - n["PE"][phase]
                total = ke_lost + pe_lost
                floor = 1e-3 * float(np.max(np.abs(total))) if total.size else 0.0
                ke_share = np.divide(
                    ke_lost, total, out=np.full_like(total, np.nan), where=np.abs(total) > floor
                )
                label = f"granrs {_case_label(best_runs, case)}"
                curves[0].append(plots.Curve(tp, ke_lost, i, label))
                curves[1].append(plots.Curve(tp, pe_lost, i, label))
                curves[2].append(plots.Curve(tp, total, i, label))
                curves[3].append(plots.Curve(tp, ke_share, i, f"KE, case {case}"))
                curves[3].append(plots.Curve(tp, 1.0 - ke_share, i, f"PE, case {case}", ":"))
            ab = "ab"[link - 1]
            for r, (number, name) in enumerate(
                (
                    ("4.13", "kinetic energy lost ΔKE"),
                    ("4.14", "potential energy lost ΔPE"),
                    ("4.15", "mechanical energy lost ΔE"),
                )
            ):
                energy_rows[r].append(
                    plots.Panel(
                        f"Fig. {number}: {name}, link {link}",
                        f"{name.split()[-1]} [mJ]",
                        curves[r],
                        y_scale=1e3,
                        xlabel="time since the link's entry [ms]",
                        legend=link == 1 and r == 0,
                    )
                )
            energy_rows[3].append(
                plots.Panel(
                    f"Fig. 4.16 ({ab}): shares of ΔKE and ΔPE in ΔE, link {link}",
                    "share of ΔE [%]",
                    curves[3],
                    y_scale=100.0,
                    ylim=(0.0, 110.0),
                    xlabel="time since the link's entry [ms]",
                    legend=link == 1,
                )
            )
        fig = plots.panel_grid(
            energy_rows,
            title=f"Figs. 4.13-4.16: energy each link loses since its entry (eqs. 4.9-4.10), "
            f"link mass {_grams(best)}",
            row_height=3.6,
        )
        links.append(
            ctx.add_figure(
                "fig_4_13_4_16_energy.png",
                plots.png_bytes(fig),
                "Figs. 4.13-4.16: energy per link",
            )
            + "\n\n*Rows: Fig. 4.13, ΔKE; Fig. 4.14, ΔPE; Fig. 4.15, ΔE; Fig. 4.16, the "
            "shares of ΔKE and ΔPE in ΔE; left: link 1, right: link 2.*"
        )

        # The pin force (the thesis has no figure of it).
        pin_curves = []
        for i, case in enumerate(_CHAIN_CASES):
            for runs, style, label in (
                (best_runs, "-", f"granrs {_case_label(best_runs, case)}, {_grams(best)}"),
                (steel_runs, "--", steel_label if case == _CHAIN_CASES[-1] else None),
            ):
                series = runs[case].series
                assert series is not None
                force = np.hypot(series["pin.Fx"], series["pin.Fy"])
                pin_curves.append(plots.Curve(series["t"], force, i, label, style, width=1.4))
        fig = plots.panel_grid(
            [
                [
                    plots.Panel(
                        "Pin force: the force link 1 exerts on link 2",
                        "|F_pin| [N]",
                        pin_curves,
                        xlabel="time since the first tip's entry [ms]",
                        legend=True,
                    )
                ]
            ],
            width=8.0,
            row_height=4.6,
        )
        links.append(
            ctx.add_figure("fig_4_pin_force.png", plots.png_bytes(fig), "Pin force against time")
            + "\n\n*The magnitude of the force link 1 exerts on link 2 at the pin (no thesis "
            "figure).*"
        )
    return f"""### Figs. 4.7-4.16: the chain against time

granrs at the best-fit link mass ({_grams(best)}), Table 4.4 coefficients, force at the tip;
each link's time runs from its own tip's entry. Figs. 4.7-4.8: tip depth and downward tip
velocity per link over the whole run (solid; dashed: the solid-steel mass), with the
experiments' end points (Table 4.2, mean ± sd), the thesis's simulated end points (Table 4.5)
and the granrs stops. Figs. 4.9-4.16 cover each link's penetration phase (its entry to its
own stop): |F_d|, |F_s| = |(F_sh, F_sv)| and |F_r| = |F_d + F_s| (eqs. 4.1-4.2); the dynamic
share |F_d| / (|F_d| + |F_s|) and the static share 1 - that (Fig. 4.12); and the kinetic,
potential and mechanical energy each link has lost since its entry (eqs. 4.9-4.10), with the
kinetic and potential shares of the total (Fig. 4.16; just after entry a link still gains
kinetic energy, so ΔKE < 0 and the potential share exceeds 100 %: that panel is clipped at
110 %). The thesis's own curves are images
and are not reproduced. Last: the magnitude of the pin force on link 2 over the whole run
(the thesis has no such figure).

{chr(10).join(chr(10) + link for link in links)}
"""


@register_chapter("4", "Chapter 4: the two-link chain")
def chapter_4(ctx: ReportContext) -> str:
    """Chapter 4: the chain against Tables 4.2 and 4.5-4.6, the link mass, Figs. 4.7-4.16."""
    experiments = _rows("chain_experiments")
    runs_by_mass: dict[float, dict[int, Result]] = {}
    with ctx.step("chapter 4: Table 4.2 (experiments) vs granrs at two link masses"):
        for mass, _ in _CHAIN_MASSES:
            runs_by_mass[mass] = {
                case: ctx.chain(case, mass=mass, record=_CHAIN_RECORD) for case in _CHAIN_CASES
            }
    table_4_2, rms_by_mass = _ch4_table_4_2(experiments, runs_by_mass)
    ctx.add_headline(
        "Chain (chapter 4) depths vs Table 4.2, RMS relative error over the 6 link-cases: "
        + "; ".join(
            f"{_pct(rms_by_mass[m])} % at {_grams(m)} per link ({label})"
            for m, label in _CHAIN_MASSES
        )
        + "."
    )
    table_4_5 = _ch4_table_4_5(experiments)
    sweep_text, best, _ = _ch4_mass_sweep(ctx, experiments, rms_by_mass)
    with ctx.step(f"chapter 4: runs at the best-fit mass ({_grams(best)})"):
        best_runs = {
            case: ctx.chain(case, mass=best, record=_CHAIN_RECORD) for case in _CHAIN_CASES
        }
    compared: dict[float, ChainRuns] = {**runs_by_mass, best: best_runs}
    stops = _ch4_stop_times(ctx, experiments, compared)
    quoted = _ch4_quoted(experiments, compared)
    figures = _ch4_figures(ctx, experiments, best, best_runs, runs_by_mass[cases.CHAIN["mass"]])
    return "\n".join(
        [
            "The thesis's two-link chain (sec. 4.1): two round-ended steel links, L = 0.135 m, "
            "d = 0.0064 m, pinned at their top ends by a frictionless joint, falling onto the "
            "play sand of chapter 3 (rho_g = 1650 kg/m³ assumed; the thesis does not restate "
            "it). Link 1 leans at q1 ≈ -15°, link 2 at q2 ≈ +15° (Table 4.1). Coefficients: "
            "Table 4.4 per link and case (the case 3, link 2 row is missing in the source: "
            "the Table 4.3 expressions at alpha = 74°). **The link mass is not in the thesis**; "
            "the report shows it as an unknown.",
            "",
            table_4_2,
            table_4_5,
            sweep_text,
            stops,
            quoted,
            figures,
        ]
    )


# --------------------------------------------------------------------------------------
# Chapter 5: the leg
# --------------------------------------------------------------------------------------

#: The thesis's drop heights and the speed each was simulated at (secs. 5.2.2, 5.3.2).
_HEIGHT_SPEEDS: dict[str, float] = {"h1": 3.28, "h2": 2.35}
#: What sec. 5.2.2's text says the average subject does (depth [m], t_s [s]) at each
#: speed; compared with the Table 5.1 means in the report.
_THESIS_TEXT_MEANS: dict[str, tuple[float, float]] = {"h1": (0.05, 0.030), "h2": (0.06, 0.035)}
#: Joint stiffnesses of the spring-damper study [N m/rad] (log-spaced, 3 per decade).
_LEG_STIFFNESS: tuple[float, ...] = tuple(
    float(f"{k:.3g}") for k in np.logspace(math.log10(3.0), math.log10(30000.0), 13)
)
#: Damping ratio of the spring-dampers: c = 2 zeta sqrt(k I_ref), I_ref the half trunk's
#: moment of inertia about the hip (Winter's segment data as scaled by granrs).
_LEG_DAMPING_RATIO = 0.1
_LEG_RECORD = ("state", "forces")


@dataclass(frozen=True)
class _JointSetting:
    """One joint setting of the leg study: a name, the scene fields it sets, k and c."""

    name: str
    fields: dict[str, Any]
    k: float = math.nan
    c: float = math.nan


def _human_coefficients(height: str) -> tuple[Coefficients, dict[str, Any]]:
    """The thesis's coefficients for drop height ``height`` (sec. 5.3.2) and their row."""
    speed = _HEIGHT_SPEEDS[height]
    row = next(r for r in _rows("human_coefficients") if math.isclose(r["v0"], speed))
    coefficients = Coefficients(
        eta_h=row["eta_h"], eta_d=row["eta_d"], eta_v=row["eta_v"], lam=row["lambda"]
    )
    return coefficients, row


def _subject_means(rows: Sequence[Mapping[str, Any]]) -> dict[str, tuple[float, float]]:
    """Mean and sd across subjects of t_s, depth and v0 (the subjects' means)."""
    out = {}
    for key in ("t_s_mean", "depth_mean", "v0_mean"):
        values = [row[key] for row in rows]
        out[key] = (statistics.fmean(values), statistics.stdev(values))
    return out


def _leg_reference_inertia() -> float:
    """The half trunk's moment of inertia about the hip [kg m^2] (I_ref of the damping)."""
    segments = {s["name"]: s for s in cases.leg().leg_segments()}
    trunk = segments["half_trunk"]
    return float(trunk["inertia"] + trunk["mass"] * trunk["com"] ** 2)


def _leg_settings() -> list[_JointSetting]:
    """The joint settings of the study, in report order."""
    i_ref = _leg_reference_inertia()
    settings = [
        _JointSetting("locked (default)", {}),
        _JointSetting("free", {"joints": "free"}),
        _JointSetting("locked, thesis sole (eqs. 5.5-5.7)", {"sole_model": "thesis"}),
    ]
    for k in _LEG_STIFFNESS:
        c = round(2.0 * _LEG_DAMPING_RATIO * math.sqrt(k * i_ref), 4)
        settings.append(
            _JointSetting(f"spring-damper k = {k:g}", {"joints": {"k": k, "c": c}}, k, c)
        )
    return settings


def _combined_error(pairs: Iterable[tuple[float, float]]) -> float:
    """RMS of the relative errors (eq. 5.16 form) of (reference, value) pairs."""
    rms, _ = _rms(relative_error(ref, value) for ref, value in pairs)
    return rms


def _ch5_table_5_1(ctx: ReportContext) -> tuple[str, dict[str, dict[str, tuple[float, float]]]]:
    """Table 5.1 per subject and height against granrs (locked joints, box sole).

    Returns the Markdown and the experiments' means across subjects per height.
    """
    experiments = _rows("table_5_1")
    means: dict[str, dict[str, tuple[float, float]]] = {}
    body = []
    thesis_eps = []
    with ctx.step("chapter 5: Table 5.1 (experiments) vs granrs"):
        for height, speed in _HEIGHT_SPEEDS.items():
            coefficients, th = _human_coefficients(height)
            rows = [row for row in experiments if row["height_case"] == height]
            for row in rows:
                r = ctx.leg(row["v0_mean"], coefficients=coefficients)
                body.append(
                    [
                        height,
                        f"subject {int(row['subject'])}",
                        _pm(row["v0_mean"], row["v0_sd"], ".2f"),
                        _pm(row["t_s_mean"], row["t_s_sd"], ".0f", 1e3),
                        _pm(row["depth_mean"], row["depth_sd"], ".0f", 1e3),
                        f"{r.scene.v0:.2f}",
                        _fmt(r.t_s, ".1f", 1e3) + _status_note(r),
                        _fmt(r.t_s - row["t_s_mean"], "+.1f", 1e3),
                        _fmt(r.depth, ".1f", 1e3),
                        _pct(relative_error(row["depth_mean"], r.depth)),
                    ]
                )
            m = means[height] = _subject_means(rows)
            r = ctx.leg(m["v0_mean"][0], coefficients=coefficients)
            body.append(
                [
                    height,
                    f"**mean of {len(rows)} subjects** (± sd across subjects)",
                    _pm(*m["v0_mean"], ".2f"),
                    _pm(*m["t_s_mean"], ".1f", 1e3),
                    _pm(*m["depth_mean"], ".1f", 1e3),
                    f"{r.scene.v0:.2f}",
                    _fmt(r.t_s, ".1f", 1e3) + _status_note(r),
                    _fmt(r.t_s - m["t_s_mean"][0], "+.1f", 1e3),
                    _fmt(r.depth, ".1f", 1e3),
                    _pct(relative_error(m["depth_mean"][0], r.depth)),
                ]
            )
            r = ctx.leg(speed, coefficients=coefficients)
            thesis_eps.append((height, relative_error(m["depth_mean"][0], th["depth_sim"]), th))
            body.append(
                [
                    height,
                    "thesis simulation (sec. 5.3.2; Δ and ε vs it)",
                    f"{speed:.2f}",
                    _fmt(th["t_s_sim"], ".0f", 1e3),
                    _fmt(th["depth_sim"], ".0f", 1e3),
                    f"{r.scene.v0:.2f}",
                    _fmt(r.t_s, ".1f", 1e3) + _status_note(r),
                    _fmt(r.t_s - th["t_s_sim"], "+.1f", 1e3),
                    _fmt(r.depth, ".1f", 1e3),
                    _pct(relative_error(th["depth_sim"], r.depth)),
                ]
            )
    header = [
        "height",
        "row",
        "v0 [m/s]",
        "t_s exp. / thesis [ms]",
        "depth exp. / thesis [mm]",
        "v0 run [m/s]",
        "t_s granrs [ms]",
        "Δt_s granrs - ref. [ms]",
        "depth granrs [mm]",
        "ε depth (eq. 5.16) [%]",
    ]
    thesis_lines = "\n".join(
        f"- {height} (v0 = {_HEIGHT_SPEEDS[height]} m/s): the thesis's simulated depth "
        f"{_fmt(th['depth_sim'], '.0f', 1e3)} mm against the subjects' mean "
        f"{_fmt(means[height]['depth_mean'][0], '.1f', 1e3)} mm is ε = {_pct(eps)} % by eq. "
        f"5.16; the thesis prints {_fmt(th['depth_rel_err_pct'], '.2f')} %. Its t_s "
        f"{_fmt(th['t_s_sim'], '.0f', 1e3)} ms against the mean "
        f"{_fmt(means[height]['t_s_mean'][0], '.1f', 1e3)} ms. Sec. 5.2.2's text says the "
        f"average subject stops at {_fmt(_THESIS_TEXT_MEANS[height][0], '.2f')} m after "
        f"{_fmt(_THESIS_TEXT_MEANS[height][1], '.3f')} s at this speed."
        for height, eps, th in thesis_eps
    )
    text = f"""### Table 5.1: the experiments against granrs

Table 5.1 (per subject: mean ± sd of the jumps from each height; units m and m/s although the
source prints "in") against granrs's leg (chapter 5's average subject: 75.35 kg, 1.78 m, foot
0.254 m, shoe 0.086 m, tibia 0.432 m; Dempster/Winter segments; all joints locked; box sole;
force at the tip) dropped at each subject's mean speed with the thesis's coefficients of that
height (sec. 5.3.2: h1 at {_HEIGHT_SPEEDS["h1"]} m/s, h2 at {_HEIGHT_SPEEDS["h2"]} m/s; the
thesis gives no per-subject anthropometry, so every subject is the average body). The mean
row is the mean (± sd) of the five subjects' means, run at their mean speed; the thesis row
is the thesis's own simulation, and granrs at the thesis's speed, Δ and ε there taken
against the thesis.

{md_table(header, body, "ll")}

{thesis_lines}
"""
    return text, means


def _ch5_joint_study(
    ctx: ReportContext, means: Mapping[str, Mapping[str, tuple[float, float]]]
) -> tuple[str, list[_JointSetting], dict[tuple[str, str], Result], dict[str, str]]:
    """The leg's joints: locked, free, spring-dampers, and the thesis sole.

    Returns the Markdown, the settings, the runs by (setting name, height), and the names
    of the settings closest to the thesis and to the experiments.
    """
    settings = _leg_settings()
    runs: dict[tuple[str, str], Result] = {}
    with ctx.step(f"chapter 5: joint study ({len(settings)} settings x 2 speeds)"):
        for setting in settings:
            for height, speed in _HEIGHT_SPEEDS.items():
                runs[(setting.name, height)] = ctx.leg(speed, record=_LEG_RECORD, **setting.fields)
    thesis = {h: _human_coefficients(h)[1] for h in _HEIGHT_SPEEDS}

    def errors(name: str) -> tuple[float, float]:
        """Combined RMS relative error of depth and t_s at both speeds: vs the thesis, vs
        the experiments' mean."""
        pairs_th, pairs_exp = [], []
        for h in _HEIGHT_SPEEDS:
            r = runs[(name, h)]
            t_s = r.t_s if r.stopped else math.nan
            pairs_th += [(thesis[h]["depth_sim"], r.depth), (thesis[h]["t_s_sim"], t_s)]
            pairs_exp += [(means[h]["depth_mean"][0], r.depth), (means[h]["t_s_mean"][0], t_s)]
        return _combined_error(pairs_th), _combined_error(pairs_exp)

    scores = {s.name: errors(s.name) for s in settings}

    def score(name: str, which: int) -> float:
        """The score ``which`` (0: thesis, 1: experiments), infinite when undefined."""
        value = scores[name][which]
        return value if math.isfinite(value) else math.inf

    best_th = min(scores, key=lambda n: score(n, 0))
    best_exp = min(scores, key=lambda n: score(n, 1))

    body = [
        [
            "**thesis simulation** (sec. 5.3.2)",
            "",
            "",
            *(
                cell
                for h in _HEIGHT_SPEEDS
                for cell in (
                    _fmt(thesis[h]["t_s_sim"], ".0f", 1e3),
                    _fmt(thesis[h]["depth_sim"], ".0f", 1e3),
                )
            ),
            "",
            "",
        ],
        [
            "**experiments**, mean of 5 subjects (Table 5.1)",
            "",
            "",
            *(
                cell
                for h in _HEIGHT_SPEEDS
                for cell in (
                    _fmt(means[h]["t_s_mean"][0], ".1f", 1e3),
                    _fmt(means[h]["depth_mean"][0], ".1f", 1e3),
                )
            ),
            "",
            "",
        ],
    ]
    for s in settings:
        spring = math.isfinite(s.k)
        cells = [s.name, _fmt(s.k, "g") if spring else "-", _fmt(s.c, ".3g") if spring else "-"]
        for h in _HEIGHT_SPEEDS:
            r = runs[(s.name, h)]
            cells += [_fmt(r.t_s, ".1f", 1e3) + _status_note(r), _fmt(r.depth, ".1f", 1e3)]
        th, ex = scores[s.name]
        mark_th = " (closest)" if s.name == best_th else ""
        mark_ex = " (closest)" if s.name == best_exp else ""
        body.append([*cells, _pct(th) + mark_th, _pct(ex) + mark_ex])
    header = ["setting", "k [N m/rad]", "c [N m s/rad]"]
    for h, speed in _HEIGHT_SPEEDS.items():
        header += [f"t_s {h}, {speed} m/s [ms]", f"depth {h}, {speed} m/s [mm]"]
    header += ["RMS ε vs thesis [%]", "RMS ε vs experiments [%]"]

    # A convergence check of the stiffest setting: the same run at dt / 4.
    stiff = settings[-1]
    check = []
    with ctx.step("chapter 5: stiffest spring-damper at dt / 4 (convergence check)"):
        for h, speed in _HEIGHT_SPEEDS.items():
            fine = ctx.run(cases.leg(v0=speed, dt=ctx.dt / 4.0, **stiff.fields))
            coarse = runs[(stiff.name, h)]
            check.append(
                f"{h}: depth {_fmt(coarse.depth, '.2f', 1e3)} / {_fmt(fine.depth, '.2f', 1e3)} "
                f"mm, t_s {_fmt(coarse.t_s, '.2f', 1e3)} / {_fmt(fine.t_s, '.2f', 1e3)} ms"
            )

    def describe(name: str) -> str:
        """``name``'s numbers at both speeds."""
        parts = []
        for h, speed in _HEIGHT_SPEEDS.items():
            r = runs[(name, h)]
            parts.append(
                f"{_fmt(r.depth, '.0f', 1e3)} mm / {_fmt(r.t_s, '.0f', 1e3)} ms at {speed} m/s"
            )
        return ", ".join(parts)

    springs = [s for s in settings if math.isfinite(s.k)]
    edges = {springs[0].name: "softest", springs[-1].name: "stiffest"}

    def edge(name: str) -> str:
        """A warning when ``name`` is the softest or stiffest spring of the sweep."""
        return (
            f" (the {edges[name]} spring swept: the best may lie outside the range)"
            if name in edges
            else ""
        )

    within = [n for n in scores if score(n, 0) <= 0.1 or score(n, 1) <= 0.1]
    gap = (
        "No setting comes within 10 % (RMS) of either reference."
        if not within
        else "Within 10 % (RMS) of a reference: " + ", ".join(within) + "."
    )
    ctx.add_headline(
        f"Leg (chapter 5): closest to the thesis's simulation: {best_th} "
        f"({describe(best_th)}; RMS ε {_pct(scores[best_th][0])} %){edge(best_th)}; "
        f"closest to the "
        f"experiments' mean: {best_exp} ({describe(best_exp)}; RMS ε "
        f"{_pct(scores[best_exp][1])} %){edge(best_exp)}. Locked joints (the default): "
        f"{describe(settings[0].name)}. {gap}"
    )
    i_ref = _leg_reference_inertia()
    text = f"""### The joints: locked, free, spring-dampers

The thesis's mannequin had joints "to preserve the necessary degrees of freedom" (sec. 5.3.1)
but does not say how stiff they were, and its foot depth hangs on it. granrs runs the leg at
the thesis's two speeds with its coefficients for each, for: every joint (ankle, knee, hip)
locked; every joint free; a rotational spring-damper at every joint, relaxed at the touchdown
posture, for {len(_LEG_STIFFNESS)} stiffnesses k from {_LEG_STIFFNESS[0]:g} to
{_LEG_STIFFNESS[-1]:g} N m/rad (log-spaced), with damping c = 2 ζ sqrt(k I_ref), ζ =
{_LEG_DAMPING_RATIO:g} and I_ref = {i_ref:.2f} kg m² (the half trunk about the hip, the
largest segment; a light damping, so that the stiffness is what varies); and the locked leg
with the thesis's sole (eqs. 5.5-5.7 with the shank's angle) instead of the box. RMS ε is
the root mean square of the four relative errors (depth and t_s at both speeds, eq. 5.16
form) against the thesis's simulation or the experiments' mean.

{md_table(header, body, "l")}

- **Closest to the thesis's simulation: {best_th}** ({describe(best_th)}; RMS ε
  {_pct(scores[best_th][0])} %){edge(best_th)}.
- **Closest to the experiments' mean: {best_exp}** ({describe(best_exp)}; RMS ε
  {_pct(scores[best_exp][1])} %){edge(best_exp)}.
- {gap}
- Convergence check, stiffest setting (k = {stiff.k:g} N m/rad) at dt and dt / 4:
  {"; ".join(check)}.
"""
    return text, settings, runs, {"thesis": best_th, "experiments": best_exp}


def _ch5_figures(
    ctx: ReportContext,
    means: Mapping[str, Mapping[str, tuple[float, float]]],
    settings: Sequence[_JointSetting],
    runs: Mapping[tuple[str, str], Result],
    best: Mapping[str, str],
) -> str:
    """Fig. 5.10 (foot depth and velocity) for a few joint settings, and depth and t_s
    against the joint stiffness."""
    from . import plots

    shown = [settings[0].name, settings[1].name, settings[2].name]
    for name in (best["thesis"], best["experiments"]):
        if name not in shown:
            shown.append(name)
    links = []
    with ctx.step("chapter 5: Fig. 5.10 and the stiffness figure"):
        rows = []
        for h, speed in _HEIGHT_SPEEDS.items():
            thesis = _human_coefficients(h)[1]
            d_curves, v_curves, d_points, v_points = [], [], [], []
            for i, name in enumerate(shown):
                r = runs[(name, h)]
                assert r.series is not None
                t = r.series["t"]
                d_curves.append(plots.Curve(t, r.series["depth"], i, name))
                v_curves.append(plots.Curve(t, -r.series["v_tip_y"], i, name))
                if r.stopped:
                    d_points.append(plots.Point(r.t_s, r.depth, i, "stop"))
                    v_points.append(plots.Point(r.t_s, 0.0, i, "stop"))
            m = means[h]
            d_points.append(
                plots.Point(
                    m["t_s_mean"][0],
                    m["depth_mean"][0],
                    None,
                    x_sd=m["t_s_mean"][1],
                    y_sd=m["depth_mean"][1],
                )
            )
            v_points.append(plots.Point(m["t_s_mean"][0], 0.0, None, x_sd=m["t_s_mean"][1]))
            d_points.append(plots.Point(thesis["t_s_sim"], thesis["depth_sim"], None, "thesis"))
            v_points.append(plots.Point(thesis["t_s_sim"], 0.0, None, "thesis"))
            rows.append(
                [
                    plots.Panel(
                        f"Fig. 5.10 (a): foot depth, {h}, v0 = {speed} m/s",
                        "foot depth d [mm]",
                        d_curves,
                        d_points,
                        y_scale=1e3,
                        legend=h == "h1",
                    ),
                    plots.Panel(
                        f"Fig. 5.10 (b): foot vertical velocity, {h}, v0 = {speed} m/s",
                        r"downward foot velocity $-v_{y,T}$ [m/s]",
                        v_curves,
                        v_points,
                        y_from_zero=False,
                        zero_line=True,
                    ),
                ]
            )
        fig = plots.panel_grid(
            rows,
            title="Fig. 5.10: the foot against time for several joint settings",
            point_labels={
                "experiment": "experiments' end, mean ± sd of 5 subjects (Table 5.1)",
                "thesis": "thesis simulation end (sec. 5.3.2)",
                "stop": "granrs stop",
            },
            row_height=4.4,
        )
        links.append(
            ctx.add_figure(
                "fig_5_10_depth_velocity.png",
                plots.png_bytes(fig),
                "Fig. 5.10: foot depth and velocity for several joint settings",
            )
            + "\n\n*Left: Fig. 5.10 (a), foot depth against time; right: Fig. 5.10 (b), "
            "downward foot velocity; top: h1, bottom: h2.*"
        )

        springs = [s for s in settings if math.isfinite(s.k)]
        panels = []
        for key, name, unit_label in (
            ("depth", "foot depth at the stop", "depth [mm]"),
            ("t_s", "stopping time", "t_s [ms]"),
        ):
            curves, lines = [], []
            for i, (h, speed) in enumerate(_HEIGHT_SPEEDS.items()):
                values = np.array([getattr(runs[(s.name, h)], key) for s in springs])
                ks = np.array([s.k for s in springs])
                curves.append(plots.Curve(ks, values, i, f"granrs, {h}, {speed} m/s", marker="."))
                thesis = _human_coefficients(h)[1]
                ref = thesis["depth_sim"] if key == "depth" else thesis["t_s_sim"]
                lines.append(plots.RefLine(ref, f"thesis simulation, {h}", i, "--"))
                mean = means[h]["depth_mean" if key == "depth" else "t_s_mean"][0]
                lines.append(plots.RefLine(mean, f"experiments' mean, {h}", i, ":"))
                locked = getattr(runs[(settings[0].name, h)], key)
                lines.append(plots.RefLine(locked, f"granrs locked, {h}", i, "-."))
            panels.append(
                plots.Panel(
                    f"{name} against the joint stiffness (ζ = {_LEG_DAMPING_RATIO:g})",
                    unit_label,
                    curves,
                    lines=lines,
                    xlabel="joint stiffness k [N m/rad] (ankle, knee and hip)",
                    x_scale=1.0,
                    y_scale=1e3,
                    xlog=True,
                    legend=key == "depth",
                )
            )
        fig = plots.panel_grid([panels], row_height=4.8, width=12.0)
        links.append(
            ctx.add_figure(
                "fig_5_joint_stiffness.png",
                plots.png_bytes(fig),
                "Foot depth and stopping time against the joint stiffness",
            )
        )
    return f"""### Fig. 5.10: the foot against time

Foot depth and downward velocity at both speeds for: {", ".join(shown)}; the experiments'
end points (the mean ± sd of the five subjects' means, Table 5.1), the thesis's simulated end
points (sec. 5.3.2) and the granrs stops. The second figure: depth and t_s of the
spring-damper settings against k, with the thesis's simulation (dashed), the experiments'
mean (dotted) and the locked leg (dash-dotted).

{chr(10).join(chr(10) + link for link in links)}
"""


@register_chapter("5", "Chapter 5: the leg")
def chapter_5(ctx: ReportContext) -> str:
    """Chapter 5: the leg against Table 5.1 and sec. 5.3.2, the joints, Fig. 5.10."""
    table_5_1, means = _ch5_table_5_1(ctx)
    study, settings, runs, best = _ch5_joint_study(ctx, means)
    figures = _ch5_figures(ctx, means, settings, runs, best)
    return "\n".join(
        [
            "One leg of the thesis's average subject landing on both feet on fine sand "
            "(rho_g = 1600 kg/m³, sec. 5.3.2): foot, shank, thigh and half of head-arms-trunk "
            "(half the body), segment data from Dempster as tabulated by Winter, scaled to "
            "75.35 kg and 1.78 m; posture at touchdown: knee and hip flexed 20°, trunk 10° "
            "forward, flat foot (granrs assumptions; the thesis gives none). The sole is a "
            "box of the foot's length and the shoe's width (MODEL.md), the coefficients the "
            "thesis's for each speed (sec. 5.3.2), the force at the tip (the sole). The "
            "thesis's human model (SolidWorks, GrabCAD parts) is not published, so this "
            "chapter compares end results only.",
            "",
            table_5_1,
            study,
            figures,
        ]
    )


# --------------------------------------------------------------------------------------
# The report
# --------------------------------------------------------------------------------------


def _anchor(title: str) -> str:
    """The GitHub heading anchor of ``title``."""
    kept = "".join(c for c in title.lower() if c.isalnum() or c in " -_")
    return kept.replace(" ", "-")


def _header(ctx: ReportContext, chapters: Sequence[Chapter], dt: float, seconds: float) -> str:
    """The report's header: what was run, how to reproduce, summary, contents."""
    settings = sorted(ctx.settings)
    sign_models = ", ".join(sorted({s for s, _ in settings})) or "n/a"
    apply_at = ", ".join(sorted({a for _, a in settings})) or "n/a"
    date = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    chapter_args = "".join(f" --chapter {c.key}" for c in chapters)
    chapter_keys = repr(tuple(c.key for c in chapters)).replace("'", '"')
    contents = "\n".join(f"- [{c.title}](#{_anchor(c.title)})" for c in chapters)
    headlines = "\n".join(f"- {h}" for h in ctx.headlines) or "- (no findings)"
    return f"""# granrs reproduction report

granrs reproduces the simulations of the thesis "Bipedal impact with granular matter": a
resistance force of dynamic drag plus static depth-dependent terms acting on rods sinking
into sand. This report runs the thesis's cases and sets the results beside its tables.

## What was run

- granrs {__version__} (Python {platform.python_version()}, numpy {np.__version__},
  {platform.system()} {platform.machine()}), generated {date}
- chapters: {", ".join(c.key for c in chapters)}
- integrator: fixed-step RK4 with located events, dt = {dt:g} s ({1.0 / dt:g} Hz; the
  thesis ran at 10 kHz)
- sign model of the static terms: {sign_models}
- point of application of the resistance force: {apply_at} (the thesis's CAD runs, sec.
  3.3.2)
- {ctx.runs} simulations in {ctx.sim_seconds:.2f} s ({seconds:.1f} s with figures)
- reference numbers: the thesis's tables as shipped in `granrs.data` (see
  `granrs.data.provenance(name)`), and a few values the thesis gives only in its text
  (cited where used); nothing is edited to fit
- relative errors: the thesis's eq. 3.21, ε = |reference - granrs| / |reference|

## How to reproduce

```sh
granrs reproduce --out DIR --dt {dt:g}{chapter_args}
```

or, from Python, `granrs.report.reproduce("DIR", chapters={chapter_keys}, dt={dt:g})`.

## Summary and known gaps

{headlines}

## Contents

{contents}
"""


def _validate_out_dir(out_dir: Path) -> None:
    """Reject an output path that exists and is not a directory (field ``out_dir``)."""
    if out_dir.exists() and not out_dir.is_dir():
        raise InvalidParameterError(
            f"the output directory {str(out_dir)!r} exists and is not a directory",
            field="out_dir",
        )


def _write(out_dir: Path, report: str, figures: Mapping[str, bytes]) -> Path:
    """Write the report and figures to a temporary directory, then move them into place.

    A new ``out_dir`` is created by one rename. In an existing ``out_dir`` the report file
    and the ``figures`` folder are replaced (the old folder is removed); other files are
    left alone.
    """
    out_dir = out_dir.absolute()
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.tmp-", dir=out_dir.parent))
    try:
        # mkdtemp's folder is private (0700); the report folder gets the usual umask.
        new = staging / "report"
        (new / FIGURES_DIR).mkdir(parents=True)
        for name, png in figures.items():
            (new / FIGURES_DIR / name).write_bytes(png)
        (new / REPORT_NAME).write_text(report, encoding="utf-8")
        if not out_dir.exists():
            os.replace(new, out_dir)
            return out_dir / REPORT_NAME
        _validate_out_dir(out_dir)
        old_figures = out_dir / FIGURES_DIR
        if old_figures.exists():
            os.replace(old_figures, staging / "old-figures")
        os.replace(new / FIGURES_DIR, old_figures)
        os.replace(new / REPORT_NAME, out_dir / REPORT_NAME)
        return out_dir / REPORT_NAME
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def reproduce(
    out_dir: str | os.PathLike[str],
    *,
    chapters: Sequence[str] | None = None,
    dt: float = 1e-4,
    progress: bool = True,
) -> Path:
    """Run the thesis's cases and write the reproduction report; return its path.

    Writes ``out_dir/README.md`` (Markdown) and its PNG figures in ``out_dir/figures/``.
    Everything is computed in memory before anything is written, and the files are moved
    into place at the end, so an error leaves ``out_dir`` as it was (a new ``out_dir`` is
    not created). In an existing ``out_dir`` the report and the ``figures`` folder are
    replaced.

    Args:
        out_dir: the output directory (created if missing).
        chapters: the keys of the chapters to run, from :data:`CHAPTERS` (``"3"``: the free
            link, ``"4"``: the two-link chain, ``"5"``: the leg); None (the default) runs
            every chapter, as the command line does.
        dt: the integration step of every scene [s]; an invalid one raises the scene's
            :class:`~granrs.errors.InvalidParameterError` (``field="dt"``).
        progress: print one line per table and figure to stderr.

    Returns:
        The path of the report, ``out_dir/README.md``.

    Raises:
        UnknownNameError: an unknown chapter (``field="chapters"``).
        InvalidParameterError: an invalid ``dt`` (``field="dt"``) or an ``out_dir`` that is
            a file (``field="out_dir"``).
    """
    out_path = Path(out_dir)
    if chapters is None:
        chapters = tuple(CHAPTERS)
    elif isinstance(chapters, str):
        chapters = (chapters,)
    selected = []
    for key in chapters:
        if key not in CHAPTERS:
            raise UnknownNameError(
                f"unknown chapter {key!r}; available: {', '.join(CHAPTERS)}", field="chapters"
            )
        selected.append(CHAPTERS[key])
    if not selected:
        raise InvalidParameterError("no chapter selected", field="chapters")
    # The step is checked by a scene, the same rule every run uses (field "dt").
    cases.free_link(q_deg=0.0, v0=1.0, dt=dt)
    _validate_out_dir(out_path)

    start = time.perf_counter()
    ctx = ReportContext(dt=dt, progress=progress)
    bodies = []
    for chapter in selected:
        ctx.log(f"{chapter.title}")
        bodies.append(f"## {chapter.title}\n\n{chapter.build(ctx).strip()}\n")
    seconds = time.perf_counter() - start
    report = _header(ctx, selected, dt, seconds) + "\n" + "\n".join(bodies)
    path = _write(out_path, report, ctx.figures)
    ctx.log(f"wrote {path} and {len(ctx.figures)} figures in {seconds:.1f} s")
    return path


# The calibration chapter (issue 7) registers itself after chapter 5.
from . import report_calibration as _report_calibration  # noqa: E402, F401
