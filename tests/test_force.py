"""granrs.resistance_force: the force law on its own, vectorized.

Checked against an independent numpy transcription of MODEL.md's equations, against the
forces the simulator itself records, and for its error handling."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import granrs
from granrs import cases
from granrs.errors import InvalidParameterError, UnknownNameError
from granrs.forces import thesis_row

L, DC, RHO, G = 0.19, 0.0127, 1650.0, 9.81
C = {"eta_h": 5.5, "eta_d": 11.0, "eta_v": 53.0, "lam": 0.25}


def by_hand(depth, q_deg, vx, vy, omega, c=C):
    """MODEL.md's rod force, written out in numpy (raw sign)."""
    q = np.radians(q_deg)
    e = np.stack([np.sin(q), np.cos(q)])
    d = np.maximum(depth, 0.0)
    li = np.minimum(d / np.cos(q), L)
    v_e = np.stack([vx + 0.5 * li * omega * np.cos(q), vy - 0.5 * li * omega * np.sin(q)])
    speed = np.hypot(*v_e)
    sin_angle = np.abs(e[0] * v_e[1] - e[1] * v_e[0]) / np.where(speed > 0, speed, 1.0)
    a_r = DC * li * sin_angle
    f_d = -c["eta_d"] * RHO * a_r * speed * v_e
    f_sh = -np.sign(v_e[0]) * c["eta_h"] * G * RHO * DC * d**2
    f_sv = -np.sign(v_e[1]) * c["eta_v"] * (d / L) ** c["lam"] * G * RHO * math.pi / 4 * DC**2 * li
    return f_d[0], f_d[1], f_sh, f_sv


@settings(max_examples=200, deadline=None)
@given(
    depth=st.floats(1e-6, 0.3),
    q_deg=st.floats(-89.0, 89.0),
    vx=st.floats(-5, 5),
    vy=st.floats(-5, 5),
    omega=st.floats(-50, 50),
)
def test_matches_the_equations_written_out(depth, q_deg, vx, vy, omega) -> None:
    f = granrs.resistance_force(depth, q_deg, vx, vy, omega, coefficients=C)
    for got, want in zip(
        (f.F_dx, f.F_dy, f.F_sh, f.F_sv), by_hand(depth, q_deg, vx, vy, omega), strict=True
    ):
        assert got == pytest.approx(float(want), rel=1e-12, abs=1e-12)
    assert f.F_x == pytest.approx(float(f.F_dx + f.F_sh), rel=1e-15, abs=1e-15)
    assert f.F_y == pytest.approx(float(f.F_dy + f.F_sv), rel=1e-15, abs=1e-15)


def test_broadcasting_and_shapes() -> None:
    depth = np.linspace(0.0, 0.1, 6)[:, None]
    q = np.array([0.0, 30.0, 60.0])
    f = granrs.resistance_force(depth, q, 0.2, -1.0, omega=1.5, coefficients=C)
    assert f.F_x.shape == (6, 3)
    want = by_hand(np.broadcast_to(depth, (6, 3)), np.broadcast_to(q, (6, 3)), 0.2, -1.0, 1.5)
    np.testing.assert_allclose(f.F_sv, want[3], rtol=1e-12, atol=1e-12)
    # Coefficients as arrays broadcast too.
    arr = dict(C, eta_v=np.array([0.0, 53.0, 106.0]))
    g = granrs.resistance_force(0.05, q, 0.0, -1.0, coefficients=arr)
    assert g.F_sv[0] == 0.0 and g.F_sv[2] == pytest.approx(
        2
        * g.F_sv[1]
        * (by_hand(0.05, 60.0, 0.0, -1.0, 0.0)[3] / by_hand(0.05, 30.0, 0.0, -1.0, 0.0)[3]),
        rel=1e-12,
    )
    # Above the surface: nothing.
    above = granrs.resistance_force(-0.01, 20.0, 1.0, -1.0, coefficients=C)
    assert all(float(v) == 0.0 for v in (above.F_x, above.F_y))


def test_effects_switch_terms_off() -> None:
    full = granrs.resistance_force(0.04, 30.0, 0.5, -2.0, coefficients=C)
    only_v = granrs.resistance_force(0.04, 30.0, 0.5, -2.0, coefficients=C, effects=["static_v"])
    assert only_v.F_sv == full.F_sv
    assert only_v.F_dx == 0.0 and only_v.F_dy == 0.0 and only_v.F_sh == 0.0
    smooth = granrs.resistance_force(
        0.04, 0.0, 0.0, -1e-4, coefficients=C, sign_model="smooth", smooth_eps=1e-3
    )
    raw = granrs.resistance_force(0.04, 0.0, 0.0, -1e-4, coefficients=C)
    assert smooth.F_sv == pytest.approx(math.tanh(0.1) * raw.F_sv, rel=1e-12)


def test_agrees_with_the_forces_the_simulator_records() -> None:
    scene = cases.free_link(q_deg=45, v0=2.27).replace(record=("state", "forces"), sign_model="raw")
    r = granrs.simulate(scene)
    s = r.series
    assert s is not None
    f = granrs.resistance_force(
        s["depth"],
        np.degrees(s["q"]),
        s["v_tip_x"],
        s["v_tip_y"],
        s["omega"],
        coefficients=thesis_row(scene.forces),
    )
    np.testing.assert_allclose(f.F_dx, s["F_dx"], rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(f.F_dy, s["F_dy"], rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(np.abs(f.F_sv), np.abs(s["F_sv"]), rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(np.abs(f.F_sh), np.abs(s["F_sh"]), rtol=1e-10, atol=1e-10)


def test_bad_input_names_the_field_and_index() -> None:
    with pytest.raises(InvalidParameterError) as err:
        granrs.resistance_force([0.01, 0.02, float("nan")], 0.0, 0.0, -1.0)
    assert err.value.field == "depth" and "index 2" in str(err.value)
    with pytest.raises(InvalidParameterError) as err:
        granrs.resistance_force(0.01, [10.0, 90.0], 0.0, -1.0)
    assert err.value.field == "q_deg"
    with pytest.raises(InvalidParameterError) as err:
        granrs.resistance_force(0.01, 0.0, 0.0, -1.0, coefficients=dict(C, eta_d=-1.0))
    assert err.value.field == "eta_d"
    with pytest.raises(InvalidParameterError) as err:
        granrs.resistance_force(0.01, 0.0, 0.0, -1.0, coefficients={"eta_h": 1.0})
    assert err.value.field == "coefficients"
    with pytest.raises(UnknownNameError) as err:
        granrs.resistance_force(0.01, 0.0, 0.0, -1.0, sign_model="modes")
    assert err.value.field == "sign_model"
    with pytest.raises(UnknownNameError) as err:
        granrs.resistance_force(0.01, 0.0, 0.0, -1.0, effects=["wind"])
    assert err.value.field == "effects"
    with pytest.raises(InvalidParameterError) as err:
        granrs.resistance_force(np.zeros(3), np.zeros(4), 0.0, -1.0)
    with pytest.raises(InvalidParameterError) as err:
        granrs.resistance_force(0.01, 0.0, 0.0, -1.0, length=0.0)
    assert err.value.field == "length"
    with pytest.raises(InvalidParameterError) as err:
        granrs.resistance_force("deep", 0.0, 0.0, -1.0)
    assert err.value.field == "depth"


def test_docstring_example() -> None:
    import doctest

    import granrs.force

    failures, tried = doctest.testmod(granrs.force, verbose=False, report=True)
    assert tried > 0 and failures == 0
