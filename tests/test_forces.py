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


def test_the_cases_give_the_thesis_law_as_terms() -> None:
    """granrs.cases build the thesis's terms from its tables (values typed here from the
    thesis: Table 3.4 row q = 45; Table 4.4 case 1 per link)."""
    assert granrs.cases.free_link(q_deg=45, v0=2.27).forces == (
        forces.gravity(),
        forces.drag(eta_d=11.0),
        forces.static_h(eta_h=5.5),
        forces.static_v(eta_v=53.0, lam=0.25),
        forces.joint_springs(),
    )
    assert granrs.cases.chain(case=1).forces == (
        forces.gravity(),
        forces.drag(eta_d=(13.0, 10.0)),
        forces.static_h(eta_h=(8.0, 11.8)),
        forces.static_v(eta_v=(33.0, 137.0), lam=(0.125, 0.205)),
        forces.joint_springs(),
    )


def test_the_default_scene_is_the_thesis_law_at_its_defaults() -> None:
    assert granrs.Scene().forces == forces.thesis()
    assert forces.thesis() == (
        forces.gravity(),
        forces.drag(),
        forces.static_h(),
        forces.static_v(),
        forces.joint_springs(),
    )


def test_a_term_left_out_is_not_evaluated_nor_stored() -> None:
    scene = granrs.cases.free_link(
        q_deg=30, v0=2.0, forces=[forces.gravity(), forces.static_v()], record=("forces",)
    )
    series = granrs.simulate(scene).series
    assert "F_sv" in series and "mode_y" in series
    assert not {"F_dx", "F_dy", "F_sh", "mode_x"} & set(series)


def test_every_term_describes_itself_from_the_core() -> None:
    assert forces.TERMS == (
        "gravity",
        "drag",
        "static_h",
        "static_v",
        "joint_springs",
        "poncelet",
        "axial_drag",
        "rft",
        "rft_inertial",
        "rft3d",
        "rft3d_inertial",
    )
    for name in forces.TERMS:
        info = forces.info(name)
        # A required parameter (no default) is given; the others take their defaults.
        required = {p.name: 1.0 for p in info.params if p.required}
        assert all(math.isnan(p.default) for p in info.params if p.required)
        t = forces.term(name, **required)
        assert t.name == name and t.info.name == name
        assert t.info.equation and t.info.source
        # Each constructor's defaults are the registry's (one source of truth).
        built = getattr(forces, name)(**required)
        expected = {p.name: required.get(p.name, p.default) for p in t.info.params}
        assert dict(built.params) == expected
        if required:
            # Left out, a required parameter is to come from a scene's medium: the term
            # says which are missing, and refuses to be used without them.
            pending = forces.term(name)
            assert pending.missing == tuple(required)
            assert set(pending.params) == {p.name for p in info.params} - set(required)
            with pytest.raises(granrs.GranrsError, match="required") as caught:
                pending.require()
            assert caught.value.field == f"{name}.{next(iter(required))}"
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


@pytest.mark.parametrize("old", ["coefficients", "coefficients2", "effects"])
def test_the_old_fields_say_what_to_write(old: str) -> None:
    """Issue 16: coefficients and effects are the terms' business now."""
    base = granrs.cases.free_link(q_deg=45, v0=1.0)
    with pytest.raises(granrs.UnknownNameError) as info:
        base.replace(**{old: None})
    assert info.value.field == old
    assert "forces=" in str(info.value)


def test_select_keeps_the_named_terms_in_order() -> None:
    scene = granrs.cases.free_link(q_deg=45, v0=1.0)
    kept = forces.select(scene.forces, "static_v", "gravity")
    assert kept == (forces.gravity(), forces.static_v(eta_v=53.0, lam=0.25))
    with pytest.raises(granrs.UnknownNameError, match="did you mean `drag`"):
        forces.select(scene.forces, "drg")


def test_forces_must_be_terms() -> None:
    with pytest.raises(granrs.InvalidParameterError):
        granrs.Scene(forces=["gravity"])  # type: ignore[list-item]
    with pytest.raises(granrs.InvalidParameterError):
        granrs.Scene(forces=[forces.gravity(), forces.gravity()])
