"""The granrs exception tree.

Every error granrs raises on purpose derives from :class:`GranrsError`. Errors caused by
the caller's input also derive from :class:`ValueError`, so ``except ValueError`` keeps
working for code that does not know granrs.

The Rust core raises the same classes: its one error enum is converted exhaustively in
``rust/python/errors.rs``.
"""

from __future__ import annotations

__all__ = [
    "AnimationSizeWarning",
    "CoefficientTableError",
    "CoefficientsWarning",
    "GranrsError",
    "InvalidParameterError",
    "InvalidSceneError",
    "MeasurementError",
    "MediumError",
    "SimulationError",
    "StepSizeWarning",
    "UnknownNameError",
]


class GranrsError(Exception):
    """Base class of every error granrs raises on purpose."""


class InvalidSceneError(GranrsError, ValueError):
    """A scene (or one of its fields) is not valid. ``field`` names the offending field."""

    def __init__(self, message: str, field: str | None = None) -> None:
        super().__init__(message)
        self.field = field


class InvalidParameterError(InvalidSceneError):
    """A numeric field is out of its allowed range (negative mass, NaN speed, ...)."""


class UnknownNameError(InvalidSceneError):
    """A name (coefficient table, point of application, effect, ...) is not one granrs knows."""


class CoefficientTableError(InvalidSceneError):
    """A coefficient table could not be read or holds invalid values."""


class MeasurementError(InvalidSceneError):
    """A measurements table (for :func:`granrs.calibrate`) could not be read or holds
    invalid values. ``field`` names the column (or ``"measurements"``)."""


class MediumError(InvalidSceneError):
    """A medium card (:mod:`granrs.media`) could not be read or holds an invalid entry: an
    unknown term or parameter, a value out of the parameter's range, a value without its
    source. ``field`` names the entry (``rft.zeta``, ``rho_g``, ``name``, ...)."""


class SimulationError(GranrsError, RuntimeError):
    """The integration itself failed (a non-finite state); never raised for bad input."""


class StepSizeWarning(UserWarning):
    """The fixed step did not resolve the run: at the contact's stiffest moment, ``dt`` times
    its fastest rate (``Result.summary["h_lambda"]``: the drag's, and each listed force term's
    own stiffness in velocity and depth) exceeded RK4's stability limit
    (:data:`granrs.RK4_STABILITY_LIMIT`), a contact's result was not resolved
    (``Result.summary["unresolved_stops"]``: the steps' own error estimates put t_s or the
    depth more than 1 % off, ``summary["step_error"]``, or a stop or a stick was decided by
    where the step located it rather than by the run), or steps where the force's signs
    chattered gained energy. Such a run is checked first (``Scene.step_check``, on by
    default): run again at ``dt / 10``, it warns only if its t_s, depth or status moves by
    more than 1 % there, and the message states that move. The run finished with finite
    numbers, but they are not the converged answer: the message gives the ``dt`` used and a
    ``dt`` that resolves it; rerun with that ``dt`` or ``method="dopri5"``."""


class CoefficientsWarning(UserWarning):
    """A scene's angle (free link: ``q_deg``) or speed (leg: ``v0``) now selects another
    row of the thesis's coefficient table than the one its ``coefficients_source`` names,
    but its force parameters are no longer that row's (they were changed): they are kept
    as given, and ``coefficients_source`` says so. A scene whose parameters are still the
    named row's takes the new row instead, without a warning (:class:`granrs.Scene`)."""


class AnimationSizeWarning(UserWarning):
    """Writing an animation would hold more than :data:`granrs.animation.BIG_SAVE_BYTES` of
    frames (what the GIF writer keeps in memory before it writes): the message gives the
    frame count, the frame size and the estimate, and how to make it smaller (a larger
    ``frame_dt``, a lower ``dpi``). Raised as an error (``warnings.simplefilter("error",
    AnimationSizeWarning)``) it stops the write before any frame is drawn."""
