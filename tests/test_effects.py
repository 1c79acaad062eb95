"""A term a scene does not list is neither evaluated nor stored (issues 5 and 16)."""

from __future__ import annotations

import pytest

import granrs
from granrs import cases
from granrs.forces import select


def test_terms_that_are_off_are_not_stored() -> None:
    full = cases.free_link(q_deg=0, v0=2.214).replace(record=("forces",))
    pruned = full.replace(forces=select(full.forces, "gravity", "static_v"))
    a, b = granrs.simulate(full), granrs.simulate(pruned)
    assert a.series is not None and b.series is not None
    assert {"F_dx", "F_dy", "F_sh", "F_sv", "mode_x", "mode_y"} <= set(a.series)
    assert "F_sv" in b.series and "mode_y" in b.series
    assert not {"F_dx", "F_dy", "F_sh", "mode_x"} & set(b.series)
    # A vertical drop feels F_sv only: the pruned scene gives the same impact.
    assert b.depth == pytest.approx(a.depth, rel=1e-12)
    assert b.t_s == pytest.approx(a.t_s, rel=1e-12)


def test_a_term_that_is_off_changes_the_answer() -> None:
    scene = cases.free_link(q_deg=45, v0=2.27)
    full = granrs.simulate(scene)
    no_drag = granrs.simulate(
        scene.replace(forces=select(scene.forces, "gravity", "static_h", "static_v"))
    )
    assert no_drag.summary["F_d_max"] == 0.0
    assert no_drag.depth > full.depth


def test_springs_are_free_without_joint_springs() -> None:
    leg = cases.leg(v0=3.28)
    spring = leg.replace(knee={"k": 300.0, "c": 5.0})
    without = granrs.simulate(
        spring.replace(forces=select(spring.forces, "gravity", "drag", "static_h", "static_v"))
    )
    free = granrs.simulate(leg.replace(knee="free"))
    assert without.depth == free.depth and without.t_s == free.t_s
    assert granrs.simulate(spring).depth != free.depth
