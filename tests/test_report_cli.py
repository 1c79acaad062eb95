"""The whole report through the command line: ``granrs reproduce --quiet`` into a folder that
exists already.

A file of its own, apart from tests/test_report.py, whose fixture builds the whole report
too: under pytest-xdist (``--dist loadfile``, one file per worker at a time) the two builds,
the longest tests there are, run on two workers at once instead of one after the other.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from granrs.cli import main


def test_cli_reproduce_quiet_replaces_report(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--quiet prints nothing; an existing report folder is updated in place."""
    out = tmp_path / "existing"
    (out / "figures").mkdir(parents=True)
    (out / "figures" / "stale.png").write_bytes(b"old")
    (out / "keep.txt").write_text("mine")
    assert main(["reproduce", "--out", str(out), "--quiet"]) == 0
    captured = capsys.readouterr()
    assert captured.out == ""
    # No progress, and no warning: the command's own warnings are part of its output (one
    # line each). Its one step-size warning was a false alarm (the chain, case 2, under
    # `poncelet` to all stops: step_error 0.031 while t_s and depth move by 1e-4 at dt / 10);
    # the step's check runs that chain again at dt / 10 and finds it resolved.
    assert captured.err == ""
    assert (out / "README.md").is_file()
    assert (out / "keep.txt").read_text() == "mine"
    assert not (out / "figures" / "stale.png").exists()
    assert any((out / "figures").glob("*.png"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["existing"]  # no temp leftovers
