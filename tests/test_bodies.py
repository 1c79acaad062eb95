"""The chain and the leg through the Python API: cases, scene fields, results (issue 4)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import granrs
from granrs import cases, data
from granrs.errors import InvalidParameterError, InvalidSceneError, UnknownNameError
from granrs.forces import thesis_row


def _csv_rows(name: str) -> list[dict[str, float]]:
    table = data.load(name)
    return table.to_dict("records")


class TestChainCase:
    @pytest.mark.parametrize("case", [1, 2, 3])
    def test_case_takes_table_4_1_and_4_4(self, case: int) -> None:
        exp = [r for r in _csv_rows("chain_experiments") if r["v0_case"] == case]
        coef = [r for r in _csv_rows("chain_coefficients") if r["v0_case"] == case]
        scene = cases.chain(case)
        assert scene.kind == "chain"
        assert scene.q_deg == exp[0]["q0_deg"] and scene.q2_deg == exp[1]["q0_deg"]
        assert scene.v0 == pytest.approx((exp[0]["v0_mean"] + exp[1]["v0_mean"]) / 2)
        for c, row in ((thesis_row(scene.forces), coef[0]), (thesis_row(scene.forces, 1), coef[1])):
            assert (c.eta_h, c.eta_d, c.eta_v, c.lam) == (
                row["eta_h"],
                row["eta_d"],
                row["eta_v"],
                row["lambda"],
            )
        # Thesis sec. 4.1: 0.135 m x 0.0064 m links; the mass is the steel cylinder.
        assert (scene.length, scene.diameter) == (0.135, 0.0064)
        steel = 7850 * math.pi / 4 * 0.0064**2 * 0.135
        assert scene.mass == pytest.approx(steel, rel=2e-3)

    def test_one_coefficient_set_applies_to_both_links(self) -> None:
        c = granrs.Coefficients(eta_h=9, eta_d=12, eta_v=100, lam=0.2)
        scene = cases.chain(2, coefficients=c)
        assert thesis_row(scene.forces) == c and thesis_row(scene.forces, 1) == c
        assert scene.forces == granrs.forces.thesis(c)  # one value for both links
        pair = cases.chain(2, coefficients=(c, {"eta_h": 1, "eta_d": 2, "eta_v": 3, "lam": 0.1}))
        assert thesis_row(pair.forces, 1).eta_v == 3

    def test_result_has_a_result_per_link(self) -> None:
        r = granrs.simulate(cases.chain(1, end="all_stops"))
        assert r.status == "stopped" and len(r.contacts) == 2
        assert all(c.stopped for c in r.contacts)
        assert (r.t_s, r.depth) == (r.contacts[0].t_s, r.contacts[0].depth)
        # The thesis's asymmetric case: the links stop at different times.
        assert abs(r.contacts[0].t_s - r.contacts[1].t_s) > 1e-3
        for c in r.contacts:
            s = c.summary
            assert s["link_dE"] == pytest.approx(s["link_dKE"] + s["link_dPE"])
            assert 0 < s["link_dE"] < s["dE"]
        assert r.joints["pin"]["F_max"] > 0

    def test_lighter_links_sink_less(self) -> None:
        heavy = granrs.simulate(cases.chain(1, end="all_stops"))
        light = granrs.simulate(cases.chain(1, mass=0.017, end="all_stops"))
        for h, li in zip(heavy.contacts, light.contacts, strict=True):
            assert li.depth < h.depth

    def test_series_are_named_per_link_and_joint(self) -> None:
        r = granrs.simulate(cases.chain(3, record=("state", "forces", "energy")))
        s = r.series
        assert s is not None
        for name in ("x_pin", "q1", "q2", "omega2", "c0.depth", "c1.F_sv", "pin.Fx", "link2.KE"):
            assert name in s, name
        # Link energies add up to the body's (the pin is massless here).
        total = s["link1.KE"] + s["link2.KE"]
        assert np.allclose(total, s["KE"], rtol=1e-12, atol=1e-15)

    @pytest.mark.parametrize("bad", [0, 4, "1", True])
    def test_unknown_case(self, bad: object) -> None:
        with pytest.raises(InvalidParameterError) as e:
            cases.chain(bad)  # type: ignore[arg-type]
        assert e.value.field == "case"


@settings(max_examples=15, deadline=None)
@given(
    q=st.floats(min_value=1.0, max_value=60.0),
    v0=st.floats(min_value=0.5, max_value=4.0),
    eta_v=st.floats(min_value=10.0, max_value=300.0),
)
# Found when events were first polished on the RK4 map, the earliest hit alone: the two
# links' mirror-image events parted (t_s by 4e-12 s; one link never stopped).
@example(q=3.0, v0=4.0, eta_v=13.0)
@example(q=3.0, v0=4.0, eta_v=10.0)
def test_mirror_symmetric_chain_stops_both_links_together(
    q: float, v0: float, eta_v: float
) -> None:
    c = granrs.Coefficients(eta_h=10.0, eta_d=12.0, eta_v=eta_v, lam=0.2)
    scene = cases.chain(1, q1_deg=-q, q2_deg=q, coefficients=c, v0=v0, end="all_stops")
    r = granrs.simulate(scene)
    a, b = r.contacts
    assert a.stopped and b.stopped
    assert a.t_s == pytest.approx(b.t_s, abs=1e-12)
    assert a.depth == pytest.approx(b.depth, rel=1e-12)


class TestLeg:
    @pytest.mark.parametrize("v0", [3.28, 2.35])
    def test_thesis_rows(self, v0: float) -> None:
        row = next(r for r in _csv_rows("human_coefficients") if r["v0"] == v0)
        scene = cases.leg(v0)
        c = thesis_row(scene.forces)
        assert (c.eta_h, c.eta_d, c.eta_v, c.lam) == (
            row["eta_h"],
            row["eta_d"],
            row["eta_v"],
            row["lambda"],
        )
        assert scene.rho_g == row["rho_g"] and str(v0) in scene.coefficients_source
        assert (scene.body_mass, scene.height) == (75.35, 1.78)

    def test_segments_are_winter_fractions_of_the_body(self) -> None:
        segs = {s["name"]: s for s in cases.leg().leg_segments()}
        m, h = 75.35, 1.78
        # Winter (2009) Table 4.1: foot 0.0145, leg 0.0465, thigh 0.100, HAT 0.678 (half).
        for name, frac in (
            ("foot", 0.0145),
            ("shank", 0.0465),
            ("thigh", 0.1),
            ("half_trunk", 0.339),
        ):
            assert segs[name]["mass"] == pytest.approx(frac * m)
        assert sum(s["mass"] for s in segs.values()) == pytest.approx(m / 2, rel=1e-3)
        assert segs["shank"]["length"] == 0.432
        assert segs["thigh"]["length"] == pytest.approx((0.530 - 0.285) * h)
        assert segs["shank"]["inertia"] == pytest.approx(
            segs["shank"]["mass"] * (0.302 * 0.432) ** 2
        )

    def test_joints_matter(self) -> None:
        locked = granrs.simulate(cases.leg(3.28))
        free = granrs.simulate(cases.leg(3.28, joints="free"))
        spring = granrs.simulate(cases.leg(3.28, joints={"k": 300.0, "c": 5.0}))
        assert locked.stopped and free.stopped and spring.stopped
        # A free leg folds: the foot alone is stopped, far sooner and shallower.
        assert free.depth < 0.5 * locked.depth and free.t_s < 0.5 * locked.t_s
        assert spring.summary["dissipated"] > 0 == free.summary["dissipated"]
        assert set(locked.joints) >= {"ankle", "knee", "hip"}
        assert locked.joints["knee"]["torque_max"] > 0

    def test_locked_leg_is_near_the_half_body_point_mass(self) -> None:
        """A rigid leg sinking flat is close to a point mass of half the body on the sole
        (an independent model, integrated here with numpy): the body barely turns."""
        r = granrs.simulate(cases.leg(3.28))
        c = thesis_row(r.scene.forces)
        m, rho, g, fs, ws, ll = 75.35 / 2, 1600.0, 9.81, 0.254, 0.086, 0.432
        d, v, t, dt = 0.0, 3.28, 0.0, 1e-6
        while v > 0:
            f = (
                c.eta_d * rho * fs * ws * v * v
                + c.eta_v * (d / ll) ** c.lam * g * rho * fs * ws * d
            )
            v += dt * (g - f / m)
            d += dt * v
            t += dt
        assert r.depth == pytest.approx(d, rel=0.1)
        assert r.t_s == pytest.approx(t, rel=0.15)

    def test_thesis_sole_form_needs_a_tilted_shank(self) -> None:
        ok = granrs.simulate(cases.leg(3.28, sole_model="thesis"))
        assert ok.stopped
        with pytest.raises(InvalidParameterError) as e:
            cases.leg(3.28, sole_model="thesis", knee_deg=20.0, hip_deg=20.0, trunk_deg=0.0)
        assert e.value.field == "sole_model"

    def test_series_names(self) -> None:
        r = granrs.simulate(cases.leg(2.35, record=("state", "forces", "energy")))
        s = r.series
        assert s is not None
        for name in ("y_ankle", "q_shank", "depth", "F_sv", "knee.torque", "ankle.Fy", "trunk.PE"):
            assert name in s, name


class TestBodyFields:
    def test_field_of_another_body_is_refused(self) -> None:
        with pytest.raises(InvalidSceneError) as e:
            granrs.Scene(body="free_link", q2_deg=10.0)
        assert e.value.field == "q2_deg"
        with pytest.raises(InvalidSceneError) as e:
            cases.leg(3.28, q_deg=10.0)
        assert e.value.field == "q_deg"
        with pytest.raises(InvalidSceneError) as e:
            cases.chain(1, knee_deg=30.0)
        assert e.value.field == "knee_deg"

    def test_unknown_body_and_joint(self) -> None:
        with pytest.raises(UnknownNameError) as e:
            granrs.Scene(body="arm")
        assert e.value.field == "body"
        with pytest.raises(UnknownNameError) as e:
            cases.leg(3.28, knee="stiff")
        assert e.value.field == "knee"
        with pytest.raises(InvalidParameterError) as e:
            cases.leg(3.28, hip={"k": 1.0})
        assert e.value.field == "hip"

    @pytest.mark.parametrize(
        ("overrides", "field"),
        [
            ({"body_mass": -1.0}, "body_mass"),
            ({"knee_deg": 200.0}, "knee_deg"),
            ({"ankle": {"k": -1.0, "c": 0.0}}, "ankle.k"),
            ({"knee": {"k": 1.0, "c": float("nan")}}, "knee.c"),
            ({"sole_height": 0.0}, "sole_height"),
        ],
    )
    def test_bad_leg_input_names_the_field(self, overrides: dict, field: str) -> None:
        with pytest.raises(InvalidParameterError) as e:
            cases.leg(3.28, **overrides)
        assert e.value.field == field

    @pytest.mark.parametrize(
        ("overrides", "field"),
        [
            ({"pin_mass": -0.1}, "pin_mass"),
            ({"q2_deg": 95.0}, "q2_deg"),
            ({"coefficients": ({"eta_h": 1, "eta_d": 1, "eta_v": 1, "lam": 0.1},) * 2}, None),
        ],
    )
    def test_bad_chain_input_names_the_field(self, overrides: dict, field: str | None) -> None:
        if field is None:
            assert granrs.simulate(cases.chain(1, **overrides)).stopped
            return
        with pytest.raises(InvalidParameterError) as e:
            cases.chain(1, **overrides)
        assert e.value.field == field


class TestStiffJoints:
    def test_a_joint_too_stiff_for_the_step_is_refused_before_running(self) -> None:
        # c / I_foot * dt ~ 8: RK4 at 10 kHz would blow up (it once panicked in the core).
        with pytest.raises(InvalidParameterError) as e:
            cases.leg(3.28, joints={"k": 13925.0, "c": 488.0})
        assert e.value.field == "ankle.c" and "dt" in str(e.value)
        with pytest.raises(InvalidParameterError) as e:
            cases.leg(3.28, knee={"k": 1e9, "c": 0.0})
        assert e.value.field == "knee.k"

    def test_a_smaller_step_runs_it_and_it_is_nearly_locked(self) -> None:
        stiff = granrs.simulate(cases.leg(3.28, joints={"k": 13925.0, "c": 488.0}, dt=1e-5))
        locked = granrs.simulate(cases.leg(3.28, dt=1e-5))
        assert stiff.stopped
        assert stiff.depth == pytest.approx(locked.depth, rel=0.05)
