"""Animations of a body in space (``granrs.animate`` of a :class:`granrs.space.Result`).

The body is drawn as its own surface (a sphere, capsule or cylinder as a grid of facets, a
cuboid's six faces, a mesh's triangles) at each frame's recorded pose, over the sand's
surface as a plane, with the sand's force on it as an arrow from its centre of mass. The
playback settings and their checks are :mod:`granrs.animation`'s, as for planar bodies.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import animation as mpl_animation
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from . import space
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
from .errors import AnimationSizeWarning, InvalidParameterError

#: The recorded columns an animation of a body in space reads.
POSE = ("t", "x", "y", "z", "qw", "qx", "qy", "qz")


def _grid(u: np.ndarray, v: np.ndarray, point: Any) -> list[np.ndarray]:
    """Quads of a parametric surface ``point(u, v) -> (3,)`` on the grid ``u x v``."""
    p = np.array([[point(a, b) for b in v] for a in u])
    return [
        np.array([p[i, j], p[i + 1, j], p[i + 1, j + 1], p[i, j + 1]])
        for i in range(len(u) - 1)
        for j in range(len(v) - 1)
    ]


def body_polygons(scene: space.Scene) -> list[np.ndarray]:
    """The body's surface as polygons in its body frame (its centre of mass the origin)."""
    shape = scene.body.shape
    phi = np.linspace(0.0, 2.0 * np.pi, 25)
    if isinstance(shape, space.Sphere):
        r = shape.radius
        return _grid(
            np.linspace(0.0, np.pi, 13),
            phi,
            lambda t, f: r * np.array([np.sin(t) * np.cos(f), np.sin(t) * np.sin(f), np.cos(t)]),
        )
    if isinstance(shape, space.Capsule | space.Cylinder):
        r, h = shape.radius, shape.length / 2.0
        polys = _grid(
            np.linspace(-h, h, 3),
            phi,
            lambda s, f: np.array([r * np.cos(f), r * np.sin(f), s]),
        )
        for sign in (1.0, -1.0):
            if isinstance(shape, space.Capsule):
                polys += _grid(
                    np.linspace(0.0, np.pi / 2, 6),
                    phi,
                    lambda t, f, s=sign: np.array(
                        [
                            r * np.sin(t) * np.cos(f),
                            r * np.sin(t) * np.sin(f),
                            s * (h + r * np.cos(t)),
                        ]
                    ),
                )
            else:
                polys.append(np.array([[r * np.cos(f), r * np.sin(f), sign * h] for f in phi]))
        return polys
    if isinstance(shape, space.Cuboid):
        a, b, c = (0.5 * float(x) for x in shape.size)
        corners = np.array([[x, y, z] for x in (-a, a) for y in (-b, b) for z in (-c, c)])
        faces = ((0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5))
        return [corners[list(f)] for f in faces]
    vertices = scene.body_vertices()
    assert vertices is not None
    return [vertices[t] for t in np.asarray(shape.triangles)]


def _rotation(q: np.ndarray) -> np.ndarray:
    """The rotation matrix of the unit quaternion ``(w, x, y, z)``."""
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


class SpaceAnimation(mpl_animation.FuncAnimation):
    """A ``matplotlib.animation.FuncAnimation`` of a body in space; :meth:`write` saves it.

    Attributes:
        frame_times: the simulated time of each frame [s].
        frame_dt: simulated time per frame [s].
        speed: simulated seconds per second of movie [-].
        fps: frames per second of the movie [1/s].
        polygons: the body's surface in its body frame, as drawn.
    """

    def __init__(
        self,
        result: space.Result,
        times: np.ndarray,
        frame_dt: float,
        speed: float,
        fps: float,
        dpi: float,
    ) -> None:
        series = result.series
        assert series is not None
        t = np.asarray(series["t"])
        self.frame_times = times
        self.frame_dt = frame_dt
        self.speed = speed
        self.fps = fps
        self.dpi = dpi
        self.n_frames = len(times)
        pose = {k: np.interp(times, t, np.asarray(series[k])) for k in POSE[1:]}
        self.centres = np.stack([pose["x"], pose["y"], pose["z"]], axis=1)
        self.quats = np.stack([pose[k] for k in ("qw", "qx", "qy", "qz")], axis=1)
        force = [np.interp(times, t, np.asarray(series[k])) for k in ("Fx", "Fy", "Fz")]
        self.forces = np.stack(force, axis=1)
        self.polygons = body_polygons(result.scene)
        reach = max(float(np.abs(p).max()) for p in self.polygons)
        lo = self.centres.min(axis=0) - reach
        hi = self.centres.max(axis=0) + reach
        span = float((hi - lo).max())
        mid = 0.5 * (lo + hi)
        # No pyplot: no global figure left open, no window (as the planar animation).
        fig = Figure(figsize=(5.5, 5.0), dpi=dpi)
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(projection="3d")
        ax.set_xlim(mid[0] - span / 2, mid[0] + span / 2)
        ax.set_ylim(mid[1] - span / 2, mid[1] + span / 2)
        ax.set_zlim(mid[2] - span / 2, mid[2] + span / 2)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        s = result.scene.surface
        gx, gy = np.meshgrid(np.linspace(*ax.get_xlim(), 2), np.linspace(*ax.get_ylim(), 2))
        ax.plot_surface(gx, gy, np.full_like(gx, s), color="tan", alpha=0.35)
        self.body = Poly3DCollection(
            [], facecolor="steelblue", edgecolor="k", linewidths=0.2, alpha=0.9
        )
        ax.add_collection3d(self.body)
        peak = float(np.linalg.norm(self.forces, axis=1).max())
        self.force_scale = 0.5 * span / peak if peak > 0 else 0.0
        (self.arrow,) = ax.plot([], [], [], color="crimson", lw=2.0, label="sand's force")
        self.title = ax.set_title("")
        ax.legend(loc="upper right")
        self.ax = ax
        super().__init__(
            fig, self._draw, frames=self.n_frames, interval=1000.0 / fps, blit=False, repeat=True
        )

    def drawn(self, k: int) -> list[np.ndarray]:
        """The body's polygons at frame ``k``, world frame [m]."""
        rot = _rotation(self.quats[k])
        return [p @ rot.T + self.centres[k] for p in self.polygons]

    def _draw(self, k: int) -> list[Any]:
        self.body.set_verts(self.drawn(k))
        c, f = self.centres[k], self.forces[k] * self.force_scale
        self.arrow.set_data_3d([c[0], c[0] + f[0]], [c[1], c[1] + f[1]], [c[2], c[2] + f[2]])
        self.title.set_text(f"t = {self.frame_times[k] * 1e3:.1f} ms")
        return [self.body, self.arrow, self.title]

    def write(self, path: str | os.PathLike[str], progress: bool | None = None) -> Path:
        """Write the animation to ``path`` (``.gif``, ``.mp4`` or ``.html``), whole or not at
        all; warns first where its frames would take more than
        :data:`granrs.animation.BIG_SAVE_BYTES`. Returns the path."""
        out = check_output(path)
        width, height = (int(x) for x in self.ax.figure.get_size_inches() * self.dpi)
        estimate = saved_bytes(self.n_frames, width, height)
        if estimate > BIG_SAVE_BYTES:
            warnings.warn(
                AnimationSizeWarning(
                    f"writing {out}: {self.n_frames} frames of {width} x {height} px take about "
                    f"{estimate / 1e6:,.0f} MB; {DEFAULT_FRAMES} frames or a lower dpi take less"
                ),
                stacklevel=2,
            )
        suffix = out.suffix.lower()
        fps: Any = self.fps
        bar = progress_bar(self.n_frames, progress, "granrs animate", "frame")
        try:
            with replacing(out) as tmp:
                if suffix == ".html":
                    writer: Any = mpl_animation.HTMLWriter(fps=fps, embed_frames=True)
                elif suffix == ".gif":
                    writer = mpl_animation.PillowWriter(fps=fps)
                else:
                    writer = mpl_animation.FFMpegWriter(fps=fps)
                tick = lambda _i, _n: bar.update(1)  # noqa: E731
                self.save(str(tmp), writer=writer, dpi=self.dpi, progress_callback=tick)
        finally:
            bar.close()
        return out


def animate(
    result: space.Result,
    frame_dt: float | None = None,
    speed: float | None = None,
    fps: float | None = None,
    *,
    out: str | os.PathLike[str] | None = None,
    dpi: float = 100.0,
    progress: bool | None = None,
) -> SpaceAnimation:
    """``granrs.animate`` of a body in space (its arguments are those of planar results):
    the scene must have recorded its series (``record=True``)."""
    playback(frame_dt, speed, fps)
    dpi_value = _positive(dpi, "dpi")
    assert dpi_value is not None
    if out is not None:
        check_output(out)
    series = result.series
    if series is None or any(k not in series for k in POSE) or len(series["t"]) == 0:
        raise InvalidParameterError(
            "the result recorded no series to animate: run the scene with record=True, e.g. "
            "granrs.simulate(scene.replace(record=True))",
            field="record",
        )
    t = np.asarray(series["t"], dtype=float)
    times, frame_dt, speed, fps = frame_times(t, frame_dt, speed, fps)
    anim = SpaceAnimation(result, times, frame_dt, speed, fps, dpi_value)
    if out is not None:
        anim.write(out, progress=progress)
    return anim
