"""``granrs.simulate``: run one scene."""

from __future__ import annotations

import warnings

from . import _granrs, space
from .errors import InvalidParameterError, StepSizeWarning
from .result import Result
from .scene import _CORE_FIELDS, Scene

__all__ = ["RK4_STABILITY_LIMIT", "simulate"]

#: ``h lambda`` beyond which the classical RK4 is unstable for a real, negative rate
#: (the stability region's extent on the negative real axis, 2.785).
RK4_STABILITY_LIMIT = 2.785
#: A rise of the mechanical energy beyond this fraction of its size counts as a rise.
ENERGY_ROSE_RTOL = 1e-9
#: The relative error of t_s or depth, as the run's steps estimate it (``step_error``),
#: beyond which a run warns: 1 %, the change that counts as a result that moves with the step.
STEP_ERROR_LIMIT = 0.01


def step_advice(
    dt: float,
    h_lambda: float,
    unresolved: int = 0,
    unresolved_stops: int = 0,
    step_error: float = 0.0,
) -> str:
    """What to tell a user whose run did not resolve its contact: ``h_lambda`` above
    :data:`RK4_STABILITY_LIMIT`, ``unresolved_stops`` contacts the step did not resolve
    (the steps' own error estimate ``step_error`` above :data:`STEP_ERROR_LIMIT`, a stop
    that fell between the steps, or a stick that the step's overshoot decided), or
    ``unresolved`` steps the sign modes chattered through."""
    if h_lambda > RK4_STABILITY_LIMIT:
        why = (
            f"dt times the contact's fastest rate reached {h_lambda:.3g} (RK4 is stable below "
            f"{RK4_STABILITY_LIMIT})"
        )
        advice = f"use dt <= {dt * 0.5 / h_lambda:.2g} s (dt * rate <= 0.5)"
    elif unresolved_stops and step_error > STEP_ERROR_LIMIT:
        why = (
            f"the steps' own error estimates put t_s or the depth {100 * step_error:.3g} % off "
            f"(step_error {step_error:.3g}, above {STEP_ERROR_LIMIT})"
        )
        advice = f"use dt <= {dt / 10:.2g} s (dt / 10)"
    elif unresolved_stops:
        why = (
            f"{unresolved_stops} contact{'s' if unresolved_stops != 1 else ''} did not "
            "resolve: a stop fell between the steps (the tip's vertical velocity was not zero "
            "where the stop was located: the impact is over in too few steps), or the step "
            "decided a stick (the located sign switch overshot zero, and the contact slid on "
            "where the sand would have held it)"
        )
        advice = f"use dt <= {dt / 10:.2g} s (dt / 10)"
    else:
        why = (
            f"in {unresolved} step{'s' if unresolved != 1 else ''} the force's signs switched "
            "more than 32 times, the step was taken as it was, and the energy rose"
        )
        advice = "use a smaller dt"
    return (
        f"dt = {dt:g} s does not resolve this scene's contact: {why}, so the result is not "
        f'the converged answer; {advice}, or method="dopri5"'
    )


def simulate(scene: Scene | space.Scene) -> Result | space.Result:
    """Run one scene and return its :class:`~granrs.Result` (a planar scene) or its
    :class:`granrs.space.Result` (a body in space, :class:`granrs.space.Scene`).

    The scene is validated in full before the run starts (an invalid field raises a
    :class:`~granrs.errors.InvalidSceneError` subclass naming it). The run itself releases
    the GIL; on the main thread, Ctrl-C stops it within a fraction of a second and raises
    ``KeyboardInterrupt``. A body that has not stopped by ``scene.t_end`` is not an error:
    the result's ``status`` says ``"not_stopped"``.

    Example:
        >>> import granrs
        >>> r = granrs.simulate(granrs.cases.free_link(q_deg=45, v0=2.27))
        >>> round(r.depth, 3)
        0.029
    """
    if isinstance(scene, space.Scene):
        result3 = space.run(scene)
        h_lambda = result3.summary["h_lambda"]
        if h_lambda > RK4_STABILITY_LIMIT:
            warnings.warn(StepSizeWarning(step_advice(scene.dt, h_lambda)), stacklevel=2)
        return result3
    if not isinstance(scene, Scene):
        raise InvalidParameterError(
            f"simulate() takes a granrs.Scene or a granrs.space.Scene, got {type(scene).__name__}",
            field="scene",
        )
    # scene._compiled() and _granrs.run in one call of the core.
    outcome = _granrs.run_scene(scene.__dict__, _CORE_FIELDS)
    result = Result(scene, outcome)
    if (
        outcome.h_lambda > RK4_STABILITY_LIMIT
        or outcome.unresolved_stops
        or (
            outcome.unresolved
            # (The run's energies are always computed, whatever its outputs.)
            and energy_rose(result._raw_dict()["energy_start"], result._raw_dict()["energy_end"])
        )
    ):
        advice = step_advice(
            scene.dt,
            outcome.h_lambda,
            outcome.unresolved,
            outcome.unresolved_stops,
            outcome.step_error,
        )
        warnings.warn(StepSizeWarning(advice), stacklevel=2)
    return result


def energy_rose(start: float, end: float) -> bool:
    """Whether the mechanical energy ended above where it started, beyond rounding (1e-9 of
    its size): with steps the sign modes chattered through (``unresolved``), the sign of
    the chatter's error. Chatter at rest loses energy; a step too large for the contact
    gains it."""
    return end - start > ENERGY_ROSE_RTOL * max(abs(start), abs(end), 1e-12)
