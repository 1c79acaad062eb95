"""Numbers and Markdown for the report: the thesis's relative error (eq. 3.21), number
formatting (``n/a`` for what is not finite) and GitHub Markdown tables.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from .. import data
from ..result import Result
from ..scene import Scene

__all__ = ["md_table", "relative_error"]


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


def _rms(values: Iterable[float]) -> tuple[float, int]:
    """Root mean square of the finite values and their count (NaN, 0 when there are none)."""
    finite = [v for v in values if math.isfinite(v)]
    if not finite:
        return math.nan, 0
    return math.sqrt(sum(v * v for v in finite) / len(finite)), len(finite)


def _rows(name: str) -> list[dict[str, Any]]:
    """The rows of a shipped table as dicts (numbers as float, text as str)."""
    frame = data.load(name, as_="numpy")
    columns = list(frame)
    n = len(frame[columns[0]]) if columns else 0
    return [
        {c: v.item() if isinstance(v, np.generic) else v for c in columns for v in [frame[c][i]]}
        for i in range(n)
    ]


def table_3_1_drop(q_deg: float) -> tuple[float, float]:
    """The fastest Table 3.1 drop at ``q_deg``: (q [deg], v0 [m/s], the measured mean)."""
    rows = [r for r in _rows("table_3_1") if r["q_deg"] == q_deg]
    if not rows:
        raise ValueError(f"Table 3.1 has no drop at q = {q_deg:g} deg")
    fastest = max(rows, key=lambda r: r["v0_mean"])
    return float(fastest["q_deg"]), float(fastest["v0_mean"])


def watch_caption(scene: Scene, what: str) -> str:
    """The caption of a free-link animation: ``what`` and the drop's q and v0, read from
    ``scene`` (as the animation's title reads them)."""
    return f"{what}: q = {scene.q_deg:g}°, v0 = {scene.v0:g} m/s"


def _status_note(result: Result) -> str:
    """`` (status)`` for a run that did not stop, else empty."""
    return "" if result.stopped else f" ({result.status})"
