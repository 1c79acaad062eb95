"""``granrs.simulate``: run one scene."""

from __future__ import annotations

from . import _granrs
from .errors import InvalidParameterError
from .result import Result
from .scene import _CORE_FIELDS, Scene

__all__ = ["simulate"]


def simulate(scene: Scene) -> Result:
    """Run one scene and return its :class:`~granrs.Result`.

    The scene is validated in full before the run starts (an invalid field raises a
    :class:`~granrs.errors.InvalidSceneError` subclass naming it). The run itself releases
    the GIL. A body that has not stopped by ``scene.t_end`` is not an error: the result's
    ``status`` says ``"not_stopped"``.

    Example:
        >>> import granrs
        >>> r = granrs.simulate(granrs.cases.free_link(q_deg=45, v0=2.27))
        >>> round(r.depth, 3)
        0.029
    """
    if not isinstance(scene, Scene):
        raise InvalidParameterError(
            f"simulate() takes a granrs.Scene, got {type(scene).__name__}", field="scene"
        )
    # scene._compiled() and _granrs.run in one call of the core.
    return Result(scene, _granrs.run_scene(scene.__dict__, _CORE_FIELDS))
