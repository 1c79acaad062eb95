"""The README's Python examples run as written (issue 2: a five-line API example that runs)."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

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
