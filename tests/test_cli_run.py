"""``granrs run SCENE.toml`` and ``granrs scene new`` (issue 5): output, series files and
exit codes (0 ok, 2 bad input with one line naming the field and file:line, 1 simulation
failure).

Expected values come from running the same scene through ``granrs.simulate`` directly.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pandas as pd
import pytest

import granrs
from granrs import cases
from granrs.cli import SERIES_RECORD, main
from granrs.errors import SimulationError
from granrs.scenefile import dumps

FREE_LINK = cases.free_link(q_deg=45.0, v0=2.27)
CHAIN = cases.chain(case=1)
LEG = cases.leg(v0=3.28)


@pytest.fixture
def free_link_file(tmp_path: Path) -> Path:
    path = tmp_path / "free_link.toml"
    path.write_text(dumps(FREE_LINK))
    return path


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def assert_one_line_error(err: str, *needles: str) -> None:
    """stderr is exactly one ``granrs: error: ...`` line (no traceback) holding each needle."""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("granrs: error: "), err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in lines[0], (needle, err)


# --- success ------------------------------------------------------------------------------


def test_run_prints_summary_table(capsys: pytest.CaptureFixture[str], free_link_file: Path) -> None:
    """Issue 5: the table shows the status and each quantity of the contact with its unit."""
    expected = granrs.simulate(FREE_LINK)
    code, out, err = run(capsys, "run", str(free_link_file))
    assert code == 0, err
    assert err == ""
    assert f"status {expected.status}" in out
    rows = {line.split()[0]: line.split()[1:] for line in out.splitlines() if line.strip()}
    assert rows["t_s"] == ["s", f"{expected.t_s:.6g}"]
    assert rows["depth"] == ["m", f"{expected.depth:.6g}"]
    assert rows["dE"] == ["J", f"{expected.summary['dE']:.6g}"]
    assert rows["quantity"] == ["unit", "rod"]


def test_run_chain_has_a_column_per_link_and_joints(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "chain.toml"
    path.write_text(dumps(CHAIN))
    expected = granrs.simulate(CHAIN)
    code, out, _ = run(capsys, "run", str(path))
    assert code == 0
    rows = {line.split()[0]: line.split()[1:] for line in out.splitlines() if line.strip()}
    assert rows["quantity"] == ["unit", "link1", "link2"]
    assert rows["depth"] == ["m", *(f"{c.depth:.6g}" for c in expected.contacts)]
    assert rows["pin"][0] == f"{expected.joints['pin']['F_max']:.6g}"


def test_run_json(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """Issue 5: --json prints the summary as (strict) JSON; NaN becomes null."""
    path = tmp_path / "chain.toml"
    path.write_text(dumps(CHAIN))
    expected = granrs.simulate(CHAIN)
    code, out, _ = run(capsys, "run", str(path), "--json")
    assert code == 0
    data = json.loads(out)
    assert data["status"] == expected.status
    assert data["body"] == "chain"
    assert list(data["contacts"]) == ["link1", "link2"]
    for name, contact in zip(["link1", "link2"], expected.contacts, strict=True):
        got = data["contacts"][name]
        assert got["depth"] == contact.depth
        assert got["stopped"] == contact.stopped
        assert got["t_s"] == (None if math.isnan(contact.t_s) else contact.t_s)
    assert data["run"]["steps"] == expected.summary["steps"]
    assert data["joints"]["pin"]["F_max"] == expected.joints["pin"]["F_max"]
    assert data["units"]["depth"] == "m"


def test_set_overrides_fields(capsys: pytest.CaptureFixture[str], free_link_file: Path) -> None:
    """Issue 5: --set field=value (TOML scalars, repeatable) gives the variant's result."""
    variant = FREE_LINK.replace(v0=1.5, apply_at="centroid")
    expected = granrs.simulate(variant)
    code, out, _ = run(
        capsys,
        "run",
        str(free_link_file),
        "--set",
        "v0=1.5",
        "--set",
        'apply_at="centroid"',
        "--json",
    )
    assert code == 0
    assert json.loads(out)["depth"] == expected.depth


def test_series_csv_turns_on_recording(
    capsys: pytest.CaptureFixture[str], free_link_file: Path, tmp_path: Path
) -> None:
    """Issue 5: --series on a scene that records nothing records state+forces+energy, says
    so, and writes the columns of Result.to_frame()."""
    out_csv = tmp_path / "series.csv"
    code, _, err = run(capsys, "run", str(free_link_file), "--series", str(out_csv))
    assert code == 0
    assert "records nothing" in err
    frame = granrs.simulate(FREE_LINK.replace(record=SERIES_RECORD)).to_frame()
    written = pd.read_csv(out_csv, index_col="t [s]")
    assert [_name(c) for c in written.columns] == list(frame.columns)
    assert len(written) == len(frame)
    assert written.index.to_numpy() == pytest.approx(frame.index.to_numpy(), rel=1e-12)
    assert written["depth [m]"].to_numpy() == pytest.approx(frame["depth"].to_numpy(), rel=1e-12)


def _name(column: str) -> str:
    """A --series column's series name (``"q [rad]"`` -> ``"q"``)."""
    return column.rsplit(" [", 1)[0]


def test_series_keeps_the_scene_record(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    scene = FREE_LINK.replace(record=("state",))
    path = tmp_path / "s.toml"
    path.write_text(dumps(scene))
    out_csv = tmp_path / "series.csv"
    code, _, err = run(capsys, "run", str(path), "--series", str(out_csv))
    assert code == 0
    assert "records nothing" not in err
    frame = granrs.simulate(scene).to_frame()
    written = pd.read_csv(out_csv, index_col="t [s]")
    assert [_name(c) for c in written.columns] == list(frame.columns)


def test_series_parquet_without_pyarrow_is_a_clear_error(
    capsys: pytest.CaptureFixture[str],
    free_link_file: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Issue 5: parquet without pyarrow says to pip install pyarrow (exit 2, no traceback)
    before running anything."""
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    out = tmp_path / "series.parquet"
    code, stdout, err = run(capsys, "run", str(free_link_file), "--series", str(out))
    assert code == 2
    assert stdout == ""
    assert_one_line_error(err, "pip install pyarrow")
    assert not out.exists()


def test_series_parquet(
    capsys: pytest.CaptureFixture[str], free_link_file: Path, tmp_path: Path
) -> None:
    pytest.importorskip("pyarrow")
    out = tmp_path / "series.parquet"
    code, _, _ = run(capsys, "run", str(free_link_file), "--series", str(out))
    assert code == 0
    frame = granrs.simulate(FREE_LINK.replace(record=SERIES_RECORD)).to_frame()
    # The file's columns are the series' names, each with its unit ("x [m]").
    written = [c.rsplit(" [", 1)[0] for c in pd.read_parquet(out).columns]
    assert written == list(frame.columns)


def test_series_unknown_extension(
    capsys: pytest.CaptureFixture[str], free_link_file: Path, tmp_path: Path
) -> None:
    code, _, err = run(capsys, "run", str(free_link_file), "--series", str(tmp_path / "s.xlsx"))
    assert code == 2
    assert_one_line_error(err, ".xlsx", ".csv")


# --- exit codes of bad input and failures -------------------------------------------------


def test_unknown_key_exit_2_names_key_file_and_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "typo.toml"
    path.write_text('format = 1\nbody = "free_link"\nlenght = 0.2\n')
    code, out, err = run(capsys, "run", str(path))
    assert code == 2
    assert out == ""
    assert_one_line_error(err, f"{path}:3:", "'lenght'", "did you mean 'length'?")


def test_out_of_range_exit_2_names_field_and_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "bad.toml"
    path.write_text('body = "chain"\n\n\npin_mass = -1.0\n')
    code, _, err = run(capsys, "run", str(path))
    assert code == 2
    assert_one_line_error(err, f"{path}:4:", "pin_mass")


def test_syntax_error_exit_2_with_line_and_column(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "syntax.toml"
    path.write_text("q_deg = 10.0\nv0 = = 2\n")
    code, _, err = run(capsys, "run", str(path))
    assert code == 2
    assert_one_line_error(err, f"{path}:2:6:", "invalid TOML")


def test_bad_set_exit_2_names_the_override(
    capsys: pytest.CaptureFixture[str], free_link_file: Path
) -> None:
    code, _, err = run(capsys, "run", str(free_link_file), "--set", "q_deg=95")
    assert code == 2
    assert_one_line_error(err, "--set q_deg=95", "q_deg")
    code, _, err = run(capsys, "run", str(free_link_file), "--set", "q_deg")
    assert code == 2
    assert_one_line_error(err, "FIELD=VALUE")


def test_missing_file_exit_2(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = run(capsys, "run", str(tmp_path / "nope.toml"))
    assert code == 2
    assert_one_line_error(err, "nope.toml")


def test_simulation_failure_exit_1(
    capsys: pytest.CaptureFixture[str], free_link_file: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A SimulationError (a non-finite state) exits with 1, not 2."""

    def blow_up(scene: granrs.Scene) -> granrs.Result:
        raise SimulationError("state is not finite at t = 0.01 s")

    monkeypatch.setattr("granrs.api.simulate", blow_up)
    code, out, err = run(capsys, "run", str(free_link_file))
    assert code == 1
    assert out == ""
    assert "not finite" in err and "Traceback" not in err


def test_run_without_file_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, _ = run(capsys, "run")
    assert code == 2


# --- scene new ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("body", "expected"),
    [("free_link", cases.free_link(0.0, 2.214)), ("chain", CHAIN), ("leg", LEG)],
)
def test_scene_new_writes_a_runnable_template(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, body: str, expected: granrs.Scene
) -> None:
    code, out, _ = run(capsys, "scene", "new", "--body", body)
    assert code == 0
    assert granrs.scenefile.loads(out) == expected
    path = tmp_path / "t.toml"
    path.write_text(out)
    code, out, _ = run(capsys, "run", str(path), "--json")
    assert code == 0
    assert json.loads(out)["depth"] == granrs.simulate(expected).depth


def test_scene_new_out_refuses_to_overwrite(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "scene.toml"
    assert run(capsys, "scene", "new", "--out", str(path))[0] == 0
    first = path.read_text()
    path.write_text("mine")
    code, _, err = run(capsys, "scene", "new", "--body", "leg", "--out", str(path))
    assert code == 2
    assert_one_line_error(err, "--force")
    assert path.read_text() == "mine"
    assert run(capsys, "scene", "new", "--out", str(path), "--force")[0] == 0
    assert path.read_text() == first
