"""The README's code blocks run as written: its Python examples (a five-line example first),
its ``granrs`` commands, and its install, test and docs commands are the ones CI runs."""

from __future__ import annotations

import contextlib
import io
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def _python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


def test_readme_has_a_short_python_example() -> None:
    blocks = _python_blocks()
    assert blocks, "README has no python example"
    code_lines = [ln for ln in blocks[0].splitlines() if ln.strip()]
    assert len(code_lines) <= 6


def test_readme_python_examples_run() -> None:
    outputs = []
    for block in _python_blocks():
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(compile(block, str(README), "exec"), {})
        outputs.append(out.getvalue())
    assert "stopped after" in outputs[0] and "mm depth" in outputs[0]
    # Every later example prints something (a table or an array).
    assert all(text.strip() for text in outputs[1:])


# --- the shell blocks ------------------------------------------------------------------------

CI_RUN = README.parent / ".ci" / "run"


def _bash_blocks() -> list[str]:
    return re.findall(r"```bash\n(.*?)```", README.read_text(), flags=re.S)


def _commands(block: str) -> list[str]:
    """The commands of a shell block: its non-empty lines, without trailing comments."""
    lines = (re.sub(r"\s+#.*$", "", line).strip() for line in block.splitlines())
    return [line for line in lines if line and not line.startswith("#")]


def test_readme_starts_with_the_two_commands_that_ci_runs() -> None:
    """The README's first shell block is exactly two commands (install and reproduce;
    install the test extras and run every test), and CI runs the second as written, so the
    README's test command is the one that is tested. The README's docs command is the one
    CI builds the site with."""
    first = _commands(_bash_blocks()[0])
    assert len(first) == 2, first
    assert first[0].endswith("pip install . && granrs reproduce --out granrs-report")
    assert first[1].endswith("pip install -e '.[test]' && cargo test && pytest -n auto")
    ci = CI_RUN.read_text()
    assert first[1] in ci.splitlines()
    docs = [c for b in _bash_blocks() for c in _commands(b) if "sphinx-build" in c]
    assert len(docs) == 1, docs
    assert docs[0] in ci, "CI does not build the docs with the README's docs command"


def _granrs_commands() -> list[str]:
    return [c for b in _bash_blocks() for c in _commands(b) if c.startswith("granrs ")]


def test_readme_has_granrs_commands() -> None:
    """The test below has something to run."""
    assert len(_granrs_commands()) >= 2


@pytest.mark.parametrize("command", _granrs_commands())
def test_readme_granrs_commands_run(command: str, tmp_path: Path) -> None:
    """Every ``granrs ...`` line of the README's shell blocks runs as written (from a
    directory that has the repository's ``examples/``), exits 0 and prints no traceback.
    The reproduce command of the first block is run by the README's first command, not
    here (minutes)."""
    (tmp_path / "examples").symlink_to(README.parent / "examples")
    script = Path(sys.executable).with_name("granrs")
    assert script.is_file(), f"no granrs command beside {sys.executable}: is granrs installed?"
    argv = [str(script), *shlex.split(command)[1:]]
    done = subprocess.run(argv, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr


def test_readme_links_and_paths_exist_in_a_clone() -> None:
    """Every relative link of the README, and every repository path it names in backticks,
    is in the repository: no pointer to a file a clone does not have (it once sent readers
    to ``../shared/MODEL.md``)."""
    text = README.read_text()
    root = README.parent
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text)
    local = [link for link in links if not re.match(r"[a-z]+://", link)]
    assert local, "the README links no page of the docs"
    missing = [link for link in local if not (root / link).exists()]
    named = re.findall(r"`((?:docs|examples|benches|tests|python|rust|\.ci)/[^`\s]*)`", text)
    # (docs/_build/ is what the docs command writes, not a file of the clone.)
    missing += [p for p in named if not p.startswith("docs/_build/") and not (root / p).exists()]
    assert not missing, missing
    assert "shared/" not in text and "MODEL.md" not in text
