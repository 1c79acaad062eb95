"""The physics' properties on the chain and the leg (issue 6; the free link's are in
test_properties.py).

Domain (moderate, so that the 10 kHz step resolves the contacts; the free link's tests show
what happens past RK4's stability limit): the chain's case-1 scene with each link's angle
in (-60, 60) deg, v0 in [0, 5] m/s, vx0 in [-1, 1] m/s, omega0 in [-10, 10] rad/s, link
masses 10 g .. 200 g, coefficients 0.5x .. 2x Table 4.4's, and a free, locked or
spring-damper pin; the leg at 3.28 m/s with body mass 40 .. 120 kg, v0 in [0.5, 4] m/s,
coefficients 0.5x .. 2x sec. 5.3.2's, and each joint locked or free. Asserted: every run
ends finite with depth >= 0 (or raises the typed SimulationError); the mirrored chain
gives the mirrored result to 1e-12; with the force at the immersed centroid, KE + PE
(springs included) never rises, to 1e-8 of the energy scale.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import granrs
from granrs import Coefficients, Scene, cases
from granrs.forces import thesis, thesis_row

#: Derandomized, as in test_properties.py: the same examples on every CI run.
SETTINGS = settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
ENERGY_RTOL = 1e-8


def _scaled(c: Coefficients, f: float) -> Coefficients:
    return Coefficients(eta_h=c.eta_h * f, eta_d=c.eta_d * f, eta_v=c.eta_v * f, lam=c.lam)


@st.composite
def chains(draw: st.DrawFn, apply_at: str = "tip") -> Scene:
    base = cases.chain(1)
    f = draw(st.floats(0.5, 2.0))
    pin = draw(st.sampled_from(["free", "locked", {"k": 0.05, "c": 0.001}, {"k": 0.5, "c": 0.0}]))
    return base.replace(
        q_deg=draw(st.floats(-60.0, 60.0)),
        q2_deg=draw(st.floats(-60.0, 60.0)),
        v0=draw(st.floats(0.0, 5.0)),
        vx0=draw(st.floats(-1.0, 1.0)),
        omega0=draw(st.floats(-10.0, 10.0)),
        mass=draw(st.floats(0.01, 0.2)),
        forces=thesis(
            _scaled(thesis_row(base.forces), f),
            _scaled(thesis_row(base.forces, 1) or thesis_row(base.forces), f),
        ),
        pin_joint=pin,
        apply_at=apply_at,
        end="all_stops",
        t_end=0.5,
    )


@st.composite
def legs(draw: st.DrawFn, apply_at: str = "tip") -> Scene:
    base = cases.leg(v0=3.28)
    joint = st.sampled_from(["locked", "free"])
    return base.replace(
        body_mass=draw(st.floats(40.0, 120.0)),
        v0=draw(st.floats(0.5, 4.0)),
        forces=thesis(_scaled(thesis_row(base.forces), draw(st.floats(0.5, 2.0)))),
        ankle=draw(joint),
        knee=draw(joint),
        hip=draw(joint),
        apply_at=apply_at,
        t_end=0.5,
    )


def _run(scene: Scene) -> granrs.Result | None:
    try:
        return granrs.simulate(scene)
    except granrs.SimulationError:
        return None


def _finite(r: granrs.Result) -> None:
    assert r.status in ("stopped", "not_stopped")
    for c in r.contacts:
        assert c.depth >= 0.0 and math.isfinite(c.depth)
        for key, value in c.summary.items():
            if key in ("t_s", "t_entry") and math.isnan(value):
                continue
            assert math.isfinite(value), (key, value)
    for joint in r.joints.values():
        assert all(math.isfinite(v) for v in joint.values())


@pytest.mark.filterwarnings("ignore::granrs.StepSizeWarning")
@SETTINGS
@given(chains())
def test_chain_finite(scene: Scene) -> None:
    r = _run(scene)
    if r is not None:
        _finite(r)


@pytest.mark.filterwarnings("ignore::granrs.StepSizeWarning")
@SETTINGS
@given(legs())
def test_leg_finite(scene: Scene) -> None:
    r = _run(scene)
    if r is not None:
        _finite(r)


@pytest.mark.filterwarnings("ignore::granrs.StepSizeWarning")
@SETTINGS
@given(chains())
def test_chain_mirror_symmetry(scene: Scene) -> None:
    """Both links' angles, vx0 and omega0 negated: each contact's x_tip_end and dq negate,
    its depth and t_s stay, to 1e-12 relative."""
    assert scene.q2_deg is not None
    mirrored = scene.replace(
        q_deg=-scene.q_deg, q2_deg=-scene.q2_deg, vx0=-scene.vx0, omega0=-scene.omega0
    )
    a, b = _run(scene), _run(mirrored)
    assert (a is None) == (b is None)
    if a is None or b is None:
        return
    assert a.status == b.status
    for ca, cb in zip(a.contacts, b.contacts, strict=True):
        for key in ("x_tip_end", "dq"):
            x, y = ca.summary[key], cb.summary[key]
            assert abs(x + y) <= 1e-12 * max(abs(x), abs(y), 1e-300), (key, x, y)
        for key in ("depth", "t_s"):
            x, y = ca.summary[key], cb.summary[key]
            same = abs(x - y) <= 1e-12 * max(abs(x), abs(y)) or (math.isnan(x) and math.isnan(y))
            assert same, (key, x, y)


def _energy_never_rises(scene: Scene) -> None:
    r = _run(scene.replace(record=("energy",)))
    if r is None:
        return
    _finite(r)
    assert r.series is not None
    energy = r.series["E"]
    rise = float(np.max(energy - np.minimum.accumulate(energy)))
    scale = abs(r.summary["energy_start"]) + abs(r.summary["energy_end"])
    assert rise <= ENERGY_RTOL * scale, (rise, scale)


@SETTINGS
@given(chains(apply_at="centroid"))
def test_chain_energy_never_rises_at_the_centroid(scene: Scene) -> None:
    _energy_never_rises(scene)


@SETTINGS
@given(legs(apply_at="centroid"))
def test_leg_energy_never_rises_at_the_centroid(scene: Scene) -> None:
    _energy_never_rises(scene)
