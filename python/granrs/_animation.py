"""The drawing behind :func:`granrs.animate` (see :mod:`granrs.animation` for what a frame
shows and the settings): :func:`animate`, any body placed from its linkage and the recorded
coordinates, the immersed parts, the force arrows of every recorded term and
:class:`ImpactAnimation`. Kept apart because it imports matplotlib, which ``import granrs``
should not pay for: ``granrs.animate`` loads it on first use.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import os
import textwrap
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib import animation as mpl_animation
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import FancyArrowPatch, Patch, Polygon
from matplotlib.transforms import Bbox

from . import _space_animation, space
from . import forces as _forces
from ._files import replacing
from ._progress import progress_bar
from .animation import (
    BIG_SAVE_BYTES,
    DEFAULT_FRAMES,
    _positive,
    check_output,
    frame_times,
    playback,
    saved_bytes,
)
from .bodies import DEFAULT_CHORDS
from .errors import AnimationSizeWarning, InvalidParameterError
from .result import Result, _names
from .scene import BODY_FIELDS, FIELD_INFO

if TYPE_CHECKING:
    from .bodies import Contact, Joint, Link
    from .scene import Scene

__all__ = ["ImpactAnimation", "animate", "term_colour"]

#: Longest force arrow, as a fraction of the body's longest link.
_ARROW_FRACTION = 0.6
#: The narrowest figure [in]: a tall, thin scene (a vertical rod) still leaves its axes'
#: cell room for the title, clear of the legend's column.
_MIN_WIDTH = 7.2
#: A view of the contacts alone is added when the whole body is this many times larger.
_ZOOM_RATIO = 3.0
_MM = 1e3
#: Size of the titles [pt]; a title is wrapped to its axes' width at about 0.55 of this per
#: character.
_TITLE_SIZE = 9.0


# --- the terms' arrows ---------------------------------------------------------------------

#: Colours of the terms' arrows, in the order of the registry's terms that record a force
#: (drag, static_h, static_v, ... as matplotlib's first colours); grey is the sum's.
_PALETTE = (
    "tab:blue",
    "tab:orange",
    "tab:green",
    "tab:red",
    "tab:purple",
    "tab:brown",
    "tab:pink",
    "tab:olive",
    "tab:cyan",
)
#: The force component a term's single series column holds, by the column's last letter
#: (``F_sh``: horizontal, ``F_sv``: vertical); a term with two columns holds (x, y).
_ONE_COLUMN_AXIS = {"h": 0, "x": 0, "v": 1, "y": 1}


def _term_columns(term: str) -> tuple[tuple[str, int], ...]:
    """The series columns of ``term``'s force on a contact (the core's registry) with the
    component each holds (0: x, 1: y); none for a body term (gravity, joint springs)."""
    columns = _forces.info(term).columns
    if len(columns) == 2:
        return ((columns[0], 0), (columns[1], 1))
    return tuple((c, _ONE_COLUMN_AXIS[c[-1]]) for c in columns if c[-1] in _ONE_COLUMN_AXIS)


def term_colour(term: str) -> str:
    """The colour of ``term``'s arrow: one per registered term that records a force."""
    recorded = [t for t in _forces.TERMS if _forces.info(t).columns]
    return _PALETTE[recorded.index(term) % len(_PALETTE)] if term in recorded else "black"


# --- geometry -------------------------------------------------------------------------------


def _axis(q: np.ndarray) -> np.ndarray:
    """Unit axes e = (sin q, cos q) of angles from the vertical, shape (n, 2)."""
    return np.stack([np.sin(q), np.cos(q)], axis=-1)


def _normal(q: np.ndarray) -> np.ndarray:
    """Normals n = (cos q, -sin q) = de/dq, shape (n, 2)."""
    return np.stack([np.cos(q), -np.sin(q)], axis=-1)


def _local(joint: np.ndarray, q: np.ndarray, s: float, n: float) -> np.ndarray:
    """World position of the point (s, n) of a link with joint ``joint`` and angle ``q``
    (``docs/bodies/linkage.md``: J + s e + n n), shape (n_frames, 2) [m]."""
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


def _polyline_centroid(points: np.ndarray) -> np.ndarray | None:
    """Length centroid of the part of a polyline (k, 2) with y <= 0, or None."""
    total, moment = 0.0, np.zeros(2)
    for a, b in itertools.pairwise(points):
        if a[1] > 0.0 and b[1] > 0.0:
            continue
        if a[1] > 0.0 or b[1] > 0.0:
            t = a[1] / (a[1] - b[1])
            cut = a + t * (b - a)
            a, b = (cut, b) if a[1] > 0.0 else (a, cut)
        length = float(np.hypot(*(b - a)))
        total += length
        moment += length * 0.5 * (a + b)
    return moment / total if total > 0.0 else None


def _rod_outline(tip: np.ndarray, top: np.ndarray, diameter: float) -> np.ndarray:
    """The rectangle of a rod from ``tip`` to ``top`` (each (n, 2)), shape (n, 4, 2)."""
    along = top - tip
    along = along / np.linalg.norm(along, axis=-1, keepdims=True)
    side = 0.5 * diameter * np.stack([along[:, 1], -along[:, 0]], axis=-1)
    return np.stack([tip + side, top + side, top - side, tip - side], axis=1)


def _rod_centroid(tip: np.ndarray, top: np.ndarray, length: float) -> np.ndarray:
    """Centroid E of a rod's immersed part: T + l/2 e with l = min(d / cos q, L)
    (``rust/body/rod.rs``); the tip where nothing is immersed."""
    e = (top - tip) / length
    depth = np.maximum(-tip[:, 1], 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        immersed = np.where(depth >= length * e[:, 1], length, depth / e[:, 1])
    return tip + 0.5 * immersed[:, None] * e


def _arc_angles(c: Contact) -> np.ndarray:
    """The angles of an arc contact's chord ends [rad], from ``start_deg`` to ``end_deg``."""
    chords = c.chords or DEFAULT_CHORDS
    return np.radians(np.linspace(c.start_deg or 0.0, c.end_deg or 0.0, chords + 1))


def _contact_s(c: Contact) -> list[float]:
    """The places along its link's axis that a contact reaches [m]."""
    s0 = c.at[0]
    if c.shape == "arc":
        return list(s0 + (c.radius or 0.0) * np.cos(_arc_angles(c)))
    return [s0, s0 + (c.length or 0.0)]


def _link_span(
    link: Link, joints: Sequence[Joint], contacts: Sequence[Contact]
) -> tuple[float, float]:
    """The part ``[s_lo, s_hi]`` of a link's axis to draw [m]: what its own geometry spans
    (its joint at s = 0, its centre of mass, the joints it carries, its contacts), at least
    ``link.length`` long: grown away from the joint when everything lies on one side of it
    (a link hanging from its joint either way), about the middle otherwise."""
    s = [0.0, link.com[0], *(j.at[0] for j in joints)]
    s += [x for c in contacts for x in _contact_s(c)]
    lo, hi = min(s), max(s)
    length = link.length
    if hi - lo >= length:
        return lo, hi
    if lo >= 0.0 and hi > 0.0:
        return 0.0, length
    if hi <= 0.0 and lo < 0.0:
        return -length, 0.0
    middle = 0.5 * (lo + hi)
    return middle - 0.5 * length, middle + 0.5 * length


@dataclass
class _Contact:
    """One contact's drawing data over the frames (world coordinates [m])."""

    name: str
    #: ``"rod"``, ``"box"`` or ``"arc"``.
    shape_kind: str
    #: Outline of the contact's shape, (n, k, 2).
    shape: np.ndarray
    #: The reference point T the series records (``tip_x``, ``tip_y``: a rod's tip, the
    #: middle of a box's sole, an arc's middle), (n, 2).
    reference: np.ndarray
    #: Point of application of the force, (n, 2).
    applied: np.ndarray
    #: Force of each recorded term, (n, 2) [N], in the order of ``Result.terms``.
    forces: dict[str, np.ndarray]
    #: Depth of the contact (the series' ``depth``), (n,) [m].
    depth: np.ndarray
    #: Its size [m]: a rod's or a box's length, an arc's diameter.
    size: float

    @property
    def total(self) -> np.ndarray:
        """The sum of the recorded terms, (n, 2) [N]."""
        return sum(self.forces.values(), np.zeros_like(self.applied))


@dataclass
class _Link:
    """One link's drawing data over the frames [m]."""

    name: str
    #: The ends of its bar along its axis, (n, 2, 2).
    bar: np.ndarray
    #: From its axis out to each joint it carries off the axis, each (n, 2, 2).
    spokes: list[np.ndarray]


@dataclass
class _Pose:
    """The body over the frames: its links, joints and contacts [m]."""

    links: list[_Link]
    #: The root point and every joint, (n, j, 2).
    joints: np.ndarray
    contacts: list[_Contact]
    #: Reference length for the force scale: the longest link [m].
    size: float


def _column(series: dict[str, np.ndarray], name: str, frames: np.ndarray) -> np.ndarray:
    t = np.asarray(series["t"], dtype=float)
    return np.interp(frames, t, np.asarray(series[name], dtype=float))


def _contact_forces(
    series: dict[str, np.ndarray], prefix: str, frames: np.ndarray, terms: Sequence[str]
) -> dict[str, np.ndarray]:
    """The recorded force of each of ``terms`` on one contact as vectors, (n, 2) each [N]:
    the terms whose columns the series holds."""
    out: dict[str, np.ndarray] = {}
    for term in terms:
        columns = [(c, axis) for c, axis in _term_columns(term) if f"{prefix}{c}" in series]
        if not columns:
            continue
        force = np.zeros((len(frames), 2))
        for c, axis in columns:
            force[:, axis] = _column(series, f"{prefix}{c}", frames)
        out[term] = force
    return out


def _contact(
    c: Contact,
    origin: np.ndarray,
    q: np.ndarray,
    centroid: bool,
    forces: dict[str, np.ndarray],
    depth: np.ndarray | None,
) -> _Contact:
    """One contact placed on its link (joint ``origin``, angle ``q``) over the frames."""
    s0, n0 = c.at
    length = c.length or 0.0
    if c.shape == "rod":
        tip = _local(origin, q, s0, n0)
        top = _local(origin, q, s0 + length, n0)
        shape = _rod_outline(tip, top, c.diameter or 0.0)
        reference = tip
        applied = _rod_centroid(tip, top, length) if centroid else tip
    elif c.shape == "arc":
        r = c.radius or 0.0
        phi = _arc_angles(c)
        # A thin band about the arc (10 % of its radius thick), through its chords' ends.
        band = [(s0 + k * r * np.cos(f), n0 + k * r * np.sin(f)) for k, f in
                [(1.05, f) for f in phi] + [(0.95, f) for f in phi[::-1]]]  # fmt: skip
        shape = np.stack([_local(origin, q, s, n) for s, n in band], axis=1)
        mid = math.radians(0.5 * ((c.start_deg or 0.0) + (c.end_deg or 0.0)))
        reference = _local(origin, q, s0 + r * math.cos(mid), n0 + r * math.sin(mid))
        applied = reference.copy()
        if centroid:
            chords = np.stack(
                [_local(origin, q, s0 + r * np.cos(f), n0 + r * np.sin(f)) for f in phi], axis=1
            )
            for k in range(len(q)):
                e = _polyline_centroid(chords[k])
                if e is not None:
                    applied[k] = e
    else:
        h = c.height or 0.0
        corners = ((s0, n0), (s0 + length, n0), (s0 + length, n0 - h), (s0, n0 - h))
        shape = np.stack([_local(origin, q, s, n) for s, n in corners], axis=1)
        reference = _local(origin, q, s0 + 0.5 * length, n0)
        applied = reference.copy()
        if centroid:
            for k in range(len(q)):
                e = _polygon_centroid(_clip_below_surface(shape[k]))
                if e is not None:
                    applied[k] = e
    if depth is None:  # no series column: the lowest point of the outline
        depth = np.maximum(-shape[:, :, 1].min(axis=1), 0.0)
    name = c.name or c.link
    size = 2.0 * (c.radius or 0.0) if c.shape == "arc" else length
    return _Contact(name, c.shape, shape, reference, applied, forces, depth, size)


def _pose(result: Result, frames: np.ndarray) -> _Pose:
    """Place the body at each frame from its linkage (``scene.body``: links, joints,
    contacts) and the recorded root position and link angles."""
    scene, series = result.scene, result.series
    assert series is not None
    body = scene.body
    coords = _names(scene)["coords"]
    order = body.order  # type: ignore[union-attr]
    links = {link.name: link for link in body.links}  # type: ignore[union-attr]
    joints = body.joints  # type: ignore[union-attr]
    contacts = body.contacts  # type: ignore[union-attr]
    joint_of = {j.child: j for j in joints}
    root = np.stack([_column(series, coords[0], frames), _column(series, coords[1], frames)], -1)
    origin: dict[str, np.ndarray] = {}
    q: dict[str, np.ndarray] = {}
    for i, name in enumerate(order):
        q[name] = _column(series, coords[2 + i], frames)
        j = joint_of.get(name)
        origin[name] = root if j is None else _local(origin[j.parent], q[j.parent], *j.at)
    drawn = []
    for name in order:
        carried = [j for j in joints if j.parent == name]
        on_it = [c for c in contacts if c.link == name]
        lo, hi = _link_span(links[name], carried, on_it)
        o, a = origin[name], q[name]
        bar = np.stack([_local(o, a, lo, 0.0), _local(o, a, hi, 0.0)], axis=1)
        spokes = [
            np.stack([_local(o, a, j.at[0], 0.0), _local(o, a, *j.at)], axis=1)
            for j in carried
            if j.at[1] != 0.0
        ]
        drawn.append(_Link(name, bar, spokes))
    several = len(contacts) > 1
    placed = []
    for i, c in enumerate(contacts):
        prefix = f"c{i}." if several else ""
        forces = _contact_forces(series, prefix, frames, result.terms)
        depth = _column(series, f"{prefix}depth", frames) if f"{prefix}depth" in series else None
        placed.append(
            _contact(c, origin[c.link], q[c.link], scene.apply_at == "centroid", forces, depth)
        )
    joint_points = np.stack([root] + [origin[j.child] for j in joints], axis=1)
    size = max(link.length for link in links.values())
    return _Pose(drawn, joint_points, placed, size)


def _title(scene: Scene) -> str:
    """The body and the scene's own start: a built-in body's start fields that apply to it
    (``v0``, ``q_deg``, ...; those at zero left out), or a linkage's links and root."""
    kind = scene.kind
    if kind != "linkage":
        parts = []
        for field in dataclasses.fields(scene):
            f = FIELD_INFO[field.name]
            if f["part"] != "start" or kind not in BODY_FIELDS.get(field.name, (kind,)):
                continue
            value = getattr(scene, field.name)
            if value is None or value == 0.0:
                continue
            unit = {"deg": "°"}.get(f["unit"], f" {f['unit']}")
            parts.append(f"{field.name} = {value:g}{unit}")
        return f"{kind}: " + ", ".join(parts)
    body = scene.body
    root = body.root  # type: ignore[union-attr]
    n_links = len(body.links)  # type: ignore[union-attr]
    text = f"linkage: {n_links} link{'s' if n_links > 1 else ''}, root {root.kind}"
    if root.kind == "pinned":
        text += f" at ({root.position[0]:g}, {root.position[1]:g}) m"
    elif any(root.velocity):
        text += f", v = ({root.velocity[0]:g}, {root.velocity[1]:g}) m/s"
    if root.rate == 0.0:
        text += ", its angle held"
    elif root.rate is not None:
        text += f", turning at {root.rate:g} rad/s"
    return text


# --- drawing --------------------------------------------------------------------------------

_SAND = "#e8d5a9"
_SURFACE = "#8b6d3f"
_WET = "#6b4a1f"
_BODY_FACE = "#9aa4b1"
_BODY_EDGE = "#2f3b4c"
_TOTAL_COLOUR = "#7f7f7f"


def _force_scale(pose: _Pose) -> float:
    """Arrow length per newton [m/N]: the largest term or sum of any contact at any frame
    is drawn ``_ARROW_FRACTION`` of the body's longest link long; 0 without forces."""
    largest = 0.0
    for c in pose.contacts:
        for f in [*c.forces.values(), c.total]:
            largest = max(largest, float(np.nanmax(np.linalg.norm(f, axis=-1), initial=0.0)))
    return _ARROW_FRACTION * pose.size / largest if largest > 0.0 else 0.0


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


def _near_contacts(pose: _Pose) -> list[np.ndarray]:
    """The points a view of the contacts shows: each contact's reference point and the
    vertices of its outline within its own size of it (a leg's sole, not its whole box)."""
    points = []
    for c in pose.contacts:
        points.append(c.reference)
        near = np.linalg.norm(c.shape - c.reference[:, None, :], axis=-1) <= c.size
        points.append(c.shape[near])
    return points


@dataclass
class _ViewArtists:
    """The artists of one axes (the whole body, or its contacts zoomed)."""

    #: Per link (by name): its bar.
    links: dict[str, Line2D]
    #: Per link, its spokes to off-axis joints.
    spokes: list[list[Line2D]]
    #: The root and the joints, as dots.
    joints: Line2D
    #: Per contact: its outline.
    shapes: list[Polygon]
    wet: list[Polygon]
    #: Per contact: the sum's arrow, then the terms', by name.
    arrows: list[dict[str, FancyArrowPatch]]

    @classmethod
    def build(cls, ax: Any, pose: _Pose) -> _ViewArtists:
        empty = np.zeros((3, 2))
        shapes = []
        for c in pose.contacts:
            if c.shape_kind == "box":
                patch = Polygon(
                    empty, closed=True, fill=False, ec=_BODY_EDGE, lw=0.9, ls="--", zorder=2
                )
            else:
                patch = Polygon(empty, closed=True, fc=_BODY_FACE, ec=_BODY_EDGE, lw=1.0, zorder=3)
            shapes.append(ax.add_patch(patch))
        links = {}
        spokes = []
        for link in pose.links:
            (links[link.name],) = ax.plot(
                [], [], "-", color=_BODY_EDGE, lw=3.0, solid_capstyle="butt", zorder=3.5
            )
            spokes.append(
                [ax.plot([], [], "-", color=_BODY_EDGE, lw=1.5, zorder=3.5)[0] for _ in link.spokes]
            )
        (joints,) = ax.plot(
            [], [], "o", ms=5, mfc="white", mec=_BODY_EDGE, mew=1.5, ls="none", zorder=5.5
        )
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
                        color=term_colour(term),
                        lw=1.8,
                        zorder=6,
                    )
                )
            arrows.append(mine)
        return cls(links, spokes, joints, shapes, wet, arrows)

    def draw(self, pose: _Pose, k: int, scale: float) -> list[Any]:
        changed: list[Any] = []
        for link, spokes in zip(pose.links, self.spokes, strict=True):
            line = self.links[link.name]
            line.set_data(link.bar[k, :, 0] * _MM, link.bar[k, :, 1] * _MM)
            changed.append(line)
            for spoke, ends in zip(spokes, link.spokes, strict=True):
                spoke.set_data(ends[k, :, 0] * _MM, ends[k, :, 1] * _MM)
                changed.append(spoke)
        self.joints.set_data(pose.joints[k, :, 0] * _MM, pose.joints[k, :, 1] * _MM)
        changed.append(self.joints)
        for patch, wet, arrows, contact in zip(
            self.shapes, self.wet, self.arrows, pose.contacts, strict=True
        ):
            patch.set_xy(contact.shape[k] * _MM)
            immersed = _clip_below_surface(contact.shape[k])
            wet.set_visible(len(immersed) >= 3)
            if len(immersed) >= 3:
                wet.set_xy(immersed * _MM)
            changed += [patch, wet]
            start = contact.applied[k]
            if "total" in arrows:
                _place(arrows["total"], start, start + scale * contact.total[k])
            # The terms tip to tail, so that together they end where the sum does.
            at = start
            for term, force in contact.forces.items():
                end = at + scale * force[k]
                _place(arrows[term], at, end)
                at = end
            changed += list(arrows.values())
        return changed


def _wrap(text: str, cell: Bbox, fig: Figure) -> str:
    """``text`` wrapped to the width of ``cell`` (figure coordinates)."""
    points = cell.width * fig.get_figwidth() * 72.0
    return textwrap.fill(text, width=max(20, int(points / (0.55 * _TITLE_SIZE))))


def _place(arrow: FancyArrowPatch, start: np.ndarray, end: np.ndarray) -> None:
    """Put an arrow from ``start`` to ``end`` [m]; hide it when shorter than 0.05 mm."""
    visible = bool(np.hypot(*(end - start)) * _MM > 0.05)
    arrow.set_visible(visible)
    if visible:
        arrow.set_positions(tuple(start * _MM), tuple(end * _MM))


# --- the animation --------------------------------------------------------------------------


class ImpactAnimation(mpl_animation.FuncAnimation):
    """A :class:`matplotlib.animation.FuncAnimation` of one recorded impact (see
    :func:`granrs.animate`).

    Attributes:
        result: the run it shows.
        frame_times: simulated time of each frame [s], ``k * frame_dt``.
        frame_dt: simulated time per frame [s].
        speed: simulated seconds per second of movie [-].
        fps: frames per second of the movie [1/s].
        depths: depth of each contact at each frame, (n_frames, n_contacts) [m] (the
            series' ``depth``).
        title: the body and its start, from the scene's own fields (the first view's
            title; over the views when the contacts get a view of their own).
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
            [c.depth for c in self._pose.contacts] or [np.zeros(len(frame_times))], axis=-1
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
        scale = self.force_scale = _force_scale(pose)
        ends = [c.applied + scale * c.total for c in pose.contacts if c.forces]
        body = [link.bar.reshape(-1, 2) for link in pose.links]
        body += [c.shape.reshape(-1, 2) for c in pose.contacts]
        body.append(pose.joints.reshape(-1, 2))
        whole = _limits(body + ends)
        views = [("", whole)]
        if pose.contacts:
            near = _limits(_near_contacts(pose) + ends)
            if (whole[1] - whole[0]).max() > _ZOOM_RATIO * (near[1] - near[0]).max():
                # A body much larger than its contacts (a leg): they get a view of their own.
                views.append(("contacts", near))
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
            top=0.90,
            wspace=0.25,
        )
        self.title = title = _title(self.result.scene)
        if len(views) > 1:
            # Over both views (the body's is narrow): the views are named instead.
            left = grid[0, 0].get_position(fig)
            cells = Bbox.union([left, grid[0, len(views) - 1].get_position(fig)])
            fig.suptitle(_wrap(title, cells, fig), x=0.5 * (cells.x0 + cells.x1), y=0.985,
                         fontsize=_TITLE_SIZE, va="top")  # fmt: skip
            views[0] = ("body", views[0][1])
        self._views = []
        for i, (name, (lo, hi)) in enumerate(views):
            ax = fig.add_subplot(grid[0, i])
            ax.set_xlim(lo[0] * _MM, hi[0] * _MM)
            ax.set_ylim(lo[1] * _MM, hi[1] * _MM)
            ax.set_aspect("equal", adjustable="box")
            ax.set_xlabel("x [mm]")
            if i == 0:
                ax.set_ylabel("y [mm]")
            ax.set_title(
                _wrap(name or title, grid[0, i].get_position(fig), fig), fontsize=_TITLE_SIZE
            )
            ax.axhspan((lo[1] - 1.0) * _MM, 0.0, color=_SAND, zorder=0)
            ax.axhline(0.0, color=_SURFACE, lw=1.2, zorder=1)
            self._views.append(_ViewArtists.build(ax, pose))
        present = list(dict.fromkeys(t for c in pose.contacts for t in c.forces))
        handles: list[Any] = [
            Line2D([], [], color=term_colour(t), lw=2.0, label=t) for t in present
        ]
        if present:
            handles.append(Line2D([], [], color=_TOTAL_COLOUR, lw=6.0, alpha=0.5, label="sum"))
        handles.append(Patch(fc=_WET, alpha=0.55, hatch="///", label="immersed"))
        if scale > 0.0:
            note = f"force arrows\n10 mm = {0.01 / scale:.3g} N"
        elif present:
            note = "no force"
        elif "forces" not in self.result.scene.record:
            note = "forces not recorded"
        else:
            note = "no force on a contact"
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

    def frame_pixels(self) -> tuple[int, int]:
        """Width and height of a written frame [px] (the figure at ``dpi``)."""
        width, height = self.figure.get_size_inches() * self.dpi
        return round(float(width)), round(float(height))

    def _write_gif(self, tmp: Path, tick: Any) -> None:
        """Write the frames as a GIF to ``tmp`` (the temporary file of ``replacing``): the
        still parts (axes, ticks, sand, legend) drawn once, each frame only the moving artists
        over them (what matplotlib calls blitting), and each frame reduced to the first
        frame's palette (the legend holds every arrow's colour). Drawing every frame whole
        through matplotlib's writer drew it twice and quantized it apart: about four times
        slower."""
        from PIL import Image

        canvas = self.figure.canvas
        assert isinstance(canvas, FigureCanvasAgg)
        moving = self.draw(0)
        for artist in moving:
            artist.set_animated(True)
        try:
            canvas.draw()  # everything but the moving artists
            background = canvas.copy_from_bbox(self.figure.bbox)
            frames: list[Any] = []
            palette: Any = None
            for k in range(self.n_frames):
                canvas.restore_region(background)
                changed = self.draw(k)
                for artist in sorted(changed, key=lambda a: a.get_zorder()):
                    self.figure.draw_artist(artist)
                rgb = Image.frombuffer(
                    "RGBA", canvas.get_width_height(), canvas.buffer_rgba(), "raw", "RGBA", 0, 1
                ).convert("RGB")
                if palette is None:
                    palette = rgb.quantize(colors=255, method=Image.Quantize.MEDIANCUT)
                frames.append(rgb.quantize(palette=palette, dither=Image.Dither.NONE))
                tick(k, self.n_frames)
        finally:
            for artist in moving:
                artist.set_animated(False)
        gif = {"format": "GIF", "save_all": True, "loop": 0, "duration": 1000.0 / self.fps}
        frames[0].save(tmp, append_images=frames[1:], **gif)

    def write(self, path: str | os.PathLike[str], progress: bool | None = None) -> Path:
        """Write the animation to ``path``: ``.gif`` (Pillow), ``.mp4`` (ffmpeg) or ``.html``
        (a self-contained JavaScript player). The path is checked first, before any frame is
        drawn; frames that would take more than :data:`granrs.animation.BIG_SAVE_BYTES` as
        pixels warn first (:class:`~granrs.errors.AnimationSizeWarning`, with the estimate).
        ``progress``: a tqdm bar of the frames on stderr (None: when stderr is a terminal).
        Returns the path."""

        out = check_output(path)
        suffix = out.suffix.lower()
        width, height = self.frame_pixels()
        estimate = saved_bytes(self.n_frames, width, height)
        if estimate > BIG_SAVE_BYTES:
            span = float(self.frame_times[-1] - self.frame_times[0])
            warnings.warn(
                AnimationSizeWarning(
                    f"writing {out}: {self.n_frames} frames of {width} x {height} px take "
                    f"about {estimate / 1e6:,.0f} MB (one byte a pixel, held in memory until "
                    f"written); frame_dt = {span / (DEFAULT_FRAMES - 1):.3g} s gives "
                    f"{DEFAULT_FRAMES} frames, and a lower dpi smaller ones"
                ),
                stacklevel=2,
            )
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
                    self._write_gif(tmp, tick)
                else:
                    writer = mpl_animation.FFMpegWriter(fps=fps)
                    self.save(str(tmp), writer=writer, dpi=self.dpi, progress_callback=tick)
        finally:
            bar.close()
        return out


# --- the entry point ------------------------------------------------------------------------


def animate(
    result: Result,
    frame_dt: float | None = None,
    speed: float | None = None,
    fps: float | None = None,
    *,
    out: str | os.PathLike[str] | None = None,
    dpi: float = 100.0,
    progress: bool | None = None,
) -> ImpactAnimation:
    """An animation of a recorded impact, from its series alone (no second simulation).

    Args:
        result: a :func:`granrs.simulate` result whose scene recorded ``"state"`` (and
            ``"forces"`` for the force arrows): ``scene.replace(record=("state", "forces"))``;
            or a body in space's (:class:`granrs.space.Result`) recorded with ``record=True``,
            drawn in 3D: its surface at each pose over the sand's plane, with the sand's
            force as an arrow from its centre of mass.
        frame_dt: simulated time per frame [s] (default: ``speed / fps``).
        speed: playback speed, simulated seconds per second of movie [-] (default 0.02:
            50x slow motion; faster for a run longer than
            :data:`granrs.animation.DEFAULT_FRAMES` such frames); ``speed = frame_dt * fps``.
        fps: frames per second of the movie [1/s] (default 25).
        out: if given, also write the animation there (``.gif``, ``.mp4`` or ``.html``);
            checked before anything is drawn.
        dpi: resolution of written frames [dots per inch].
        progress: while writing ``out``, a tqdm bar of the frames on stderr (None: when
            stderr is a terminal; True: always; False: never).

    Returns:
        An :class:`ImpactAnimation` (a ``matplotlib.animation.FuncAnimation``) with
        ``floor(t_end / frame_dt) + 1`` frames, ``t_end`` the last recorded time [s]; frame
        ``k`` shows ``t = k * frame_dt``. In Jupyter it shows inline.

    Raises:
        InvalidParameterError: before any frame is drawn, naming the field: ``result`` not a
            Result, or one that recorded no state (``field="record"``); ``frame_dt``,
            ``speed``, ``fps`` or ``dpi`` not positive (or inconsistent); more than
            :data:`granrs.animation.MAX_FRAMES` frames (``field="frame_dt"``); ``out`` with
            an unknown suffix or in a missing or unwritable directory.

    Warns:
        AnimationSizeWarning: writing ``out`` would hold more than
            :data:`granrs.animation.BIG_SAVE_BYTES` of frames; the message gives the estimate.
    """
    if isinstance(result, space.Result):
        return _space_animation.animate(  # type: ignore[return-value]
            result, frame_dt, speed, fps, out=out, dpi=dpi, progress=progress
        )
    if not isinstance(result, Result):
        raise InvalidParameterError(
            f"animate() takes a granrs.Result or a granrs.space.Result, got "
            f"{type(result).__name__}",
            field="result",
        )
    playback(frame_dt, speed, fps)  # the values checked before the series are read
    dpi_value = _positive(dpi, "dpi")
    assert dpi_value is not None
    target = check_output(out) if out is not None else None
    series = result.series
    needed = ("t", *_names(result.scene)["coords"])
    if series is None or any(name not in series for name in needed) or len(series["t"]) == 0:
        raise InvalidParameterError(
            "the result recorded no state to animate: run the scene with "
            "record=('state', 'forces'), e.g. granrs.simulate(scene.replace(record=('state', "
            "'forces')))",
            field="record",
        )
    t = np.asarray(series["t"], dtype=float)
    times, frame_dt, speed, fps = frame_times(t, frame_dt, speed, fps)
    anim = ImpactAnimation(result, times, frame_dt, speed, fps, dpi=dpi_value)
    if target is not None:
        anim.write(target, progress=progress)
    return anim
