"""Force terms as objects (issue 16, "An open model"): granrs.forces, Scene.forces,
result.terms, the gravity-off energy fix, and the errors of bad terms."""

from __future__ import annotations

import math

import pytest

import granrs
from granrs import forces


def test_nothing_acting_keeps_every_energy() -> None:
    """Issue 16's fix: with gravity off the energies used g anyway, so a free link with
    nothing acting 'lost' 0.040 J in 10 ms of free flight."""
    scene = granrs.cases.free_link(q_deg=30, v0=2.0, forces=[], t_end=0.01)
    result = granrs.simulate(scene)
    assert result.terms == ()
    assert abs(result.summary["dKE"]) <= 1e-12
    assert abs(result.summary["dE"]) <= 1e-12


def test_gravity_alone_conserves_energy() -> None:
    scene = granrs.cases.free_link(q_deg=30, v0=2.0, forces=[forces.gravity()], t_end=0.01)
    result = granrs.simulate(scene)
    assert result.terms == ("gravity",)
    # Free fall for 10 ms from 2 m/s: KE grows by m g (v t + g t^2 / 2) > 0.
    m, g, t, v = 0.184, 9.81, 0.01, 2.0
    assert result.summary["dKE"] == pytest.approx(-m * g * (v * t + 0.5 * g * t * t), rel=1e-9)
    assert abs(result.summary["dE"]) <= 1e-9


def test_terms_run_in_the_scene_order() -> None:
    scene = granrs.cases.free_link(
        q_deg=10, v0=1.0, forces=[forces.static_v(), forces.gravity(), forces.drag()]
    )
    assert granrs.simulate(scene).terms == ("static_v", "gravity", "drag")


@pytest.mark.parametrize(
    "scene",
    [
        granrs.cases.free_link(q_deg=45, v0=2.27),
        granrs.cases.free_link(q_deg=0, v0=1.0, apply_at="centroid"),
        granrs.cases.chain(case=1, end="all_stops"),
        granrs.cases.chain(case=3, end="all_stops"),
        granrs.cases.leg(v0=3.28, joints={"k": 300.0, "c": 5.0}),
    ],
    ids=["free_link", "free_link_centroid", "chain1", "chain3", "leg_sprung"],
)
def test_the_thesis_law_as_terms_is_the_thesis_law(scene: granrs.Scene) -> None:
    """The same law given as terms (per contact for the chain) gives identical results."""
    as_terms = forces.thesis(scene.coefficients, *filter(None, [scene.coefficients2]))
    reset = {"coefficients": granrs.Scene().coefficients}
    if scene.body == "chain":
        reset["coefficients2"] = None
    other = scene.replace(forces=as_terms, **reset)
    a, b = granrs.simulate(scene), granrs.simulate(other)
    for ca, cb in zip(a.contacts, b.contacts, strict=True):
        for key in ("t_s", "depth", "dE", "F_d_max", "F_s_end"):
            assert ca.summary[key] == cb.summary[key] or (
                math.isnan(ca.summary[key]) and math.isnan(cb.summary[key])
            ), key


def test_a_term_left_out_is_not_evaluated_nor_stored() -> None:
    scene = granrs.cases.free_link(
        q_deg=30, v0=2.0, forces=[forces.gravity(), forces.static_v()], record=("forces",)
    )
    series = granrs.simulate(scene).series
    assert "F_sv" in series and "mode_y" in series
    assert not {"F_dx", "F_dy", "F_sh", "mode_x"} & set(series)


def test_every_term_describes_itself_from_the_core() -> None:
    assert forces.TERMS == ("gravity", "drag", "static_h", "static_v", "joint_springs")
    for name in forces.TERMS:
        t = forces.term(name)
        assert t.name == name and t.info.name == name
        assert t.info.equation and t.info.source
        # Each constructor's defaults are the registry's (one source of truth).
        built = getattr(forces, name)()
        assert dict(built.params) == {p.name: p.default for p in t.info.params}
    sv = forces.static_v().info
    assert [p.name for p in sv.params] == ["eta_v", "lam"]
    assert sv.params[0].default == 248.0 and sv.params[0].unit == "-"
    assert "Table 3.4" in sv.params[0].source
    assert sv.columns == ("F_sv",)


@pytest.mark.parametrize(
    ("make", "field", "words"),
    [
        (lambda: forces.term("stati_v"), "term", "did you mean `static_v`"),
        (lambda: forces.term("static_v", eta=1.0), "static_v.eta", "`static_v.eta_v`"),
        (lambda: forces.static_v(eta_v=math.nan), "static_v.eta_v", "NaN"),
        (lambda: forces.static_v(lam=-0.1), "static_v.lam", ">= 0"),
        (lambda: forces.drag(eta_d=math.inf), "drag.eta_d", "inf"),
        (lambda: forces.term("gravity", g=9.81), "gravity.g", "takes no parameters"),
    ],
)
def test_bad_terms_are_typed_errors_naming_the_parameter(make, field, words) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(granrs.GranrsError) as info:
        make()
    assert isinstance(info.value, ValueError)
    assert info.value.field == field
    assert words in str(info.value)


def test_per_contact_parameters_must_match_the_contacts() -> None:
    terms = [forces.gravity(), forces.drag(eta_d=(13.0, 10.0, 9.0))]
    with pytest.raises(granrs.InvalidSceneError) as info:
        granrs.cases.chain(case=1, forces=terms)
    assert info.value.field == "drag.eta_d"


def test_forces_and_coefficients_are_not_mixed() -> None:
    base = granrs.cases.free_link(q_deg=45, v0=1.0)  # Table 3.4's q = 45 row
    with pytest.raises(granrs.InvalidSceneError) as info:
        base.replace(forces=[forces.gravity()])
    assert info.value.field == "coefficients"


def test_forces_must_be_terms() -> None:
    with pytest.raises(granrs.InvalidParameterError):
        granrs.Scene(forces=["gravity"])  # type: ignore[list-item]
    with pytest.raises(granrs.InvalidParameterError):
        granrs.Scene(forces=[forces.gravity(), forces.gravity()])
