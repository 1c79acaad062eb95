"""Scene validation: every invalid input raises a typed granrs error naming its field, before
any simulation runs.

Invalid input reaches granrs two ways, and both are checked: through ``cases.free_link``
(which validates the scene it builds, and never simulates), and through a ``Scene`` built by
hand and passed to ``granrs.simulate`` (validated in full by the Rust core before the run).
The classes are those of ``granrs.errors``: InvalidParameterError for a value out of range
or of the wrong type, UnknownNameError for a name granrs does not know; both are
InvalidSceneError, GranrsError and ValueError.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import granrs
from granrs import Coefficients, Scene, cases
from granrs.errors import (
    GranrsError,
    InvalidParameterError,
    InvalidSceneError,
    UnknownNameError,
)
from granrs.forces import thesis

NAN = math.nan
INF = math.inf


def raises_naming(
    call: Callable[[], Any], cls: type[InvalidSceneError], field: str
) -> InvalidSceneError:
    """Run ``call``; assert it raises exactly ``cls`` (or a subclass) with ``.field`` set."""
    with pytest.raises(cls) as info:
        call()
    err = info.value
    assert isinstance(err, GranrsError)
    assert isinstance(err, ValueError)
    assert err.field == field, (err.field, field, str(err))
    return err


def via_free_link(field: str, value: Any, **extra: Any) -> Callable[[], Any]:
    """Build a free link with ``field`` set to ``value`` (validates, does not simulate)."""
    if field == "q_deg":
        return lambda: cases.free_link(value, 2.0, **extra)
    if field == "v0":
        return lambda: cases.free_link(30.0, value, **extra)
    return lambda: cases.free_link(30.0, 2.0, **{field: value}, **extra)


def via_simulate(field: str, value: Any, **extra: Any) -> Callable[[], Any]:
    """Build a Scene by hand with ``field`` set to ``value`` and simulate it."""
    return lambda: granrs.simulate(Scene(**{field: value}, **extra))


PATHS = {"free_link": via_free_link, "simulate": via_simulate}

# ---------------------------------------------------------------------------------------
# Numbers out of range

#: (field, value) pairs a scene must refuse with InvalidParameterError naming the field.
OUT_OF_RANGE = [
    *[
        (f, v)
        for f in ("length", "diameter", "mass", "rho_g")
        for v in (-1.0, 0.0, -0.0, NAN, INF, -INF)
    ],
    ("v0", NAN),
    ("v0", -1.0),
    ("v0", -1e-300),
    ("v0", INF),
    ("q_deg", 90.0),
    ("q_deg", -90.0),
    ("q_deg", 90.5),
    ("q_deg", -180.0),
    ("q_deg", NAN),
    ("q_deg", INF),
    ("dt", 0.0),
    ("dt", -1e-4),
    ("dt", NAN),
    ("dt", INF),
    ("t_end", 0.0),
    ("t_end", -1.0),
    ("t_end", NAN),
    ("t_end", INF),
    ("g", -9.81),
    ("g", NAN),
    ("inertia", 0.0),
    ("inertia", -1e-3),
    ("inertia", NAN),
    ("vx0", NAN),
    ("vx0", INF),
    ("omega0", NAN),
    ("omega0", -INF),
    ("record_stride", 0),
    ("record_stride", 1.5),
    ("record_stride", -1),
    ("record_stride", NAN),
]


@pytest.mark.parametrize("path", sorted(PATHS))
@pytest.mark.parametrize(("field", "value"), OUT_OF_RANGE)
def test_out_of_range(path: str, field: str, value: float) -> None:
    """A number outside its allowed range raises InvalidParameterError naming the field."""
    raises_naming(PATHS[path](field, value), InvalidParameterError, field)


@pytest.mark.parametrize("path", sorted(PATHS))
@pytest.mark.parametrize("value", [0.0, -1e-3, NAN, INF])
def test_smooth_eps(path: str, value: float) -> None:
    """The smooth sign model's velocity scale must be finite and positive."""
    call = PATHS[path]("smooth_eps", value, sign_model="smooth")
    raises_naming(call, InvalidParameterError, "smooth_eps")


# ---------------------------------------------------------------------------------------
# Names

UNKNOWN_NAMES = [
    ("apply_at", "middle"),
    ("apply_at", "Tip"),
    ("sign_model", "sgn"),
    ("end", "never"),
    ("end", "first-stop"),
    ("body", "chain_of_three"),
]


@pytest.mark.parametrize("path", sorted(PATHS))
@pytest.mark.parametrize(("field", "value"), UNKNOWN_NAMES)
def test_unknown_name(path: str, field: str, value: str) -> None:
    """A name granrs does not know raises UnknownNameError naming the field and the name."""
    err = raises_naming(PATHS[path](field, value), UnknownNameError, field)
    assert value in str(err)


@pytest.mark.parametrize("path", sorted(PATHS))
@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("record", ("state", "torque")),
        ("record", ("energies",)),
    ],
)
def test_unknown_list_entry(path: str, field: str, value: tuple[str, ...]) -> None:
    """An unknown entry of record raises UnknownNameError naming the list (an unknown force
    term: tests/test_forces.py)."""
    err = raises_naming(PATHS[path](field, value), UnknownNameError, field)
    assert value[-1] in str(err)


@pytest.mark.parametrize("path", sorted(PATHS))
@pytest.mark.parametrize("field", ["forces", "record"])
def test_name_list_given_as_string(path: str, field: str) -> None:
    """A bare string where a list of names is expected is refused (not read letter by
    letter)."""
    raises_naming(PATHS[path](field, "state"), InvalidParameterError, field)


def test_unknown_coefficient_table() -> None:
    """An unknown coefficient table name raises UnknownNameError naming coefficients."""
    err = raises_naming(
        lambda: cases.free_link(45, 2.27, coefficients="table_9_9"),
        UnknownNameError,
        "coefficients",
    )
    assert "table_9_9" in str(err)


# ---------------------------------------------------------------------------------------
# Coefficients

COEFFICIENT_FIELDS = ("eta_h", "eta_d", "eta_v", "lam")
GOOD = {"eta_h": 5.5, "eta_d": 11.0, "eta_v": 53.0, "lam": 0.25}


@pytest.mark.parametrize("name", COEFFICIENT_FIELDS)
@pytest.mark.parametrize("value", [-1.0, -1e-12, NAN, INF, -INF])
def test_bad_coefficient(name: str, value: float) -> None:
    """A negative or non-finite coefficient raises InvalidParameterError naming
    coefficients.<name>, whether given as Coefficients or as a mapping to free_link; as the
    terms of a Scene, it names the term's parameter (static_v.lam)."""
    bad = {**GOOD, name: value}
    field = f"coefficients.{name}"
    raises_naming(lambda: Coefficients(**bad), InvalidParameterError, field)
    raises_naming(lambda: cases.free_link(45, 2.27, coefficients=bad), InvalidParameterError, field)
    term = {"eta_h": "static_h", "eta_d": "drag", "eta_v": "static_v", "lam": "static_v"}[name]
    raises_naming(
        lambda: granrs.simulate(Scene(forces=thesis(bad))), InvalidParameterError, f"{term}.{name}"
    )


@pytest.mark.parametrize("name", COEFFICIENT_FIELDS)
def test_bool_coefficient(name: str) -> None:
    """A bool is not a coefficient."""
    bad = {**GOOD, name: True}
    raises_naming(lambda: Coefficients(**bad), InvalidParameterError, f"coefficients.{name}")


def test_zero_coefficients_are_valid() -> None:
    """Zero is allowed for every coefficient (eta >= 0, lambda >= 0, MODEL.md)."""
    zero = dict.fromkeys(COEFFICIENT_FIELDS, 0.0)
    cases.free_link(45, 2.27, coefficients={**GOOD, "lam": 0.0})
    Coefficients(**zero)


# ---------------------------------------------------------------------------------------
# Wrong types

#: Numeric fields of a Scene (as cases.free_link and Scene take them).
NUMERIC_FIELDS = (
    "length",
    "diameter",
    "mass",
    "rho_g",
    "g",
    "q_deg",
    "v0",
    "vx0",
    "omega0",
    "dt",
    "t_end",
    "record_stride",
    "inertia",
)


@pytest.mark.parametrize("path", sorted(PATHS))
@pytest.mark.parametrize("value", [True, False])
@pytest.mark.parametrize("field", NUMERIC_FIELDS)
def test_bool_where_number_expected(path: str, field: str, value: bool) -> None:
    """A bool where a number is expected is refused (not read as 1 or 0) with a scene error
    naming the field."""
    raises_naming(PATHS[path](field, value), InvalidSceneError, field)


def test_wrong_type_is_an_invalid_parameter_everywhere() -> None:
    """A bool or a string where a number is expected raises the same class whichever field
    it is and whichever way the scene was built: InvalidParameterError, as Coefficients and
    cases.free_link (q_deg, v0, dt) already do.

    Pins down: the Rust core's dict conversion (rust/python/mod.rs, get_f64 -> bad_type)
    raised the base InvalidSceneError for these, so ``Scene(v0=True)`` and
    ``free_link(30, True)`` raised different classes for the same mistake. All cases are
    collected so that one failure lists every (field, path, value) at fault."""
    wrong: list[str] = []
    for field in NUMERIC_FIELDS:
        for path, make in sorted(PATHS.items()):
            for value in (True, "2.0"):
                with pytest.raises(InvalidSceneError) as info:
                    make(field, value)()
                assert info.value.field == field
                if type(info.value) is not InvalidParameterError:
                    wrong.append(f"{field}={value!r} via {path}: {type(info.value).__name__}")
    assert not wrong, "expected InvalidParameterError:\n" + "\n".join(wrong)


@pytest.mark.parametrize("path", sorted(PATHS))
@pytest.mark.parametrize("value", ["heavy", None, [1.0], 1 + 2j])
def test_non_number_mass(path: str, value: Any) -> None:
    """Anything but a real number where one is expected raises a scene error naming it."""
    raises_naming(PATHS[path]("mass", value), InvalidSceneError, "mass")


def test_simulate_not_a_scene() -> None:
    """simulate() takes a Scene, not anything else."""
    for thing in ("not a scene", None, {"q_deg": 45.0}, 3):
        raises_naming(lambda t=thing: granrs.simulate(t), InvalidParameterError, "scene")


# ---------------------------------------------------------------------------------------
# Before any simulation runs


def test_refused_before_running() -> None:
    """An invalid scene is refused before the run: a run of this scene would take minutes
    (1e8 steps), the refusal takes far less than a second."""
    slow = {"end": "time", "t_end": 100.0, "dt": 1e-6}
    for field, value in [("mass", -1.0), ("record_stride", 0), ("apply_at", "middle")]:
        t0 = time.perf_counter()
        with pytest.raises(InvalidSceneError):
            granrs.simulate(Scene(**slow, **{field: value}))
        assert time.perf_counter() - t0 < 0.5, field


def test_valid_scene_passes() -> None:
    """The checks refuse only invalid input: the boundary values are accepted."""
    for kw in (
        {"v0": 0.0},
        {"q_deg": 89.9},
        {"q_deg": -89.9},
        {"g": 0.0},
        {"vx0": -1.0},
        {"record_stride": 3, "record": ("state",)},
        {"sign_model": "smooth", "smooth_eps": 1e-2},
        {"forces": ()},
    ):
        scene = Scene(t_end=0.01, **kw)
        scene.validate()
        assert granrs.simulate(scene).status in ("stopped", "not_stopped")


# ---------------------------------------------------------------------------------------
# Hypothesis: any invalid number, any numeric field

negatives = st.floats(max_value=-math.ulp(0.0), allow_infinity=True)
non_finite = st.sampled_from([NAN, INF, -INF])
non_positive = st.one_of(st.floats(max_value=0.0, allow_infinity=True), non_finite)
negative = st.one_of(negatives, non_finite)

#: For each numeric field, a strategy of values it must refuse.
INVALID: dict[str, st.SearchStrategy[float]] = {
    "length": non_positive,
    "diameter": non_positive,
    "mass": non_positive,
    "rho_g": non_positive,
    "inertia": non_positive,
    "dt": non_positive,
    "t_end": non_positive,
    "v0": negative,
    "g": negative,
    "q_deg": st.one_of(
        st.floats(min_value=90.0, allow_infinity=True),
        st.floats(max_value=-90.0, allow_infinity=True),
        st.just(NAN),
    ),
    "vx0": non_finite,
    "omega0": non_finite,
    "record_stride": st.one_of(
        st.integers(max_value=0),
        st.floats(min_value=1.0, max_value=1e6).filter(lambda x: x != int(x)),
        negative,
    ),
}


@st.composite
def invalid_field(draw: st.DrawFn) -> tuple[str, float]:
    field = draw(st.sampled_from(sorted(INVALID)))
    return field, draw(INVALID[field])


@settings(max_examples=300, deadline=None)
@given(invalid_field(), st.sampled_from(sorted(PATHS)))
def test_any_invalid_number_names_its_field(case: tuple[str, float], path: str) -> None:
    """Whatever invalid number a field gets, the error is an InvalidParameterError naming
    that field."""
    field, value = case
    raises_naming(PATHS[path](field, value), InvalidParameterError, field)


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(COEFFICIENT_FIELDS), negative)
def test_any_invalid_coefficient_names_it(name: str, value: float) -> None:
    """Whatever negative or non-finite value a coefficient gets, the error names it."""
    bad = {**GOOD, name: value}
    raises_naming(
        lambda: cases.free_link(45, 2.27, coefficients=bad),
        InvalidParameterError,
        f"coefficients.{name}",
    )
