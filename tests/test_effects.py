"""Effects: a term a scene does not list is neither evaluated nor stored (issue 5)."""

from __future__ import annotations

import pytest

import granrs
from granrs import _granrs, cases


def test_registry_matches_the_core() -> None:
    assert tuple(granrs.EFFECT_INFO) == granrs.EFFECTS == tuple(_granrs.EFFECTS)
    for name, effect in granrs.EFFECT_INFO.items():
        assert effect.name == name and effect.parameters and effect.equation
    assert granrs.EFFECT_INFO["drag"].velocity_dependent
    assert not granrs.EFFECT_INFO["static_v"].velocity_dependent


def test_terms_that_are_off_are_not_stored() -> None:
    full = cases.free_link(q_deg=0, v0=2.214).replace(record=("forces",))
    pruned = full.replace(effects=("gravity", "static_v"))
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
    no_drag = granrs.simulate(scene.replace(effects=("gravity", "static_h", "static_v")))
    assert no_drag.summary["F_d_max"] == 0.0
    assert no_drag.depth > full.depth


def test_springs_are_free_without_joint_springs() -> None:
    leg = cases.leg(v0=3.28)
    spring = leg.replace(knee={"k": 300.0, "c": 5.0})
    without = granrs.simulate(spring.replace(effects=("gravity", "drag", "static_h", "static_v")))
    free = granrs.simulate(leg.replace(knee="free"))
    assert without.depth == free.depth and without.t_s == free.t_s
    assert granrs.simulate(spring).depth != free.depth
