"""Progress bars of granrs's long commands: one tqdm bar on stderr, in the style of
:func:`granrs.sweep` and :func:`granrs.compare`."""

from __future__ import annotations

import sys
from typing import Any


def progress_bar(total: int | None, progress: bool | None, desc: str, unit: str) -> Any:
    """A ``tqdm.auto`` bar on stderr: ``progress`` None shows it when stderr is a terminal,
    True always, False never (a disabled bar accepts the same calls and prints nothing).
    ``total`` None counts without an end."""
    from tqdm.auto import tqdm

    from .errors import InvalidParameterError

    if not (progress is None or isinstance(progress, bool)):
        raise InvalidParameterError(
            f"progress must be True, False or None; got {progress!r}", field="progress"
        )
    disable = (not sys.stderr.isatty()) if progress is None else not progress
    return tqdm(total=total, unit=unit, desc=desc, disable=disable, file=sys.stderr)
