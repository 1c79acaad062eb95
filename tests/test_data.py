"""Tests of granrs.data: the thesis tables shipped in the package.

Expected values come from the CSV files read here with the csv module (never through the
code under test), and from the provenance table of the thesis README.
"""

from __future__ import annotations

import csv
import math
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from granrs import data
from granrs.errors import UnknownNameError

REPO_DATA = Path(__file__).resolve().parents[1] / "python" / "granrs" / "data"

EXPECTED_STEMS = [
    "bodies",
    "sweep_3_4_initial_velocities",
    "table_3_1_free_link_experiments",
    "table_3_4_free_link_coefficients",
    "table_3_5_free_link_thesis_simulation",
    "table_3_6_free_link_forces",
    "table_3_7_free_link_energy",
    "table_4_chain_coefficients_and_simulation",
    "table_4_chain_experiments",
    "table_5_1_human_experiments",
    "table_5_human_coefficients_and_simulation",
]

EXPECTED_ALIASES = {
    "bodies": "bodies",
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

# From the table in thesis/README.md (PROVENANCE.md).
EXPECTED_PROVENANCE = {
    "bodies": "sections 3.2.1, 4.1, 5.2-5.3",
    "table_3_1_free_link_experiments": "Table 3.1",
    "table_3_4_free_link_coefficients": "Table 3.4",
    "sweep_3_4_initial_velocities": "section 3.4",
    "table_3_5_free_link_thesis_simulation": "Table 3.5",
    "table_3_6_free_link_forces": "Table 3.6",
    "table_3_7_free_link_energy": "Table 3.7",
    "table_4_chain_experiments": "Tables 4.1-4.2",
    "table_4_chain_coefficients_and_simulation": "Tables 4.4-4.6",
    "table_5_1_human_experiments": "Table 5.1",
    "table_5_human_coefficients_and_simulation": "section 5.3.2",
}


def read_csv_rows(stem: str) -> tuple[list[str], list[list[str]]]:
    """Header and data rows of a shipped file, read independently with the csv module."""
    with open(REPO_DATA / f"{stem}.csv", encoding="utf-8", newline="") as handle:
        rows = list(csv.reader(handle))
    return rows[0], [row for row in rows[1:] if row]


def test_names_lists_every_shipped_csv() -> None:
    """names() is exactly the CSV files of the package, by full stem."""
    on_disk = sorted(p.stem for p in REPO_DATA.glob("*.csv"))
    assert data.names() == EXPECTED_STEMS
    assert data.names() == on_disk


def test_names_returns_a_new_list() -> None:
    listed = data.names()
    listed.clear()
    assert data.names() == EXPECTED_STEMS


def test_aliases_are_the_documented_ones() -> None:
    for alias, stem in EXPECTED_ALIASES.items():
        assert data.path(alias).name == f"{stem}.csv"
    assert data.aliases() == {k: v for k, v in EXPECTED_ALIASES.items() if k != "bodies"}


@pytest.mark.parametrize("alias", sorted(EXPECTED_ALIASES))
def test_alias_loads_the_same_table_as_the_stem(alias: str) -> None:
    by_alias = data.load(alias)
    by_stem = data.load(EXPECTED_ALIASES[alias])
    pd.testing.assert_frame_equal(by_alias, by_stem)


def test_stem_with_csv_suffix_is_accepted() -> None:
    assert data.path("bodies.csv").name == "bodies.csv"


@pytest.mark.parametrize("name", EXPECTED_STEMS)
def test_path_reads_the_file_unchanged(name: str) -> None:
    """path() gives the shipped bytes, through importlib.resources."""
    traversable = data.path(name)
    assert traversable.is_file()
    assert traversable.read_bytes() == (REPO_DATA / f"{name}.csv").read_bytes()
    with resources.as_file(traversable) as real_path:
        assert real_path.read_bytes() == (REPO_DATA / f"{name}.csv").read_bytes()


@pytest.mark.parametrize("name", EXPECTED_STEMS)
def test_every_name_loads_and_numpy_agrees_with_pandas(name: str) -> None:
    header, rows = read_csv_rows(name)
    frame = data.load(name)
    arrays = data.load(name, as_="numpy")
    assert isinstance(frame, pd.DataFrame)
    assert isinstance(arrays, dict)
    assert list(frame.columns) == header
    assert list(arrays) == header
    assert len(frame) == len(rows)
    for column, values in arrays.items():
        assert isinstance(values, np.ndarray)
        assert values.shape == (len(rows),)
        if values.dtype == np.float64:
            np.testing.assert_array_equal(frame[column].to_numpy(dtype=np.float64), values)
        else:
            assert values.dtype == object
            assert list(frame[column]) == list(values)


@pytest.mark.parametrize("name", EXPECTED_STEMS)
def test_numeric_cells_match_the_csv(name: str) -> None:
    """Numeric columns hold float(cell), empty cells NaN; text columns hold the cells."""
    header, rows = read_csv_rows(name)
    arrays = data.load(name, as_="numpy")
    for i, column in enumerate(header):
        cells = [row[i] if i < len(row) else "" for row in rows]
        values = arrays[column]
        if values.dtype == np.float64:
            for cell, value in zip(cells, values, strict=True):
                if cell.strip() == "":
                    assert math.isnan(value)
                else:
                    assert value == float(cell)
        else:
            assert [str(v) for v in values] == [c.strip() for c in cells]


def test_column_types_of_known_tables() -> None:
    coefficients = data.load("table_3_4", as_="numpy")
    assert list(coefficients) == ["alpha_deg", "q_deg", "eta_h", "eta_d", "eta_v", "lambda"]
    assert all(v.dtype == np.float64 for v in coefficients.values())
    np.testing.assert_array_equal(coefficients["q_deg"], [0, 5, 15, 25, 35, 45, 55, 65, 75, 85])
    simulation = data.load("table_3_5", as_="numpy")
    assert simulation["note"].dtype == object
    assert simulation["note"][0] == ""
    assert "garbled" in simulation["note"][11]
    chain = data.load("chain_coefficients", as_="numpy")
    assert chain["t_s_sim"].dtype == np.float64
    assert math.isnan(chain["t_s_sim"][-1])
    assert chain["link"].dtype == np.float64
    bodies = data.load("bodies", as_="numpy")
    assert bodies["value"].dtype == object  # "0.45 x 0.32 x 0.09" is text
    assert bodies["value"][0] == "0.190"


def test_numpy_result_is_a_fresh_copy() -> None:
    """Mutating a loaded array must not change the next load (the parse is cached)."""
    first = data.load("table_3_4", as_="numpy")
    first["eta_h"][:] = -1.0
    del first["lambda"]
    second = data.load("table_3_4", as_="numpy")
    assert second["eta_h"][0] == 6.5
    assert "lambda" in second


@pytest.mark.parametrize("name", EXPECTED_STEMS)
def test_provenance_of_every_table(name: str) -> None:
    assert data.provenance(name) == EXPECTED_PROVENANCE[name]


def test_provenance_accepts_aliases() -> None:
    assert data.provenance("table_3_4") == "Table 3.4"
    assert data.provenance("chain_experiments") == "Tables 4.1-4.2"


def test_provenance_file_is_shipped() -> None:
    text = (resources.files("granrs.data") / "PROVENANCE.md").read_text(encoding="utf-8")
    first_line = text.splitlines()[0]
    assert "provenance" in first_line.lower()
    assert "shared thesis folder" in first_line
    assert "# The thesis and its numbers" in text
    assert "| file | thesis | what |" in text


def test_module_exports() -> None:
    assert set(data.__all__) == {"aliases", "load", "names", "path", "provenance"}
    assert data.__doc__ is not None and "Table 3.4" in data.__doc__


@pytest.mark.parametrize("bad", ["table_3_3", "", "Table_3_4", "table_3_4_free_link", "x.csv", 3])
@pytest.mark.parametrize("function", [data.load, data.path, data.provenance])
def test_unknown_name_is_rejected(function: object, bad: object) -> None:
    with pytest.raises(UnknownNameError) as info:
        function(bad)  # type: ignore[operator]
    assert info.value.field == "name"
    message = str(info.value)
    assert "table_3_4_free_link_coefficients" in message
    assert "bodies" in message
    assert "table_3_4" in message


@pytest.mark.parametrize("bad", ["polars", "dataframe", "", "NUMPY", None])
def test_unknown_output_format_is_rejected(bad: object) -> None:
    with pytest.raises(UnknownNameError) as info:
        data.load("table_3_4", as_=bad)  # type: ignore[call-overload]
    assert info.value.field == "as_"
    assert "numpy" in str(info.value) and "pandas" in str(info.value)
