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


def assert_rests(pos: list[Any], force: list[float], weight: float, timestep: float) -> slice:
    """The rest line over the last 5 s of a run recorded at each step: the foot's position
    (``pos``) moves less than 0.1 mm, the sand's vertical force (``force``) balances
    ``weight`` to 1e-3 on average with a step-to-step spread under 5 % of it. Returns the
    window, for the energy checks each test makes its own way."""
    last = slice(-round(5.0 / timestep), None)
    assert np.all(np.isfinite(pos))
    assert np.max(np.ptp(np.array(pos)[last], axis=0)) < 1e-4
    fz = np.array(force)[last]
    assert abs(fz.mean() / weight - 1) < 1e-3
    assert np.max(np.abs(np.diff(fz))) < 0.05 * weight
    return last
