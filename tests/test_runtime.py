"""A scene may list every contact term, and Dopri5 reaches tight tolerances on a run whose
force law jumps at an event.

Before: a scene could list at most four contact terms while six exist ("at most 4 contact
terms", said only by the error), and the sprung leg at 3.28 m/s under ``method="dopri5"``
with a tight tolerance failed with "step size underflow at t = 0 s": its sole starts a hair
above the surface, the drag jumps on at the entry, and every trial step across the entry
failed the error test however short it was, while the entry was never located.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import granrs
from granrs import _granrs, forces
from granrs.errors import InvalidParameterError

#: Every contact term, with parameters that make each act on a free link.
ALL_CONTACT_TERMS = (
    forces.drag(),
    forces.static_h(),
    forces.static_v(),
    forces.poncelet(c=0.8, k=150.0),
    forces.rft(zeta=1e6),
    forces.rft_inertial(),
    forces.axial_drag(eta_a=6.0),
)


def test_every_contact_term_is_in_the_list() -> None:
    """The registry's contact terms on a rod are those above (a new one joins this test;
    the terms of bodies in space are tested in tests/test_space.py)."""
    contact = {
        t["name"]
        for t in _granrs.term_infos()
        if t["acts"] == "contact" and "rod" in (t["shapes"] or ())
    }
    assert contact == {t.name for t in ALL_CONTACT_TERMS}


def test_a_scene_lists_every_contact_term_at_once() -> None:
    """Every contact term (and gravity) on one rod: it runs, and each term's force is
    recorded, finite, and acts at some sample."""
    scene = granrs.cases.free_link(q_deg=20.0, v0=2.0).replace(
        forces=(forces.gravity(), *ALL_CONTACT_TERMS), record=["forces"]
    )
    result = granrs.simulate(scene)
    assert result.status == "stopped"
    assert math.isfinite(result.summary["t_s"]) and result.summary["depth"] > 0
    series = result.series
    columns = [c for c in series if c.startswith("F_")]
    # One column per axis each term writes: at least one per term.
    assert len(columns) >= len(ALL_CONTACT_TERMS), columns
    for c in columns:
        values = np.asarray(series[c])
        assert np.isfinite(values).all(), c
    acting = [c for c in columns if np.abs(np.asarray(series[c])).max() > 0]
    assert len(acting) >= len(ALL_CONTACT_TERMS), acting


SPRUNG_LEG = granrs.cases.leg(v0=3.28, joints={"k": 300.0, "c": 5.0})


@pytest.mark.parametrize(
    ("rtol", "atol"), [(1e-12, 1e-14), (1e-12, 1e-20), (1e-6, 1e-14), (1e-13, 1e-13)]
)
def test_dopri5_at_tight_tolerances_runs_the_sprung_leg(rtol: float, atol: float) -> None:
    """The sprung leg under Dopri5 at tolerances down to 1e-12 (atol down to 1e-20): it runs,
    and stops where RK4 at a 100 times finer step than the thesis's stops (to 1e-7 s, 1e-7 m
    for the tight runs)."""
    reference = granrs.simulate(SPRUNG_LEG.replace(dt=1e-6))
    result = granrs.simulate(SPRUNG_LEG.replace(method="dopri5", rtol=rtol, atol=atol))
    assert result.status == "stopped"
    tol = 1e-5 if rtol > 1e-9 else 1e-7
    assert result.summary["t_s"] == pytest.approx(reference.summary["t_s"], abs=tol)
    assert result.summary["depth"] == pytest.approx(reference.summary["depth"], abs=tol)


def test_a_relative_tolerance_below_what_f64_resolves_is_refused() -> None:
    """rtol below 100 times f64's epsilon (the floor of MATLAB's ode45 and SciPy's RK45) is
    a typed error naming rtol and the bound, before the run: it asks each step for less
    error than its own round-off (the sprung leg at rtol = atol = 1e-16 used to end in a
    step size underflow)."""
    with pytest.raises(InvalidParameterError) as err:
        granrs.simulate(SPRUNG_LEG.replace(method="dopri5", rtol=1e-16, atol=1e-16))
    assert err.value.field == "rtol"
    assert "2.2e-14" in str(err.value)
    granrs.simulate(SPRUNG_LEG.replace(method="dopri5", rtol=2.3e-14, t_end=1e-3, end="time"))
