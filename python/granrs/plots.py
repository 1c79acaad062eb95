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

Units on the axes are ms and mm for readability; the inputs are SI (s, m, m/s).
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

__all__ = [
    "AlphaPoint",
    "AlphaSeries",
    "EndPoint",
    "SpeedCurve",
    "alpha_figure",
    "impact_figure",
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
