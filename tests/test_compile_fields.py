"""``simulate`` compiles a Scene from its attributes (``_granrs.compile_fields``), without the
dict ``Scene._plain()`` that ``_granrs.compile`` reads (issue 5: the call overhead of a new
scene). The two must be the same conversion: the same runs, bitwise, and the same typed
error naming the same field for bad input.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from typing import Any

import pytest

import granrs
from granrs import Scene, _granrs, cases
from granrs.errors import GranrsError
from granrs.forces import select, thesis
from granrs.scene import _CORE_FIELDS, BODIES


def _via_dict(scene: Scene) -> Any:
    return _granrs.compile(scene._plain())


def _via_fields(scene: Scene) -> Any:
    return _granrs.compile_fields(scene.__dict__, _CORE_FIELDS[scene.kind])


def _outcome(compiled: Any) -> dict[str, Any]:
    d = _granrs.run(compiled).to_dict()
    d.pop("run_seconds")
    return d


def _same(a: Any, b: Any) -> bool:
    """Equal, NaN equal to NaN (the results hold NaN for what did not happen)."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return bool(a == b)


SCENES = [
    cases.free_link(q_deg=45.0, v0=2.27),
    cases.free_link(q_deg=0.0, v0=2.214).replace(sign_model="raw", apply_at="centroid"),
    Scene(
        q_deg=30,
        v0=1,
        inertia=1e-3,
        record_stride=2,
        forces=select(thesis(), *("gravity", "static_v")),
    ),
    Scene(sign_model="smooth", smooth_eps=2e-3, method="dopri5", rtol=1e-6, atol=1e-9),
    cases.chain(1),
    cases.chain(1).replace(pin_joint={"k": 0.5, "c": 0.01}),
    cases.leg(v0=3.28),
    cases.leg(v0=3.28).replace(knee={"k": 300.0, "c": 2.0}, sole_model="thesis", foot_deg=5.0),
]


def test_the_core_keeps_every_field_name() -> None:
    """Every field a Scene sends has a slot of its own in the core's spec; the only fields
    it does not send are the notes (provenance the run does not read: the terms' source and
    the medium, whose values the scene's rho_g, g and terms already hold)."""
    from granrs.scene import FIELD_INFO

    sent = set(itertools.chain.from_iterable(_CORE_FIELDS.values()))
    notes = {n for n, f in FIELD_INFO.items() if f["part"] == "notes"}
    assert notes == {"coefficients_source", "medium"}
    assert sent == set(_granrs.SCENE_FIELDS) - notes


@pytest.mark.parametrize("scene", SCENES, ids=lambda s: s.body)
def test_fields_compile_as_the_dict_does(scene: Scene) -> None:
    assert _same(_outcome(_via_fields(scene)), _outcome(_via_dict(scene)))
    assert _same(
        granrs.simulate(scene).summary, granrs.simulate(dataclasses.replace(scene)).summary
    )


def test_any_names_tuple_reads_the_same_fields() -> None:
    """The core keeps each names tuple's slots (by the tuple's identity): another tuple, in
    another order, with a name it does not know, reads the same scene."""
    scene = cases.free_link(q_deg=30.0, v0=1.5)
    names = _CORE_FIELDS["free_link"]
    want = _outcome(_via_dict(scene))
    for other in (tuple(reversed(names)), (*names, "not_a_field"), names[::2] + names[1::2]):
        assert _same(_outcome(_granrs.compile_fields(scene.__dict__, other)), want)
    with pytest.raises(GranrsError) as info:
        _granrs.compile_fields(scene.__dict__, tuple(n for n in names if n != "mass"))
    assert info.value.field == "mass"


def test_the_compiled_scene_is_kept_on_the_scene() -> None:
    """Compiled once per Scene (it is frozen); a dict without a known body is refused naming
    the field."""
    scene = cases.free_link(q_deg=30.0, v0=1.5)
    first = scene._compiled()
    assert scene._compiled() is first
    assert scene.__dict__["_compiled_cache"] is first
    assert _granrs.compiled_scene(scene.__dict__, _CORE_FIELDS) is first
    # simulate() compiles through the same cache (run_scene).
    fresh = cases.free_link(q_deg=30.0, v0=1.5)
    assert _same(granrs.simulate(fresh).summary, granrs.simulate(scene).summary)
    assert "_compiled_cache" in fresh.__dict__
    for fields in ({"body": "tripod"}, {}):
        with pytest.raises(GranrsError) as info:
            _granrs.compiled_scene(fields, _CORE_FIELDS)
        assert info.value.field == "body"


BAD = [
    {"mass": -1.0},
    {"length": math.nan},
    {"dt": 0},
    {"t_end": 10**400},
    {"record_stride": 1.5},
    {"q_deg": True},
    {"v0": "fast"},
    {"apply_at": "heel"},
    {"sign_model": "smooth", "smooth_eps": -1.0},
    {"forces": (granrs.forces.drag(eta_d=1.0),), "inertia": -2.0},
]


@pytest.mark.parametrize("change", BAD, ids=lambda c: ",".join(c))
def test_bad_fields_raise_the_same_error(change: dict[str, Any]) -> None:
    """The core validates a Scene's fields before any run, whichever way they arrive."""
    # A Scene refuses them on construction (the core compiles it then) ...
    with pytest.raises(GranrsError) as refused:
        Scene(**change)
    # ... so the two conversions are fed the same fields on a Scene made without its
    # checks: a default scene's attributes with the bad ones put in.
    scene = object.__new__(Scene)
    fields = {k: v for k, v in Scene().__dict__.items() if k != "_compiled_cache"}
    scene.__dict__.update({**fields, **change})
    errors = []
    for compile_ in (_via_dict, _via_fields):
        with pytest.raises(GranrsError) as info:
            compile_(scene)
        errors.append(info.value)
    a, b = errors
    assert (type(a), a.field, str(a)) == (type(b), b.field, str(b))
    assert (type(refused.value), refused.value.field) == (type(a), a.field)
    with pytest.raises(type(a)) as info:
        granrs.simulate(scene)
    assert info.value.field == a.field


def test_one_field_table_describes_every_scene_field() -> None:
    """Issue 16: the core's field table (rust/spec/fields.rs) names exactly the Scene's
    fields, and drives BODY_FIELDS, the TOML notes, the docstring and the errors' units."""
    from granrs import scenefile
    from granrs.scene import BODY_FIELDS, FIELD_INFO

    assert set(FIELD_INFO) == {f.name for f in dataclasses.fields(Scene)}
    assert set(FIELD_INFO) == set(_granrs.SCENE_FIELDS)
    # v0 belongs to the built-in bodies: a linkage's initial motion is in its elements.
    assert BODY_FIELDS["q2_deg"] == ("chain",) and BODY_FIELDS["v0"] == BODIES
    for name, f in FIELD_INFO.items():
        assert f["part"] in ("body", "medium", "forces", "start", "solver", "outputs", "notes")
        assert f["doc"] and f["note"], name
        assert f"        {name}: " in (Scene.__doc__ or ""), name
        assert f["note"] in scenefile._NOTES[name]
    with pytest.raises(granrs.InvalidParameterError, match=r"> 0 \[kg/m\^3\]"):
        granrs.simulate(Scene(rho_g=-1.0))
