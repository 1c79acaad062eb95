"""granrs: rods, linkages and feet sinking into sand.

A Rust-accelerated simulator of the granular resistance force of "Bipedal impact with
granular matter" (dynamic drag plus static depth-dependent terms) acting on planar rigid
and articulated bodies, integrated with a fixed-step RK4 at 10 kHz and exact events.

Quick start::

    import granrs
    scene = granrs.cases.free_link(q_deg=45, v0=2.27)   # the thesis's steel rod
    result = granrs.simulate(scene)
    print(result.t_s, result.depth, result.summary["dE"])
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from . import (
    _granrs,
    animation,
    bodies,
    cases,
    coefficients,
    data,
    forces,
    media,
    scenefile,
    space,
)
from .api import RK4_STABILITY_LIMIT, simulate
from .batch import fast_lanes, sweep
from .calibrate import CalibrationResult, Measurements, calibrate
from .coefficients import Coefficients
from .compare import compare
from .errors import (
    AnimationSizeWarning,
    CoefficientsWarning,
    CoefficientTableError,
    GranrsError,
    InvalidParameterError,
    InvalidSceneError,
    MeasurementError,
    MediumError,
    SimulationError,
    StepSizeWarning,
    UnknownNameError,
)
from .force import ResistanceForce, resistance_force
from .result import ContactResult, Result
from .scene import OUTPUTS, RECORDS, Scene

if TYPE_CHECKING:
    from ._animation import ImpactAnimation, animate

__version__: str = _granrs.__version__

__all__ = [
    "OUTPUTS",
    "RECORDS",
    "RK4_STABILITY_LIMIT",
    "AnimationSizeWarning",
    "CalibrationResult",
    "CoefficientTableError",
    "Coefficients",
    "CoefficientsWarning",
    "ContactResult",
    "GranrsError",
    "ImpactAnimation",
    "InvalidParameterError",
    "InvalidSceneError",
    "MeasurementError",
    "Measurements",
    "MediumError",
    "ResistanceForce",
    "Result",
    "Scene",
    "SimulationError",
    "StepSizeWarning",
    "UnknownNameError",
    "__version__",
    "animate",
    "animation",
    "bodies",
    "calibrate",
    "cases",
    "coefficients",
    "compare",
    "data",
    "fast_lanes",
    "forces",
    "media",
    "resistance_force",
    "scenefile",
    "simulate",
    "space",
    "sweep",
]


def __getattr__(name: str) -> Any:
    # granrs.animate and granrs.ImpactAnimation import matplotlib (granrs._animation): loaded
    # on first use, so that `import granrs` does not pay for it.
    if name in ("animate", "ImpactAnimation"):
        from . import _animation

        return getattr(_animation, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
