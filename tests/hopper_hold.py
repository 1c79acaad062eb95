"""Gymnasium's hopper held upright on sand, for the rest tests of the planar and the 3D
couplings (tests/test_mujoco.py, tests/test_mujoco_space.py)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np


def hold_upright(
    model: Any, data: Any, sand: Any, mode: str, seconds: float, record: Callable[[Any], None]
) -> None:
    """Hold the hopper's joints at their start angles with a PD controller on its own motors
    (gain 200, damping 10, clipped to the motors' range) for ``seconds`` at the model's own
    timestep, with ``sand`` applied in ``mode`` (``"step"`` or ``"callback"``), calling
    ``record(data)`` after each step."""
    q0 = data.qpos[3:6].copy()
    if mode == "callback":
        sand.install()
    try:
        for _ in range(round(seconds / model.opt.timestep)):
            pd = 200.0 * (q0 - data.qpos[3:6]) - 10.0 * data.qvel[3:6]
            data.ctrl[:] = np.clip(pd, -200, 200) / 200
            if mode == "step":
                sand.step(data)
            mujoco.mj_step(model, data)
            record(data)
    finally:
        if mode == "callback":
            sand.uninstall()
