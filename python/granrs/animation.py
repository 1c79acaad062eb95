"""An impact you can watch: :func:`animate` (also :func:`granrs.animate`) turns a recorded
run into a matplotlib animation.

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
returned :class:`ImpactAnimation` shows inline in Jupyter (its ``_repr_html_`` falls back to
``to_jshtml()``) and writes GIF (Pillow), MP4 (needs ffmpeg) or HTML
(:meth:`ImpactAnimation.write`).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from ._playback import (
    ANIMATION_FORMATS,
    BIG_SAVE_BYTES,
    DEFAULT_FPS,
    DEFAULT_FRAMES,
    DEFAULT_SPEED,
    MAX_FRAMES,
    _positive,
    check_output,
    frame_count,
    playback,
    saved_bytes,
)
from .errors import InvalidParameterError
from .result import Result, _names

if TYPE_CHECKING:
    from ._animation import ImpactAnimation

__all__ = [
    "ANIMATION_FORMATS",
    "BIG_SAVE_BYTES",
    "DEFAULT_FPS",
    "DEFAULT_FRAMES",
    "DEFAULT_SPEED",
    "MAX_FRAMES",
    "ImpactAnimation",
    "animate",
    "check_output",
    "frame_count",
    "playback",
    "saved_bytes",
]


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
            ``"forces"`` for the force arrows): ``scene.replace(record=("state", "forces"))``.
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
    if not isinstance(result, Result):
        raise InvalidParameterError(
            f"animate() takes a granrs.Result, got {type(result).__name__}", field="result"
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
    span = float(t[-1] - t[0])
    frame_dt, speed, fps = playback(frame_dt, speed, fps, span=span)
    n = frame_count(span, frame_dt)
    if n > MAX_FRAMES:
        raise InvalidParameterError(
            f"frame_dt = {frame_dt:g} s gives {n} frames over {span:g} s; at most {MAX_FRAMES} "
            f"(use frame_dt >= {span / (MAX_FRAMES - 1):.3g} s)",
            field="frame_dt",
        )
    from ._animation import ImpactAnimation

    times = np.minimum(t[0] + frame_dt * np.arange(n), t[-1])
    anim = ImpactAnimation(result, times, frame_dt, speed, fps, dpi=dpi_value)
    if target is not None:
        anim.write(target, progress=progress)
    return anim


def __getattr__(name: str) -> Any:
    # ImpactAnimation (a matplotlib FuncAnimation) lives in granrs._animation, which imports
    # matplotlib: loaded on first use, so that `import granrs` does not pay for it.
    if name == "ImpactAnimation":
        from ._animation import ImpactAnimation

        return ImpactAnimation
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
