"""``granrs.simulate``: run one scene."""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from . import _granrs, space
from .errors import GranrsError, InvalidParameterError, SimulationError, StepSizeWarning
from .result import Result
from .scene import _CORE_FIELDS, Scene

__all__ = ["RK4_STABILITY_LIMIT", "STEP_CHECK_FACTOR", "STEP_ERROR_LIMIT", "simulate"]

#: ``h lambda`` beyond which the classical RK4 is unstable for a real, negative rate
#: (the stability region's extent on the negative real axis, 2.785).
RK4_STABILITY_LIMIT = 2.785
#: A rise of the mechanical energy beyond this fraction of its size counts as a rise.
ENERGY_ROSE_RTOL = 1e-9
#: The relative change of t_s or the depth that counts as a result that moves with the step:
#: 1 %. The step's check (``Scene.step_check``) warns when a run's t_s or depth moves by more
#: than this at ``dt / STEP_CHECK_FACTOR`` (or its status changes); the steps' own error
#: estimate ``step_error`` is read against it in the warning's text.
STEP_ERROR_LIMIT = 0.01
#: The step's check runs a suspect again at ``dt / STEP_CHECK_FACTOR``.
STEP_CHECK_FACTOR = 10
#: A run whose steps' own error estimate (``step_error``) exceeds this is a suspect, checked
#: at ``dt / STEP_CHECK_FACTOR`` (under the sign models that estimate, all but ``"raw"``).
#: Measured on ``benches/step_warning.py`` (seeds 7, 11, 23, 3 and 42, 200 scenes each, dt
#: 1e-3 and 1e-4): the smallest ``step_error`` of a run that moved by more than 1 % and that
#: no other test flags is 3.0e-5; this is a third of it.
SUSPECT_STEP_ERROR = 1e-5


def step_advice(
    dt: float,
    h_lambda: float,
    unresolved: int = 0,
    unresolved_stops: int = 0,
    step_error: float = 0.0,
    moved: str | None = None,
) -> str:
    """What to tell a user whose run did not resolve its contact: ``moved``, what the step's
    check measured at ``dt / STEP_CHECK_FACTOR`` (None: the run was not checked), and why the
    run was checked: ``h_lambda`` above :data:`RK4_STABILITY_LIMIT`, the steps' own error
    estimate ``step_error``, ``unresolved_stops`` contacts the step did not resolve (a stop
    that fell between the steps, or a stick that the step's overshoot decided), or
    ``unresolved`` steps the sign modes chattered through."""
    finer = f"use dt <= {dt / STEP_CHECK_FACTOR:.2g} s (dt / {STEP_CHECK_FACTOR})"
    if h_lambda > RK4_STABILITY_LIMIT:
        why = (
            f"dt times the contact's fastest rate reached {h_lambda:.3g} (RK4 is stable below "
            f"{RK4_STABILITY_LIMIT})"
        )
        advice = f"use dt <= {dt * 0.5 / h_lambda:.2g} s (dt * rate <= 0.5)"
    elif step_error > STEP_ERROR_LIMIT:
        why = (
            f"the steps' own error estimates put t_s or the depth {100 * step_error:.3g} % off "
            f"(step_error {step_error:.3g}, above {STEP_ERROR_LIMIT})"
        )
        advice = finer
    elif unresolved_stops:
        why = (
            f"{unresolved_stops} contact{'s' if unresolved_stops != 1 else ''} did not "
            "resolve: a stop fell between the steps (the tip's vertical velocity was not zero "
            "where the stop was located: the impact is over in too few steps), or the step "
            "decided a stick (the located sign switch overshot zero, and the contact slid on "
            "where the sand would have held it)"
        )
        advice = finer
    elif unresolved:
        why = (
            f"in {unresolved} step{'s' if unresolved != 1 else ''} the force's signs switched "
            "more than 32 times, the step was taken as it was, and the energy rose"
        )
        advice = "use a smaller dt"
    else:
        why = f"the steps' own error estimate is step_error {step_error:.3g}"
        advice = finer
    if moved is None:
        return (
            f"dt = {dt:g} s does not resolve this scene's contact: {why}, so the result is not "
            f'the converged answer; {advice}, or method="dopri5"'
        )
    return (
        f"dt = {dt:g} s does not resolve this scene's contact: {moved} (checked because {why}), "
        f'so the result is not the converged answer; {advice}, or method="dopri5"'
    )


def suspects(
    h_lambda: Any,
    step_error: Any,
    unresolved_stops: Any,
    unresolved: Any,
    energy_start: Any,
    energy_end: Any,
    estimates: Any = True,
) -> Any:
    """Which runs the step's check runs again at ``dt / STEP_CHECK_FACTOR`` (numpy arrays of
    runs, or one run's numbers): those that warn without the check (:func:`loud`), and, where
    the run ``estimates`` its error (every sign model but ``"raw"``), ``step_error`` above
    :data:`SUSPECT_STEP_ERROR`. A field the run did not compute (NaN) flags nothing."""
    return loud(h_lambda, unresolved_stops, unresolved, energy_start, energy_end) | (
        estimates & (step_error > SUSPECT_STEP_ERROR)
    )


#: What a comparison of one run's numbers gives (not a numpy array of runs).
_ONE_RUN = (bool, np.bool_)


def loud(
    h_lambda: Any, unresolved_stops: Any, unresolved: Any, energy_start: Any, energy_end: Any
) -> Any:
    """The runs that warn without the step's check (``step_check=False``, or a check that
    cannot run), numpy arrays of runs or one run's numbers: ``h_lambda`` above
    :data:`RK4_STABILITY_LIMIT`, a contact the step did not resolve (``unresolved_stops``),
    or steps the sign modes chattered through (``unresolved``) with a rise in the mechanical
    energy beyond rounding (:data:`ENERGY_ROSE_RTOL` of its size): chatter at rest loses
    energy; a step too large for the contact gains it."""
    stiff_or_stop = (h_lambda > RK4_STABILITY_LIMIT) | (unresolved_stops > 0)
    chatter = unresolved > 0
    if isinstance(chatter, _ONE_RUN):
        # One run: the energies only where it chattered (a run's check costs no numpy call).
        return bool(stiff_or_stop) or (bool(chatter) and bool(_rose(energy_start, energy_end)))
    with np.errstate(invalid="ignore"):
        return stiff_or_stop | (chatter & _rose(energy_start, energy_end))


def _rose(start: Any, end: Any) -> Any:
    """Whether the mechanical energy ended above where it started beyond rounding."""
    scale = np.maximum(np.maximum(abs(start), abs(end)), 1e-12)
    return end - start > ENERGY_ROSE_RTOL * scale


def relative_move(coarse: float, fine: float) -> float:
    """How far ``coarse`` is from ``fine``, relative to ``fine`` (0 where both are NaN, as a
    contact that stops at neither step; infinite where only one is)."""
    if math.isnan(coarse) and math.isnan(fine):
        return 0.0
    if math.isnan(coarse) or math.isnan(fine):
        return math.inf
    if coarse == fine:
        return 0.0
    return abs(coarse - fine) / abs(fine) if fine != 0.0 else math.inf


def step_move(
    coarse: Mapping[str, Sequence[float]],
    fine: Mapping[str, Sequence[float]],
    status: tuple[str, str],
    fine_dt: float,
) -> dict[str, Any]:
    """What the step's check measured: each contact's ``t_s`` and ``depth`` at ``dt``
    (``coarse``) and at ``fine_dt``, by name (``"t_s"``, ``"depth"``; a body with several
    contacts ``"c0.t_s"``, ...), the status at both, the largest relative move and whether
    the run moved (by more than :data:`STEP_ERROR_LIMIT`, or its status changed)."""
    moves: dict[str, float] = {}
    several = len(coarse["t_s"]) > 1
    for key in ("t_s", "depth"):
        for i, (a, b) in enumerate(zip(coarse[key], fine[key], strict=True)):
            moves[f"c{i}.{key}" if several else key] = relative_move(float(a), float(b))
    largest = max(moves.values(), default=0.0)
    return {
        "dt": fine_dt,
        "moves": moves,
        "status": status,
        "largest": largest,
        "moved": status[0] != status[1] or largest > STEP_ERROR_LIMIT,
    }


def describe_move(check: Mapping[str, Any]) -> str:
    """The check's finding in words: "t_s moves 3.2 % at dt = 1e-05 s" (the largest move, and
    the status if it changed)."""
    at = f"at dt = {check['dt']:g} s"
    a, b = check["status"]
    parts = []
    if a != b:
        parts.append(f"its status is {b!r} {at} against {a!r}")
    name, move = max(check["moves"].items(), key=lambda kv: kv[1], default=("t_s", 0.0))
    if move > STEP_ERROR_LIMIT:
        size = "beyond measure" if math.isinf(move) else f"{100 * move:.3g} %"
        parts.append(f"{name} moves {size} {at}")
    return " and ".join(parts)


def _contacts(raw: Mapping[str, Any]) -> dict[str, list[float]]:
    return {"t_s": list(raw["t_s"]), "depth": list(raw["depth"])}


def check_step(scene: Scene, outcome: Any, raw: Mapping[str, Any]) -> dict[str, Any] | None:
    """The step's check of one run (``outcome``, the run of ``scene`` at its own ``dt``;
    ``raw``, its outcome as a dict): the same scene at ``dt / STEP_CHECK_FACTOR`` (no series
    recorded, only the outputs the check reads), compared by :func:`step_move`. None where it
    cannot run: the finer run would take more steps than a run may (``t_end / dt``) or is
    refused."""
    fine_dt = scene.dt / STEP_CHECK_FACTOR
    try:
        fine_scene = scene.replace(dt=fine_dt, record=(), outputs=("t_s", "depth"))
        fine = _granrs.run_scene(fine_scene.__dict__, _CORE_FIELDS)
    except SimulationError:
        # A run that diverges at dt / 10: its status changed ("failed").
        return {
            "dt": fine_dt,
            "moves": {},
            "status": (outcome.status, "failed"),
            "largest": math.inf,
            "moved": True,
        }
    except GranrsError:
        return None
    return step_move(
        _contacts(raw), _contacts(fine.to_dict()), (outcome.status, fine.status), fine_dt
    )


def simulate(scene: Scene | space.Scene) -> Result | space.Result:
    """Run one scene and return its :class:`~granrs.Result` (a planar scene) or its
    :class:`granrs.space.Result` (a body in space, :class:`granrs.space.Scene`).

    The scene is validated in full before the run starts (an invalid field raises a
    :class:`~granrs.errors.InvalidSceneError` subclass naming it). The run itself releases
    the GIL; on the main thread, Ctrl-C stops it within a fraction of a second and raises
    ``KeyboardInterrupt``. A body that has not stopped by ``scene.t_end`` is not an error:
    the result's ``status`` says ``"not_stopped"``.

    A run whose step looks too coarse for its contact (``h_lambda`` beyond RK4's stability
    limit, a stop or a stick the step decided, chatter that gained energy, or the steps' own
    error estimate ``step_error`` above 1e-5) is run again at ``dt / 10`` when
    ``scene.step_check`` is on (the default), and warns :class:`~granrs.StepSizeWarning`
    only if its ``t_s``, depth or status moves there by more than 1 %; the result is the
    run at ``scene.dt`` either way, and ``Result.step_check`` holds what the check measured
    (None: no check ran). With ``step_check=False`` nothing is run again, and the first
    three of those warn as they are.

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
    return _checked(scene, outcome, result)


def _checked(scene: Scene, outcome: Any, result: Result) -> Result:
    """``result`` after the step's check (see :func:`simulate`): it warns, and it keeps what
    the check measured in ``result.step_check``; the result's numbers are the run's."""
    h_lambda, unresolved_stops, unresolved = (
        outcome.h_lambda,
        outcome.unresolved_stops,
        outcome.unresolved,
    )
    # The energies only where steps were unresolved (reading them converts the outcome; the
    # run's energies are always computed, whatever its outputs).
    e0 = e1 = math.nan
    if unresolved:
        raw = result._raw_dict()
        e0, e1 = raw["energy_start"], raw["energy_end"]
    if scene.step_check:
        if not suspects(
            h_lambda,
            outcome.step_error,
            unresolved_stops,
            unresolved,
            e0,
            e1,
            scene.sign_model != "raw",
        ):
            # Not a suspect, so not loud either (a suspect is every loud run and more).
            return result
        check = check_step(scene, outcome, result._raw_dict())
        if check is not None:
            result.step_check = check
            if check["moved"]:
                advice = _advice(scene, outcome, describe_move(check))
                warnings.warn(StepSizeWarning(advice), stacklevel=3)
            return result
    if loud(h_lambda, unresolved_stops, unresolved, e0, e1):
        warnings.warn(StepSizeWarning(_advice(scene, outcome, None)), stacklevel=3)
    return result


def _advice(scene: Scene, outcome: Any, moved: str | None) -> str:
    return step_advice(
        scene.dt,
        outcome.h_lambda,
        outcome.unresolved,
        outcome.unresolved_stops,
        outcome.step_error,
        moved,
    )
