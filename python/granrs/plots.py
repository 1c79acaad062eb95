"""Figures of the reproduction report (:mod:`granrs.report`), drawn with matplotlib.

The functions here take plain numbers and arrays (no scenes, no simulation) and return a
:class:`matplotlib.figure.Figure` built without :mod:`matplotlib.pyplot`, so nothing here
touches the global backend or opens a window; :func:`png_bytes` renders a figure to PNG with
the Agg renderer.

* :func:`impact_figure`: the thesis's Figs. 3.15-3.20 for one impact angle: tip depth and tip
  vertical velocity against time for several drop speeds (granrs curves), with the
  experiments' end points (Table 3.1, mean +- sd) and the thesis's simulated end points
  (Table 3.5).
* :func:`alpha_figure`: the thesis's Figs. 3.22-3.23: a stopping result (depth or t_s)
  against the impact angle alpha = 90 deg - q for the three simulated speeds.
* :func:`panel_grid`: a grid of panels, each a few curves (:class:`Curve`), reference end
  points (:class:`Point`) and horizontal reference lines (:class:`RefLine`) against time or
  any other variable: the chain's and the leg's figures (chapters 4 and 5).

Units on the axes are ms and mm for readability; the inputs are SI (s, m, m/s).
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

__all__ = [
    "POINT_KINDS",
    "AlphaPoint",
    "AlphaSeries",
    "Curve",
    "EndPoint",
    "Panel",
    "Point",
    "RefLine",
    "SpeedCurve",
    "alpha_figure",
    "impact_figure",
    "panel_grid",
    "png_bytes",
]

#: One colour per drop speed (colour-blind friendly "tab" colours), fastest first.
SPEED_COLOURS: tuple[str, ...] = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple")

_MS = 1e3  # s -> ms
_MM = 1e3  # m -> mm


@dataclass(frozen=True)
class EndPoint:
    """The end of a penetration phase: stopping time and depth, with optional sds.

    Attributes:
        t_s: stopping time [s].
        depth: depth of the tip at the stop [m].
        t_s_sd: standard deviation of t_s [s] (NaN: no error bar).
        depth_sd: standard deviation of the depth [m] (NaN: no error bar).
    """

    t_s: float
    depth: float
    t_s_sd: float = math.nan
    depth_sd: float = math.nan


@dataclass(frozen=True)
class SpeedCurve:
    """One drop speed of an impact figure: the granrs time series and the reference ends.

    Attributes:
        v0: drop speed [m/s] (for the legend).
        t: time [s].
        depth: tip depth [m] (positive below the surface).
        v_tip_y: tip vertical velocity [m/s], y up (negative while sinking).
        experiment: the measured end point (Table 3.1), or None.
        thesis: the thesis's simulated end point (Table 3.5), or None when it has no row.
    """

    v0: float
    t: np.ndarray
    depth: np.ndarray
    v_tip_y: np.ndarray
    experiment: EndPoint | None = None
    thesis: EndPoint | None = None


@dataclass(frozen=True)
class AlphaSeries:
    """One speed of an alpha figure: granrs values at each angle.

    Attributes:
        label: legend text, e.g. ``"v01 = 2.21-2.27 m/s"``.
        alpha_deg: impact angles alpha = 90 - q [deg].
        values: the plotted quantity at each angle, SI (m or s).
    """

    label: str
    alpha_deg: np.ndarray
    values: np.ndarray


@dataclass(frozen=True)
class AlphaPoint:
    """One reference point of an alpha figure (a thesis Table 3.5 row).

    Attributes:
        alpha_deg: impact angle alpha = 90 - q [deg].
        value: the plotted quantity, SI (m or s).
        series: index of the speed series it belongs to (its colour), or None for a point
            that belongs to none of them (drawn grey).
        doubtful: the source row carries a note (drawn hollow).
    """

    alpha_deg: float
    value: float
    series: int | None
    doubtful: bool = False


def _colour(i: int) -> str:
    """The colour of speed ``i``."""
    return SPEED_COLOURS[i % len(SPEED_COLOURS)]


def png_bytes(fig: Figure, dpi: int = 110) -> bytes:
    """Render ``fig`` to PNG bytes with the Agg renderer (no display, no global state)."""
    FigureCanvasAgg(fig)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi, metadata={"Software": None})
    return buffer.getvalue()


def _finite(x: float) -> bool:
    """Whether ``x`` is a finite number (an error bar to draw)."""
    return x is not None and math.isfinite(x)


def impact_figure(
    q_deg: float, curves: Sequence[SpeedCurve], figure_numbers: tuple[str, str]
) -> Figure:
    """Depth and tip velocity against time at one impact angle (thesis Figs. 3.15-3.20).

    Left panel: tip depth [mm] against time [ms]; right panel: downward tip velocity
    -v_y,T [m/s] against time [ms]. One colour per speed: the granrs curve as a line, the
    experiment's end point (t_s mean, depth mean) as a filled circle with sd error bars (on
    the velocity panel at zero velocity, with the t_s sd as a horizontal bar) and the
    thesis's simulated end point as a hollow square.

    Args:
        q_deg: the impact angle from the vertical [deg] (for the title).
        curves: one entry per drop speed, fastest first.
        figure_numbers: the thesis figure numbers of the depth and the velocity panel,
            e.g. ``("3.15", "3.16")``.
    """
    fig = Figure(figsize=(11.0, 4.4), layout="constrained")
    ax_d, ax_v = fig.subplots(1, 2)
    for i, c in enumerate(curves):
        colour = _colour(i)
        t_ms = np.asarray(c.t) * _MS
        ax_d.plot(t_ms, np.asarray(c.depth) * _MM, color=colour, lw=1.8)
        ax_v.plot(t_ms, -np.asarray(c.v_tip_y), color=colour, lw=1.8)
        if c.experiment is not None:
            e = c.experiment
            xerr = e.t_s_sd * _MS if _finite(e.t_s_sd) else None
            yerr = e.depth_sd * _MM if _finite(e.depth_sd) else None
            style = {"fmt": "o", "color": colour, "mec": "black", "ms": 7, "capsize": 3}
            ax_d.errorbar(e.t_s * _MS, e.depth * _MM, xerr=xerr, yerr=yerr, **style)
            ax_v.errorbar(e.t_s * _MS, 0.0, xerr=xerr, **style)
        if c.thesis is not None:
            th = c.thesis
            style = {"marker": "s", "ms": 8, "mfc": "none", "mec": colour, "mew": 2, "ls": ""}
            ax_d.plot(th.t_s * _MS, th.depth * _MM, **style)
            ax_v.plot(th.t_s * _MS, 0.0, **style)

    handles: list[Line2D] = [
        Line2D([], [], color=_colour(i), lw=1.8, label=f"granrs, v0 = {c.v0:.2f} m/s")
        for i, c in enumerate(curves)
    ]
    handles.append(
        Line2D(
            [],
            [],
            marker="o",
            color="grey",
            mec="black",
            ls="",
            ms=7,
            label="experiment end (Table 3.1, mean ± sd)",
        )
    )
    handles.append(
        Line2D(
            [],
            [],
            marker="s",
            mfc="none",
            mec="grey",
            mew=2,
            ls="",
            ms=8,
            label="thesis simulation end (Table 3.5)",
        )
    )
    ax_d.set_xlabel("time t [ms]")
    ax_d.set_ylabel("tip depth d [mm]")
    ax_d.set_title(f"Fig. {figure_numbers[0]}: tip depth, q = {q_deg:g}°")
    ax_v.set_xlabel("time t [ms]")
    ax_v.set_ylabel(r"downward tip velocity $-v_{y,T}$ [m/s]")
    ax_v.set_title(f"Fig. {figure_numbers[1]}: tip vertical velocity, q = {q_deg:g}°")
    ax_v.axhline(0.0, color="black", lw=0.6)
    for ax in (ax_d, ax_v):
        ax.grid(True, alpha=0.3)
        ax.set_xlim(left=0.0)
    ax_d.set_ylim(bottom=0.0)
    ax_d.legend(handles=handles, loc="lower right", fontsize=8)
    return fig


def alpha_figure(
    series: Sequence[AlphaSeries],
    points: Sequence[AlphaPoint],
    *,
    quantity: str,
    unit_scale: float,
    unit: str,
    title: str,
    other_label: str = "thesis, other speeds (Table 3.5)",
) -> Figure:
    """A stopping result against the impact angle alpha (thesis Figs. 3.22-3.23).

    granrs values are lines with dots, one colour per speed; thesis points are diamonds in
    the colour of their speed (hollow when the source row is doubtful, grey when the point
    belongs to none of the speeds).

    Args:
        series: granrs values per speed.
        points: the thesis's points.
        quantity: the y-axis quantity, e.g. ``"tip depth at the stop d"``.
        unit_scale: factor from SI to the plotted unit (1e3 for mm or ms).
        unit: the plotted unit, e.g. ``"mm"``.
        title: the figure title (cite the thesis figure number).
        other_label: legend text of the grey points.
    """
    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    ax = fig.subplots()
    handles: list[Line2D] = []
    for i, s in enumerate(series):
        order = np.argsort(s.alpha_deg)
        ax.plot(
            np.asarray(s.alpha_deg)[order],
            np.asarray(s.values)[order] * unit_scale,
            color=_colour(i),
            marker=".",
            ms=7,
            lw=1.6,
        )
        handles.append(Line2D([], [], color=_colour(i), marker=".", lw=1.6, label=s.label))
    has_doubtful = has_other = False
    for p in points:
        colour = "grey" if p.series is None else _colour(p.series)
        has_other |= p.series is None
        has_doubtful |= p.doubtful
        ax.plot(
            p.alpha_deg,
            p.value * unit_scale,
            marker="D" if p.series is not None else "^",
            ms=7,
            ls="",
            mfc="none" if p.doubtful else colour,
            mec="black" if not p.doubtful else colour,
            mew=1.0 if not p.doubtful else 2.0,
        )
    handles.append(
        Line2D(
            [], [], marker="D", color="grey", mec="black", ls="", ms=7, label="thesis (Table 3.5)"
        )
    )
    if has_doubtful:
        handles.append(
            Line2D(
                [],
                [],
                marker="D",
                mfc="none",
                mec="grey",
                mew=2,
                ls="",
                ms=7,
                label="thesis, doubtful row (has a note)",
            )
        )
    if has_other:
        handles.append(
            Line2D([], [], marker="^", color="grey", mec="black", ls="", ms=7, label=other_label)
        )
    ax.set_xlabel(r"impact angle $\alpha = 90^\circ - q$ [deg]")
    ax.set_ylabel(f"{quantity} [{unit}]")
    ax.set_title(title)
    ax.set_xlim(0.0, 95.0)
    ax.set_xticks(np.arange(0.0, 91.0, 15.0))
    ax.grid(True, alpha=0.3)
    ax.legend(handles=handles, fontsize=8, loc="best")
    return fig


# --------------------------------------------------------------------------------------
# Panel grids (chapters 4 and 5)
# --------------------------------------------------------------------------------------

#: How each kind of :class:`Point` is drawn: matplotlib marker keywords (the colour is the
#: point's own; a hollow marker takes it as its edge). ``experiment``: a measured end point
#: with sd bars; ``thesis``: the thesis's simulated end point; ``stop``: a granrs stop;
#: ``chosen``: a selected setting; ``other``: any other marked value.
POINT_KINDS: dict[str, dict[str, Any]] = {
    "experiment": {"marker": "o", "ms": 7, "mec": "black"},
    "thesis": {"marker": "s", "ms": 8, "mfc": "none", "mew": 2},
    "stop": {"marker": "x", "ms": 8, "mew": 2},
    "chosen": {"marker": "*", "ms": 14, "mec": "black"},
    "other": {"marker": "D", "ms": 8, "mfc": "none", "mew": 2},
}


@dataclass(frozen=True)
class Curve:
    """One line of a panel.

    Attributes:
        x: abscissa, SI (e.g. time [s]); scaled by the panel's ``x_scale``.
        y: ordinate, SI; scaled by the panel's ``y_scale``.
        colour: index into :data:`SPEED_COLOURS`.
        label: legend text (None: not in the legend).
        style: line style (``"-"``, ``"--"``, ``":"``).
        marker: point marker (``""``: none).
        width: line width.
    """

    x: np.ndarray
    y: np.ndarray
    colour: int = 0
    label: str | None = None
    style: str = "-"
    marker: str = ""
    width: float = 1.8


@dataclass(frozen=True)
class Point:
    """A reference point of a panel (an end point, a stop, a chosen setting).

    Attributes:
        x: abscissa, SI.
        y: ordinate, SI.
        colour: index into :data:`SPEED_COLOURS`, or None for grey.
        kind: one of :data:`POINT_KINDS`.
        x_sd: standard deviation of x, SI (NaN: no error bar).
        y_sd: standard deviation of y, SI (NaN: no error bar).
    """

    x: float
    y: float
    colour: int | None = 0
    kind: str = "experiment"
    x_sd: float = math.nan
    y_sd: float = math.nan


@dataclass(frozen=True)
class RefLine:
    """A horizontal reference line (a target value) with its legend text.

    Attributes:
        y: the value, SI.
        label: legend text.
        colour: index into :data:`SPEED_COLOURS`, or None for black.
        style: line style.
    """

    y: float
    label: str
    colour: int | None = None
    style: str = "--"


@dataclass(frozen=True)
class Panel:
    """One panel of :func:`panel_grid`.

    Attributes:
        title: the panel title (cite the thesis figure number).
        ylabel: y-axis label, in the plotted unit.
        curves: the lines.
        points: the reference points.
        lines: horizontal reference lines.
        xlabel: x-axis label, in the plotted unit.
        x_scale: factor from SI to the plotted x unit (1e3: s -> ms).
        y_scale: factor from SI to the plotted y unit.
        xlog: logarithmic x axis.
        y_from_zero: start the y axis at zero.
        ylim: the y-axis range in the plotted unit (None: automatic).
        zero_line: draw y = 0.
        legend: draw the legend in this panel (curves with a label, point kinds and
            reference lines of this panel).
    """

    title: str
    ylabel: str
    curves: Sequence[Curve] = ()
    points: Sequence[Point] = ()
    lines: Sequence[RefLine] = ()
    xlabel: str = "time t [ms]"
    x_scale: float = _MS
    y_scale: float = 1.0
    xlog: bool = False
    y_from_zero: bool = True
    ylim: tuple[float, float] | None = None
    zero_line: bool = False
    legend: bool = False


def _maybe_colour(i: int | None, default: str) -> str:
    """The colour of index ``i``, or ``default`` when it is None."""
    return default if i is None else _colour(i)


def _draw_panel(ax: Axes, panel: Panel, point_labels: dict[str, str]) -> None:
    """Draw ``panel`` on the axes ``ax``."""
    handles: list[Line2D] = []
    labels_seen: set[str] = set()
    for c in panel.curves:
        colour = _colour(c.colour)
        ax.plot(
            np.asarray(c.x) * panel.x_scale,
            np.asarray(c.y) * panel.y_scale,
            color=colour,
            ls=c.style,
            lw=c.width,
            marker=c.marker or None,
            ms=6,
        )
        if c.label and c.label not in labels_seen:
            labels_seen.add(c.label)
            handles.append(
                Line2D(
                    [],
                    [],
                    color=colour,
                    ls=c.style,
                    lw=c.width,
                    marker=c.marker or None,
                    label=c.label,
                )
            )
    for line in panel.lines:
        colour = _maybe_colour(line.colour, "black")
        ax.axhline(line.y * panel.y_scale, color=colour, ls=line.style, lw=1.2)
        handles.append(Line2D([], [], color=colour, ls=line.style, lw=1.2, label=line.label))
    kinds: list[str] = []
    for p in panel.points:
        if p.kind not in POINT_KINDS:
            raise ValueError(f"unknown point kind {p.kind!r}; known: {', '.join(POINT_KINDS)}")
        colour = _maybe_colour(p.colour, "grey")
        style = dict(POINT_KINDS[p.kind])
        if style.get("mfc") == "none":
            style["mec"] = colour
        x, y = p.x * panel.x_scale, p.y * panel.y_scale
        xerr = p.x_sd * panel.x_scale if _finite(p.x_sd) else None
        yerr = p.y_sd * panel.y_scale if _finite(p.y_sd) else None
        if xerr is not None or yerr is not None:
            ax.errorbar(x, y, xerr=xerr, yerr=yerr, fmt="none", ecolor=colour, capsize=3)
        ax.plot(x, y, ls="", color=colour, **style)
        if p.kind not in kinds:
            kinds.append(p.kind)
    for kind in kinds:
        style = dict(POINT_KINDS[kind])
        if style.get("mfc") == "none":
            style["mec"] = "grey"
        handles.append(
            Line2D([], [], color="grey", ls="", label=point_labels.get(kind, kind), **style)
        )
    if panel.zero_line:
        ax.axhline(0.0, color="black", lw=0.6)
    if panel.xlog:
        ax.set_xscale("log")
    ax.set_xlabel(panel.xlabel)
    ax.set_ylabel(panel.ylabel)
    ax.set_title(panel.title, fontsize=10)
    ax.grid(True, alpha=0.3)
    if not panel.xlog:
        ax.set_xlim(left=0.0)
    if panel.ylim is not None:
        ax.set_ylim(*panel.ylim)
    elif panel.y_from_zero:
        ax.set_ylim(bottom=0.0)
    if panel.legend and handles:
        ax.legend(handles=handles, fontsize=7, loc="best")


def panel_grid(
    rows: Sequence[Sequence[Panel]],
    *,
    title: str | None = None,
    point_labels: dict[str, str] | None = None,
    width: float = 11.0,
    row_height: float = 3.8,
) -> Figure:
    """A grid of panels, one row per entry of ``rows`` (every row the same length).

    Args:
        rows: the panels, row by row.
        title: the figure's title (cite the thesis figure numbers), or None.
        point_labels: legend text of each point kind used (default: the kind's name).
        width: figure width [inch].
        row_height: height of one row [inch].
    """
    if not rows or not rows[0]:
        raise ValueError("panel_grid needs at least one panel")
    n_cols = len(rows[0])
    if any(len(row) != n_cols for row in rows):
        raise ValueError("every row of panel_grid must have the same number of panels")
    fig = Figure(figsize=(width, row_height * len(rows)), layout="constrained")
    axes = fig.subplots(len(rows), n_cols, squeeze=False)
    for i, row in enumerate(rows):
        for j, panel in enumerate(row):
            _draw_panel(axes[i][j], panel, point_labels or {})
    if title:
        fig.suptitle(title)
    return fig
