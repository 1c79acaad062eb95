"""Every shipped example scene runs as a user runs it: the installed ``granrs`` command on
each ``examples/scenes/*.toml``, once with the text summary and once with ``--json``, in a
process of its own. Each must exit 0 with its summary on standard output and nothing on
standard error: no traceback, no warning.

The gallery scripts (``examples/gallery/``) are run by the documentation build (sphinx-gallery,
``abort_on_example_error``), which ``.ci/run`` does in a venv made with the README's docs
command; ``tests/test_docs_api.py`` then checks that each drew its figure. The README's code
blocks are run by ``tests/test_readme.py``.

Written against a shipped scene that crashed: ``granrs run
examples/scenes/three_link_pendulum.toml`` (a scene with no contact) ended in an IndexError
traceback from the text summary while ``--json`` worked, and no test ran the text summary
of the example scenes.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCENES = sorted((ROOT / "examples" / "scenes").glob("*.toml"))


def _granrs() -> list[str]:
    """The ``granrs`` command of the running environment (its console script beside the
    interpreter, as ``pip install`` puts it), else the same entry point through Python."""
    script = Path(sys.executable).with_name("granrs")
    if script.is_file():
        return [str(script)]
    return [sys.executable, "-c", "import sys; from granrs.cli import main; sys.exit(main())"]


def _run(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*_granrs(), *args],
        cwd=cwd,
        env=os.environ.copy(),
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_the_example_scenes_are_there() -> None:
    """The examples the docs list (docs/scenes_toml.md) ship: a rename cannot empty the
    tests below unnoticed."""
    names = {p.name for p in SCENES}
    listed = (ROOT / "docs" / "scenes_toml.md").read_text(encoding="utf-8")
    assert len(names) >= 5, names
    assert all(f"`{name}`" in listed for name in names), "docs/scenes_toml.md misses a scene"


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_example_scene_runs_with_the_text_summary(path: Path, tmp_path: Path) -> None:
    done = _run("run", str(path), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    assert "status" in done.stdout


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_example_scene_runs_as_json(path: Path, tmp_path: Path) -> None:
    done = _run("run", "--json", str(path), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    summary = json.loads(done.stdout)
    assert summary["status"] in ("stopped", "end_time"), summary["status"]
    assert summary["body"] in done.stdout
