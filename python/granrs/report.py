"""The reproduction report: run the thesis's cases and compare them with its tables.

:func:`reproduce` runs the chapters asked for, writes ``README.md`` (the report, Markdown)
and its PNG figures under ``figures/`` in an output directory, and returns the path of the
report. The command line ``granrs reproduce --out DIR`` calls it (see :mod:`granrs.cli`).

Chapters form a registry (:data:`CHAPTERS`): a chapter is a function that takes a
:class:`ReportContext`, runs its simulations through it, adds its figures and headline
numbers to it, and returns its Markdown text. :func:`register_chapter` adds one, so the
chain (chapter 4) and the leg (chapter 5) can follow the free link (chapter 3) without
touching the rest.

Chapter 3 (the free link) compares granrs with:

* Table 3.1 (the experiments: mean and sd of five drops), with Table 3.4 coefficients and
  the force applied at the tip, as the thesis's CAD runs did (sec. 3.3.2);
* Table 3.5 (the thesis's own simulation), every row, with the relative error of eq. 3.21;
  and the same with the Table 3.2 closed-form coefficients;
* Tables 3.6 (forces) and 3.7 (energies) at the speeds of sec. 3.4 (``sweep_3_4``);
* Figs. 3.15-3.20 (depth and tip velocity against time) and 3.22-3.23 (depth and stopping
  time against the impact angle alpha).

Relative errors follow the thesis's eq. 3.21, epsilon = |reference - granrs| / |reference|,
the reference being the experiment or the thesis's table. Every number in the report is
computed at run time; nothing is edited to fit.

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
        e_d, e_t = errors(runs[coefficients])
        variant_rows.append(
            [
                label,
                _pct(clean_median(e_d)[0]),
                _pct(_median(e_d)[0]),
                _pct(clean_median(e_t)[0]),
                _pct(_median(e_t)[0]),
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
  `granrs.data.provenance(name)`); nothing is edited to fit
- relative errors: the thesis's eq. 3.21, ε = |reference - granrs| / |reference|

## How to reproduce

```sh
granrs reproduce --out DIR --dt {dt:g}{chapter_args}
```

or, from Python, `granrs.report.reproduce("DIR", dt={dt:g})`.

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
    chapters: Sequence[str] = ("3",),
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
            link).
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
    if isinstance(chapters, str):
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
