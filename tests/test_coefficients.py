"""Tests of granrs.coefficients: Table 3.4, the Table 3.2 closed forms, validation, user CSVs.

Expected values are independent of the code under test: the Table 3.4 CSV is read here with
the csv module, the Table 3.2 forms are written out again below from MODEL.md, and the check
values at alpha = 90 deg are the ones MODEL.md quotes.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from granrs import coefficients as co
from granrs.coefficients import Coefficients
from granrs.errors import CoefficientTableError, InvalidParameterError, UnknownNameError

TABLE_3_4_CSV = (
    Path(__file__).resolve().parents[1]
    / "python"
    / "granrs"
    / "data"
    / "table_3_4_free_link_coefficients.csv"
)
FIELDS = ("eta_h", "eta_d", "eta_v", "lam")


def table_3_4_csv() -> dict[float, tuple[float, float, float, float]]:
    """q_deg -> (eta_h, eta_d, eta_v, lambda), read with the csv module."""
    with open(TABLE_3_4_CSV, encoding="utf-8", newline="") as handle:
        return {
            float(row["q_deg"]): (
                float(row["eta_h"]),
                float(row["eta_d"]),
                float(row["eta_v"]),
                float(row["lambda"]),
            )
            for row in csv.DictReader(handle)
        }


def as_tuple(c: Coefficients) -> tuple[float, float, float, float]:
    return (c.eta_h, c.eta_d, c.eta_v, c.lam)


# Table 3.2 as MODEL.md reads it: alpha = pi/2 - |q|, q = |q| in radians.
def form_a(a: float, q: float, rho: float) -> tuple[float, float, float, float]:
    """alpha in 90, 85, 75."""
    h = rho / (100 * a**2)
    return h, 1.5 * h * a, 10 * h * a**3, 1e-4 * rho / a


def form_b(a: float, q: float, rho: float) -> tuple[float, float, float, float]:
    """alpha 65."""
    h = rho / (100 * a**2)
    return h, 1.5 * h * a, 10 * h * a**3, 2e-4 * rho * a


def form_c(a: float, q: float, rho: float) -> tuple[float, float, float, float]:
    """alpha 55, 45."""
    h = rho * a**2 / 100
    return h, 2 / 3 * h * q, 10 * h * a**3, 2e-4 * rho * a


def form_d(a: float, q: float, rho: float) -> tuple[float, float, float, float]:
    """alpha 35, 25."""
    h = rho * a**2 / 100
    return h, 2 / 3 * h * q, 10 * h * q**3, 2e-4 * rho * a


def form_e(a: float, q: float, rho: float) -> tuple[float, float, float, float]:
    """alpha 15, 5."""
    h = rho * a**2 / 10
    return h, 2 / 3 * h * a, 10 * h * q**3, 2e-4 * rho * q


Form = Callable[[float, float, float], tuple[float, float, float, float]]


def expected_3_2(form: Form, q_deg: float, rho: float = 1650.0) -> tuple[float, ...]:
    q = math.radians(abs(q_deg))
    return form(math.pi / 2 - q, q, rho)


# ------------------------------------------------------------------------------------------
# Coefficients


def test_coefficients_store_floats_and_round_trip() -> None:
    c = Coefficients(eta_h=1, eta_d=2.5, eta_v=np.float64(3.0), lam=0)
    assert as_tuple(c) == (1.0, 2.5, 3.0, 0.0)
    assert all(type(v) is float for v in as_tuple(c))
    assert c.as_dict() == {"eta_h": 1.0, "eta_d": 2.5, "eta_v": 3.0, "lam": 0.0}
    assert Coefficients(**c.as_dict()) == c


def test_coefficients_are_frozen() -> None:
    c = Coefficients(1.0, 2.0, 3.0, 0.5)
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.eta_h = 2.0  # type: ignore[misc]


@pytest.mark.parametrize("field", FIELDS)
@pytest.mark.parametrize(
    "bad", [math.nan, math.inf, -math.inf, -1.0, -1e-300, True, False, "1.0", None, 1 + 0j]
)
def test_coefficients_reject_each_bad_value(field: str, bad: object) -> None:
    values: dict[str, object] = {"eta_h": 1.0, "eta_d": 2.0, "eta_v": 3.0, "lam": 0.5}
    values[field] = bad
    with pytest.raises(InvalidParameterError) as info:
        Coefficients(**values)  # type: ignore[arg-type]
    assert info.value.field == f"coefficients.{field}"
    message = str(info.value)
    assert f"coefficients.{field}" in message
    assert ">= 0" in message and "finite" in message


finite_non_negative = st.floats(min_value=0.0, allow_nan=False, allow_infinity=False)
negative = st.floats(max_value=-1e-300, allow_infinity=False)
bad_value = st.one_of(negative, st.just(math.nan), st.just(math.inf), st.just(-math.inf))


@given(st.tuples(*[finite_non_negative] * 4))
def test_any_finite_non_negative_quadruple_is_accepted(values: tuple[float, ...]) -> None:
    c = Coefficients(*values)
    assert as_tuple(c) == values


@given(
    st.tuples(*[finite_non_negative] * 4),
    st.sampled_from(range(4)),
    bad_value,
)
def test_one_negative_or_nan_value_is_rejected_by_name(
    values: tuple[float, ...], index: int, bad: float
) -> None:
    mutated = list(values)
    mutated[index] = bad
    with pytest.raises(InvalidParameterError) as info:
        Coefficients(*mutated)
    assert info.value.field == f"coefficients.{FIELDS[index]}"


# ------------------------------------------------------------------------------------------
# Table 3.4


def test_table_3_4_angles() -> None:
    assert tuple(co.TABLE_3_4_Q_DEG) == (0, 5, 15, 25, 35, 45, 55, 65, 75, 85)
    assert sorted(table_3_4_csv()) == list(co.TABLE_3_4_Q_DEG)


def test_table_3_4_at_45_is_the_csv_row() -> None:
    c, row = co.table_3_4(45)
    assert row == 45.0
    assert as_tuple(c) == (5.5, 11.0, 53.0, 0.25)
    assert as_tuple(c) == table_3_4_csv()[45.0]


@pytest.mark.parametrize("q", [0, 5, 15, 25, 35, 45, 55, 65, 75, 85])
def test_table_3_4_every_row_is_the_csv_row(q: int) -> None:
    c, row = co.table_3_4(q)
    assert row == q
    assert as_tuple(c) == table_3_4_csv()[float(q)]
    c_neg, row_neg = co.table_3_4(-q)
    assert (c_neg, row_neg) == (c, row)


@pytest.mark.parametrize(
    ("q", "row"),
    [
        (44, 45),
        (-44, 45),
        (49.9, 45),
        (50.1, 55),
        (1, 0),
        (2.4, 0),
        (89, 85),
        (90, 85),
        (-90, 85),
        (80.1, 85),
        (79.9, 75),
    ],
)
def test_table_3_4_uses_the_nearest_row(q: float, row: float) -> None:
    c, used = co.table_3_4(q)
    assert used == row
    assert as_tuple(c) == table_3_4_csv()[float(row)]


@pytest.mark.parametrize(
    ("q", "row"),
    [(2.5, 5), (10, 15), (20, 25), (30, 35), (40, 45), (50, 55), (60, 65), (70, 75), (80, 85)],
)
def test_table_3_4_ties_go_to_the_larger_angle(q: float, row: float) -> None:
    assert co.table_3_4(q)[1] == row
    assert co.table_3_4(-q)[1] == row


@given(st.floats(min_value=-90.0, max_value=90.0))
def test_table_3_4_row_is_nearest_and_symmetric(q: float) -> None:
    c, row = co.table_3_4(q)
    distance = abs(abs(q) - row)
    for other in co.TABLE_3_4_Q_DEG:
        d_other = abs(abs(q) - other)
        assert distance < d_other or (distance == d_other and row >= other)
    assert co.table_3_4(-q) == (c, row)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, 90.001, -120.0, True, "45", None])
def test_table_3_4_rejects_bad_angles(bad: object) -> None:
    with pytest.raises(InvalidParameterError) as info:
        co.table_3_4(bad)  # type: ignore[arg-type]
    assert info.value.field == "q_deg"


# ------------------------------------------------------------------------------------------
# Table 3.2


def test_table_3_2_check_values_of_model_md() -> None:
    """MODEL.md: alpha = 90 deg, rho_g = 1650 gives about 6.69, 15.8, 259, 0.105."""
    c = co.table_3_2(0.0)
    assert as_tuple(c) == pytest.approx((6.69, 15.8, 259.0, 0.105), rel=1e-2)
    assert as_tuple(co.table_3_2(0.0, rho_g=1650.0)) == as_tuple(c)


def test_table_3_2_restored_35_row_matches_table_3_4() -> None:
    """The alpha = 35 row (q = 55) is restored from the 25 row; it matches Table 3.4.

    With the alpha = 55/45 forms instead, eta_v would be about 14, not about 57.
    """
    c = co.table_3_2(55.0)
    assert as_tuple(c) == pytest.approx(table_3_4_csv()[55.0], rel=0.15)


@pytest.mark.parametrize(
    ("q", "form"),
    [
        (0.0, form_a),
        (5.0, form_a),
        (10.0, form_a),
        (15.0, form_a),
        (19.99, form_a),
        (20.0, form_b),  # alpha 70: halfway between 75 and 65 -> larger |q|
        (25.0, form_b),
        (29.99, form_b),
        (30.0, form_c),  # alpha 60: between 65 and 55
        (35.0, form_c),
        (44.0, form_c),
        (45.0, form_c),
        (49.99, form_c),
        (50.0, form_d),  # alpha 40: between 45 and 35
        (55.0, form_d),
        (65.0, form_d),
        (69.99, form_d),
        (70.0, form_e),  # alpha 20: between 25 and 15
        (75.0, form_e),
        (85.0, form_e),
        (89.9, form_e),
    ],
)
def test_table_3_2_band_and_form(q: float, form: Form) -> None:
    for angle in (q, -q):
        got = as_tuple(co.table_3_2(angle))
        assert got == pytest.approx(expected_3_2(form, q), rel=1e-12)


def test_table_3_2_forms_differ_across_each_edge() -> None:
    """Guards the band tests: the forms on either side of each edge really differ."""
    for q, below, above in [(20, form_a, form_b), (30, form_b, form_c), (50, form_c, form_d)]:
        assert expected_3_2(below, q) != pytest.approx(expected_3_2(above, q), rel=1e-3)
    assert expected_3_2(form_d, 70) != pytest.approx(expected_3_2(form_e, 70), rel=1e-3)


@given(
    st.floats(min_value=-89.99, max_value=89.99),
    st.floats(min_value=1.0, max_value=5000.0),
)
def test_table_3_2_is_linear_in_rho_for_eta_h_and_lambda(q: float, rho: float) -> None:
    base = co.table_3_2(q, rho_g=1000.0)
    scaled = co.table_3_2(q, rho_g=rho)
    factor = rho / 1000.0
    assert scaled.eta_h == pytest.approx(base.eta_h * factor, rel=1e-9)
    assert scaled.lam == pytest.approx(base.lam * factor, rel=1e-9)
    assert co.table_3_2(-q, rho_g=rho) == scaled


@pytest.mark.parametrize("bad", [90.0, -90.0, 95.0, math.nan, math.inf, -math.inf, True, "0"])
def test_table_3_2_rejects_bad_angles(bad: object) -> None:
    with pytest.raises(InvalidParameterError) as info:
        co.table_3_2(bad)  # type: ignore[arg-type]
    assert info.value.field == "q_deg"


@pytest.mark.parametrize("bad", [0.0, -1650.0, math.nan, math.inf, True, "1650", None])
def test_table_3_2_rejects_bad_density(bad: object) -> None:
    with pytest.raises(InvalidParameterError) as info:
        co.table_3_2(10.0, rho_g=bad)  # type: ignore[arg-type]
    assert info.value.field == "rho_g"


# ------------------------------------------------------------------------------------------
# resolve


def test_resolve_table_3_4() -> None:
    c, source = co.resolve("table_3_4", 44.0)
    assert as_tuple(c) == table_3_4_csv()[45.0]
    assert source == "Table 3.4, row q = 45 deg (nearest to q = 44 deg)"
    c_exact, source_exact = co.resolve("table_3_4", 45)
    assert c_exact == c
    assert source_exact == "Table 3.4, row q = 45 deg"
    c_neg, source_neg = co.resolve("table_3_4", -44.0)
    assert c_neg == c
    assert "row q = 45 deg" in source_neg and "-44" in source_neg


def test_resolve_table_3_2() -> None:
    c, source = co.resolve("table_3_2", 44.0, rho_g=1600.0)
    assert as_tuple(c) == pytest.approx(expected_3_2(form_c, 44.0, 1600.0), rel=1e-12)
    assert source.startswith("Table 3.2 closed form, band alpha 55/45, at q = 44 deg")
    assert "rho_g = 1600" in source
    assert "band alpha 90/85/75" in co.resolve("table_3_2", 0.0)[1]
    assert "band alpha 65," in co.resolve("table_3_2", 20.0)[1]
    assert "band alpha 15/5" in co.resolve("table_3_2", -80.0)[1]


def test_resolve_user_coefficients() -> None:
    given_c = Coefficients(1.0, 2.0, 3.0, 0.5)
    c, source = co.resolve(given_c, 30.0)
    assert c is given_c
    assert "user" in source
    c_map, _ = co.resolve({"eta_h": 1, "eta_d": 2, "eta_v": 3, "lam": 0.5}, 30.0)
    assert c_map == given_c
    c_lambda, _ = co.resolve({"eta_h": 1, "eta_d": 2, "eta_v": 3, "lambda": 0.5}, 30.0)
    assert c_lambda == given_c


@pytest.mark.parametrize("bad", ["table_3_3", "Table 3.4", "", "table_3_4_free_link_coefficients"])
def test_resolve_rejects_unknown_names(bad: str) -> None:
    with pytest.raises(UnknownNameError) as info:
        co.resolve(bad, 10.0)
    assert info.value.field == "coefficients"
    assert "table_3_4" in str(info.value) and "table_3_2" in str(info.value)


@pytest.mark.parametrize("bad", [42, None, 1.5, [1.0, 2.0, 3.0, 0.5], (1.0, 2.0, 3.0, 0.5)])
def test_resolve_rejects_wrong_types(bad: object) -> None:
    with pytest.raises(InvalidParameterError) as info:
        co.resolve(bad, 10.0)  # type: ignore[arg-type]
    assert not isinstance(info.value, UnknownNameError)
    assert info.value.field == "coefficients"


@pytest.mark.parametrize(
    "bad",
    [
        {"eta_h": 1, "eta_d": 2, "eta_v": 3},
        {"eta_h": 1, "eta_d": 2, "eta_v": 3, "lam": 0.5, "rho": 1650},
        {"eta_h": 1, "eta_d": 2, "eta_v": 3, "lam": 0.5, "lambda": 0.5},
        {},
    ],
)
def test_resolve_rejects_mappings_with_wrong_keys(bad: dict[str, float]) -> None:
    with pytest.raises(InvalidParameterError) as info:
        co.resolve(bad, 10.0)
    assert info.value.field == "coefficients"


def test_resolve_mapping_values_are_validated() -> None:
    with pytest.raises(InvalidParameterError) as info:
        co.resolve({"eta_h": 1, "eta_d": 2, "eta_v": -3, "lam": 0.5}, 10.0)
    assert info.value.field == "coefficients.eta_v"


@pytest.mark.parametrize(
    ("spec", "q", "field"), [("table_3_4", math.nan, "q_deg"), ("table_3_2", 90.0, "q_deg")]
)
def test_resolve_passes_angle_errors_on(spec: str, q: float, field: str) -> None:
    with pytest.raises(InvalidParameterError) as info:
        co.resolve(spec, q)
    assert info.value.field == field


def test_resolve_passes_density_errors_on() -> None:
    with pytest.raises(InvalidParameterError) as info:
        co.resolve("table_3_2", 10.0, rho_g=-1.0)
    assert info.value.field == "rho_g"


# ------------------------------------------------------------------------------------------
# load_table

GOOD_CSV = (
    "q_deg,eta_h,eta_d,eta_v,lambda,comment\n0,6.5,15.2,248,0.106,first\n\n45,5.5,11,53,0.25,\n"
)


def test_load_table_reads_a_good_file(tmp_path: Path) -> None:
    path = tmp_path / "good.csv"
    path.write_text(GOOD_CSV, encoding="utf-8")
    table = co.load_table(path)
    assert list(table) == [0.0, 45.0]
    assert table[0.0] == Coefficients(6.5, 15.2, 248.0, 0.106)
    assert table[45.0] == Coefficients(5.5, 11.0, 53.0, 0.25)
    assert co.load_table(str(path)) == table
    assert co.load_table(io.StringIO(GOOD_CSV)) == table


def test_load_table_of_the_shipped_table_3_4_matches_table_3_4() -> None:
    table = co.load_table(TABLE_3_4_CSV)
    for q, c in table.items():
        assert co.table_3_4(q) == (c, q)


def test_load_table_accepts_a_byte_order_mark_and_padded_header(tmp_path: Path) -> None:
    path = tmp_path / "bom.csv"
    path.write_text("\ufeffq_deg, eta_h ,eta_d,eta_v,lambda\n5,1,2,3,0.1\n", encoding="utf-8")
    assert co.load_table(path) == {5.0: Coefficients(1.0, 2.0, 3.0, 0.1)}


@pytest.mark.parametrize("missing", ["q_deg", "eta_h", "eta_d", "eta_v", "lambda"])
def test_load_table_missing_column(tmp_path: Path, missing: str) -> None:
    columns = ["q_deg", "eta_h", "eta_d", "eta_v", "lambda"]
    values = ["0", "1", "2", "3", "0.1"]
    keep = [i for i, c in enumerate(columns) if c != missing]
    path = tmp_path / "missing.csv"
    path.write_text(
        ",".join(columns[i] for i in keep) + "\n" + ",".join(values[i] for i in keep) + "\n",
        encoding="utf-8",
    )
    with pytest.raises(CoefficientTableError) as info:
        co.load_table(path)
    assert info.value.field == missing
    message = str(info.value)
    assert "missing.csv" in message and "row 1" in message and repr(missing) in message


@pytest.mark.parametrize(
    ("column", "cell"),
    [("eta_d", "abc"), ("eta_h", ""), ("lambda", "1,5"), ("q_deg", "ten"), ("eta_v", "3 N")],
)
def test_load_table_cell_not_a_number(tmp_path: Path, column: str, cell: str) -> None:
    row = {"q_deg": "15", "eta_h": "1", "eta_d": "2", "eta_v": "3", "lambda": "0.1"}
    row[column] = cell
    path = tmp_path / "notnumber.csv"
    with open(path, "w", encoding="utf-8", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(row))
        writer.writeheader()
        writer.writerow({"q_deg": "0", "eta_h": "1", "eta_d": "2", "eta_v": "3", "lambda": "0.1"})
        writer.writerow(row)
    with pytest.raises(CoefficientTableError) as info:
        co.load_table(path)
    assert info.value.field == column
    message = str(info.value)
    assert "notnumber.csv" in message and "row 3" in message and repr(column) in message


def test_load_table_short_row(tmp_path: Path) -> None:
    path = tmp_path / "short.csv"
    path.write_text("q_deg,eta_h,eta_d,eta_v,lambda\n0,1,2,3\n", encoding="utf-8")
    with pytest.raises(CoefficientTableError) as info:
        co.load_table(path)
    assert info.value.field == "lambda"
    assert "row 2" in str(info.value)


@pytest.mark.parametrize(
    ("column", "value"),
    [
        ("eta_v", "-3"),
        ("eta_h", "-0.5"),
        ("eta_d", "nan"),
        ("lambda", "-0.1"),
        ("lambda", "inf"),
        ("q_deg", "nan"),
        ("q_deg", "95"),
    ],
)
def test_load_table_invalid_value(tmp_path: Path, column: str, value: str) -> None:
    row = {"q_deg": "25", "eta_h": "1", "eta_d": "2", "eta_v": "3", "lambda": "0.1"}
    row[column] = value
    path = tmp_path / "invalid.csv"
    path.write_text(
        "q_deg,eta_h,eta_d,eta_v,lambda\n0,1,2,3,0.1\n5,1,2,3,0.1\n" + ",".join(row.values()),
        encoding="utf-8",
    )
    with pytest.raises(CoefficientTableError) as info:
        co.load_table(path)
    assert info.value.field == column
    message = str(info.value)
    assert "invalid.csv" in message and "row 4" in message and repr(column) in message


def test_load_table_duplicate_angle(tmp_path: Path) -> None:
    path = tmp_path / "dup.csv"
    path.write_text("q_deg,eta_h,eta_d,eta_v,lambda\n5,1,2,3,0.1\n5.0,1,2,3,0.2\n", "utf-8")
    with pytest.raises(CoefficientTableError) as info:
        co.load_table(path)
    assert info.value.field == "q_deg"
    assert "row 3" in str(info.value)


@pytest.mark.parametrize("text", ["", "q_deg,eta_h,eta_d,eta_v,lambda\n"])
def test_load_table_without_rows(tmp_path: Path, text: str) -> None:
    path = tmp_path / "empty.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(CoefficientTableError) as info:
        co.load_table(path)
    assert info.value.field is None
    assert "empty.csv" in str(info.value)


def test_load_table_errors_are_value_errors(tmp_path: Path) -> None:
    """CoefficientTableError is a ValueError, so generic callers can catch it."""
    path = tmp_path / "bad.csv"
    path.write_text("q_deg,eta_h\n0,1\n", encoding="utf-8")
    with pytest.raises(ValueError):
        co.load_table(path)


def test_module_exports() -> None:
    for name in (
        "Coefficients",
        "TABLE_3_4_Q_DEG",
        "load_table",
        "resolve",
        "table_3_2",
        "table_3_4",
    ):
        assert name in co.__all__
        assert hasattr(co, name)
    assert co.__doc__ is not None
    for citation in ("Table 3.2", "Table 3.4", "section 3.3"):
        assert citation in co.__doc__
