"""Measurements to calibrate against: the thesis's tables or a CSV, checked on load
(:class:`~granrs.errors.MeasurementError` names the file, line and column), with the
sd each quantity gets in the fit.
"""

from __future__ import annotations

import csv
import difflib
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from .. import data
from ..errors import (
    InvalidParameterError,
    MeasurementError,
    UnknownNameError,
)

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["BODIES", "QUANTITIES", "THESIS_MEASUREMENTS", "THESIS_RESOLUTION", "Measurements"]

#: The bodies :func:`calibrate` can fit: the thesis's, each built by the function of
#: :mod:`granrs.cases` of the same name, and ``"space"``, bodies in space, each row's
#: :class:`granrs.space.Scene` made by a function of the row that the caller gives.
BODIES: tuple[str, ...] = ("free_link", "chain", "leg", "space")
#: The measured quantities: depth at the stop [m] and stopping time [s].
QUANTITIES: tuple[str, ...] = ("depth", "t_s")
#: Columns every measurement table has (besides the body's own, see :data:`_KEY_COLUMNS`).
_VALUE_COLUMNS: tuple[str, ...] = ("t_s_mean", "t_s_sd", "depth_mean", "depth_sd")
#: The columns that say which run a row is, per body.
_KEY_COLUMNS: dict[str, tuple[str, ...]] = {
    "free_link": ("q_deg", "v0_mean"),
    "chain": ("link", "v0_case", "q0_deg", "v0_mean"),
    "leg": ("v0_mean",),
    # Bodies in space: the columns the caller's function of the row reads.
    "space": (),
}
#: The thesis's measurements by name: (body, data table, what the rows are).
THESIS_MEASUREMENTS: dict[str, tuple[str, str, str]] = {
    "table_3_1": ("free_link", "table_3_1", "Table 3.1: the free link, 4 angles x 3 speeds"),
    "table_4_chain": (
        "chain",
        "chain_experiments",
        "Tables 4.1-4.2: the chain, 3 cases x 2 links",
    ),
    "table_5_1": ("leg", "table_5_1", "Table 5.1: 5 subjects x 2 heights"),
    "table_5_1_means": (
        "leg",
        "table_5_1",
        "Table 5.1 averaged per height: mean and sd across the 5 subjects' means",
    ),
}
#: The rounding of the thesis's printed means: 1 mm and 1 ms.
THESIS_RESOLUTION: dict[str, float] = {"depth": 0.001, "t_s": 0.001}


# --------------------------------------------------------------------------------------------
# Measurements


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


@dataclass(frozen=True)
class Measurements:
    """Measured depths and stopping times with their spread, one row per measured case.

    Attributes:
        body: ``"free_link"``, ``"chain"``, ``"leg"`` or ``"space"`` (bodies in space):
            what the rows were measured on.
        rows: one row per case: the body's key columns (free link: ``q_deg`` [deg],
            ``v0_mean`` [m/s]; chain: ``link`` (1 or 2), ``v0_case``, ``q0_deg`` [deg],
            ``v0_mean`` [m/s], one row per link; leg: ``v0_mean`` [m/s]; space: whatever
            the function that makes each row's scene reads), then
            ``t_s_mean``, ``t_s_sd`` [s], ``depth_mean``, ``depth_sd`` [m], and any other
            columns of the source (ignored).
        source: where the rows come from (a thesis table or a file name).
        resolution: the rounding of the printed means, by quantity [m, s]: added in
            quadrature to the sd of the fit (see the module's notes); 0 for none.
    """

    body: str
    rows: pd.DataFrame
    source: str
    resolution: Mapping[str, float] = field(default_factory=lambda: {"depth": 0.0, "t_s": 0.0})

    def __post_init__(self) -> None:
        if self.body not in BODIES:
            raise UnknownNameError(
                f"unknown body {self.body!r}; measurements fit one of {', '.join(BODIES)}",
                field="body",
            )
        for q in QUANTITIES:
            r = self.resolution.get(q, 0.0)
            if not _is_number(r) or not math.isfinite(r) or r < 0:
                raise InvalidParameterError(
                    f"resolution[{q!r}] must be a finite number >= 0 [m or s]; got {r!r}",
                    field="resolution",
                )

    def __len__(self) -> int:
        return len(self.rows)

    @classmethod
    def thesis(cls, name: str = "table_3_1") -> Measurements:
        """The thesis's measurements: ``"table_3_1"`` (free link), ``"table_4_chain"``
        (chain), ``"table_5_1"`` (the leg, per subject and height) or ``"table_5_1_means"``
        (the leg: per height, the mean and sd across the subjects' means). The means are
        printed to 1 mm and 1 ms: ``resolution`` is set to that."""
        import pandas as pd

        if name not in THESIS_MEASUREMENTS:
            hint = difflib.get_close_matches(str(name), list(THESIS_MEASUREMENTS), n=1)
            more = f"; did you mean {hint[0]!r}?" if hint else ""
            raise UnknownNameError(
                f"unknown thesis measurements {name!r}{more} "
                f"(available: {', '.join(THESIS_MEASUREMENTS)})",
                field="measurements",
            )
        body, table, what = THESIS_MEASUREMENTS[name]
        rows = data.load(table)
        if name == "table_5_1_means":
            groups = []
            for height, g in rows.groupby("height_case", sort=True):
                groups.append(
                    {
                        "height_case": height,
                        "v0_mean": g["v0_mean"].mean(),
                        "v0_sd": g["v0_mean"].std(ddof=1),
                        "t_s_mean": g["t_s_mean"].mean(),
                        "t_s_sd": g["t_s_mean"].std(ddof=1),
                        "depth_mean": g["depth_mean"].mean(),
                        "depth_sd": g["depth_mean"].std(ddof=1),
                        "subjects": len(g),
                    }
                )
            rows = pd.DataFrame(groups)
        _check_frame(rows, body, f"thesis {name}")
        return cls(body, rows.reset_index(drop=True), f"thesis {what}", dict(THESIS_RESOLUTION))

    @classmethod
    def from_csv(
        cls,
        path_or_file: str | os.PathLike[str] | IO[str],
        body: str = "free_link",
        resolution: Mapping[str, float] | None = None,
    ) -> Measurements:
        """Read measurements from a CSV file with the columns of the thesis's table for
        ``body`` (see :attr:`rows`; other columns are kept and ignored).

        Raises :class:`~granrs.errors.MeasurementError` naming the file, the row (the line of
        the file; the header is line 1) and the column when a column is missing, a cell is
        not a number, a mean is not finite and > 0 or an sd is not finite and >= 0, a chain
        case lacks one of its links, or the file has no rows. ``resolution`` (default: none)
        as in :attr:`resolution`.
        """
        if body not in BODIES:
            raise UnknownNameError(
                f"unknown body {body!r}; measurements fit one of {', '.join(BODIES)}",
                field="body",
            )
        if isinstance(path_or_file, (str, os.PathLike)):
            name = os.fspath(path_or_file)
            try:
                with open(name, encoding="utf-8-sig", newline="") as handle:
                    rows = _read_csv(handle, name, body)
            except OSError as error:
                raise MeasurementError(
                    f"cannot read measurements {name}: {error.strerror or error}",
                    field="measurements",
                ) from None
        else:
            name = str(getattr(path_or_file, "name", "<file>"))
            rows = _read_csv(path_or_file, name, body)
        res = {"depth": 0.0, "t_s": 0.0}
        res.update(resolution or {})
        return cls(body, rows, name, res)

    @classmethod
    def load(cls, spec: str | os.PathLike[str], body: str | None = None) -> Measurements:
        """``"thesis:NAME"`` or a thesis name (see :meth:`thesis`), or a CSV path read with
        :meth:`from_csv` for ``body`` (default ``"free_link"``)."""
        text = os.fspath(spec)
        name = text.removeprefix("thesis:")
        if text.startswith("thesis:") or name in THESIS_MEASUREMENTS:
            m = cls.thesis(name)
            if body is not None and body != m.body:
                raise InvalidParameterError(
                    f"thesis {name} measures the {m.body}, not the {body}", field="body"
                )
            return m
        return cls.from_csv(text, body or "free_link")

    def subset(self, mask: Any = None, **columns: Any) -> Measurements:
        """The rows where ``mask`` (a boolean array) holds and every ``column=values`` matches
        (one value or a list), e.g. ``subset(q_deg=[0, 45, 75])``."""
        keep = np.ones(len(self.rows), dtype=bool)
        if mask is not None:
            keep &= np.asarray(mask, dtype=bool)
        for name, values in columns.items():
            if name not in self.rows.columns:
                hint = difflib.get_close_matches(name, list(self.rows.columns), n=1)
                more = f"; did you mean {hint[0]!r}?" if hint else ""
                raise UnknownNameError(f"measurements have no column {name!r}{more}", field=name)
            vals = list(values) if isinstance(values, (list, tuple, set, np.ndarray)) else [values]
            keep &= self.rows[name].isin(vals).to_numpy()
        return Measurements(
            self.body, self.rows[keep].reset_index(drop=True), self.source, dict(self.resolution)
        )

    def sd_fit(self, quantity: str) -> np.ndarray:
        """The sd of ``quantity`` used as the fit's weight: measured sd and rounding in
        quadrature [m or s]."""
        sd = self.rows[f"{quantity}_sd"].to_numpy(dtype=float)
        r = float(self.resolution.get(quantity, 0.0))
        return np.sqrt(sd**2 + r**2 / 12.0)


def _check_frame(rows: pd.DataFrame, body: str, name: str) -> None:
    """The checks of :func:`_read_csv` on a frame (for the shipped tables)."""
    for column in (*_KEY_COLUMNS[body], *_VALUE_COLUMNS):
        if column not in rows.columns:
            raise MeasurementError(f"{name}: missing column {column!r}", field=column)


def _read_csv(handle: IO[str], filename: str, body: str) -> pd.DataFrame:
    import pandas as pd

    required = (*_KEY_COLUMNS[body], *_VALUE_COLUMNS)
    try:
        reader = csv.DictReader(handle, strict=True)
        if reader.fieldnames is None:
            raise MeasurementError(f"{filename}: the file is empty", field="measurements")
        reader.fieldnames = [name.strip() for name in reader.fieldnames]
        for column in required:
            if column not in reader.fieldnames:
                raise MeasurementError(
                    f"{filename}, row 1 (header): missing column {column!r}; the {body} needs "
                    f"{', '.join(required)}",
                    field=column,
                )
        records: list[dict[str, Any]] = []
        for record in reader:
            row = reader.line_num
            if not any((v or "").strip() for v in record.values() if isinstance(v, str)):
                continue
            out: dict[str, Any] = {k: v for k, v in record.items() if k is not None}
            for column in required:
                cell = record.get(column)
                try:
                    value = float((cell or "").strip())
                except ValueError:
                    raise MeasurementError(
                        f"{filename}, row {row}, column {column!r}: {cell!r} is not a number",
                        field=column,
                    ) from None
                bad = not math.isfinite(value)
                if column.endswith("_sd"):
                    bad = bad or value < 0.0
                    what = "a finite sd >= 0"
                elif column in ("t_s_mean", "depth_mean", "v0_mean"):
                    bad = bad or value <= 0.0
                    what = "a finite mean > 0"
                elif column == "link":
                    bad = bad or value not in (1.0, 2.0)
                    what = "1 or 2"
                else:
                    what = "finite"
                if column in ("q_deg", "q0_deg") and not bad and abs(value) >= 90.0:
                    bad, what = True, "an angle with |q| < 90 deg"
                if bad:
                    raise MeasurementError(
                        f"{filename}, row {row}, column {column!r}: {cell!r} must be {what}",
                        field=column,
                    )
                out[column] = value
            out["_line"] = row
            records.append(out)
    except UnicodeDecodeError as error:
        raise MeasurementError(
            f"{filename}: not a UTF-8 text file ({error})", field="measurements"
        ) from error
    except csv.Error as error:
        raise MeasurementError(
            f"{filename}: not a valid CSV file ({error})", field="measurements"
        ) from error
    if not records:
        raise MeasurementError(f"{filename}: no data rows", field="measurements")
    frame = pd.DataFrame(records)
    if body == "chain":
        for case, g in frame.groupby("v0_case"):
            links = sorted(g["link"])
            if links != [1.0, 2.0]:
                raise MeasurementError(
                    f"{filename}, row {int(g['_line'].iloc[0])}, column 'link': chain case "
                    f"{case:g} needs one row for link 1 and one for link 2; got links {links}",
                    field="link",
                )
    return frame.drop(columns="_line")
