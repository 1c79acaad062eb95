"""Loading the repository's scripts (benches, the docs' extension) as modules in tests: they
are files, not part of the installed package."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

#: The repository's root (this file is in its ``tests``).
REPO = Path(__file__).resolve().parents[1]


def load_module(name: str, path: Path, reuse: bool = False) -> ModuleType:
    """The script at ``path`` run as a module named ``name`` and registered in
    ``sys.modules`` under it (its dataclasses and pickles look their module up there). Each
    call runs it afresh, unless ``reuse`` and a module of that name is loaded already."""
    if reuse and name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module
