"""The coefficients of the granular resistance force: eta_h, eta_d, eta_v and lambda.

Source: the thesis "Bipedal impact with granular matter", section 3.3 (the force model, eqs.
3.1-3.3 and 3.16-3.20, with the coefficients of section 3.3.1) and section 3.4. The force on
one contact is (the model's page of the docs, ``docs/model.md``)::

    F_d  = - eta_d * rho_g * A_r * |v_E| * v_E                      (dynamic)
    F_sh = - sgn(v_Ex) * eta_h * g * rho_g * w * d^2                (static, horizontal)
    F_sv = - sgn(v_Ey) * eta_v * (d / L)^lambda * g * rho_g * V     (static, vertical)

so all four coefficients are dimensionless. The thesis gives them two ways, and granrs keeps
both and never mixes them silently:

* Table 3.4 (:func:`table_3_4`): the values actually used in its free-link runs, tuned by hand,
  at q = 0, 5, 15, ..., 85 degrees (read from the shipped ``table_3_4`` CSV, see
  :mod:`granrs.data`).
* Table 3.2 (:func:`table_3_2`): closed forms in the impact angle and the sand density
  rho_g, piecewise by angle band, from which Table 3.4 was tuned.

q is the angle of the body's axis from the vertical and alpha = pi/2 - |q| its angle from the
horizontal. Both tables are symmetric in the sign of q (the thesis uses alpha =
pi/2 - abs(q) for negative angles, section 4.3.1), so only |q| matters.

:func:`resolve` turns a user's choice (a table name, a :class:`Coefficients` or a mapping)
into coefficients plus a sentence saying where they come from; :func:`load_table` reads a
user's own table from CSV.
"""

from __future__ import annotations

import csv
import functools
import math
import numbers
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import IO, Any, TypeGuard

from . import data
from .errors import CoefficientTableError, InvalidParameterError, UnknownNameError

__all__ = [
    "DEFAULT_RHO_G",
    "TABLE_3_2_ALPHA_DEG",
    "TABLE_3_4_Q_DEG",
    "Coefficients",
    "load_table",
    "resolve",
    "table_3_2",
    "table_3_4",
]

#: Bulk density of the thesis's play sand, packing included, kg/m^3 (thesis section 3.3.1;
#: ``bodies.csv``). The default ``rho_g`` of :func:`table_3_2`.
DEFAULT_RHO_G: float = 1650.0

#: The angles q from the vertical, in degrees, of the rows of Table 3.4.
TABLE_3_4_Q_DEG: tuple[float, ...] = (0.0, 5.0, 15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0, 85.0)

#: The angles alpha from the horizontal, in degrees, of the rows of Table 3.2.
TABLE_3_2_ALPHA_DEG: tuple[float, ...] = (90.0, 85.0, 75.0, 65.0, 55.0, 45.0, 35.0, 25.0, 15.0, 5.0)

_FIELDS = ("eta_h", "eta_d", "eta_v", "lam")
_CSV_COLUMNS = {"eta_h": "eta_h", "eta_d": "eta_d", "eta_v": "eta_v", "lam": "lambda"}


def _is_real(value: object) -> TypeGuard[numbers.Real]:
    """A real number that is not a bool (numpy scalars included)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


@dataclass(frozen=True)
class Coefficients:
    """The four dimensionless coefficients of the resistance force, as in the thesis's
    equations 3.1-3.3: eta_h, eta_d, eta_v and lambda.

    Attributes:
        eta_h: scaling constant of the horizontal static force F_sh, dimensionless, >= 0.
        eta_d: scaling constant of the dynamic (drag) force F_d, dimensionless, >= 0.
        eta_v: scaling constant of the vertical static force F_sv, dimensionless, >= 0.
        lam: the exponent lambda of the depth power law (d / L)^lambda in F_sv,
            dimensionless, >= 0.

    Values are stored as Python floats. Each must be a finite real number (not a bool);
    otherwise :class:`~granrs.errors.InvalidParameterError` is raised with
    ``field="coefficients.<name>"``.
    """

    eta_h: float
    eta_d: float
    eta_v: float
    lam: float

    def __post_init__(self) -> None:
        for name in _FIELDS:
            value = getattr(self, name)
            field = f"coefficients.{name}"
            allowed = "a finite real number >= 0"
            if not _is_real(value):
                raise InvalidParameterError(
                    f"{field} must be {allowed}, got {value!r} of type {type(value).__name__}",
                    field=field,
                )
            try:
                number = float(value)
            except OverflowError:  # an int beyond the floats, e.g. 10**400
                number = math.inf
            if not math.isfinite(number) or number < 0.0:
                raise InvalidParameterError(
                    f"{field} must be {allowed}, got {value!r}", field=field
                )
            object.__setattr__(self, name, number)

    def as_dict(self) -> dict[str, float]:
        """``{"eta_h": ..., "eta_d": ..., "eta_v": ..., "lam": ...}`` (a new dict)."""
        return {"eta_h": self.eta_h, "eta_d": self.eta_d, "eta_v": self.eta_v, "lam": self.lam}


def _check_angle(q_deg: object, *, limit_deg: float, inclusive: bool) -> float:
    """|q_deg| as a float, or InvalidParameterError(field="q_deg")."""
    allowed = f"a finite angle in degrees with |q_deg| {'<=' if inclusive else '<'} {limit_deg:g}"
    if not _is_real(q_deg):
        raise InvalidParameterError(f"q_deg must be {allowed}, got {q_deg!r}", field="q_deg")
    q = abs(float(q_deg))
    if not math.isfinite(q) or q > limit_deg or (q == limit_deg and not inclusive):
        raise InvalidParameterError(f"q_deg must be {allowed}, got {q_deg!r}", field="q_deg")
    return q


def _nearest(value: float, grid: tuple[float, ...], *, ties_to_larger: bool) -> float:
    """The grid point nearest to ``value``; exactly halfway goes up (or down) as asked."""
    sign = -1.0 if ties_to_larger else 1.0
    return min(grid, key=lambda point: (abs(point - value), sign * point))


# --------------------------------------------------------------------------------------------
# Table 3.4


@functools.lru_cache(maxsize=1)
def _table_3_4_rows() -> dict[float, Coefficients]:
    table = data.load("table_3_4", as_="numpy")
    q_column = [float(q) for q in table["q_deg"]]
    if tuple(q_column) != TABLE_3_4_Q_DEG:
        raise CoefficientTableError(
            f"the shipped Table 3.4 has q_deg {q_column}, expected {list(TABLE_3_4_Q_DEG)}",
            field="q_deg",
        )
    rows: dict[float, Coefficients] = {}
    for i, q in enumerate(q_column):
        values = {name: float(table[column][i]) for name, column in _CSV_COLUMNS.items()}
        rows[q] = Coefficients(**values)
    return rows


def table_3_4(q_deg: float) -> tuple[Coefficients, float]:
    """The Table 3.4 row for the angle ``q_deg`` from the vertical, in degrees.

    Table 3.4 holds the coefficients the thesis used in its free-link runs (section 3.4), at
    q = 0, 5, 15, ..., 85 degrees (:data:`TABLE_3_4_Q_DEG`). The row at the tabulated angle
    nearest to |q_deg| is returned (the table is symmetric in the sign of q), with that
    tabulated angle in degrees (>= 0). Halfway between two rows (e.g. q = 10 between 5 and 15,
    q = 60 between 55 and 65) the row with the larger |q| is used. Values are not
    interpolated: the thesis tuned each row by hand and they are far from smooth in q.

    ``q_deg`` must be finite with |q_deg| <= 90 (a rod at or past horizontal is never
    tabulated, so 85 < |q| <= 90 uses the 85 row); otherwise
    :class:`~granrs.errors.InvalidParameterError` with ``field="q_deg"``.
    """
    q = _check_angle(q_deg, limit_deg=90.0, inclusive=True)
    row = _nearest(q, TABLE_3_4_Q_DEG, ties_to_larger=True)
    return _table_3_4_rows()[row], row


# --------------------------------------------------------------------------------------------
# Table 3.2

# A form maps (alpha, q, rho_g, eta_h) -> value, with alpha = pi/2 - |q| and q = |q| in
# radians, rho_g in kg/m^3; eta_h is ignored by the eta_h form itself.
_Form = Callable[[float, float, float, float], float]


@dataclass(frozen=True)
class _Band:
    """Rows of Table 3.2 that share one set of closed forms."""

    alphas_deg: tuple[float, ...]
    eta_h: _Form
    eta_d: _Form
    eta_v: _Form
    lam: _Form

    @property
    def label(self) -> str:
        return "/".join(f"{a:g}" for a in self.alphas_deg)


#: Table 3.2 of the thesis (section 3.3.1): the closed forms of eta_h, eta_d, eta_v and lambda,
#: in alpha = pi/2 - |q| and q = |q| (radians) and the sand density rho_g (kg/m^3), grouped by
#: the tabulated alphas (degrees) that share them. The alpha = 35 row is
#: shifted by one cell in the extracted source; it is restored to the alpha = 25 forms, which
#: match Table 3.4's alpha = 35 row.
_TABLE_3_2: tuple[_Band, ...] = (
    _Band(
        alphas_deg=(90.0, 85.0, 75.0),
        eta_h=lambda a, q, rho, h: rho / (100.0 * a**2),
        eta_d=lambda a, q, rho, h: 1.5 * h * a,
        eta_v=lambda a, q, rho, h: 10.0 * h * a**3,
        lam=lambda a, q, rho, h: 1e-4 * rho / a,
    ),
    _Band(
        alphas_deg=(65.0,),
        eta_h=lambda a, q, rho, h: rho / (100.0 * a**2),
        eta_d=lambda a, q, rho, h: 1.5 * h * a,
        eta_v=lambda a, q, rho, h: 10.0 * h * a**3,
        lam=lambda a, q, rho, h: 2e-4 * rho * a,
    ),
    _Band(
        alphas_deg=(55.0, 45.0),
        eta_h=lambda a, q, rho, h: rho * a**2 / 100.0,
        eta_d=lambda a, q, rho, h: (2.0 / 3.0) * h * q,
        eta_v=lambda a, q, rho, h: 10.0 * h * a**3,
        lam=lambda a, q, rho, h: 2e-4 * rho * a,
    ),
    _Band(
        alphas_deg=(35.0, 25.0),
        eta_h=lambda a, q, rho, h: rho * a**2 / 100.0,
        eta_d=lambda a, q, rho, h: (2.0 / 3.0) * h * q,
        eta_v=lambda a, q, rho, h: 10.0 * h * q**3,
        lam=lambda a, q, rho, h: 2e-4 * rho * a,
    ),
    _Band(
        alphas_deg=(15.0, 5.0),
        eta_h=lambda a, q, rho, h: rho * a**2 / 10.0,
        eta_d=lambda a, q, rho, h: (2.0 / 3.0) * h * a,
        eta_v=lambda a, q, rho, h: 10.0 * h * q**3,
        lam=lambda a, q, rho, h: 2e-4 * rho * q,
    ),
)

assert sorted(a for band in _TABLE_3_2 for a in band.alphas_deg) == sorted(TABLE_3_2_ALPHA_DEG)


def _table_3_2_band(q_abs_deg: float) -> _Band:
    """The band of the tabulated alpha nearest to 90 - |q| (ties: larger |q|, smaller alpha)."""
    alpha = _nearest(90.0 - q_abs_deg, TABLE_3_2_ALPHA_DEG, ties_to_larger=False)
    return next(band for band in _TABLE_3_2 if alpha in band.alphas_deg)


def _check_rho_g(rho_g: object) -> float:
    allowed = "a finite density in kg/m^3 > 0"
    if not _is_real(rho_g):
        raise InvalidParameterError(f"rho_g must be {allowed}, got {rho_g!r}", field="rho_g")
    rho = float(rho_g)
    if not math.isfinite(rho) or rho <= 0.0:
        raise InvalidParameterError(f"rho_g must be {allowed}, got {rho_g!r}", field="rho_g")
    return rho


def table_3_2(q_deg: float, rho_g: float = DEFAULT_RHO_G) -> Coefficients:
    """The Table 3.2 closed forms at the angle ``q_deg`` (degrees from the vertical).

    ``rho_g`` is the bulk density of the sand in kg/m^3 (default 1650, the thesis's play
    sand, section 3.3.1). The forms are evaluated at alpha = pi/2 - |q| and q = |q| in
    radians, as the thesis requires (section 3.3.1), at the actual angle.

    Table 3.2 gives the forms at alpha = 90, 85, 75, 65, 55, 45, 35, 25, 15, 5 degrees; they
    change between 75 and 65, 65 and 55, 45 and 35, 25 and 15. For any angle the forms of the
    nearest tabulated alpha are used, so the forms change at alpha = 70, 60, 40 and 20 degrees
    (|q| = 20, 30, 50, 70); exactly on such an edge the forms of the smaller alpha (the larger
    |q|) are used, as in :func:`table_3_4`. Beyond the table (alpha > 90 cannot happen;
    alpha < 5) the nearest row's forms are extrapolated.

    Check: at q = 0, rho_g = 1650 this gives eta_h, eta_d, eta_v, lambda of about
    6.69, 15.8, 259, 0.105, against Table 3.4's 6.5, 15.2, 248, 0.106.

    Raises :class:`~granrs.errors.InvalidParameterError` with ``field="q_deg"`` unless
    ``q_deg`` is finite with |q_deg| < 90, and with ``field="rho_g"`` unless ``rho_g`` is
    finite and > 0.
    """
    q_abs_deg = _check_angle(q_deg, limit_deg=90.0, inclusive=False)
    rho = _check_rho_g(rho_g)
    return _eval_table_3_2(_table_3_2_band(q_abs_deg), q_abs_deg, rho)


def _eval_table_3_2(band: _Band, q_abs_deg: float, rho: float) -> Coefficients:
    q = math.radians(q_abs_deg)
    alpha = math.pi / 2.0 - q
    eta_h = band.eta_h(alpha, q, rho, math.nan)
    return Coefficients(
        eta_h=eta_h,
        eta_d=band.eta_d(alpha, q, rho, eta_h),
        eta_v=band.eta_v(alpha, q, rho, eta_h),
        lam=band.lam(alpha, q, rho, eta_h),
    )


# --------------------------------------------------------------------------------------------
# resolve


def _from_mapping(spec: Mapping[Any, Any]) -> Coefficients:
    keys = set(spec)
    if "lambda" in keys and "lam" not in keys:
        keys = (keys - {"lambda"}) | {"lam"}
        spec = {("lam" if k == "lambda" else k): v for k, v in spec.items()}
    missing = [name for name in _FIELDS if name not in keys]
    extra = sorted(repr(k) for k in keys - set(_FIELDS))
    if missing or extra:
        problems = []
        if missing:
            problems.append(f"missing {', '.join(missing)}")
        if extra:
            problems.append(f"unexpected {', '.join(extra)}")
        raise InvalidParameterError(
            "coefficients given as a mapping must have exactly the keys eta_h, eta_d, eta_v, "
            f"lam ('lambda' is accepted for lam): {'; '.join(problems)}",
            field="coefficients",
        )
    return Coefficients(**{name: spec[name] for name in _FIELDS})


_TABLE_NAMES = ("table_3_4", "table_3_2")


def resolve(
    spec: str | Coefficients | Mapping[str, float],
    q_deg: float,
    rho_g: float = DEFAULT_RHO_G,
) -> tuple[Coefficients, str]:
    """Coefficients for a scene, and a human-readable sentence saying where they come from.

    ``spec`` is one of:

    * ``"table_3_4"``: :func:`table_3_4` at ``q_deg``, e.g.
      ``"Table 3.4, row q = 45 deg (nearest to q = 44 deg)"``;
    * ``"table_3_2"``: :func:`table_3_2` at ``q_deg`` and ``rho_g`` (kg/m^3), e.g.
      ``"Table 3.2 closed form, band alpha 55/45, at q = 44 deg, rho_g = 1650 kg/m^3"``;
    * a :class:`Coefficients`, used as given (``q_deg`` and ``rho_g`` are not used);
    * a mapping with exactly the keys ``eta_h``, ``eta_d``, ``eta_v``, ``lam`` (or ``lambda``),
      validated as :class:`Coefficients`.

    Raises :class:`~granrs.errors.UnknownNameError` (``field="coefficients"``) for any other
    string, :class:`~granrs.errors.InvalidParameterError` (``field="coefficients"``) for any
    other type or a mapping with wrong keys, and the errors of the chosen source for invalid
    ``q_deg``, ``rho_g`` or coefficient values.
    """
    if isinstance(spec, str):
        if spec == "table_3_4":
            coefficients, row = table_3_4(q_deg)
            q = float(q_deg)
            if q == row:
                where = ""
            elif q == -row:
                where = f" (for q = {q:g} deg: the table is symmetric in the sign of q)"
            elif q >= 0.0:
                where = f" (nearest to q = {q:g} deg)"
            else:
                where = f" (nearest to |q| = {-q:g} deg, for q = {q:g} deg)"
            return coefficients, f"Table 3.4, row q = {row:g} deg{where}"
        if spec == "table_3_2":
            coefficients = table_3_2(q_deg, rho_g)
            band = _table_3_2_band(abs(float(q_deg)))
            source = (
                f"Table 3.2 closed form, band alpha {band.label}, at q = {float(q_deg):g} deg, "
                f"rho_g = {float(rho_g):g} kg/m^3"
            )
            return coefficients, source
        raise UnknownNameError(
            f"unknown coefficient source {spec!r}; valid names are: {', '.join(_TABLE_NAMES)} "
            "(or pass a Coefficients or a mapping with eta_h, eta_d, eta_v, lam)",
            field="coefficients",
        )
    if isinstance(spec, Coefficients):
        values = ", ".join(f"{k} = {v:g}" for k, v in spec.as_dict().items())
        return spec, f"user coefficients ({values})"
    if isinstance(spec, Mapping):
        coefficients = _from_mapping(spec)
        values = ", ".join(f"{k} = {v:g}" for k, v in coefficients.as_dict().items())
        return coefficients, f"user coefficients ({values})"
    raise InvalidParameterError(
        "coefficients must be 'table_3_4', 'table_3_2', a Coefficients or a mapping with "
        f"eta_h, eta_d, eta_v, lam; got {type(spec).__name__}",
        field="coefficients",
    )


# --------------------------------------------------------------------------------------------
# load_table


def load_table(path_or_file: str | os.PathLike[str] | IO[str]) -> dict[float, Coefficients]:
    """Read a user's coefficient table from CSV: angle in degrees -> :class:`Coefficients`.

    The file needs a header with the columns ``q_deg`` (angle from the vertical, degrees,
    finite, |q_deg| <= 90, no duplicates), ``eta_h``, ``eta_d``, ``eta_v`` and ``lambda``
    (dimensionless, finite, >= 0); other columns are ignored, as are blank lines. The keys of
    the result are the ``q_deg`` values as floats, in file order. ``path_or_file`` is a path or
    an open text file.

    Raises :class:`~granrs.errors.CoefficientTableError` naming the file, the row (the line of
    the file; the header is line 1) and the column, with ``field`` the column name, when a
    column is missing, a cell does not parse as a number, or a value is invalid; and when the
    table has no data rows (``field=None``). Nothing partial is returned. A file that cannot
    be opened raises the usual :class:`OSError`.
    """
    if isinstance(path_or_file, (str, os.PathLike)):
        filename = os.fspath(path_or_file)
        with open(filename, encoding="utf-8-sig", newline="") as handle:
            return _read_table(handle, filename)
    filename = str(getattr(path_or_file, "name", "<file>"))
    return _read_table(path_or_file, filename)


def _read_table(handle: IO[str], filename: str) -> dict[float, Coefficients]:
    columns = ("q_deg", *_CSV_COLUMNS.values())
    try:
        reader = csv.DictReader(handle, strict=True)
        fieldnames = reader.fieldnames
        if fieldnames is None:
            raise CoefficientTableError(f"{filename}: the file is empty", field=None)
        reader.fieldnames = [name.strip() for name in fieldnames]
        header_row = reader.line_num
        for column in columns:
            if column not in reader.fieldnames:
                raise CoefficientTableError(
                    f"{filename}, row {header_row} (header): missing column {column!r}; "
                    f"required columns are {', '.join(columns)}",
                    field=column,
                )
        table: dict[float, Coefficients] = {}
        for record in reader:
            row = reader.line_num
            values: dict[str, float] = {}
            for column in columns:
                cell = record.get(column)
                try:
                    values[column] = float((cell or "").strip())
                except ValueError:
                    raise CoefficientTableError(
                        f"{filename}, row {row}, column {column!r}: {cell!r} is not a number",
                        field=column,
                    ) from None
            q = values["q_deg"]
            if not math.isfinite(q) or abs(q) > 90.0:
                raise CoefficientTableError(
                    f"{filename}, row {row}, column 'q_deg': {q!r} is not a finite angle "
                    "with |q_deg| <= 90",
                    field="q_deg",
                )
            if q in table:
                raise CoefficientTableError(
                    f"{filename}, row {row}, column 'q_deg': duplicate angle {q:g}",
                    field="q_deg",
                )
            try:
                table[q] = Coefficients(
                    **{name: values[column] for name, column in _CSV_COLUMNS.items()}
                )
            except InvalidParameterError as error:
                name = (error.field or "").removeprefix("coefficients.")
                column = _CSV_COLUMNS.get(name, name)
                raise CoefficientTableError(
                    f"{filename}, row {row}, column {column!r}: {values[column]!r} is invalid "
                    "(must be finite and >= 0)",
                    field=column,
                ) from error
    except UnicodeDecodeError as error:
        raise CoefficientTableError(f"{filename}: not a UTF-8 text file ({error})") from error
    except csv.Error as error:
        raise CoefficientTableError(f"{filename}: not a valid CSV file ({error})") from error
    if not table:
        raise CoefficientTableError(f"{filename}: the table has no data rows", field=None)
    return table
