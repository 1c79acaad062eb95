"""Scenes as TOML files (issue 5): the round trip is exact, and every error points at the
offending key and its line.

The expected lines, columns and key sets are computed here from the text each test writes
(or from ``Scene``'s fields and ``BODY_FIELDS``), never from the code under test.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import granrs
from granrs import Coefficients, Scene, cases
from granrs.cases import template
from granrs.errors import InvalidParameterError, InvalidSceneError, UnknownNameError
from granrs.forces import select, thesis
from granrs.scene import BODY_FIELDS, RECORDS
from granrs.scenefile import dumps, key_lines, load, loads, parse_override

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "scenes"


def line_of(text: str, startswith: str) -> int:
    """The 1-based number of the only line of ``text`` that starts with ``startswith``."""
    hits = [i for i, line in enumerate(text.splitlines(), 1) if line.startswith(startswith)]
    assert len(hits) == 1, (startswith, hits)
    return hits[0]


def same_bits(a: Scene, b: Scene) -> None:
    """``a == b`` and every float has the same sign (``-0.0`` stays ``-0.0``)."""
    assert a == b
    for f in dataclasses.fields(Scene):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, float):
            assert math.copysign(1.0, x) == math.copysign(1.0, y), f.name


# --- round trip ---------------------------------------------------------------------------

THESIS_SCENES = {
    "free_link": cases.free_link(q_deg=45.0, v0=2.27),
    "chain": cases.chain(case=1),
    "leg": cases.leg(v0=3.28, knee={"k": 300.0, "c": 5.0}, hip="free"),
}


@pytest.mark.parametrize("body", list(THESIS_SCENES))
def test_round_trip_thesis_scenes(body: str, tmp_path: Path) -> None:
    """Issue 5: load(save(scene)) == scene for each body, via text and via a file."""
    scene = THESIS_SCENES[body]
    same_bits(loads(dumps(scene)), scene)
    path = tmp_path / "scene.toml"
    granrs.scenefile.dump(scene, path)
    same_bits(load(path), scene)
    same_bits(load(str(path)), scene)


@pytest.mark.parametrize("body", list(THESIS_SCENES))
def test_writes_exactly_the_fields_of_the_body(body: str) -> None:
    """Issue 5: every field that applies to the body and is not None, and nothing else."""
    scene = THESIS_SCENES[body]
    data = tomllib.loads(dumps(scene))
    expected = {
        f.name
        for f in dataclasses.fields(Scene)
        if (f.name not in BODY_FIELDS or body in BODY_FIELDS[f.name])
        and getattr(scene, f.name) is not None
    }
    assert set(data) == expected | {"format"}
    assert data["format"] == 1
    assert data["forces"] == [t.to_dict() for t in scene.forces]


def test_none_fields_are_left_out() -> None:
    """A field whose value is None is not a key (TOML has no null); loading gives None."""
    scene = Scene(body="chain", q_deg=10.0)
    data = tomllib.loads(dumps(scene))
    for name in ("inertia", "q2_deg"):
        assert name not in data
        assert getattr(loads(dumps(scene)), name) is None


AWKWARD = [
    {"smooth_eps": 1e-300},
    {"atol": 5e-324},
    {"q_deg": 0.1 + 0.2},
    {"q_deg": -0.0, "vx0": -0.0, "omega0": -0.0, "depth0": -0.0, "v0": -0.0},
    {"rho_g": 2.0**60, "mass": 1e22, "g": 12345678901234567.0},
    {"length": 1.0000000000000002, "diameter": 0.30000000000000004},
    {"forces": thesis(Coefficients(eta_h=1e-300, eta_d=0.1 + 0.2, eta_v=2.0**53, lam=0.0))},
    {"record_stride": 7, "record": ("energy", "state"), "forces": ()},
    {"coefficients_source": 'a "quoted" \\ back\\slash\nnew line\ttab \x01 \x7f # = [x] é ∂'},
    {"coefficients_source": ""},
    {"coefficients_source": "'''\"\"\"\\u0041"},
]


@pytest.mark.parametrize("changes", AWKWARD)
def test_round_trip_awkward_values(changes: dict[str, Any]) -> None:
    """Issue 5: tiny, inexact, negative-zero and huge floats and escaped strings come back
    bit for bit."""
    scene = Scene(**changes).validate()
    text = dumps(scene)
    same_bits(loads(text), scene)
    for name, value in changes.items():
        if isinstance(value, str):
            assert tomllib.loads(text)[name] == value


def test_integer_in_float_field_reads_as_float() -> None:
    """``length = 1`` is 1.0 m (a float), and the file stays valid TOML for tomllib."""
    scene = loads("length = 1\nv0 = 3\n")
    assert scene.length == 1.0 and isinstance(scene.length, float)
    assert isinstance(scene.v0, float)


JOINT = st.one_of(
    st.sampled_from(["free", "locked"]),
    st.fixed_dictionaries(
        {
            "k": st.floats(0.0, 1e3, allow_subnormal=True),
            "c": st.floats(0.0, 10.0, allow_subnormal=True),
        }
    ),
)
COEF = st.builds(
    Coefficients,
    eta_h=st.floats(0.0, 1e3),
    eta_d=st.floats(0.0, 1e3),
    eta_v=st.floats(0.0, 1e3),
    lam=st.floats(0.0, 3.0),
)
POSITIVE = st.floats(1e-3, 1e3)
SUBSETS_TERMS = st.lists(st.sampled_from(granrs.forces.TERMS), unique=True).map(tuple)
#: The thesis's terms with random parameters, a random subset of them (one contact's
#: parameters for every contact, or for the chain one per link).
FORCES = st.tuples(COEF, SUBSETS_TERMS).map(lambda a: select(thesis(a[0]), *a[1]))
FORCES_CHAIN = st.tuples(COEF, COEF, SUBSETS_TERMS).map(lambda a: select(thesis(a[0], a[1]), *a[2]))
SUBSETS_RECORD = st.lists(st.sampled_from(RECORDS), unique=True).map(tuple)

COMMON = {
    "rho_g": POSITIVE,
    "g": st.floats(0.0, 100.0),
    "forces": FORCES,
    "coefficients_source": st.text(max_size=30),
    "v0": st.floats(0.0, 10.0),
    "depth0": st.floats(0.0, 0.05),
    "vx0": st.floats(-5.0, 5.0),
    "apply_at": st.sampled_from(["tip", "centroid"]),
    "sign_model": st.sampled_from(["modes", "raw", "smooth"]),
    "smooth_eps": st.floats(1e-300, 1.0),
    "dt": st.floats(1e-6, 1e-3),
    "method": st.sampled_from(["rk4", "dopri5"]),
    "rtol": st.floats(1e-14, 1e-2),
    "atol": st.floats(1e-300, 1e-2),
    "t_end": st.floats(1e-3, 10.0),
    "end": st.sampled_from(["first_stop", "all_stops", "time"]),
    "record": SUBSETS_RECORD,
    "record_stride": st.integers(1, 1000),
}
RODS = {
    "length": POSITIVE,
    "diameter": POSITIVE,
    "mass": POSITIVE,
    "inertia": st.none() | POSITIVE,
    "q_deg": st.floats(-89.9, 89.9),
    "omega0": st.floats(-50.0, 50.0),
}
CHAIN = {
    "q2_deg": st.none() | st.floats(-89.9, 89.9),
    "forces": FORCES | FORCES_CHAIN,
    "pin_mass": st.floats(0.0, 1.0),
    "pin_joint": JOINT,
}
LEG = {
    "body_mass": st.floats(20.0, 150.0),
    "height": st.floats(1.0, 2.2),
    "foot_length": st.floats(0.1, 0.4),
    "shoe_width": st.floats(0.05, 0.2),
    "tibia_length": st.floats(0.2, 0.6),
    "sole_height": st.none() | st.floats(0.01, 0.5),
    "ankle": JOINT,
    "knee": JOINT,
    "hip": JOINT,
    "knee_deg": st.floats(0.0, 150.0),
    "hip_deg": st.floats(-30.0, 150.0),
    "trunk_deg": st.floats(-60.0, 60.0),
    "foot_deg": st.floats(-60.0, 60.0),
}
BASES = {
    "free_link": (THESIS_SCENES["free_link"], {**COMMON, **RODS}),
    "chain": (THESIS_SCENES["chain"], {**COMMON, **RODS, **CHAIN}),
    "leg": (THESIS_SCENES["leg"], {**COMMON, **LEG}),
}


@st.composite
def valid_scenes(draw: st.DrawFn) -> Scene:
    """A thesis scene of a random body with a random subset of its fields perturbed within
    their valid ranges (a combination the core refuses, e.g. a joint too stiff for dt, is
    retried)."""
    body = draw(st.sampled_from(list(BASES)))
    base, strategies = BASES[body]
    names = draw(st.lists(st.sampled_from(sorted(strategies)), unique=True))
    changes = {name: draw(strategies[name]) for name in names}
    try:
        return base.replace(**changes)  # checked in full on construction
    except InvalidSceneError:
        return base


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(valid_scenes())
def test_round_trip_random_scenes(scene: Scene) -> None:
    """Issue 5: load, save, load gives an identical Scene for random valid scenes."""
    text = dumps(scene)
    first = loads(text)
    same_bits(first, scene)
    assert dumps(first) == text


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("free_link_q45.toml", cases.free_link(q_deg=45.0, v0=2.27)),
        ("chain_case1.toml", cases.chain(case=1)),
        ("leg_3_28.toml", cases.leg(v0=3.28)),
    ],
)
def test_example_scene_files_are_the_thesis_cases(name: str, expected: Scene) -> None:
    """examples/scenes/*.toml are the scenes granrs.cases builds (regenerate them if a case
    changes)."""
    same_bits(load(EXAMPLES / name), expected)


@pytest.mark.parametrize("body", ["free_link", "chain", "leg"])
def test_template_loads_to_the_body(body: str) -> None:
    """``granrs scene new``'s template is a valid scene file of that body with notes."""
    text = template(body)
    assert loads(text).kind == body
    assert "# m" in text or "# deg" in text


# --- errors point at the key and its line -------------------------------------------------


def test_syntax_error_gives_file_line_and_column(tmp_path: Path) -> None:
    """Issue 5: a TOML syntax error raises InvalidSceneError with file:line:col."""
    text = 'format = 1\nbody = "free_link"\nlength = 0.2 0.3\n'
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(InvalidSceneError) as info:
        load(path)
    col = text.splitlines()[2].index("0.3") + 1
    assert f"{path}:3:{col}:" in str(info.value)
    assert info.value.field == "length"


def test_syntax_error_unterminated_string() -> None:
    with pytest.raises(InvalidSceneError, match=r"<string>:2:\d+: invalid TOML"):
        loads('body = "leg"\ncoefficients_source = "abc\n')


def test_duplicate_key_is_a_syntax_error_at_its_line() -> None:
    text = "q_deg = 10.0\nv0 = 1.0\nq_deg = 20.0\n"
    with pytest.raises(InvalidSceneError, match=r"<string>:3:\d+:"):
        loads(text)


@pytest.mark.parametrize(
    ("typo", "suggestion"),
    [("lenght", "length"), ("v_0", "v0"), ("focres", "forces"), ("formt", "format")],
)
def test_unknown_key_names_it_with_line_and_suggestion(typo: str, suggestion: str) -> None:
    """Issue 5: an unknown key raises UnknownNameError naming it, its line and the closest
    field."""
    text = f'format = 1\nbody = "free_link"\n\n# comment\n{typo} = 0.2\n'
    with pytest.raises(UnknownNameError) as info:
        loads(text, source="s.toml")
    message = str(info.value)
    assert info.value.field == typo
    assert message.startswith("s.toml:5:")
    assert f"did you mean {suggestion!r}?" in message


def test_unknown_key_without_a_close_match_has_no_suggestion() -> None:
    with pytest.raises(UnknownNameError, match="zzzzzzzz") as info:
        loads("zzzzzzzz = 1\n")
    assert "did you mean" not in str(info.value)


def test_unknown_parameter_in_a_forces_table() -> None:
    """Issue 16: an unknown parameter names term.param, its near miss and its table's line."""
    text = 'body = "free_link"\n\n[[forces]]\nterm = "gravity"\n\n[[forces]]\n'
    text += 'term = "static_v"\neta_v = 1.0\nlambda = 0.1\n'
    with pytest.raises(UnknownNameError) as info:
        loads(text)
    assert info.value.field == "static_v.lambda"
    assert str(info.value).startswith("<string>:6:")
    assert "did you mean `static_v.lam`?" in str(info.value)


def test_a_forces_table_without_a_term_points_at_the_table() -> None:
    text = "q_deg = 1.0\n[[forces]]\neta_h = 1.0\n"
    with pytest.raises(InvalidParameterError) as info:
        loads(text)
    assert info.value.field == "forces"
    assert str(info.value).startswith("<string>:2:")
    assert "term" in str(info.value)


@pytest.mark.parametrize("key", ["coefficients", "coefficients2", "effects"])
def test_keys_of_the_earlier_format_say_what_to_write(key: str) -> None:
    """Issue 16: the law is [[forces]] tables now; the old keys fail with what to write."""
    text = f"q_deg = 1.0\n{key} = 1.0\n"
    with pytest.raises(UnknownNameError) as info:
        loads(text)
    assert info.value.field == key
    assert "[[forces]]" in str(info.value)
    assert str(info.value).startswith("<string>:2:")


@pytest.mark.parametrize(
    ("line", "cls", "field"),
    [
        ('length = "long"', InvalidParameterError, "length"),
        ("length = -0.2", InvalidParameterError, "length"),
        ("v0 = nan", InvalidParameterError, "v0"),
        ("q_deg = 90.0", InvalidParameterError, "q_deg"),
        ("record_stride = 1.5", InvalidParameterError, "record_stride"),
        ("record_stride = true", InvalidParameterError, "record_stride"),
        ('apply_at = "tail"', UnknownNameError, "apply_at"),
        ('body = "arm"', UnknownNameError, "body"),
        ('forces = ["gravity", "lift"]', InvalidParameterError, "forces"),
        ('forces = "gravity"', InvalidParameterError, "forces"),
        ("dt = 1970-01-01", InvalidParameterError, "dt"),
        ('knee = "locked"', InvalidSceneError, None),  # default value: allowed
        ('knee = "free"', InvalidSceneError, "knee"),  # not a free-link field
        ("q2_deg = 10.0", InvalidSceneError, "q2_deg"),
    ],
)
def test_bad_value_raises_typed_error_with_key_line(
    line: str, cls: type[InvalidSceneError], field: str | None
) -> None:
    """Issue 5: a wrong type or out-of-range value raises the Scene/validate() error with the
    field name and the line of the key prepended."""
    text = f"# a free link (the default body)\nformat = 1\nmass = 0.2\n{line}\nrho_g = 1600.0\n"
    if field is None:
        loads(text)
        return
    with pytest.raises(cls) as info:
        loads(text, source="x.toml")
    key_line = line_of(text, line.split(" ")[0] + " ")
    assert info.value.field == field
    assert str(info.value).startswith(f"x.toml:{key_line}:"), str(info.value)
    assert field in str(info.value)


def test_bad_per_contact_value_points_at_its_table() -> None:
    """A bad value of link 2 names the term's parameter and the line of its table."""
    text = (
        'body = "chain"\nq_deg = 10.0\n\n[[forces]]\nterm = "gravity"\n\n[[forces]]\n'
        'term = "drag"\neta_d = [1.0, -1.0]\n'
    )
    with pytest.raises(InvalidParameterError) as info:
        loads(text)
    assert info.value.field == "drag.eta_d"
    assert str(info.value).startswith("<string>:7:")


def test_joint_spring_error_points_at_the_joint_line() -> None:
    """A joint's k is checked by the core (field 'knee.k'); the line is the knee's."""
    text = 'body = "leg"\nankle = "free"\nknee = { k = -300.0, c = 5.0 }\n'
    with pytest.raises(InvalidParameterError) as info:
        loads(text)
    assert info.value.field == "knee.k"
    assert str(info.value).startswith("<string>:3:")


def test_joint_too_stiff_is_refused_at_load() -> None:
    """Validation runs in full at load time (the core's RK4 stiffness check included)."""
    text = 'body = "leg"\nknee = { k = 1e12, c = 0.0 }\n'
    with pytest.raises(InvalidParameterError) as info:
        loads(text)
    assert info.value.field == "knee.k"
    assert str(info.value).startswith("<string>:2:")


def test_error_for_a_key_not_in_the_file_names_the_file_only() -> None:
    """dt so small that the default t_end needs too many steps: the core names t_end (the
    step count's bound), which the file leaves out."""
    with pytest.raises(InvalidParameterError) as info:
        loads("dt = 1e-300\n", source="f.toml")
    assert info.value.field == "t_end"
    assert str(info.value).startswith("f.toml: ")


@pytest.mark.parametrize("version", ["2", "0", '"1"', "true"])
def test_unknown_format_version_is_rejected(version: str) -> None:
    text = f"# header\nformat = {version}\nq_deg = 1.0\n"
    with pytest.raises(InvalidSceneError) as info:
        loads(text)
    assert info.value.field == "format"
    assert str(info.value).startswith("<string>:2:")
    assert "format" in str(info.value)


def test_missing_format_reads_as_current() -> None:
    assert loads("q_deg = 12.5\n") == Scene(q_deg=12.5)


def test_load_missing_file_raises_os_error(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        load(tmp_path / "missing.toml")


# --- overrides and key lines --------------------------------------------------------------


@pytest.mark.parametrize(
    ("arg", "expected"),
    [
        ("q_deg=30", ("q_deg", 30)),
        ("dt = 1e-5", ("dt", 1e-5)),
        ('apply_at="centroid"', ("apply_at", "centroid")),
        ("body=chain", ("body", "chain")),
        ('record=["state", "energy"]', ("record", ["state", "energy"])),
        ("knee={k=300.0, c=5.0}", ("knee", {"k": 300.0, "c": 5.0})),
        ("coefficients.eta_h=7", ("coefficients.eta_h", 7)),
    ],
)
def test_parse_override(arg: str, expected: tuple[str, Any]) -> None:
    assert parse_override(arg) == expected


@pytest.mark.parametrize("arg", ["q_deg", "=3", "coefficients_source=a b"])
def test_parse_override_rejects(arg: str) -> None:
    with pytest.raises(InvalidSceneError):
        parse_override(arg)


def test_overrides_replace_file_values_and_errors_name_them() -> None:
    text = 'q_deg = 10.0\n[[forces]]\nterm = "static_h"\neta_h = 1.0\n'
    scene = loads(text, overrides={"q_deg": 20, "static_h.eta_h": 7.5})
    assert scene.q_deg == 20.0 and scene.forces == (granrs.forces.static_h(eta_h=7.5),)
    with pytest.raises(InvalidSceneError, match="no \\[\\[forces\\]\\] table"):
        loads(text, overrides={"drag.eta_d": 1.0})
    with pytest.raises(InvalidParameterError) as info:
        loads(text, source="f.toml", overrides={"static_h.eta_h": -1.0})
    assert str(info.value).startswith("f.toml: --set static_h.eta_h=-1.0:")
    with pytest.raises(InvalidParameterError) as info:
        loads(text, source="f.toml", overrides={"q_deg": 100.0})
    assert str(info.value).startswith("f.toml: --set q_deg=100.0:")
    with pytest.raises(UnknownNameError, match="did you mean 'length'"):
        loads(text, overrides={"lenght": 1.0})


def test_key_lines() -> None:
    text = (
        "# c\nformat = 1\n"
        'coefficients_source = """\nlength = 5\n"""\n'
        '"q_deg" = 1.0\n'
        "knee = { k = 1.0, c = 2.0 }\n"
        '[[forces]]\nterm = "drag"\n  eta_d = 0.2\n[[forces]]\nterm = "gravity"\n'
    )
    lines = key_lines(text)
    assert lines[("format",)] == 2
    assert lines[("coefficients_source",)] == 3
    assert ("length",) not in lines  # inside a multi-line string
    assert lines[("q_deg",)] == 6
    assert lines[("knee",)] == 7
    assert lines[("forces", "#0")] == 8
    assert lines[("forces", "#0", "term")] == 9
    assert lines[("forces", "#0", "eta_d")] == 10
    assert lines[("forces", "#1", "term")] == 12
