"""The drawing behind :func:`granrs.animate` (see :mod:`granrs.animate` for what a frame
shows): the body placed from the recorded coordinates, the immersed parts, the force arrows
and :class:`ImpactAnimation`. Kept apart because it imports matplotlib, which
``import granrs`` should not pay for.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib import animation as mpl_animation
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import FancyArrowPatch, Patch, Polygon

from ._files import replacing
from ._progress import progress_bar
from .animate import TERM_COLOURS, check_output
from .bodies import DEFAULT_CHORDS
from .errors import InvalidParameterError

if TYPE_CHECKING:
    from .result import Result

__all__ = ["ANKLE_HEIGHT_FRACTION", "ImpactAnimation"]

#: Height of the ankle above the sole, fraction of body height H (Winter 2009, Fig. 4.1;
#: the core's ``leg_defaults::ANKLE_HEIGHT``, which it does not expose).
ANKLE_HEIGHT_FRACTION = 0.039
#: Longest force arrow, as a fraction of the body's reference length (rod length, tibia).
_ARROW_FRACTION = 0.6
#: The narrowest figure [in]: a tall, thin scene (a vertical rod) still leaves its axes'
#: cell room for the title, clear of the legend's column.
_MIN_WIDTH = 7.2
_MM = 1e3


# --- geometry -------------------------------------------------------------------------------


def _axis(q: np.ndarray) -> np.ndarray:
    """Unit axes e = (sin q, cos q) of angles from the vertical, shape (n, 2)."""
    return np.stack([np.sin(q), np.cos(q)], axis=-1)


def _normal(q: np.ndarray) -> np.ndarray:
    """Normals n = (cos q, -sin q) = de/dq, shape (n, 2)."""
    return np.stack([np.cos(q), -np.sin(q)], axis=-1)


def _local(joint: np.ndarray, q: np.ndarray, s: float, n: float) -> np.ndarray:
    """World position of the point (s, n) of a link with joint ``joint`` and angle ``q``
    (``rust/body/mechanism.rs``: J + s e + n n), shape (n_frames, 2) [m]."""
    return joint + s * _axis(q) + n * _normal(q)


def _clip_below_surface(polygon: np.ndarray) -> np.ndarray:
    """The part of a convex polygon (k, 2) with y <= 0 (Sutherland-Hodgman against y = 0);
    shape (m, 2), m = 0 when nothing is immersed."""
    out: list[np.ndarray] = []
    k = len(polygon)
    for i in range(k):
        a, b = polygon[i], polygon[(i + 1) % k]
        a_in, b_in = a[1] <= 0.0, b[1] <= 0.0
        if a_in:
            out.append(a)
        if a_in != b_in:
            t = a[1] / (a[1] - b[1])
            out.append(np.array([a[0] + t * (b[0] - a[0]), 0.0]))
    return np.array(out).reshape(-1, 2)


def _polygon_centroid(polygon: np.ndarray) -> np.ndarray | None:
    """Area centroid of a simple polygon (k, 2), or None if its area is zero."""
    if len(polygon) < 3:
        return None
    x, y = polygon[:, 0], polygon[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    if abs(area) < 1e-18:
        return None
    return np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6.0 * area)


def _rod_outline(tip: np.ndarray, top: np.ndarray, diameter: float) -> np.ndarray:
    """The rectangle of a rod from ``tip`` to ``top`` (each (n, 2)), shape (n, 4, 2)."""
    along = top - tip
    along = along / np.linalg.norm(along, axis=-1, keepdims=True)
    side = 0.5 * diameter * np.stack([along[:, 1], -along[:, 0]], axis=-1)
    return np.stack([tip + side, top + side, top - side, tip - side], axis=1)


@dataclass
class _Contact:
    """One contact's drawing data over the frames (world coordinates [m])."""

    name: str
    #: Outline of the contact's shape, (n, k, 2): a rod, or the foot's contact box.
    shape: np.ndarray
    #: The reference point whose depth the series records (rod tip, middle of the sole), (n, 2).
    reference: np.ndarray
    #: Point of application of the force, (n, 2).
    applied: np.ndarray
    #: Force of each term that the scene has on, (n, 2) [N].
    forces: dict[str, np.ndarray]

    @property
    def total(self) -> np.ndarray:
        """The sum of the recorded terms, (n, 2) [N]."""
        return sum(self.forces.values(), np.zeros_like(self.applied))


@dataclass
class _Pose:
    """The body over the frames: filled outlines, stick segments and joints [m]."""

    outlines: list[np.ndarray]  # each (n, k, 2)
    sticks: np.ndarray | None  # (n, m, 2): a polyline through the joints
    contacts: list[_Contact]
    #: Reference length for the force scale [m].
    size: float


def _column(series: dict[str, np.ndarray], name: str, frames: np.ndarray) -> np.ndarray:
    t = np.asarray(series["t"], dtype=float)
    return np.interp(frames, t, np.asarray(series[name], dtype=float))


def _contact_forces(
    series: dict[str, np.ndarray], prefix: str, frames: np.ndarray
) -> dict[str, np.ndarray]:
    """The recorded force terms of one contact as vectors, (n, 2) each [N]."""
    zeros = np.zeros_like(frames)
    out: dict[str, np.ndarray] = {}
    if f"{prefix}F_dx" in series:
        out["drag"] = np.stack(
            [_column(series, f"{prefix}F_dx", frames), _column(series, f"{prefix}F_dy", frames)],
            axis=-1,
        )
    if f"{prefix}F_sh" in series:
        out["static_h"] = np.stack([_column(series, f"{prefix}F_sh", frames), zeros], axis=-1)
    if f"{prefix}F_sv" in series:
        out["static_v"] = np.stack([zeros, _column(series, f"{prefix}F_sv", frames)], axis=-1)
    return out


def _rod_centroid(tip: np.ndarray, top: np.ndarray, length: float) -> np.ndarray:
    """Centroid E of a rod's immersed part: T + l/2 e with l = min(d / cos q, L)
    (``rust/body/rod.rs``); the tip where nothing is immersed."""
    e = (top - tip) / length
    depth = np.maximum(-tip[:, 1], 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        immersed = np.where(depth >= length * e[:, 1], length, depth / e[:, 1])
    return tip + 0.5 * immersed[:, None] * e


def _pose(result: Result, frames: np.ndarray) -> _Pose:
    """Place the body at each frame from the recorded coordinates and the scene."""
    scene, series = result.scene, result.series
    assert series is not None
    col = lambda name: _column(series, name, frames)  # noqa: E731
    centroid = scene.apply_at == "centroid"
    if scene.kind == "free_link":
        centre = np.stack([col("x"), col("y")], axis=-1)
        q = col("q")
        tip = _local(centre, q, -0.5 * scene.length, 0.0)
        top = _local(centre, q, 0.5 * scene.length, 0.0)
        rod = _rod_outline(tip, top, scene.diameter)
        applied = _rod_centroid(tip, top, scene.length) if centroid else tip
        contact = _Contact("rod", rod, tip, applied, _contact_forces(series, "", frames))
        return _Pose([rod], None, [contact], scene.length)
    if scene.kind == "chain":
        pin = np.stack([col("x_pin"), col("y_pin")], axis=-1)
        outlines, contacts = [], []
        for i in range(2):
            tip = _local(pin, col(f"q{i + 1}"), -scene.length, 0.0)
            rod = _rod_outline(tip, pin, scene.diameter)
            applied = _rod_centroid(tip, pin, scene.length) if centroid else tip
            outlines.append(rod)
            forces = _contact_forces(series, f"c{i}.", frames)
            contacts.append(_Contact(f"link{i + 1}", rod, tip, applied, forces))
        return _Pose(outlines, None, contacts, scene.length)
    if scene.kind == "leg":
        return _leg_pose(result, frames)
    if scene.kind == "linkage":
        return _linkage_pose(result, frames)
    raise InvalidParameterError(f"cannot draw body {scene.kind!r}", field="body")


def _linkage_pose(result: Result, frames: np.ndarray) -> _Pose:
    """A linkage: each link a bar from its joint along its axis (its joints placed on their
    parents, the root link at the root), each contact's rod or box outline."""
    scene, series = result.scene, result.series
    assert series is not None
    col = lambda name: _column(series, name, frames)  # noqa: E731
    body = scene.body
    links = {link.name: link for link in body.links}  # type: ignore[union-attr]
    joint_of = {j.child: j for j in body.joints}  # type: ignore[union-attr]
    origin: dict[str, np.ndarray] = {}
    q: dict[str, np.ndarray] = {}
    for name in body.order:  # type: ignore[union-attr]
        q[name] = col(f"q_{name}")
        j = joint_of.get(name)
        if j is None:
            origin[name] = np.stack([col("x_root"), col("y_root")], axis=-1)
        else:
            origin[name] = _local(origin[j.parent], q[j.parent], *j.at)
    size = max(link.length for link in links.values())
    bars = [
        _rod_outline(origin[n], _local(origin[n], q[n], links[n].length, 0.0), 0.04 * size)
        for n in body.order  # type: ignore[union-attr]
    ]
    contacts = []
    several = len(body.contacts) > 1  # type: ignore[union-attr]
    for i, c in enumerate(body.contacts):  # type: ignore[union-attr]
        o, a = origin[c.link], q[c.link]
        s0, n0 = c.at
        length = c.length or 0.0
        if c.shape == "rod":
            tip = _local(o, a, s0, n0)
            top = _local(o, a, s0 + length, n0)
            shape = _rod_outline(tip, top, c.diameter or 0.0)
            reference = tip
        elif c.shape == "arc":
            # A thin band about the arc (10 % of its radius thick), through its vertices.
            r, start, end = c.radius or 0.0, c.start_deg or 0.0, c.end_deg or 0.0
            phi = np.radians(np.linspace(start, end, (c.chords or DEFAULT_CHORDS) + 1))
            band = [(s0 + k * r * np.cos(f), n0 + k * r * np.sin(f)) for k, f in
                    [(1.05, f) for f in phi] + [(0.95, f) for f in phi[::-1]]]  # fmt: skip
            shape = np.stack([_local(o, a, s, n) for s, n in band], axis=1)
            mid = math.radians(0.5 * (start + end))
            reference = _local(o, a, s0 + r * math.cos(mid), n0 + r * math.sin(mid))
        else:
            h = c.height or 0.0
            corners = ((s0, n0), (s0 + length, n0), (s0 + length, n0 - h), (s0, n0 - h))
            shape = np.stack([_local(o, a, s, n) for s, n in corners], axis=1)
            reference = _local(o, a, s0 + 0.5 * length, n0)
        forces = _contact_forces(series, f"c{i}." if several else "", frames)
        contacts.append(_Contact(c.name or c.link, shape, reference, reference, forces))
    return _Pose(bars, None, contacts, size)


def _leg_pose(result: Result, frames: np.ndarray) -> _Pose:
    """The leg (``rust/bodies/leg.rs`` LegScene::model): the ankle is the root; the foot's axis
    runs heel to toe with the sole at n = h (the ankle height) below it; the shank, thigh and
    trunk rise from the ankle, the knee and the hip along their axes."""
    scene, series = result.scene, result.series
    assert series is not None
    col = lambda name: _column(series, name, frames)  # noqa: E731
    segments = {s["name"]: s for s in scene.leg_segments()}
    foot_length = scene.foot_length
    h = ANKLE_HEIGHT_FRACTION * scene.height
    box_height = scene.tibia_length if scene.sole_height is None else scene.sole_height
    ankle = np.stack([col("x_ankle"), col("y_ankle")], axis=-1)
    q_foot = col("q_foot")
    half = 0.5 * foot_length
    foot = np.stack(
        [
            _local(ankle, q_foot, s, n)
            for s, n in ((-half, h), (half, h), (half, 0.0), (-half, 0.0))
        ],
        axis=1,
    )
    box = np.stack(
        [
            _local(ankle, q_foot, s, n)
            for s, n in ((-half, h), (half, h), (half, h - box_height), (-half, h - box_height))
        ],
        axis=1,
    )
    knee = _local(ankle, col("q_shank"), segments["shank"]["length"], 0.0)
    hip = _local(knee, col("q_thigh"), segments["thigh"]["length"], 0.0)
    head = _local(hip, col("q_trunk"), segments["half_trunk"]["length"], 0.0)
    sticks = np.stack([ankle, knee, hip, head], axis=1)
    sole_middle = _local(ankle, q_foot, 0.0, h)
    if scene.apply_at == "centroid":
        applied = sole_middle.copy()
        for k in range(len(frames)):
            c = _polygon_centroid(_clip_below_surface(box[k]))
            if c is not None:
                applied[k] = c
    else:
        applied = sole_middle
    contact = _Contact("foot", box, sole_middle, applied, _contact_forces(series, "", frames))
    return _Pose([foot], sticks, [contact], scene.tibia_length)


# --- drawing --------------------------------------------------------------------------------

_SAND = "#e8d5a9"
_SURFACE = "#8b6d3f"
_WET = "#6b4a1f"
_BODY_FACE = "#9aa4b1"
_BODY_EDGE = "#2f3b4c"
_TOTAL_COLOUR = "#7f7f7f"
#: Order in which the terms are laid tip to tail.
_TERMS = ("drag", "static_h", "static_v")


def _force_scale(result: Result, size: float) -> float:
    """Arrow length per newton [m/N]: the largest term or sum of any contact at any recorded
    sample is drawn ``_ARROW_FRACTION`` of the body's reference length ``size`` [m] long (so
    the scale does not depend on frame_dt); 0 without forces."""
    series = result.series
    assert series is not None
    t = np.asarray(series["t"], dtype=float)
    largest = 0.0
    for i in range(len(result.contacts)):
        prefix = f"c{i}." if len(result.contacts) > 1 else ""
        forces = _contact_forces(series, prefix, t)
        total = sum(forces.values(), np.zeros((len(t), 2)))
        for f in [*forces.values(), total]:
            largest = max(largest, float(np.nanmax(np.linalg.norm(f, axis=-1), initial=0.0)))
    return _ARROW_FRACTION * size / largest if largest > 0.0 else 0.0


def _limits(points: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Axis limits (lower-left, upper-right) [m] around ``points`` with a margin, showing
    some sand and some air."""
    allp = np.concatenate(points)
    allp = allp[np.all(np.isfinite(allp), axis=1)]
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    span = max(hi[0] - lo[0], hi[1] - lo[1], 1e-6)
    lo[1] = min(lo[1], -0.2 * span)
    hi[1] = max(hi[1], 0.1 * span)
    pad = 0.06 * span
    return lo - pad, hi + pad


@dataclass
class _ViewArtists:
    """The artists of one axes (the whole body, or the leg's contact zoomed)."""

    outlines: list[Polygon]
    #: The outlines' edges again, above the immersed shading.
    edges: list[Polygon]
    boxes: list[Polygon]
    sticks: Line2D | None
    wet: list[Polygon]
    #: Per contact: the sum's arrow, then the terms', by name.
    arrows: list[dict[str, FancyArrowPatch]]

    @classmethod
    def build(cls, ax: Any, pose: _Pose) -> _ViewArtists:
        empty = np.zeros((3, 2))
        outlines = [
            ax.add_patch(
                Polygon(empty, closed=True, fc=_BODY_FACE, ec=_BODY_EDGE, lw=1.0, zorder=3)
            )
            for _ in pose.outlines
        ]
        edges = [
            ax.add_patch(Polygon(empty, closed=True, fill=False, ec=_BODY_EDGE, lw=1.0, zorder=4.5))
            for _ in pose.outlines
        ]
        boxes = []
        sticks = None
        if pose.sticks is not None:
            # The leg: its contact box (dashed) is not the foot's outline.
            boxes = [
                ax.add_patch(
                    Polygon(
                        empty, closed=True, fill=False, ec=_BODY_EDGE, lw=0.8, ls="--", zorder=2
                    )
                )
                for _ in pose.contacts
            ]
            (sticks,) = ax.plot([], [], "-o", color=_BODY_EDGE, lw=3.0, ms=5, zorder=3)
        wet = [
            ax.add_patch(
                Polygon(empty, closed=True, fc=_WET, ec="none", alpha=0.55, hatch="///", zorder=4)
            )
            for _ in pose.contacts
        ]
        arrows = []
        for c in pose.contacts:
            mine: dict[str, FancyArrowPatch] = {}
            if c.forces:
                mine["total"] = ax.add_patch(
                    FancyArrowPatch(
                        (0.0, 0.0),
                        (0.0, 0.0),
                        arrowstyle="simple",
                        mutation_scale=24,
                        color=_TOTAL_COLOUR,
                        alpha=0.5,
                        lw=0.0,
                        zorder=5,
                    )
                )
            for term in c.forces:
                mine[term] = ax.add_patch(
                    FancyArrowPatch(
                        (0.0, 0.0),
                        (0.0, 0.0),
                        arrowstyle="-|>",
                        mutation_scale=9,
                        color=TERM_COLOURS[term],
                        lw=1.8,
                        zorder=6,
                    )
                )
            arrows.append(mine)
        return cls(outlines, edges, boxes, sticks, wet, arrows)

    def draw(self, pose: _Pose, k: int, scale: float) -> list[Any]:
        changed: list[Any] = []
        for patch, edge, outline in zip(self.outlines, self.edges, pose.outlines, strict=True):
            patch.set_xy(outline[k] * _MM)
            edge.set_xy(outline[k] * _MM)
            changed += [patch, edge]
        for patch, contact in zip(self.boxes, pose.contacts, strict=False):
            patch.set_xy(contact.shape[k] * _MM)
            changed.append(patch)
        if self.sticks is not None and pose.sticks is not None:
            self.sticks.set_data(pose.sticks[k, :, 0] * _MM, pose.sticks[k, :, 1] * _MM)
            changed.append(self.sticks)
        for patch, arrows, contact in zip(self.wet, self.arrows, pose.contacts, strict=True):
            wet = _clip_below_surface(contact.shape[k])
            patch.set_visible(len(wet) >= 3)
            if len(wet) >= 3:
                patch.set_xy(wet * _MM)
            changed.append(patch)
            start = contact.applied[k]
            if "total" in arrows:
                _place(arrows["total"], start, start + scale * contact.total[k])
            # The terms tip to tail, so that together they end where the sum does.
            at = start
            for term in _TERMS:
                if term in arrows:
                    end = at + scale * contact.forces[term][k]
                    _place(arrows[term], at, end)
                    at = end
            changed += list(arrows.values())
        return changed


def _place(arrow: FancyArrowPatch, start: np.ndarray, end: np.ndarray) -> None:
    """Put an arrow from ``start`` to ``end`` [m]; hide it when shorter than 0.05 mm."""
    visible = bool(np.hypot(*(end - start)) * _MM > 0.05)
    arrow.set_visible(visible)
    if visible:
        arrow.set_positions(tuple(start * _MM), tuple(end * _MM))


# --- the animation --------------------------------------------------------------------------


class ImpactAnimation(mpl_animation.FuncAnimation):
    """A :class:`matplotlib.animation.FuncAnimation` of one recorded impact (see
    :func:`animate`).

    Attributes:
        result: the run it shows.
        frame_times: simulated time of each frame [s], ``k * frame_dt``.
        frame_dt: simulated time per frame [s].
        speed: simulated seconds per second of movie [-].
        fps: frames per second of the movie [1/s].
        depths: depth of each contact's reference point at each frame, (n_frames,
            n_contacts) [m] (the rod's tip, the middle of the sole; as the series' ``depth``).
        force_scale: length of a 1 N arrow [m/N].
    """

    def __init__(
        self,
        result: Result,
        frame_times: np.ndarray,
        frame_dt: float,
        speed: float,
        fps: float,
        dpi: float = 100.0,
    ) -> None:
        self.result = result
        self.frame_times = frame_times
        self.frame_dt = frame_dt
        self.speed = speed
        self.fps = fps
        self.dpi = dpi
        self._pose = _pose(result, frame_times)
        self.depths = np.stack(
            [np.maximum(-c.reference[:, 1], 0.0) for c in self._pose.contacts]
            or [np.zeros(len(frame_times))],
            axis=-1,
        )[:, : len(self._pose.contacts)]
        self.figure = self._build_figure()
        super().__init__(
            self.figure,
            self.draw,
            frames=len(frame_times),
            init_func=lambda: self.draw(0),
            interval=1000.0 / fps,
            repeat=True,
            blit=False,
            cache_frame_data=False,
        )
        self.draw(0)
        # Frame 0 is drawn: the figure is a valid still, so matplotlib's "deleted without
        # rendering anything" warning would be wrong here.
        self._draw_was_started = True

    @property
    def n_frames(self) -> int:
        """Number of frames, ``floor(t_end / frame_dt) + 1``."""
        return len(self.frame_times)

    def _build_figure(self) -> Figure:
        pose = self._pose
        scale = self.force_scale = _force_scale(self.result, pose.size)
        ends = [c.applied + scale * c.total for c in pose.contacts if c.forces]
        body = [o.reshape(-1, 2) for o in pose.outlines]
        body += [c.shape.reshape(-1, 2) for c in pose.contacts]
        if pose.sticks is not None:
            body.append(pose.sticks.reshape(-1, 2))
        views = [("", _limits(body + ends))]
        if pose.sticks is not None:
            # The leg is a metre and a half tall; its contact gets a view of its own.
            views.append(("contact", _limits([o.reshape(-1, 2) for o in pose.outlines] + ends)))
        widths = [(hi[0] - lo[0]) / (hi[1] - lo[1]) for _, (lo, hi) in views]
        height = 6.0
        side = 2.4  # the legend's column [in]
        width = max(height * 0.82 * sum(widths) + side + 0.9 * len(views), _MIN_WIDTH)
        fig = Figure(figsize=(width, height))
        fig.set_dpi(self.dpi)
        FigureCanvasAgg(fig)
        plot_right = 1.0 - side / fig.get_figwidth()
        grid = fig.add_gridspec(
            1,
            len(views),
            width_ratios=widths,
            left=0.9 / fig.get_figwidth() * 1.0,
            right=plot_right - 0.02,
            bottom=0.09,
            top=0.92,
            wspace=0.25,
        )
        scene = self.result.scene
        self._views = []
        for i, (title, (lo, hi)) in enumerate(views):
            ax = fig.add_subplot(grid[0, i])
            ax.set_xlim(lo[0] * _MM, hi[0] * _MM)
            ax.set_ylim(lo[1] * _MM, hi[1] * _MM)
            ax.set_aspect("equal", adjustable="box")
            ax.set_xlabel("x [mm]")
            if i == 0:
                ax.set_ylabel("y [mm]")
            ax.set_title(title or f"{scene.kind}, v0 = {scene.v0:g} m/s", fontsize=10)
            ax.axhspan((lo[1] - 1.0) * _MM, 0.0, color=_SAND, zorder=0)
            ax.axhline(0.0, color=_SURFACE, lw=1.2, zorder=1)
            self._views.append(_ViewArtists.build(ax, pose))
        present = [t for t in TERM_COLOURS if any(t in c.forces for c in pose.contacts)]
        handles: list[Any] = [
            Line2D([], [], color=TERM_COLOURS[t], lw=2.0, label=t) for t in present
        ]
        if present:
            handles.append(
                Line2D([], [], color=_TOTAL_COLOUR, lw=6.0, alpha=0.5, label="sum (F_r)")
            )
        handles.append(Patch(fc=_WET, alpha=0.55, hatch="///", label="immersed"))
        if scale > 0.0:
            note = f"force arrows\n10 mm = {0.01 / scale:.3g} N"
        elif not any(c.forces for c in pose.contacts):
            note = "forces not recorded"
        else:
            note = "no force"
        x_side = plot_right + 0.01
        fig.legend(
            handles=handles,
            loc="upper left",
            bbox_to_anchor=(x_side, 0.92),
            fontsize=8,
            title=note,
            title_fontsize=8,
            frameon=False,
        )
        self._clock = fig.text(x_side, 0.30, "", fontsize=10, family="monospace", va="top")
        self._depth_text = fig.text(x_side, 0.24, "", fontsize=9, family="monospace", va="top")
        return fig

    def draw(self, k: int) -> list[Any]:
        """Set every artist to frame ``k`` (0 <= k < n_frames); returns the artists changed."""
        k = int(k)
        changed: list[Any] = []
        for view in self._views:
            changed += view.draw(self._pose, k, self.force_scale)
        self._clock.set_text(f"t = {self.frame_times[k] * 1e3:.2f} ms")
        lines = ["depth"] + [
            f"{c.name} {d * 1e3:.1f} mm"
            for c, d in zip(self._pose.contacts, self.depths[k], strict=True)
        ]
        self._depth_text.set_text("\n".join(lines))
        changed += [self._clock, self._depth_text]
        self._draw_was_started = True
        return changed

    def _repr_html_(self) -> str:  # type: ignore[override]
        """Jupyter: matplotlib's representation where ``rcParams["animation.html"]`` asks
        for one, else the JavaScript player (``to_jshtml``)."""
        html = super()._repr_html_()
        fps: Any = self.fps  # see write()
        return html if html is not None else str(self.to_jshtml(fps=fps))

    def write(self, path: str | os.PathLike[str], progress: bool | None = None) -> Path:
        """Write the animation to ``path``: ``.gif`` (Pillow), ``.mp4`` (ffmpeg) or ``.html``
        (a self-contained JavaScript player). The path is checked first, before any frame is drawn.
        ``progress``: a tqdm bar of the frames on stderr (None: when stderr is a terminal).
        Returns the path."""

        out = check_output(path)
        suffix = out.suffix.lower()
        # matplotlib annotates fps as int, but only divides by it (1000 / fps, ffmpeg -r):
        # a derived frame rate such as speed / frame_dt = 12.5 is written as it is.
        fps: Any = self.fps
        bar = progress_bar(self.n_frames, progress, "granrs animate", "frame")
        try:

            def tick(_frame: int, _total: int) -> None:
                bar.update(1)

            # Whole or not at all: an error leaves an existing file as it was.
            with replacing(out) as tmp:
                if suffix == ".html":
                    # What to_jshtml() writes (its writer and mode), with the frames counted.
                    writer = mpl_animation.HTMLWriter(
                        fps=fps,
                        embed_frames=True,
                        default_mode="loop" if self._repeat else "once",
                    )
                    self.save(str(tmp), writer=writer, progress_callback=tick)
                elif suffix == ".gif":
                    writer = mpl_animation.PillowWriter(fps=fps)
                    self.save(str(tmp), writer=writer, dpi=self.dpi, progress_callback=tick)
                else:
                    writer = mpl_animation.FFMpegWriter(fps=fps)
                    self.save(str(tmp), writer=writer, dpi=self.dpi, progress_callback=tick)
        finally:
            bar.close()
        return out
