"""Fault tests (issue 34): what granrs does with inputs and conditions that break naive code.

* a sweep's check of its axes is linear in their length (it was quadratic: one axis of
  40,000 values took 37.1 s to validate against 2.8 s for a 400 x 100 product);
* a file that a command fails to write leaves the previous one intact: every writer goes
  through ``granrs._files.replacing`` (tested on a full disk: ``ulimit -f`` in a
  subprocess, where the write fails with EFBIG since Python ignores SIGXFSZ), and
  ``granrs reproduce`` installs its directory all or nothing;
* a scene file is read safely: nesting 500 deep (in the file or in ``--set``) is one line
  and exit 2, not a 3,002-line RecursionError; ``/dev/zero``, a pipe or a file larger than
  the limit is refused before it is read whole (it was a MemoryError or a hang); a UTF-8
  byte-order mark is accepted (it was refused).
"""

from __future__ import annotations

import os
import re
import shlex
import stat
import subprocess
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import granrs
from granrs import _files, batch, cases
from granrs.errors import InvalidParameterError, UnknownNameError

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "python" / "granrs"
SCENE = ROOT / "examples" / "scenes" / "free_link_q45.toml"

# ------------------------------------------------------------------------------------------
# The sweep's axis check


def _lines_in_batch(fn: Callable[[], Any]) -> int:
    """How many lines of ``granrs.batch`` ``fn`` executes (a count of work, not a time)."""
    count = 0
    target = batch.__file__

    def tracer(frame: Any, event: str, arg: Any) -> Any:
        nonlocal count
        if frame.f_code.co_filename != target:
            return None
        if event == "line":
            count += 1
        return tracer

    old = sys.gettrace()
    sys.settrace(tracer)
    try:
        fn()
    finally:
        sys.settrace(old)
    return count


def test_axis_check_is_linear_in_the_axis_length() -> None:
    """Issue 34: the check of a sweep's axes compared each value with every distinct value
    before it (``any(v is s for s in seen)``), so one axis of n values took n^2 / 2 steps.
    Counted in lines of granrs.batch run (not timed): doubling the axis must about double
    the work (the old check quadrupled it: 4.0x from 1,000 to 2,000 values)."""
    scene = cases.free_link(q_deg=0.0, v0=2.0)

    def check(n: int) -> int:
        values = list(np.linspace(1.0, 3.0, n))  # numpy floats: distinct objects
        axes = {"v0": batch._axis_values("v0", values)}
        return _lines_in_batch(lambda: batch._check_axes(scene, axes))

    small, large = check(1000), check(2000)
    assert small > 1000  # every value is looked at
    assert large / small < 2.2, (small, large)


def test_axis_check_still_checks_each_distinct_value() -> None:
    """The linear check still refuses a bad value of a non-numeric axis, and looks at each
    distinct object once (the same object repeated is checked once)."""
    scene = cases.free_link(q_deg=0.0, v0=2.0)
    with pytest.raises(UnknownNameError) as info:
        granrs.sweep(scene, apply_at=["tip"] * 5000 + ["nowhere"], progress=False)
    assert info.value.field == "apply_at"


# ------------------------------------------------------------------------------------------
# Files written whole


def _granrs_with_file_limit(args: list[str], kib: int, cwd: Path) -> subprocess.CompletedProcess:
    """``granrs ARGS`` in a shell whose files may not grow past ``kib`` KiB (a full disk)."""
    command = " ".join(shlex.quote(a) for a in [sys.executable, "-m", "granrs.cli", *args])
    env = {**os.environ, "PYTHONPATH": str(PACKAGE.parent), "PYTHONDONTWRITEBYTECODE": "1"}
    return subprocess.run(
        ["bash", "-c", f"ulimit -f {kib} && exec {command}"],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


def _previous(path: Path, size: int) -> bytes:
    """Write a previous file of ``size`` bytes at ``path``; return its content."""
    content = (b"previous content, to be kept whole\n" * (size // 35 + 1))[:size]
    path.write_bytes(content)
    return content


def _leftovers(directory: Path, keep: set[str]) -> list[str]:
    return sorted(p.name for p in directory.iterdir() if p.name not in keep)


@pytest.mark.skipif(sys.platform == "win32", reason="ulimit is POSIX")
def test_series_on_a_full_disk_leaves_the_previous_file(tmp_path) -> None:
    """Issue 34: ``granrs run --series good.csv`` wrote in place; on a full disk an existing
    114 kB CSV became 8 kB. Now the series goes to a temporary file that replaces the old
    one only once whole: the write fails (exit 1, one line naming the file) and the
    previous file is byte for byte as it was, with no temporary file left."""
    good = tmp_path / "good.csv"
    before = _previous(good, 120_000)
    proc = _granrs_with_file_limit(["run", str(SCENE), "--series", "good.csv"], 16, tmp_path)
    assert proc.returncode == 1, proc.stderr
    assert "good.csv" in proc.stderr.splitlines()[-1]
    assert "Traceback" not in proc.stderr
    assert good.read_bytes() == before
    assert _leftovers(tmp_path, {"good.csv"}) == []
    # Without the limit the same command writes the whole series (the test's own check).
    proc = _granrs_with_file_limit(["run", str(SCENE), "--series", "good.csv"], 100_000, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert good.read_bytes() != before
    assert good.read_text().startswith("t [s],")
    assert _leftovers(tmp_path, {"good.csv"}) == []


@pytest.mark.skipif(sys.platform == "win32", reason="ulimit is POSIX")
def test_animation_on_a_full_disk_leaves_the_previous_file(tmp_path) -> None:
    """Issue 34: ``granrs animate --out good.gif`` wrote in place. A GIF that does not fit
    (about 100 kB against an 8 KiB limit) leaves the previous file as it was."""
    good = tmp_path / "good.gif"
    before = _previous(good, 50_000)
    args = ["animate", str(SCENE), "--out", "good.gif", "--fps", "5", "--dpi", "50"]
    proc = _granrs_with_file_limit(args, 8, tmp_path)
    assert proc.returncode == 1, proc.stderr
    assert "good.gif" in proc.stderr.splitlines()[-1]
    assert good.read_bytes() == before
    assert _leftovers(tmp_path, {"good.gif"}) == []


def test_replacing_on_error_keeps_the_target_and_removes_the_temporary(tmp_path) -> None:
    """An error while writing (here: raised by the writer) leaves the target as it was."""
    target = tmp_path / "out.csv"
    target.write_text("old\n")
    with pytest.raises(RuntimeError), _files.replacing(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("the writer failed")
    assert target.read_text() == "old\n"
    assert _leftovers(tmp_path, {"out.csv"}) == []


def test_replacing_keeps_permissions_and_writes_through_links(tmp_path) -> None:
    """A replaced file keeps its permission bits; a new one gets those ``open`` gives (the
    umask's); a symbolic link is written through, not replaced by a file."""
    old = tmp_path / "old.txt"
    old.write_text("x")
    old.chmod(0o640)
    _files.write_text(old, "y")
    assert old.read_text() == "y"
    assert stat.S_IMODE(old.stat().st_mode) == 0o640
    plain = tmp_path / "plain.txt"
    plain.write_text("by open")
    new = tmp_path / "new.txt"
    _files.write_text(new, "z")
    assert stat.S_IMODE(new.stat().st_mode) == stat.S_IMODE(plain.stat().st_mode)
    link = tmp_path / "link.txt"
    link.symlink_to(old)
    _files.write_text(link, "through")
    assert link.is_symlink() and old.read_text() == "through"
    assert _leftovers(tmp_path, {"old.txt", "plain.txt", "new.txt", "link.txt"}) == []


@pytest.mark.parametrize(
    "command",
    [
        ["run", str(SCENE), "--series", "{bad}/x.csv"],
        [
            "compare",
            "--laws",
            "thesis_published",
            "--measurements",
            "thesis:table_3_1",
            "--quiet",
            "--out",
            "{bad}/x.json",
        ],
        ["calibrate", "--params", "eta_v", "--out", "{bad}/x.csv"],
        ["scene", "new", "--force", "--out", "{bad}/x.toml"],
    ],
    ids=["run", "compare", "calibrate", "scene"],
)
def test_an_output_path_that_cannot_be_written_is_refused_first(command, tmp_path, capsys):
    """An output file in a missing directory, or where a directory is, is the caller's
    error, found before the work (exit 2, one line naming the option); it was an OSError
    after the run (exit 1) or a traceback."""
    from granrs.cli import main

    (tmp_path / "dir.csv").mkdir()
    for bad, args in (
        ("missing", [a.replace("{bad}", str(tmp_path / "missing")) for a in command]),
        ("a directory", [*command[:-1], str(tmp_path / "dir.csv")]),
    ):
        assert main(args) == 2, (bad, capsys.readouterr())
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("granrs: error: cannot write"), err
        assert ("does not exist" if bad == "missing" else "is a directory") in err[0]


#: Calls that write a file given by path or handle. Each must write the temporary file of
#: ``granrs._files.replacing`` (named ``tmp``) or an in-memory buffer.
_WRITES = re.compile(
    r"\.write_text\(|\.write_bytes\(|\.to_csv\(|\.to_parquet\(|savefig\(|\.save\(|"
    r"open\([^)]*[\"'][wax]b?\+?[\"']|json\.dump\("
)


def test_every_writer_of_the_package_writes_whole() -> None:
    """One helper for every file granrs writes: a direct write of a path anywhere else in
    the package (``Path.write_text``, ``DataFrame.to_csv``, ``savefig``, ...) would be a
    writer that can leave a half-written file (issue 34)."""
    direct = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name == "_files.py":
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            code = line.split("#", 1)[0]
            # A medium card's own `save` writes through the whole-file helper (checked
            # below): a call of it is not a direct write.
            code = re.sub(r"\.card\(.*\)\.save\(", "", code)
            if _WRITES.search(code) and not re.search(r"\btmp\b|\bbuf(fer)?\b", code):
                direct.append(f"{path.relative_to(PACKAGE)}:{number}: {line.strip()}")
    assert direct == []
    media = (PACKAGE / "media" / "__init__.py").read_text(encoding="utf-8")
    save = media[media.index("    def save(") :].split("\n\n", 1)[0]
    assert "write_text(path, text)" in save
    assert "from .._files import write_text" in media


# ------------------------------------------------------------------------------------------
# The report's directory, all or nothing


def _toy_chapter(monkeypatch, built: list[str]) -> None:
    """Replace the report's chapters by one that runs nothing and writes a figure and a
    file (``toy.json``), so that the install is tested without the thesis's runs."""
    from granrs.report import framework

    def build(ctx: Any) -> str:
        built.append("toy")
        link = ctx.add_figure("new.png", b"\x89PNG new", "new")
        ctx.add_file("toy.json", b"{}\n")
        return f"text\n\n{link}\n"

    chapters = {"toy": framework.Chapter("toy", "A toy chapter", build)}
    monkeypatch.setattr(framework, "CHAPTERS", chapters)


def _old_report(out: Path) -> dict[str, bytes]:
    """An existing report directory with a user's own file; its files by relative path."""
    (out / "figures").mkdir(parents=True)
    (out / "figures" / "old.png").write_bytes(b"\x89PNG old")
    (out / "notes.txt").write_text("mine")
    return _tree(out)


def _tree(out: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(out)): (p.read_bytes() if p.is_file() else b"<dir>")
        for p in sorted(out.rglob("*"))
    }


def test_reproduce_refuses_a_readme_folder_before_any_run(tmp_path, monkeypatch) -> None:
    """Issue 34: ``granrs reproduce --out DIR`` whose README.md is a directory deleted the
    old figures, installed the new ones, then failed. Now it is refused before any run
    (typed error, field ``out_dir``) and the directory is as it was."""
    from granrs.report import reproduce

    built: list[str] = []
    _toy_chapter(monkeypatch, built)
    out = tmp_path / "report"
    _old_report(out)
    (out / "README.md").mkdir()
    before = _tree(out)
    with pytest.raises(InvalidParameterError) as info:
        reproduce(out, chapters=["toy"], progress=False)
    assert info.value.field == "out_dir"
    assert "README.md" in str(info.value)
    assert built == []
    assert _tree(out) == before
    assert _leftovers(tmp_path, {"report"}) == []


def test_reproduce_refuses_a_chapter_file_that_is_a_folder(tmp_path, monkeypatch) -> None:
    """A chapter's file (``toy.json``) that exists as a folder is refused before anything
    moves: the old figures stay (they were replaced before the failing move)."""
    from granrs.report import reproduce

    built: list[str] = []
    _toy_chapter(monkeypatch, built)
    out = tmp_path / "report"
    _old_report(out)
    (out / "toy.json").mkdir()
    before = _tree(out)
    with pytest.raises(InvalidParameterError) as info:
        reproduce(out, chapters=["toy"], progress=False)
    assert info.value.field == "out_dir"
    assert _tree(out) == before
    assert _leftovers(tmp_path, {"report"}) == []


def test_reproduce_undoes_the_install_when_a_move_fails(tmp_path, monkeypatch) -> None:
    """Whatever fails while the new report is moved in (here: the move of README.md, made
    to fail), the moves already made are undone: the old figures, the old chapter file
    and the old report are back, the user's own file untouched."""
    from granrs.report import framework, reproduce

    built: list[str] = []
    _toy_chapter(monkeypatch, built)
    out = tmp_path / "report"
    _old_report(out)
    (out / "README.md").write_text("old report")
    (out / "toy.json").write_text("old file")
    before = _tree(out)
    real_replace = os.replace

    def failing_replace(src: Any, dst: Any) -> None:
        # The new report's move into place fails (not the moves that undo).
        if Path(dst) == out.absolute() / "README.md" and Path(src).parent.name == "report":
            raise OSError(28, "No space left on device", str(dst))
        real_replace(src, dst)

    monkeypatch.setattr(framework.os, "replace", failing_replace)
    with pytest.raises(OSError):
        reproduce(out, chapters=["toy"], progress=False)
    monkeypatch.setattr(framework.os, "replace", real_replace)
    assert built == ["toy"]
    assert _tree(out) == before
    assert _leftovers(tmp_path, {"report"}) == []
    # And without the failure the new report is installed, the user's file kept.
    reproduce(out, chapters=["toy"], progress=False)
    after = _tree(out)
    assert after["figures/new.png"] == b"\x89PNG new"
    assert "figures/old.png" not in after
    assert after["toy.json"] == b"{}\n"
    assert after["notes.txt"] == b"mine"


# ------------------------------------------------------------------------------------------
# Scene files read safely


def _granrs_process(args: list[str], cwd: Path, prefix: str = "") -> subprocess.CompletedProcess:
    """``granrs ARGS`` in a child process (``prefix``: shell commands first, e.g. a
    ulimit), with a timeout: a hang is a failure, not a stuck suite."""
    command = " ".join(shlex.quote(a) for a in [sys.executable, "-m", "granrs.cli", *args])
    env = {**os.environ, "PYTHONPATH": str(PACKAGE.parent), "PYTHONDONTWRITEBYTECODE": "1"}
    return subprocess.run(
        ["bash", "-c", f"{prefix}exec {command}"],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )


def _one_error_line(proc: subprocess.CompletedProcess) -> str:
    assert proc.returncode == 2, proc.stderr[-2000:]
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("granrs: error: "), lines[:5]
    return lines[0]


NESTED = {
    "arrays": "[" * 500 + "]" * 500,
    "inline tables": "{a = " * 500 + "1" + "}" * 500,
    "arrays past the limit": "[" * 40 + "1.0" + "]" * 40,
}


@pytest.mark.parametrize("value", list(NESTED.values()), ids=list(NESTED))
def test_deep_nesting_is_one_line_and_exit_2(value, tmp_path, capsys) -> None:
    """Issue 34: a value nested 500 deep crashed ``granrs run`` with a 3,002-line
    RecursionError (tomllib recurses per level). Now, in the file or in ``--set``, it is
    one line naming the key, exit 2; 40 levels (which tomllib parses) are refused by the
    same limit, ``granrs.scenefile.MAX_NESTING``."""
    from granrs import scenefile
    from granrs.cli import main
    from granrs.errors import InvalidSceneError

    path = tmp_path / "deep.toml"
    path.write_text(f"q_deg = {value}\n")
    assert main(["run", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nested more than 32" in err[0], err[:3]
    assert main(["run", str(SCENE), "--set", f"q_deg={value}"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nested more than 32" in err[0] and "q_deg" in err[0], err[:3]
    with pytest.raises(InvalidSceneError, match="nested more than 32"):
        scenefile.loads(f"q_deg = {value}\n")


def test_nesting_within_the_limit_reads_as_before() -> None:
    """A linkage's tables (five deep) read, and a value nested to the limit reaches the
    scene's own check (a wrong type), not the nesting limit."""
    from granrs import scenefile
    from granrs.errors import InvalidSceneError

    linkage = (ROOT / "examples" / "scenes" / "three_link_pendulum.toml").read_text()
    assert scenefile.loads(linkage).kind == "linkage"
    value = "[" * 31 + "1.0" + "]" * 31  # 32 deep with the file's top level
    with pytest.raises(InvalidSceneError) as info:
        scenefile.loads(f"q_deg = {value}\n")
    assert "nested more than" not in str(info.value)
    assert info.value.field == "q_deg"


def test_dev_zero_is_refused_before_it_is_read(tmp_path) -> None:
    """Issue 34: ``granrs run /dev/zero`` read until memory ran out (MemoryError). Now a
    file that is not a regular file is refused before any read; the child runs under a
    1 GB address-space limit so that the old behaviour fails fast."""
    if not Path("/dev/zero").exists():
        pytest.skip("no /dev/zero")
    proc = _granrs_process(["run", "/dev/zero"], tmp_path, prefix="ulimit -v 1000000 && ")
    line = _one_error_line(proc)
    assert "/dev/zero" in line and "not a regular file" in line


def test_a_pipe_is_refused_without_waiting_for_it(tmp_path) -> None:
    """A named pipe with no writer: reading it would wait forever (the old reader hung);
    it is refused from its kind, without opening it."""
    fifo = tmp_path / "scene.toml"
    os.mkfifo(fifo)
    line = _one_error_line(_granrs_process(["run", str(fifo)], tmp_path))
    assert "not a regular file" in line


def test_a_file_above_the_limit_is_refused_before_it_is_read(tmp_path) -> None:
    """A scene file larger than ``MAX_FILE_BYTES`` (here a sparse file of 64 MiB, which the
    old reader read whole, as it would any size) is refused from its size."""
    from granrs import scenefile
    from granrs.errors import InvalidSceneError

    big = tmp_path / "big.toml"
    with open(big, "wb") as handle:
        handle.truncate(64 << 20)
    with pytest.raises(InvalidSceneError) as info:
        scenefile.load(big)
    assert info.value.field == "scene"
    assert str(scenefile.MAX_FILE_BYTES) in str(info.value)
    line = _one_error_line(_granrs_process(["run", str(big)], tmp_path))
    assert "larger than" in line


def test_a_byte_order_mark_is_accepted(tmp_path) -> None:
    """Issue 34: a UTF-8 scene file starting with a byte-order mark (as some Windows
    editors write it) was refused as invalid TOML. It reads as the same file without it,
    through every reader: the CLI, ``scenefile.load`` and ``scenefile.loads``."""
    from granrs import Scene, scenefile
    from granrs.cli import main

    text = "q_deg = 30.0\nv0 = 1.5\n"
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode())
    expected = Scene(q_deg=30.0, v0=1.5)
    assert scenefile.load(path) == expected
    assert scenefile.loads("\ufeff" + text) == expected
    assert main(["run", str(path), "--json"]) == 0


def test_a_file_that_is_not_utf8_is_a_typed_error(tmp_path) -> None:
    """Bytes that are not UTF-8 raise the scene file's typed error from every reader (from
    Python it was a UnicodeDecodeError)."""
    from granrs import scenefile
    from granrs.errors import InvalidSceneError

    path = tmp_path / "latin1.toml"
    path.write_bytes('apply_at = "tip" # caf\xe9\n'.encode("latin-1"))
    with pytest.raises(InvalidSceneError) as info:
        scenefile.load(path)
    assert info.value.field == "scene" and "UTF-8" in str(info.value)


#: Keys a random scene file sets (fields of each kind, and one unknown).
_KEYS = st.sampled_from(
    ["q_deg", "v0", "dt", "body", "record", "knee", "forces", "apply_at", "t_end", "nope"]
)
_VALUES = st.recursive(
    st.one_of(st.integers(), st.floats(), st.text(max_size=5), st.booleans()),
    lambda inner: st.one_of(
        st.lists(inner, max_size=3),
        st.dictionaries(st.text("abck", min_size=1, max_size=2), inner, max_size=3),
    ),
    max_leaves=20,
)


@settings(max_examples=300, deadline=None)
@given(st.dictionaries(_KEYS, _VALUES, max_size=4), st.booleans())
def test_any_scene_file_is_a_scene_or_a_typed_error(data, bom) -> None:
    """Whatever a scene file's keys hold (any TOML value, nested), reading it gives a
    scene or a granrs error, never another exception; with a byte-order mark the same."""
    from granrs import scenefile
    from granrs.errors import GranrsError

    text = "\n".join(f"{k} = {scenefile._format_value(v)}" for k, v in data.items())
    outcomes = []
    for t in (text, "\ufeff" + text) if bom else (text,):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", granrs.StepSizeWarning)
                outcomes.append(scenefile.loads(t))
        except GranrsError as exc:
            outcomes.append(type(exc))
    assert len(set(map(repr, outcomes))) == 1


@settings(max_examples=300, deadline=None)
@given(st.text(max_size=200))
def test_any_text_is_a_scene_or_a_typed_error(text) -> None:
    """Arbitrary text as a scene file, or as a ``--set`` value: a scene (or a value), or a
    granrs error; never another exception (a RecursionError, a UnicodeError, ...)."""
    from granrs import scenefile
    from granrs.errors import GranrsError

    for parse in (scenefile.loads, lambda t: scenefile.parse_override(f"q_deg={t}")):
        try:
            parse(text)
        except GranrsError:
            pass
