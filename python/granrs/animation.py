"""An impact you can watch: :func:`granrs.animate` turns a recorded run into a matplotlib
animation; this module holds its settings (the defaults and limits below) and the checks it
makes before anything is drawn.

The animation reads the run's recorded series only (``record=("state", "forces")``); it
never runs a second simulation. Every body is drawn the same way, from its linkage
(:class:`granrs.bodies.Linkage`; a built-in body's is ``scene.body``): each frame shows, to
scale and in millimetres,

* each link as a bar along its axis from its joint, over the part of the axis its own
  geometry spans (its joint, its children's joints, its centre of mass, its contacts; at
  least its ``length``), placed from the recorded root position and link angles, with a dot
  at every joint;
* each contact's outline: a rod (filled), a box (dashed) or an arc (a thin band);
* the sand (y < 0) and the immersed part of each contact shaded;
* the force on each contact as one arrow per recorded term (every term of the run's
  :attr:`~granrs.Result.terms` that records force columns, each column the component the
  core's registry gives it), laid tip to tail from its point of application (the contact's
  reference point: a rod's tip, the middle of a box's sole, an arc's middle; with
  ``apply_at="centroid"`` a rod's or a box's immersed centroid), over a wide grey arrow for
  their sum, on one scale for the whole animation (the largest recorded force is 0.6 of the
  body's largest link; stated in the legend);
* a clock (simulated time) and each contact's depth; the title names the body and the
  scene's own start (a built-in body's speed or angle; a linkage's root).

Frame ``k`` shows the recorded series at ``t = k * frame_dt`` (linear interpolation between
recorded samples), so the movie has ``floor(t_end / frame_dt) + 1`` frames, ``t_end`` being
the last recorded time. Playback: ``speed = frame_dt * fps`` simulated seconds per second of
movie; give any two of ``frame_dt``, ``speed`` and ``fps`` (or one, or none). The defaults
are ``fps = 25`` (:data:`DEFAULT_FPS`) and ``speed = 0.02`` (:data:`DEFAULT_SPEED`, 50x slow
motion), or faster for a long run, so that a movie left to the defaults has at most
:data:`DEFAULT_FRAMES` frames. No movie has more than :data:`MAX_FRAMES`. Writing one whose
frames take more than :data:`BIG_SAVE_BYTES` warns first
(:class:`~granrs.errors.AnimationSizeWarning`, with the estimate).

Figures are built without :mod:`matplotlib.pyplot` (no global backend, no window): the
returned :class:`granrs.ImpactAnimation` shows inline in Jupyter (its ``_repr_html_`` falls
back to ``to_jshtml()``) and writes GIF (Pillow), MP4 (needs ffmpeg) or HTML
(:meth:`granrs.ImpactAnimation.write`).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from ._files import check_target
from .errors import InvalidParameterError

__all__ = [
    "ANIMATION_FORMATS",
    "BIG_SAVE_BYTES",
    "DEFAULT_FPS",
    "DEFAULT_FRAMES",
    "DEFAULT_SPEED",
    "MAX_FRAMES",
    "check_output",
    "frame_count",
    "playback",
    "saved_bytes",
]

#: The output formats :meth:`granrs.ImpactAnimation.write` knows, by file suffix.
ANIMATION_FORMATS: tuple[str, ...] = (".gif", ".mp4", ".html")
#: Default frames per second of the movie [1/s].
DEFAULT_FPS = 25.0
#: Default playback speed [simulated s per s of movie]: 50x slow motion, so that a 30 ms
#: impact plays for 1.5 s.
DEFAULT_SPEED = 0.02
#: Most frames of a movie whose ``frame_dt`` and ``speed`` are both left to their defaults:
#: a longer run plays faster than ``DEFAULT_SPEED`` instead (a 1 s run: 250 frames, 10x
#: slow motion, rather than 1251 frames).
DEFAULT_FRAMES = 250
#: Most frames one animation may have (a guard against a ``frame_dt`` far too small).
MAX_FRAMES = 10_000
#: Writing an animation whose frames take more than this many bytes (one a pixel: what a
#: GIF holds in memory before it is written, and at most the file's size; see
#: :func:`saved_bytes`) warns first, with the estimate
#: (:class:`granrs.errors.AnimationSizeWarning`). 200 MB is about 460 frames of the
#: narrowest figure (720 x 600 px at 100 dpi).
BIG_SAVE_BYTES = 200_000_000
#: Round-off allowance of the frame count: ``t_end / frame_dt`` within this of a whole
#: number counts as that number (0.03 / 0.01 = 2.9999999999999996 gives 4 frames).
_FRAME_ROUNDOFF = 1e-9


def _positive(value: Any, name: str) -> float | None:
    """``value`` as a positive finite float (None stays None); else InvalidParameterError."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InvalidParameterError(
            f"{name} must be a positive number, got {type(value).__name__} {value!r}", field=name
        )
    number = float(value)
    if not math.isfinite(number) or number <= 0.0:
        raise InvalidParameterError(
            f"{name} must be positive and finite; got {number!r}", field=name
        )
    return number


def playback(
    frame_dt: float | None = None,
    speed: float | None = None,
    fps: float | None = None,
    span: float | None = None,
) -> tuple[float, float, float]:
    """Resolve ``(frame_dt [s], speed [-], fps [1/s])`` from any of them: ``speed = frame_dt *
    fps``. Missing values default to ``fps = DEFAULT_FPS``, then ``speed = DEFAULT_SPEED``;
    given the recorded ``span`` [s] and neither ``frame_dt`` nor ``speed``, the speed is the
    larger of ``DEFAULT_SPEED`` and the one that shows ``span`` in ``DEFAULT_FRAMES`` frames.

    Raises:
        InvalidParameterError: a value that is not a positive finite number (``field`` names
            it), or three values with ``frame_dt * fps != speed`` (``field="speed"``).
    """
    frame_dt = _positive(frame_dt, "frame_dt")
    speed = _positive(speed, "speed")
    fps = _positive(fps, "fps")
    if frame_dt is not None and speed is not None and fps is not None:
        if not math.isclose(frame_dt * fps, speed, rel_tol=1e-9):
            raise InvalidParameterError(
                f"frame_dt * fps = {frame_dt * fps:g} must equal speed = {speed:g}; give at "
                "most two of frame_dt, speed and fps",
                field="speed",
            )
        return frame_dt, speed, fps
    if frame_dt is not None and speed is not None:
        return frame_dt, speed, speed / frame_dt
    if fps is None:
        fps = DEFAULT_FPS
    if frame_dt is not None:
        return frame_dt, frame_dt * fps, fps
    if speed is None:
        speed = DEFAULT_SPEED
        if span is not None and span > 0.0:
            speed = max(speed, span / (DEFAULT_FRAMES - 1) * fps)
    return speed / fps, speed, fps


def frame_count(t_end: float, frame_dt: float) -> int:
    """Number of frames for series recorded from t = 0 to ``t_end`` [s], one every
    ``frame_dt`` [s]: ``floor(t_end / frame_dt) + 1`` (the quotient to round-off)."""
    return math.floor(t_end / frame_dt + _FRAME_ROUNDOFF) + 1


def frame_times(
    t: np.ndarray, frame_dt: float | None, speed: float | None, fps: float | None
) -> tuple[np.ndarray, float, float, float]:
    """The simulated time of each frame of series recorded at the times ``t`` [s], and the
    playback (``frame_dt``, ``speed``, ``fps``) they come from (:func:`playback`); more than
    :data:`MAX_FRAMES` frames raise an :class:`~granrs.errors.InvalidParameterError` naming
    ``frame_dt``."""
    span = float(t[-1] - t[0])
    frame_dt, speed, fps = playback(frame_dt, speed, fps, span=span)
    n = frame_count(span, frame_dt)
    if n > MAX_FRAMES:
        raise InvalidParameterError(
            f"frame_dt = {frame_dt:g} s gives {n} frames over {span:g} s; at most {MAX_FRAMES} "
            f"(use frame_dt >= {span / (MAX_FRAMES - 1):.3g} s)",
            field="frame_dt",
        )
    return np.minimum(t[0] + frame_dt * np.arange(n), t[-1]), frame_dt, speed, fps


def saved_bytes(n_frames: int, width_px: int, height_px: int) -> int:
    """Bytes of ``n_frames`` frames of ``width_px`` x ``height_px`` at one byte a pixel: what
    the GIF writer holds in memory before it writes the file (its frames reduced to one
    palette), and at most the size of the GIF itself."""
    return int(n_frames) * int(width_px) * int(height_px)


def check_output(path: str | os.PathLike[str]) -> Path:
    """Check that an animation can be written to ``path``, before anything is drawn.

    The suffix must be one of :data:`ANIMATION_FORMATS` (``.mp4`` only where matplotlib
    finds ffmpeg), the directory must exist and be writable, and an existing ``path`` must
    be a writable file. Returns the path.

    Raises:
        InvalidParameterError: ``field="out"``, with the reason.
    """
    out = Path(path)
    suffix = out.suffix.lower()
    if suffix not in ANIMATION_FORMATS:
        raise InvalidParameterError(
            f"cannot write an animation to {out}: unknown suffix {suffix or '(none)'!r}; "
            f"use {', '.join(ANIMATION_FORMATS)}",
            field="out",
        )
    from matplotlib import animation as mpl_animation

    if suffix == ".mp4" and not mpl_animation.writers.is_available("ffmpeg"):
        raise InvalidParameterError(
            f"cannot write {out}: .mp4 needs ffmpeg on PATH (e.g. apt-get install ffmpeg); "
            "write .gif or .html instead",
            field="out",
        )
    check_target(out, "out")
    return out
