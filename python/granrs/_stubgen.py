"""Write the type stub of :mod:`granrs.forces`'s term constructors from the core's registry.

``python -m granrs._stubgen`` writes ``granrs/_constructors.pyi``; ``--check`` only says
whether the file is up to date (exit status 1 if not). Run it after adding a term to the
core; ``tests/test_forces_generated.py`` fails until then.
"""

from __future__ import annotations

import sys
from pathlib import Path

from . import forces
from ._files import replacing

#: The stub's path.
PATH = Path(__file__).with_name(f"{forces.STUB_MODULE}.pyi")


def text() -> str:
    """The stub, generated from the registry of the compiled core."""
    return forces.stub(forces.info(name) for name in forces.TERMS)


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    new = text()
    old = PATH.read_text(encoding="utf-8") if PATH.exists() else None
    if "--check" in args:
        if old != new:
            print(f"{PATH} is out of date: run python -m granrs._stubgen", file=sys.stderr)
            return 1
        return 0
    if old != new:
        with replacing(PATH) as tmp:
            tmp.write_text(new, encoding="utf-8")
        print(f"wrote {PATH}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
