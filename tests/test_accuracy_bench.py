"""The accuracy benchmark (``granrs.bench.work_precision``) in quick mode."""

from __future__ import annotations

import time

from granrs.bench import SCENES, work_precision
from granrs.cli import main


def test_work_precision_quick_writes_outputs_and_converges(tmp_path):
    """The quick sweep writes its CSV, PNG and Markdown, covers every scene and method, and
    RK4's depth error shrinks at least 100x from dt = 1e-3 to 1e-5 (4th order predicts
    ~1e8x; the sign switches and the stop event lower that, but not below 100x)."""
    start = time.perf_counter()
    df = work_precision(tmp_path, quick=True, repeats=1, progress=False)
    assert time.perf_counter() - start < 60.0

    for name in ("accuracy.csv", "accuracy.png", "accuracy.md"):
        assert (tmp_path / name).is_file(), name
    assert (tmp_path / "accuracy.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    md = (tmp_path / "accuracy.md").read_text()
    assert "Failed settings" in md

    assert set(df["scene"]) == {s.name for s in SCENES}
    for scene in df["scene"].unique():
        sub = df[df["scene"] == scene]
        assert set(sub["label"]) == {"rk4 modes", "rk4 raw", "rk4 smooth", "dopri5"}
        modes = sub[(sub["label"] == "rk4 modes") & ~sub["failed"]].set_index("dt")
        coarse, fine = modes.loc[1e-3, "depth_rel_err"], modes.loc[1e-5, "depth_rel_err"]
        assert fine * 100 <= coarse, (scene, coarse, fine)


def test_cli_bench_accuracy_quick(tmp_path, capsys):
    """``granrs bench accuracy --quick`` calls the same function and writes the same files."""
    assert main(["bench", "accuracy", "--out", str(tmp_path), "--quick", "--repeats", "1"]) == 0
    assert (tmp_path / "accuracy.csv").is_file()
    assert "benchmark written" in capsys.readouterr().out
