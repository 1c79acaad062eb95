"""An impact you can watch: :func:`animate` turns a recorded run into a matplotlib animation.

The animation reads the run's recorded series only (``record=("state", "forces")``); it
never runs a second simulation. Each frame shows, to scale and in millimetres:

* the body, placed from the recorded generalized coordinates and the scene's geometry: the
  free link's rod (length L, diameter d_c), the chain's two rods (each hanging from the pin),
  or the leg's foot (its box, f_s long and 0.039 H high from the sole to the ankle) with the
  shank, thigh and half trunk as lines between the joints, and the foot's contact box dashed;
* the sand (y < 0) and the immersed part of each contact shaded;
* the force on each contact as one arrow per term of the force law, laid tip to tail from
  its point of application (the tip, the middle of the sole, or the immersed centroid E with
  ``apply_at="centroid"``): drag (F_dx, F_dy), static_h (F_sh, along x), static_v (F_sv,
  along y), over a wide grey arrow for their sum, on one scale for the whole animation (the
  largest recorded force is 0.6 of the rod's length or of the tibia; stated in the legend);
* a clock (simulated time) and each contact's depth.

Frame ``k`` shows the recorded series at ``t = k * frame_dt`` (linear interpolation between
recorded samples), so the movie has ``floor(t_end / frame_dt) + 1`` frames, ``t_end`` being
the last recorded time. Playback: ``speed = frame_dt * fps`` simulated seconds per second of
movie; give any two of ``frame_dt``, ``speed`` and ``fps`` (or one, or none: the defaults
are ``fps = 25`` and ``speed = 0.02``, i.e. 50x slow motion) and the third follows.

Figures are built without :mod:`matplotlib.pyplot` (no global backend, no window): the
returned :class:`ImpactAnimation` shows inline in Jupyter (its ``_repr_html_`` falls back to
``to_jshtml()``) and writes GIF (Pillow), MP4 (needs ffmpeg) or HTML
(:meth:`ImpactAnimation.write`).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ._files import check_target
from .errors import InvalidParameterError

if TYPE_CHECKING:
    from ._animation import ImpactAnimation
    from .result import Result
    from .scene import Scene

__all__ = [
    "ANIMATION_FORMATS",
    "DEFAULT_FPS",
    "DEFAULT_SPEED",
    "MAX_FRAMES",
    "TERM_COLOURS",
    "ImpactAnimation",
    "animate",
    "check_output",
    "frame_count",
    "playback",
]

#: The output formats :meth:`ImpactAnimation.write` knows, by file suffix.
ANIMATION_FORMATS: tuple[str, ...] = (".gif", ".mp4", ".html")
#: Default frames per second of the movie [1/s].
DEFAULT_FPS = 25.0
#: Default playback speed [simulated s per s of movie]: 50x slow motion, so that a 30 ms
#: impact plays for 1.5 s.
DEFAULT_SPEED = 0.02
#: Most frames one animation may have (a guard against a ``frame_dt`` far too small).
MAX_FRAMES = 10_000
#: Colour of each force term's arrow (and of their sum, ``"total"``).
TERM_COLOURS: dict[str, str] = {
    "drag": "tab:blue",
    "static_h": "tab:orange",
    "static_v": "tab:green",
    "total": "black",
}
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
    frame_dt: float | None = None, speed: float | None = None, fps: float | None = None
) -> tuple[float, float, float]:
    """Resolve ``(frame_dt [s], speed [-], fps [1/s])`` from any of them: ``speed = frame_dt *
    fps``. Missing values default to ``fps = DEFAULT_FPS``, then ``speed = DEFAULT_SPEED``.

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
    return speed / fps, speed, fps


def frame_count(t_end: float, frame_dt: float) -> int:
    """Number of frames for series recorded from t = 0 to ``t_end`` [s], one every
    ``frame_dt`` [s]: ``floor(t_end / frame_dt) + 1`` (the quotient to round-off)."""
    return math.floor(t_end / frame_dt + _FRAME_ROUNDOFF) + 1


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


def _state_columns(scene: Scene) -> Sequence[str]:
    from .result import _names

    return _names(scene)["coords"]


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
            50x slow motion); ``speed = frame_dt * fps``.
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
            ``granrs.animate.MAX_FRAMES`` frames (``field="frame_dt"``); ``out`` with an
            unknown suffix or in a missing or unwritable directory.
    """
    from .result import Result

    if not isinstance(result, Result):
        raise InvalidParameterError(
            f"animate() takes a granrs.Result, got {type(result).__name__}", field="result"
        )
    frame_dt, speed, fps = playback(frame_dt, speed, fps)
    dpi_value = _positive(dpi, "dpi")
    assert dpi_value is not None
    target = check_output(out) if out is not None else None
    series = result.series
    needed = ("t", *_state_columns(result.scene))
    if series is None or any(name not in series for name in needed) or len(series["t"]) == 0:
        raise InvalidParameterError(
            "the result recorded no state to animate: run the scene with "
            "record=('state', 'forces'), e.g. granrs.simulate(scene.replace(record=('state', "
            "'forces')))",
            field="record",
        )
    from ._animation import ImpactAnimation

    t = np.asarray(series["t"], dtype=float)
    span = float(t[-1] - t[0])
    n = frame_count(span, frame_dt)
    if n > MAX_FRAMES:
        raise InvalidParameterError(
            f"frame_dt = {frame_dt:g} s gives {n} frames over {span:g} s; at most {MAX_FRAMES} "
            f"(use frame_dt >= {span / (MAX_FRAMES - 1):.3g} s)",
            field="frame_dt",
        )
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
