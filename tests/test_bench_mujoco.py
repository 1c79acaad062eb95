"""The arithmetic of ``benches/bench_mujoco.py --part rollout``'s summary: the Sand's
passive-force calls grouped into MuJoCo steps, and the medians over seeds (made-up numbers,
the expected values computed by hand)."""

from __future__ import annotations

import pytest
from _modules import REPO, load_module

pytest.importorskip("mujoco")


def _bench():
    return load_module("granrs_bench_mujoco", REPO / "benches" / "bench_mujoco.py")


def test_sand_steps_groups_rk4_stages_into_steps():
    """Three RK4 steps: the first in the sand at its third stage only (its four calls' time
    counts, 1 + 1 + 2 + 1), the second out of the sand (4 x 0.5), the third in the sand
    throughout (4 x 3): 3 steps, 2 in the sand, 5 + 12 = 17 s in the sand, 2 s out."""
    calls = [
        (1, False, 1.0),
        (2, False, 1.0),
        (3, True, 2.0),
        (4, False, 1.0),
        (1, False, 0.5),
        (2, False, 0.5),
        (3, False, 0.5),
        (4, False, 0.5),
        (1, True, 3.0),
        (2, True, 3.0),
        (3, True, 3.0),
        (4, True, 3.0),
    ]
    assert _bench().sand_steps(calls) == (3, 2, 17.0, 2.0)


def test_sand_steps_one_call_per_step_and_edges():
    """Euler's one call per step (every call a stage 1); no calls; a trace that starts
    inside a step is an error."""
    bench = _bench()
    assert bench.sand_steps([(1, True, 1.0), (1, True, 4.0), (1, False, 2.0)]) == (3, 2, 5.0, 2.0)
    assert bench.sand_steps([]) == (0, 0, 0.0, 0.0)
    with pytest.raises(ValueError, match="stage 2"):
        bench.sand_steps([(2, True, 1.0)])


def test_rollout_medians_are_per_column_over_seeds():
    rows = [
        {"ratio": 0.25, "share": 0.5, "resets": 4.0},
        {"ratio": 1.0, "share": 0.75, "resets": 0.0},
        {"ratio": 0.125, "share": 1.0, "resets": 14.0},
        {"ratio": 0.375, "share": 0.0625, "resets": 2.0},
    ]
    # Sorted: ratio 0.125 0.25 0.375 1, share 0.0625 0.5 0.75 1, resets 0 2 4 14 (the means
    # differ: 0.4375, 0.578125, 5).
    assert _bench().rollout_medians(rows) == {"ratio": 0.3125, "share": 0.625, "resets": 3.0}
