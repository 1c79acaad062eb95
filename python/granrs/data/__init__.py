"""The thesis's tables, shipped with granrs as reference data.

Every table of the thesis that granrs implements ("Bipedal impact with granular matter") is
a CSV file in this package, re-read by hand from the extracted text, where the layout was
lost (shifted row labels, merged cells, missing rows). Doubtful values carry a ``note``
column. ``PROVENANCE.md`` next to the files is the full provenance; in short:

=============================================  ======================  ============================
file (stem)                                    short alias             thesis
=============================================  ======================  ============================
``bodies``                                     ``bodies``              sections 3.2.1, 4.1, 5.2-5.3
``table_3_1_free_link_experiments``            ``table_3_1``           Table 3.1
``table_3_4_free_link_coefficients``           ``table_3_4``           Table 3.4
``sweep_3_4_initial_velocities``               ``sweep_3_4``           section 3.4
``table_3_5_free_link_thesis_simulation``      ``table_3_5``           Table 3.5
``table_3_6_free_link_forces``                 ``table_3_6``           Table 3.6
``table_3_7_free_link_energy``                 ``table_3_7``           Table 3.7
``table_4_chain_experiments``                  ``chain_experiments``   Tables 4.1-4.2
``table_4_chain_coefficients_and_simulation``  ``chain_coefficients``  Tables 4.4-4.6
``table_5_1_human_experiments``                ``table_5_1``,          Table 5.1
                                               ``human_experiments``
``table_5_human_coefficients_and_simulation``  ``human_coefficients``  section 5.3.2
=============================================  ======================  ============================

All quantities are SI (m, s, kg, N, J), angles in degrees (columns named ``*_deg``).

The files are read at run time through :mod:`importlib.resources`, so they work from an
installed wheel (or a zip). Every function taking a ``name`` accepts a full stem, a short
alias, or a stem with ``.csv``; anything else raises
:class:`~granrs.errors.UnknownNameError` (``field="name"``) listing the valid names.
"""

from __future__ import annotations

import csv
import functools
import io
import math
import sys
from importlib import resources
from typing import TYPE_CHECKING, Literal, overload

import numpy as np

from ..errors import UnknownNameError

if TYPE_CHECKING:
    import pandas as pd

    if sys.version_info >= (3, 11):
        from importlib.resources.abc import Traversable
    else:
        from importlib.abc import Traversable

__all__ = ["aliases", "load", "names", "path", "provenance"]

_PROVENANCE_FILE = "PROVENANCE.md"

#: Short alias -> full file stem. Aliases are the table number before the first descriptive
#: word where that is unambiguous, and a descriptive name for the chapter 4 and 5 tables.
_ALIASES: dict[str, str] = {
    "table_3_1": "table_3_1_free_link_experiments",
    "table_3_4": "table_3_4_free_link_coefficients",
    "sweep_3_4": "sweep_3_4_initial_velocities",
    "table_3_5": "table_3_5_free_link_thesis_simulation",
    "table_3_6": "table_3_6_free_link_forces",
    "table_3_7": "table_3_7_free_link_energy",
    "chain_experiments": "table_4_chain_experiments",
    "chain_coefficients": "table_4_chain_coefficients_and_simulation",
    "table_5_1": "table_5_1_human_experiments",
    "human_experiments": "table_5_1_human_experiments",
    "human_coefficients": "table_5_human_coefficients_and_simulation",
}


def _files() -> Traversable:
    return resources.files(__name__)


@functools.lru_cache(maxsize=1)
def _stems() -> tuple[str, ...]:
    return tuple(
        sorted(
            entry.name[: -len(".csv")]
            for entry in _files().iterdir()
            if entry.is_file() and entry.name.endswith(".csv")
        )
    )


def names() -> list[str]:
    """The full stems of the shipped tables, sorted, e.g. ``"table_3_4_free_link_coefficients"``."""
    return list(_stems())


def aliases() -> dict[str, str]:
    """The short aliases, as a new dict alias -> full stem (e.g. ``"table_3_4"`` -> ...)."""
    return dict(_ALIASES)


def _resolve(name: str) -> str:
    """Full stem for a stem, a stem with ``.csv`` or an alias; UnknownNameError otherwise."""
    if isinstance(name, str):
        key = name[: -len(".csv")] if name.endswith(".csv") else name
        if key in _ALIASES:
            return _ALIASES[key]
        if key in _stems():
            return key
    raise UnknownNameError(
        f"unknown data table {name!r}; valid names are: {', '.join(_stems())} "
        f"(aliases: {', '.join(sorted(_ALIASES))})",
        field="name",
    )


def path(name: str) -> Traversable:
    """The shipped CSV file ``name`` as an :mod:`importlib.resources` Traversable.

    Open it with ``.open()`` / ``.read_text()``; use :func:`importlib.resources.as_file`
    if a real filesystem path is needed.
    """
    return _files() / f"{_resolve(name)}.csv"


@functools.cache
def _read_columns(stem: str) -> tuple[tuple[str, tuple[str, ...]], ...]:
    """The raw cells of a table, column by column (cached; immutable)."""
    text = (_files() / f"{stem}.csv").read_text(encoding="utf-8")
    rows = list(csv.reader(io.StringIO(text)))
    header = [cell.strip() for cell in rows[0]]
    body = [row for row in rows[1:] if any(cell.strip() for cell in row)]
    columns = []
    for i, column in enumerate(header):
        cells = tuple(row[i].strip() if i < len(row) else "" for row in body)
        columns.append((column, cells))
    return tuple(columns)


def _parse_float(cell: str) -> float | None:
    try:
        return float(cell)
    except ValueError:
        return None


def _column_array(cells: tuple[str, ...]) -> np.ndarray:
    """float64 if every non-empty cell is a number (empty cells -> NaN), else object."""
    values = [math.nan if cell == "" else _parse_float(cell) for cell in cells]
    if all(v is not None for v in values):
        return np.array(values, dtype=np.float64)
    return np.array(cells, dtype=object)


def _as_numpy(stem: str) -> dict[str, np.ndarray]:
    return {column: _column_array(cells) for column, cells in _read_columns(stem)}


@overload
def load(name: str, as_: Literal["pandas"] = ...) -> pd.DataFrame: ...
@overload
def load(name: str, as_: Literal["numpy"]) -> dict[str, np.ndarray]: ...
@overload
def load(name: str, as_: str) -> pd.DataFrame | dict[str, np.ndarray]: ...


def load(name: str, as_: str = "pandas") -> pd.DataFrame | dict[str, np.ndarray]:
    """Read the shipped table ``name``.

    ``as_="pandas"`` (default) returns a :class:`pandas.DataFrame`; ``as_="numpy"`` a new dict
    column name -> numpy array, in file order. Both come from the same parse: a column is
    numeric (float64, also for integer-valued columns; empty cells are NaN) when every
    non-empty cell is a number, and text otherwise (an object array of str, empty cells
    ``""``; in pandas the column holds the same strings). Units are those of the column names
    and ``PROVENANCE.md`` (SI, angles in degrees).

    Raises :class:`~granrs.errors.UnknownNameError` for an unknown ``name``
    (``field="name"``) or ``as_`` (``field="as_"``).
    """
    stem = _resolve(name)
    if as_ == "numpy":
        return _as_numpy(stem)
    if as_ == "pandas":
        import pandas as pd

        return pd.DataFrame(_as_numpy(stem))
    raise UnknownNameError(
        f"unknown output format as_={as_!r}; valid values are: 'pandas', 'numpy'",
        field="as_",
    )


@functools.lru_cache(maxsize=1)
def _provenance_table() -> dict[str, str]:
    """file stem -> the "thesis" cell of the table in PROVENANCE.md."""
    text = (_files() / _PROVENANCE_FILE).read_text(encoding="utf-8")
    table: dict[str, str] = {}
    for line in text.splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if len(cells) >= 2 and cells[0].endswith(".csv"):
            table[cells[0][: -len(".csv")]] = cells[1]
    return table


def provenance(name: str) -> str:
    """Where in the thesis the table ``name`` comes from, as listed in ``PROVENANCE.md``.

    E.g. ``"Table 3.4"``, ``"Tables 4.1-4.2"``, ``"section 3.4"`` or
    ``"sections 3.2.1, 4.1, 5.2-5.3"`` (bare section numbers get the word "section(s)").
    """
    stem = _resolve(name)
    source = _provenance_table().get(stem)
    if source is None:
        return "not listed in PROVENANCE.md"
    if source[:1].isdigit():
        plural = "," in source or "-" in source
        return f"{'sections' if plural else 'section'} {source}"
    return source
