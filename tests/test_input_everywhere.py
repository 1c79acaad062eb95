"""Bad input everywhere a user can reach it (issue 6): the Python API (Scene, replace,
simulate, sweep axes, resistance_force), TOML scenes, the command line and coefficient
tables. Every invalid field raises a typed granrs error (``granrs.errors``) that names the
field (``.field``, and in the message) and the allowed range or names, before any work
starts; no Rust panic reaches Python (pyo3's PanicException derives from BaseException, so
it would escape ``except Exception``).

tests/test_validation.py covers the free link's numeric fields through ``cases.free_link``
and ``Scene`` + ``simulate``; this file covers the rest: the chain's and the leg's fields,
joints, the integrator's fields, None and other wrong types, the same values through sweep
axes, TOML and ``granrs run``, the force law's scalar arguments, malformed CSV tables, and a
short fuzz of the scene loaders (benches/fuzz_scenes.py runs the long one).
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import granrs
from granrs import Scene, scenefile
from granrs.cli import main
from granrs.coefficients import load_table
from granrs.errors import (
    CoefficientTableError,
    GranrsError,
    InvalidParameterError,
    InvalidSceneError,
    UnknownNameError,
)

NAN, INF = math.nan, math.inf
BENCHES = Path(__file__).resolve().parent.parent / "benches"

#: Words that say what is allowed: a comparison, "finite", a list of names, ...
_RANGE = re.compile(r"allowed|<|>|finite|must be|expected|one of|needs|whole number|choose|takes")


def expect(
    call: Callable[[], Any],
    field: str | None,
    cls: type[GranrsError] = InvalidParameterError,
    *,
    allowed: bool = True,
    named: bool = True,
) -> GranrsError:
    """``call`` raises ``cls`` whose ``.field`` is ``field``, whose message names the field
    (its last part) and, with ``allowed``, says what is allowed. A PanicException, or any
    exception outside granrs's tree, fails here with its type named."""
    try:
        call()
    except BaseException as exc:  # PanicException derives from BaseException
        name = type(exc).__name__
        assert name != "PanicException", f"a Rust panic crossed into Python: {exc}"
        assert isinstance(exc, cls), f"{name}: {exc} (expected {cls.__name__})"
        assert isinstance(exc, ValueError)
        assert exc.field == field, (exc.field, field, str(exc))
        if field is not None and named:
            assert field.rpartition(".")[2] in str(exc), str(exc)
        if allowed:
            assert _RANGE.search(str(exc)), f"no allowed range in: {exc}"
        return exc
    raise AssertionError(f"no error for field {field!r}")


CHAIN = Scene(body="chain")
LEG = Scene(body="leg")
FREE = Scene()

# ---------------------------------------------------------------------------------------
# Python API: fields of every body, the integrator, joints

#: (base scene, field, bad value, error class, field named).
BAD_FIELDS: list[tuple[Scene, str, Any, type[GranrsError], str]] = [
    *[(FREE, "depth0", v, InvalidParameterError, "depth0") for v in (-1e-9, NAN, INF)],
    *[
        (FREE.replace(method="dopri5"), f, v, InvalidParameterError, f)
        for f in ("rtol", "atol")
        for v in (0.0, -1.0, NAN, INF)
    ],
    (FREE, "method", "euler", UnknownNameError, "method"),
    (FREE, "method", "RK4", UnknownNameError, "method"),
    (FREE, "end", "stop", UnknownNameError, "end"),
    (FREE, "sign_model", "Modes", UnknownNameError, "sign_model"),
    (FREE, "t_end", 1e30, InvalidParameterError, "t_end"),  # 1e34 steps: refused by count
    (FREE, "record_stride", 10**30, InvalidParameterError, "record_stride"),
    (FREE, "vx0", -INF, InvalidParameterError, "vx0"),
    *[(CHAIN, "pin_mass", v, InvalidParameterError, "pin_mass") for v in (-1.0, NAN, INF)],
    *[(CHAIN, "q2_deg", v, InvalidParameterError, "q2_deg") for v in (90.0, -95.0, NAN, INF)],
    (CHAIN, "pin_joint", "welded", UnknownNameError, "pin_joint"),
    (CHAIN, "pin_joint", {"k": 1.0}, InvalidParameterError, "pin_joint"),
    (CHAIN, "pin_joint", {"k": 1.0, "c": 0.0, "d": 2.0}, InvalidParameterError, "pin_joint"),
    (CHAIN, "pin_joint", 5, InvalidParameterError, "pin_joint"),
    *[
        (LEG, f, v, InvalidParameterError, f)
        for f in ("body_mass", "height", "foot_length", "shoe_width", "sole_height")
        for v in (0.0, -1.0, NAN, INF)
    ],
    *[(LEG, "knee_deg", v, InvalidParameterError, "knee_deg") for v in (-1.0, 151.0, NAN)],
    *[(LEG, "hip_deg", v, InvalidParameterError, "hip_deg") for v in (-31.0, 151.0, INF)],
    *[(LEG, "trunk_deg", v, InvalidParameterError, "trunk_deg") for v in (-61.0, 61.0, NAN)],
    *[(LEG, "foot_deg", v, InvalidParameterError, "foot_deg") for v in (-61.0, 61.0, NAN)],
    (LEG, "sole_model", "flat", UnknownNameError, "sole_model"),
    *[
        (LEG, j, {"k": k, "c": c}, InvalidParameterError, f"{j}.{'k' if c == 0.0 else 'c'}")
        for j in ("ankle", "knee", "hip")
        for k, c in ((-1.0, 0.0), (NAN, 0.0), (1.0, -1.0), (1.0, INF))
    ],
    *[(LEG, j, v, InvalidParameterError, j) for j in ("ankle", "knee", "hip") for v in (True, 0)],
    (LEG, "knee", "bent", UnknownNameError, "knee"),
]


@pytest.mark.parametrize(
    ("base", "field", "value", "cls", "named"),
    BAD_FIELDS,
    ids=[f"{b.body}-{f}={v!r}" for b, f, v, _, _ in BAD_FIELDS],
)
def test_bad_field_through_simulate(
    base: Scene, field: str, value: Any, cls: type[GranrsError], named: str
) -> None:
    """Each bad field raises its typed error naming it and the allowed range, through
    replace() + simulate() and through validate(), before any run (well under 0.5 s, on a
    scene that would take minutes to run)."""
    slow = base.replace(end="time", t_end=100.0, dt=1e-6) if field not in ("t_end", "dt") else base
    t0 = time.perf_counter()
    expect(lambda: granrs.simulate(slow.replace(**{field: value})), named, cls)
    assert time.perf_counter() - t0 < 0.5
    expect(lambda: base.replace(**{field: value}).validate(), named, cls)


#: A None where a value is needed: every field of each body whose default is not None.
#: Today the first group is refused as "missing"; the second is silently read as the
#: field's default (Scene(depth0=None) runs from the surface, a leg with height=None is
#: 1.78 m tall).
NONE_REFUSED = [
    *[(FREE, f) for f in ("length", "diameter", "mass", "rho_g", "g", "q_deg", "v0")],
    *[(FREE, f) for f in ("dt", "t_end", "apply_at", "sign_model", "method", "end")],
]
NONE_DEFAULTED = [
    *[(FREE, f) for f in ("depth0", "vx0", "omega0", "record_stride", "smooth_eps")],
    *[(FREE, f) for f in ("rtol", "atol")],
    (CHAIN, "pin_mass"),
    *[(LEG, f) for f in ("body_mass", "height", "foot_length", "shoe_width", "tibia_length")],
    *[(LEG, f) for f in ("knee_deg", "hip_deg", "trunk_deg", "foot_deg", "sole_model")],
]
NONE_FIELDS = NONE_REFUSED + NONE_DEFAULTED


@pytest.mark.parametrize(
    ("base", "field"), NONE_FIELDS, ids=[f"{b.body}-{f}" for b, f in NONE_FIELDS]
)
def test_none_where_a_value_is_needed(base: Scene, field: str) -> None:
    """Minimal reproducers: granrs.simulate(Scene(q_deg=None)) (wrong class, no range) and
    granrs.simulate(Scene(depth0=None)) (runs)."""
    expect(lambda: granrs.simulate(base.replace(**{field: None})), field, InvalidParameterError)


@pytest.mark.parametrize(
    ("base", "field"), NONE_REFUSED, ids=[f"{b.body}-{f}" for b, f in NONE_REFUSED]
)
def test_none_is_refused_naming_the_field(base: Scene, field: str) -> None:
    """What holds today for these fields: None is refused with a scene error naming it."""
    expect(
        lambda: granrs.simulate(base.replace(**{field: None})),
        field,
        InvalidSceneError,
        allowed=False,
    )


@pytest.mark.parametrize(
    ("field", "value"),
    [("sign_model", 1), ("apply_at", 2.5), ("method", ["rk4"]), ("end", b"time")],
)
def test_wrong_type_for_a_name(field: str, value: Any) -> None:
    """A number or a list where a name is expected: a typed error naming the field."""
    expect(lambda: granrs.simulate(FREE.replace(**{field: value})), field, InvalidSceneError)


@pytest.mark.parametrize(
    ("kw", "field"),
    [
        ({"forces": None}, "forces"),
        ({"forces": 3}, "forces"),
        ({"forces": ("gravity",)}, "forces"),
        ({"forces": {"eta_h": 1.0}}, "forces"),
        ({"record": 3}, "record"),
        ({"record": ("state", None)}, "record"),
        ({"body": True}, "body"),
        ({"body": None}, "body"),
    ],
)
def test_scene_constructor_refuses(kw: dict[str, Any], field: str | None) -> None:
    """Scene(...) itself refuses wrong types of its structured fields (no run needed)."""
    try:
        Scene(**kw)
    except TypeError:
        # A mapping with missing coefficients is refused by the dataclass constructor.
        assert field is None
        return
    except BaseException as exc:
        assert type(exc).__name__ != "PanicException"
        assert isinstance(exc, InvalidSceneError), repr(exc)
        assert exc.field == field
        return
    raise AssertionError("no error")


def test_chain_pin_joint_names_pin_joint() -> None:
    """Minimal reproducer: simulate(Scene(body="chain", pin_joint={"k": -1.0, "c": 0.0}))."""
    bad = {"k": -1.0, "c": 0.0}
    expect(lambda: granrs.simulate(CHAIN.replace(pin_joint=bad)), "pin_joint.k")


def test_link_2_s_parameter_names_the_term() -> None:
    """Minimal reproducer: link 2's lambda negative, given per contact."""
    bad = granrs.forces.static_v
    expect(lambda: Scene(body="chain", forces=[bad(lam=(0.1, -1.0))]), "static_v.lam")


def test_replace_refuses_unknown_fields_and_other_bodies() -> None:
    """replace() names an unknown field; a field of another body is refused at once."""
    expect(lambda: FREE.replace(lenght=0.2), "lenght", UnknownNameError, allowed=False)
    expect(lambda: FREE.replace(knee="free"), "knee", InvalidSceneError, allowed=False)
    expect(lambda: LEG.replace(q2_deg=10.0), "q2_deg", InvalidSceneError, allowed=False)


# ---------------------------------------------------------------------------------------
# Sweep axes: the same values, named with their run


SWEEP_BAD = [
    (FREE, "mass", [0.1, "heavy"], "mass"),
    (FREE, "mass", [True], "mass"),
    (FREE, "depth0", [0.0, -1.0], "depth0"),
    (FREE, "q_deg", [0.0, NAN], "q_deg"),
    (FREE, "record_stride", [1, 0], "record_stride"),
    (FREE, "method", ["rk4", "euler"], "method"),
    (CHAIN, "q2_deg", [10.0, 95.0], "q2_deg"),
    (CHAIN, "pin_mass", [0.0, -1.0], "pin_mass"),
    (LEG, "knee", [{"k": -1.0, "c": 0.0}], "knee.k"),
    (LEG, "foot_deg", [0.0, 70.0], "foot_deg"),
    (LEG, "height", [1.7, INF], "height"),
]


@pytest.mark.parametrize(
    ("base", "field", "values", "named"),
    SWEEP_BAD,
    ids=[f"{b.body}-{f}" for b, f, _, _ in SWEEP_BAD],
)
def test_sweep_axis_values(base: Scene, field: str, values: list[Any], named: str) -> None:
    """A bad value on a sweep axis raises the typed error naming the field (and, for the
    numbers the core checks, the run) before any run starts."""
    err = expect(lambda: granrs.sweep(base, progress=False, **{field: values}), named, GranrsError)
    if isinstance(values[-1], float) and len(values) > 1:
        assert "run 1" in str(err), str(err)


def test_sweep_arguments() -> None:
    """threads, chunk_size and an empty axis."""
    expect(lambda: granrs.sweep(FREE, threads=True), "threads")
    expect(lambda: granrs.sweep(FREE, threads=-2), "threads")
    expect(lambda: granrs.sweep(FREE, client=object(), chunk_size=0), "chunk_size")
    expect(lambda: granrs.sweep(FREE, mass=[]), "mass", allowed=False)
    err = expect(lambda: granrs.sweep([FREE, "scene"]), "scene", named=False)
    assert "item 1" in str(err)


# ---------------------------------------------------------------------------------------
# The force law on its own


RF_BAD: list[tuple[dict[str, Any], str, type[GranrsError]]] = [
    *[({"length": v}, "length", InvalidParameterError) for v in (0.0, -1.0, NAN, INF, True)],
    *[({"diameter": v}, "diameter", InvalidParameterError) for v in (0.0, NAN, "1")],
    *[({"rho_g": v}, "rho_g", InvalidParameterError) for v in (0.0, -1.0, INF)],
    *[({"g": v}, "g", InvalidParameterError) for v in (-9.81, NAN)],
    ({"sign_model": "modes"}, "sign_model", UnknownNameError),
    ({"sign_model": "tanh"}, "sign_model", UnknownNameError),
    ({"sign_model": "smooth", "smooth_eps": 0.0}, "smooth_eps", InvalidParameterError),
    ({"sign_model": "smooth", "smooth_eps": NAN}, "smooth_eps", InvalidParameterError),
    ({"effects": ("magic",)}, "effects", UnknownNameError),
    ({"effects": "drag"}, "effects", InvalidParameterError),
    ({"depth": "a"}, "depth", InvalidParameterError),
    ({"depth": 1j}, "depth", InvalidParameterError),
    ({"vy": [0.0, INF]}, "vy", InvalidParameterError),
    ({"q_deg": [0.0, -90.0]}, "q_deg", InvalidParameterError),
    ({"coefficients": "table_3_4"}, "coefficients", InvalidParameterError),
    ({"coefficients": {"eta_h": 1.0}}, "coefficients", InvalidParameterError),
]


@pytest.mark.parametrize(("kw", "field", "cls"), RF_BAD, ids=[str(k) for k, _, _ in RF_BAD])
def test_resistance_force_arguments(kw: dict[str, Any], field: str, cls: type[GranrsError]) -> None:
    """granrs.resistance_force: every scalar argument and array is checked, naming it."""
    args: dict[str, Any] = {"depth": 0.01, "q_deg": 10.0, "vx": 0.1, "vy": -1.0, **kw}
    expect(lambda: granrs.resistance_force(**args), field, cls, allowed=cls is not UnknownNameError)


# ---------------------------------------------------------------------------------------
# TOML scenes


TOML_BAD = [
    ('body = "chain"\npin_mass = -1.0\n', "pin_mass", 2),
    ('body = "chain"\nq2_deg = "ten"\n', "q2_deg", 2),
    ('body = "leg"\n\nknee = { k = 1.0, c = nan }\n', "knee.c", 3),
    ('body = "leg"\nknee = [1.0, 2.0]\n', "knee", 2),
    ('body = "leg"\nheight = 0\n', "height", 2),
    ('body = "leg"\nsole_model = "flat"\n', "sole_model", 2),
    ('body = "leg"\nfoot_deg = 90\n', "foot_deg", 2),
    ("depth0 = -inf\n", "depth0", 1),
    ('method = "dopri5"\nrtol = 0.0\n', "rtol", 2),
    ("method = 4\n", "method", 1),
    ("record_stride = 1e300\n", "record_stride", 1),
    ("q_deg = { a = 1 }\n", "q_deg", 1),
    ("v0 = [1.0]\n", "v0", 1),
    ("dt = 12:00:00\n", "dt", 1),
    ("record = [1, 2]\n", "record", 1),
    ('forces = ["gravity", 3]\n', "forces", 1),
    ("coefficients = 3\n", "coefficients", 1),
    ('\n[[forces]]\nterm = "static_v"\nlam = true\n', "static_v.lam", 2),
    ('body = "chain"\n[[forces]]\nterm = "drag"\neta_d = [1.0, "x"]\n', "drag.eta_d", 2),
]


@pytest.mark.parametrize(
    ("text", "field", "line"), TOML_BAD, ids=[t.split("\n")[-2][:30] for t, _, _ in TOML_BAD]
)
def test_toml_bad_values(text: str, field: str | None, line: int) -> None:
    """scenefile.loads: a typed error naming the field, its line in the file, and what is
    allowed, for values of the chain's and the leg's fields, joints, wrong TOML types."""
    err = expect(lambda: scenefile.loads(text, source="s.toml"), field, InvalidSceneError)
    assert str(err).startswith(f"s.toml:{line}:"), str(err)


def test_toml_pin_joint_error_has_its_line() -> None:
    """Minimal reproducer: loads('body = "chain"\\npin_joint = { k = -1.0, c = 0.0 }')."""
    text = 'body = "chain"\npin_joint = { k = -1.0, c = 0.0 }\n'
    err = expect(lambda: scenefile.loads(text, source="s.toml"), "pin_joint.k")
    assert str(err).startswith("s.toml:2:"), str(err)


def test_toml_huge_integer_says_what_is_allowed() -> None:
    """Minimal reproducer: loads("mass = 1" + "0" * 400)."""
    expect(lambda: scenefile.loads("mass = 1" + "0" * 400 + "\n", source="s.toml"), "mass")


@pytest.mark.parametrize(
    "text",
    [
        "format = true\n",
        'format = "1"\n',
        "format = 2\n",
        "[[q_deg]]\n",
        "= 1\n",
        "\x00",
        "a.b.c = 1\n",
    ],
)
def test_toml_structure(text: str) -> None:
    """Wrong format versions, arrays of tables, syntax errors, dotted unknown keys."""
    with pytest.raises(InvalidSceneError) as info:
        scenefile.loads(text, source="s.toml")
    assert str(info.value).startswith("s.toml")


# ---------------------------------------------------------------------------------------
# The command line


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


@pytest.mark.parametrize(
    ("override", "field"),
    [
        ("pin_mass=-1", "pin_mass"),
        ("q2_deg=nan", "q2_deg"),
        ("v0=-inf", "v0"),
        ("dt=0", "dt"),
        ("static_v.eta_v=-3", "static_v.eta_v"),
        ("static_v.lam=true", "static_v.lam"),
        ("static_v.mu=1", "static_v.mu"),
        ("apply_at=centre", "apply_at"),
        ("effects=gravity", "effects"),
        ("record_stride=0.5", "record_stride"),
        ("knee=free", "knee"),  # a leg field on a chain
        ("body=arm", "body"),
        ("lenght=0.2", "lenght"),
    ],
)
def test_cli_set_exit_2(
    override: str, field: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """granrs run FILE --set FIELD=VALUE with a bad value: exit 2, one line naming the
    field, nothing on stdout."""
    path = tmp_path / "chain.toml"
    path.write_text('body = "chain"\n')
    code = main(["run", str(path), "--set", override])
    out, err = capsys.readouterr()
    assert code == 2, (code, err)
    assert out == ""
    line = one_line(err)
    assert line.startswith("granrs: error: ")
    assert field in line, line


@pytest.mark.parametrize(
    "argv",
    [
        ["reproduce", "--dt", "-1", "--quiet"],
        ["reproduce", "--dt", "nan", "--quiet"],
        ["reproduce", "--dt", "0", "--quiet"],
        ["reproduce", "--dt", "abc"],
        ["reproduce", "--chapter", "9"],
        ["bench", "accuracy", "--repeats", "abc"],
        ["bench", "nothing"],
        ["scene", "new", "--body", "arm"],
        ["run"],
        ["run", "a.toml", "--series", "out.xlsx"],
        ["--bogus"],
    ],
)
def test_cli_arguments_exit_2(
    argv: list[str],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Bad command-line arguments exit with 2 and an error naming the argument, before any
    run (and nothing is written)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a.toml").write_text("q_deg = 10.0\n")
    code = main([*argv, "--out", str(tmp_path / "out")] if argv[0] == "reproduce" else argv)
    _, err = capsys.readouterr()
    assert code == 2, (code, err)
    assert "Traceback" not in err
    assert err.strip(), "no message"
    assert not (tmp_path / "out").exists()


def test_cli_bench_repeats_must_be_positive(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Minimal reproducer: granrs bench accuracy --repeats 0 --quick --quiet --out DIR."""
    code = main(
        ["bench", "accuracy", "--repeats", "-1", "--quick", "--quiet", "--out", str(tmp_path)]
    )
    capsys.readouterr()
    assert code == 2


# ---------------------------------------------------------------------------------------
# Coefficient tables

HEADER = "q_deg,eta_h,eta_d,eta_v,lambda\n"


@pytest.mark.parametrize(
    ("body", "field"),
    [
        (HEADER + "95,1,1,1,0.1\n", "q_deg"),
        (HEADER + "nan,1,1,1,0.1\n", "q_deg"),
        (HEADER + "0,inf,1,1,0.1\n", "eta_h"),
        (HEADER + "0,1,1e400,1,0.1\n", "eta_d"),
        (HEADER + "0,1,1,-0.0001,0.1\n", "eta_v"),
        (HEADER + "0,1,1,1,-1\n", "lambda"),
        (HEADER + "0,1,1,1,True\n", "lambda"),
        (HEADER + "0,1,1,1,\n", "lambda"),
        (HEADER + "0,1,1,1,0.1\x00\n", "lambda"),
        ("q_deg;eta_h;eta_d;eta_v;lambda\n0;1;1;1;0.1\n", "q_deg"),
        ("", None),
        (HEADER, None),
    ],
)
def test_malformed_coefficient_table(body: str, field: str | None, tmp_path: Path) -> None:
    """load_table on malformed CSV: CoefficientTableError naming the column (or the file)."""
    path = tmp_path / "table.csv"
    path.write_text(body, encoding="utf-8")
    try:
        load_table(path)
    except BaseException as exc:
        assert type(exc).__name__ != "PanicException"
        assert isinstance(exc, CoefficientTableError), repr(exc)
        assert exc.field == field, (exc.field, str(exc))
        assert str(path) in str(exc)
        return
    raise AssertionError("no error")


def test_coefficient_table_unterminated_quote(tmp_path: Path) -> None:
    """Minimal reproducer: load_table on 'q_deg,eta_h,eta_d,eta_v,lambda\\n0,1,1,1,"0.1\\n'."""
    path = tmp_path / "table.csv"
    path.write_text(HEADER + '0,1,1,1,"0.1\n', encoding="utf-8")
    with pytest.raises(CoefficientTableError):
        load_table(path)


def test_coefficient_table_not_utf8(tmp_path: Path) -> None:
    path = tmp_path / "table.csv"
    path.write_bytes(HEADER.encode() + b"0,1,1,1,\xff\xfe\n")
    with pytest.raises(CoefficientTableError, match="UTF-8"):
        load_table(path)


# ---------------------------------------------------------------------------------------
# A short fuzz of the loaders (benches/fuzz_scenes.py runs 100,000 inputs)


def test_fuzz_scene_loaders_short() -> None:
    """2000 random and mutated TOML texts, dicts and Scene keyword sets through
    scenefile.loads, _granrs.validate and Scene(**kw): only the accepted exception types of
    benches/fuzz_scenes.py escape (no panic, no SystemError, no crash), in a subprocess so
    that a segfault fails the test instead of the run."""
    proc = subprocess.run(
        [sys.executable, str(BENCHES / "fuzz_scenes.py"), "--n", "2000", "--seed", "11"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert "failures: 0" in proc.stdout, proc.stdout[-3000:]


def test_huge_integer_coefficient() -> None:
    """Minimal reproducer: Coefficients(eta_h=10**400, eta_d=1, eta_v=1, lam=0)."""
    big = 10**400
    expect(
        lambda: granrs.Coefficients(eta_h=big, eta_d=1.0, eta_v=1.0, lam=0.0), "coefficients.eta_h"
    )
