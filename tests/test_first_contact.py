"""What a new user meets first: every shipped example scene through ``granrs run``, a thesis
case's angle changed (Python, ``--set`` and a sweep), the summary's claims, progress on long
commands, help text, ``--series`` units and near-miss names.

Each test names what failed before its fix; expected values come from the thesis's shipped
tables or from a second path (``granrs.cases``) that does not go through the code under test.
"""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

import pandas as pd
import pytest

import granrs
from granrs import cases, data, scenefile
from granrs.cli import ROUNDOFF_RTOL, main
from granrs.errors import CoefficientsWarning, InvalidParameterError, UnknownNameError

EXAMPLES = sorted((Path(__file__).resolve().parent.parent / "examples" / "scenes").glob("*.toml"))
Q45 = Path(__file__).resolve().parent.parent / "examples" / "scenes" / "free_link_q45.toml"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def table_3_4_row(q_deg: float) -> dict[str, float]:
    """The shipped Table 3.4 row at ``q_deg`` (read from the CSV, not through granrs's lookup)."""
    table = data.load("table_3_4", as_="numpy")
    i = [float(q) for q in table["q_deg"]].index(q_deg)
    columns = {"eta_h": "eta_h", "eta_d": "eta_d", "eta_v": "eta_v", "lam": "lambda"}
    return {name: float(table[column][i]) for name, column in columns.items()}


def thesis_params(scene: granrs.Scene) -> dict[str, float]:
    row = granrs.forces.thesis_row(scene.forces)
    return dict(row.as_dict())


# --- every example scene runs -------------------------------------------------------------


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_every_example_scene_runs_as_text_and_json(
    capsys: pytest.CaptureFixture[str], path: Path
) -> None:
    """``granrs run`` on each shipped scene: exit 0, no traceback, a summary (text) and a
    JSON object. Before: three_link_pendulum.toml (no contacts) ended in an IndexError in
    summary_text."""
    code, out, err = run(capsys, "run", str(path))
    assert code == 0, err
    assert "Traceback" not in err
    assert out.startswith(f"{path}: ") and "status" in out
    scene = scenefile.load(path)
    in_space = isinstance(scene, granrs.space.Scene)
    if not in_space and not scene.body.contacts:  # type: ignore[union-attr]
        assert "no contacts" in out
    code, out, err = run(capsys, "run", str(path), "--json")
    assert code == 0, err
    summary = json.loads(out)
    kind = "space" if in_space else scene.kind  # type: ignore[union-attr]
    assert summary["body"] == kind and summary["status"] in ("stopped", "end_time")


def test_example_scenes_hold_clean_numbers_and_no_issue_numbers() -> None:
    """The shipped scene files are user-facing: no internal "issue N", and no float that is
    a computation's round-off (the pendulum had inertia = 0.005999999999999999, 16
    significant digits, for 0.8 kg * (0.3 m)^2 / 12 = 0.006)."""
    for path in EXAMPLES:
        text = path.read_text()
        assert not re.search(r"issue \d", text, re.IGNORECASE), path
        for line in text.splitlines():
            value = line.split("#", 1)[0]
            for number in re.findall(r"(?<![\w.])\d+\.\d+(?:e[-+]?\d+)?", value):
                assert not _round_off(number), f"{path.name}: {line}"


def _round_off(number: str) -> bool:
    """A long literal that is a short number plus round-off (0.005999999999999999), not a
    value that needs its digits (2 pi = 6.283185307179586)."""
    short = f"{float(number):.12g}"
    return len(_digits(number)) > 12 and len(_digits(short)) <= 8


def _digits(number: str) -> str:
    return number.split("e")[0].replace(".", "").lstrip("0").rstrip("0")


# --- the angle of a thesis case ------------------------------------------------------------


def test_replace_q_deg_takes_that_angles_row() -> None:
    """Python: the 45 deg case at q = 0 has Table 3.4's q = 0 row (before: the 45 deg row's
    coefficients stayed, 126.9 mm / 77.8 ms against 51.9 mm / 34.1 ms)."""
    scene = cases.free_link(q_deg=45.0, v0=2.27).replace(q_deg=0.0)
    assert thesis_params(scene) == table_3_4_row(0.0)
    assert scene.coefficients_source == "Table 3.4, row q = 0 deg"
    result = granrs.simulate(scene)
    assert result.depth == pytest.approx(0.0519, abs=1e-4)
    assert result.t_s == pytest.approx(0.0341, abs=1e-4)


def test_an_untabulated_angle_takes_the_nearest_row_and_says_so() -> None:
    """Between rows: the nearest (halfway: the larger angle), named in the source, no
    interpolation (the rows were tuned by hand)."""
    scene = cases.free_link(q_deg=0.0, v0=2.0).replace(q_deg=30.0)
    assert thesis_params(scene) == table_3_4_row(35.0)
    assert scene.coefficients_source == "Table 3.4, row q = 35 deg (nearest to q = 30 deg)"
    assert granrs.Scene(q_deg=-44.0).coefficients_source.startswith("Table 3.4, row q = 45 deg")


def test_replace_v0_of_the_leg_takes_that_speeds_row() -> None:
    """The leg's coefficients are per landing speed (sec. 5.3.2): the same rule."""
    assert cases.leg(v0=3.28).replace(v0=2.35) == cases.leg(v0=2.35)
    assert "row v0 = 2.35 m/s" in cases.leg(v0=3.28).replace(v0=2.3).coefficients_source


def test_set_q_deg_on_a_scene_file_takes_that_angles_row(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """TOML --set: the 45 deg file at q_deg = 0 is the q = 0 case (before: 126.9 mm)."""
    code, out, err = run(capsys, "run", str(Q45), "--set", "q_deg=0", "--json")
    assert code == 0 and err == ""
    expected = granrs.simulate(cases.free_link(q_deg=0.0, v0=2.27))
    assert json.loads(out)["depth"] == expected.depth
    assert json.loads(out)["t_s"] == expected.t_s
    assert json.loads(out)["coefficients_source"] == "Table 3.4, row q = 0 deg"
    code, out, _ = run(capsys, "run", str(Q45), "--set", "q_deg=0")
    assert "coefficients: Table 3.4, row q = 0 deg" in out


def test_a_sweep_over_q_deg_takes_each_angles_row() -> None:
    """Sweeps: the README's headline sweep (a base at q_deg = 0 swept over q_deg) gives each
    row what cases.free_link at that angle gives (before: the q = 0 row at every angle,
    17.9 mm at 45 deg against 28.9 mm)."""
    base = cases.free_link(q_deg=0.0, v0=2.0)
    # The angle axis between two others: each run's row must land at its place.
    frame = granrs.sweep(
        base, v0=[1.0, 2.0], q_deg=[0.0, 45.0, -60.0, 10.0], apply_at=["tip", "centroid"]
    )
    assert len(frame) == 16
    for row in frame.itertuples(index=False):
        case = cases.free_link(q_deg=row.q_deg, v0=row.v0, apply_at=row.apply_at)
        expected = granrs.simulate(case)
        assert (row.depth, row.steps) == (expected.depth, expected.summary["steps"]), row
    frame = frame[frame.apply_at == "tip"]
    at_45 = frame[(frame.q_deg == 45.0) & (frame.v0 == 2.0)]["depth"].iloc[0]
    assert at_45 == pytest.approx(0.0289, abs=2e-4)


def test_given_terms_are_the_callers_and_stay() -> None:
    """replace(forces=...) makes the terms the scene's own: no row is followed, no warning."""
    own = granrs.forces.thesis({"eta_h": 1.0, "eta_d": 2.0, "eta_v": 30.0, "lam": 0.5})
    scene = cases.free_link(q_deg=45.0, v0=2.27).replace(forces=own)
    assert scene.coefficients_source == granrs.scene.OWN_FORCES
    assert scene.replace(q_deg=0.0).forces == own


def test_changed_parameters_warn_once_in_python() -> None:
    """A row's terms changed in place (a scene file's value) and then a new angle: the values
    are kept, with one warning naming the row kept and the new row; later changes are quiet."""
    scene = scenefile.load(Q45, overrides={"static_v.eta_v": 300.0})
    with pytest.warns(CoefficientsWarning, match="row q = 45 deg") as caught:
        moved = scene.replace(q_deg=0.0)
    assert len(caught) == 1
    assert "Table 3.4, row q = 0 deg" in str(caught[0].message)
    assert thesis_params(moved)["eta_v"] == 300.0
    assert thesis_params(moved)["eta_d"] == table_3_4_row(45.0)["eta_d"]
    moved.replace(q_deg=15.0, v0=1.0)  # no second warning (filterwarnings = error)


def test_changed_parameters_warn_once_in_a_sweep() -> None:
    """The same in a sweep: one warning for the whole sweep, the values kept in every run."""
    scene = scenefile.load(Q45, overrides={"static_v.eta_v": 300.0})
    with pytest.warns(CoefficientsWarning) as caught:
        frame = granrs.sweep(scene, q_deg=[0.0, 15.0, 45.0, 75.0])
    assert len(caught) == 1
    assert "3 of the 4 values" in str(caught[0].message)
    # The same values pinned by saying where they come from (no row to follow, no warning).
    pinned = scene.replace(coefficients_source="Table 3.4 at 45 deg, eta_v = 300")
    expected = [granrs.simulate(pinned.replace(q_deg=q)).depth for q in (0.0, 15.0, 45.0, 75.0)]
    assert list(frame["depth"]) == expected


def test_changed_parameters_warn_once_on_the_command_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """--set of a parameter and of the angle: one ``granrs: warning:`` line that names the
    kept row and how to take the new one; the run goes on with the values given."""
    code, out, err = run(capsys, "run", str(Q45), "--set", "q_deg=0", "--set", "static_v.eta_v=300")
    assert code == 0
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("granrs: warning: q_deg = 0 selects")
    assert "Table 3.4, row q = 45 deg" in lines[0] and "coefficients_source" in lines[0]
    assert "parameters changed" in out


# --- the summary claims no more than it knows ---------------------------------------------


def test_joint_round_off_is_printed_as_zero(capsys: pytest.CaptureFixture[str]) -> None:
    """chain_case1.toml: pin_on_link1 carries no load (2.68e-15 N of round-off); the table
    prints 0 and says why (before: "2.67895e-15" as if it were a force)."""
    path = next(p for p in EXAMPLES if p.stem == "chain_case1")
    raw = granrs.simulate(scenefile.load(path)).joints
    assert 0.0 < raw["pin_on_link1"]["F_max"] < ROUNDOFF_RTOL * raw["pin"]["F_max"]
    code, out, _ = run(capsys, "run", str(path))
    assert code == 0
    row = next(line for line in out.splitlines() if line.startswith("pin_on_link1"))
    assert row.split()[1] == "0"
    pin = next(line for line in out.splitlines() if line.startswith("pin "))
    assert float(pin.split()[1]) == pytest.approx(raw["pin"]["F_max"], rel=1e-5)
    assert "round-off" in out


# --- progress ------------------------------------------------------------------------------


def _recorded(path: Path) -> granrs.Result:
    scene = scenefile.load(path).replace(record=("state", "forces"))
    return granrs.simulate(scene)


def test_animate_shows_a_progress_bar_of_frames(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Writing an animation counts its frames on stderr (before: 17.7 s with no output)."""
    anim = granrs.animate(_recorded(Q45), frame_dt=0.005, out=tmp_path / "a.gif", progress=True)
    err = capsys.readouterr().err
    assert "granrs animate" in err and f"{anim.n_frames}/{anim.n_frames}" in err
    granrs.animate(_recorded(Q45), frame_dt=0.005, out=tmp_path / "b.html", progress=True)
    assert f"{anim.n_frames}/{anim.n_frames}" in capsys.readouterr().err


def test_cli_animate_progress_on_a_terminal_and_quiet(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``granrs animate`` shows the bar when stderr is a terminal; --quiet turns it off."""
    argv = ["animate", str(Q45), "--frame-dt", "0.005", "--out", str(tmp_path / "a.gif")]
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    code, _, err = run(capsys, *argv)
    assert code == 0 and "granrs animate" in err and "frame" in err
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    code, _, err = run(capsys, *argv, "--quiet")
    assert code == 0 and "granrs animate:" not in err


def test_calibrate_shows_a_progress_bar_of_runs(capsys: pytest.CaptureFixture[str]) -> None:
    """A fit counts its runs on stderr when asked (the command line asks on a terminal)."""
    rows = granrs.Measurements.load("thesis:table_3_1").subset(q_deg=[0])
    granrs.calibrate("free_link", rows, ["eta_v"], max_nfev=2, progress=True)
    assert "granrs calibrate" in capsys.readouterr().err
    with pytest.raises(InvalidParameterError, match="progress"):
        granrs.calibrate("free_link", rows, ["eta_v"], max_nfev=2, progress="yes")  # type: ignore[arg-type]


# --- smaller things ------------------------------------------------------------------------


def test_calibrate_help_prints_a_single_percent(capsys: pytest.CaptureFixture[str]) -> None:
    """argparse does not %-format a description: "~95%%" was printed as it was written."""
    code, out, _ = run(capsys, "calibrate", "--help")
    assert code == 0
    assert "~95% intervals" in " ".join(out.split()) and "%%" not in out


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_series_columns_carry_their_units(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, path: Path
) -> None:
    """--series CSV: every column is "name [unit]", angles in rad, times in s (before: bare
    names, the angles' radians unsaid)."""
    out_csv = tmp_path / "series.csv"
    code, _, err = run(capsys, "run", str(path), "--series", str(out_csv), "--set", "t_end=0.01")
    assert code == 0, err
    columns = list(pd.read_csv(out_csv, nrows=1).columns)
    assert columns[0] == "t [s]"
    for column in columns:
        assert re.fullmatch(r"\S+ \[[^\]]+\]", column), column
    units = dict(c[:-1].split(" [") for c in columns)
    scene = scenefile.load(path)
    if isinstance(scene, granrs.space.Scene):  # a body in space: its own columns and units
        assert units == {"t": "s", **{n: u for n, (u, _) in granrs.space.SERIES_COLUMNS.items()}}
        return
    names = granrs.result._names(scene)
    for name in names["coords"][2:]:
        assert units[name] in ("rad", "s"), name
    for name in names["rates"][2:]:
        assert units[name] in ("rad/s", "-"), name
    assert all(units[n] == "m" for n in names["coords"][:2])
    assert all(units[c] == "N" for c in units if c.rsplit(".", 1)[-1].startswith("F_"))


def test_near_miss_names_suggest_the_field() -> None:
    """free_link(q_dg=45) raised Python's TypeError (missing q_deg) with no hint, and
    replace(lenght=...) listed 42 names without one."""
    with pytest.raises(UnknownNameError, match="did you mean 'q_deg'") as info:
        cases.free_link(q_dg=45.0, v0=2.0)
    assert info.value.field == "q_dg"
    with pytest.raises(UnknownNameError, match="did you mean 'length'") as info:
        granrs.Scene().replace(lenght=0.2)
    assert "fields:" not in str(info.value)
    with pytest.raises(UnknownNameError, match="did you mean 'v0'"):
        cases.leg(vo=2.0)
    with pytest.raises(InvalidParameterError, match="needs q_deg"):
        cases.free_link(v0=2.0)
    assert math.isfinite(cases.free_link(45.0, 2.27).q_deg)


def test_reproduce_shows_a_bar_of_its_chapters_on_a_terminal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``granrs reproduce`` runs for minutes: on a terminal it shows a tqdm bar of the
    chapters done (as animate, calibrate, compare and long sweeps do), beside its one line
    per table and figure; off a terminal only the lines. (Before, only the lines.)"""
    from granrs.report import framework

    monkeypatch.setitem(
        framework.CHAPTERS, "fake", framework.Chapter("fake", "A short chapter", lambda ctx: "x")
    )
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    framework.reproduce(tmp_path / "on_a_terminal", chapters=["fake"])
    err = capsys.readouterr().err
    assert "granrs reproduce: A short chapter" in err
    assert "granrs reproduce" in err and "1/1" in err and "chapter" in err

    monkeypatch.setattr(sys.stderr, "isatty", lambda: False)
    framework.reproduce(tmp_path / "in_a_pipe", chapters=["fake"])
    err = capsys.readouterr().err
    assert "granrs reproduce: A short chapter" in err and "1/1" not in err


@pytest.mark.parametrize("make", ["replace", "sweep"])
def test_an_angle_past_any_float_is_the_cores_typed_error(make: str) -> None:
    """Following the row must not get in the way of the field's own check: an integer
    angle no float holds (10**400) is the core's typed error naming ``q_deg``, in
    ``replace`` and in a sweep's axis, not an OverflowError from the row lookup (found by
    the adversarial suite once both were in)."""
    base = cases.free_link(q_deg=0.0, v0=2.0)
    with pytest.raises(InvalidParameterError) as info:
        if make == "replace":
            base.replace(q_deg=10**400)
        else:
            granrs.sweep(base, q_deg=[10**400], progress=False)
    assert info.value.field == "q_deg"
