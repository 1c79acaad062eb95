"""Files written whole: every file granrs writes goes through :func:`replacing`.

A writer that opens its target and writes into it leaves a half-written file when it
fails part way (a full disk, a file size limit, Ctrl-C): the previous file is lost and
the new one is not there. Here the content goes to a temporary file in the target's
directory (so that the rename stays on one file system), is flushed to the disk, and
replaces the target in one ``os.replace``; on any error the temporary file is removed and
the target is as it was.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path

from .errors import InvalidParameterError

__all__ = ["check_target", "replacing", "write_bytes", "write_text"]


def check_target(path: str | os.PathLike[str], field: str, what: str = "") -> Path:
    """Check, before any work, that a file can be written at ``path``: its directory exists
    and is writable, and an existing ``path`` is a writable file, not a directory. Returns
    the path.

    Raises:
        InvalidParameterError: ``field`` names the option, the message the reason.
    """
    out = Path(path)
    label = f"cannot write {what + ' ' if what else ''}{out}"
    directory = out.parent
    if not directory.is_dir():
        raise InvalidParameterError(
            f"{label}: the directory {directory} does not exist", field=field
        )
    if not os.access(directory, os.W_OK | os.X_OK):
        raise InvalidParameterError(
            f"{label}: the directory {directory} is not writable", field=field
        )
    if out.exists() and (out.is_dir() or not os.access(out, os.W_OK)):
        raise InvalidParameterError(
            f"{label}: it exists and is {'a directory' if out.is_dir() else 'not writable'}",
            field=field,
        )
    return out


def _temporary(target: Path) -> Path:
    """A new empty file beside ``target``, hidden, with its suffix (writers such as
    matplotlib's choose the format by it), created with the usual permissions (0666 less
    the umask, as ``open`` gives)."""
    while True:
        tmp = target.with_name(f".{target.name}.{secrets.token_hex(4)}.tmp{target.suffix}")
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:  # pragma: no cover - 32 random bits
            continue
        os.close(fd)
        return tmp


def _sync(path: Path) -> None:
    """Flush ``path``'s data to the disk (a full disk may only say so here)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def replacing(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Write a file whole: yields a temporary path beside ``path`` for the caller to write
    (``frame.to_csv(tmp)``, ``anim.save(tmp)``, ...); when the block ends without an error
    the temporary file replaces ``path`` (keeping an existing file's permissions; a
    symbolic link is written through), else it is removed and ``path`` is untouched."""
    target = Path(path)
    if target.is_symlink():
        target = target.resolve()
    tmp: Path | None = None
    try:
        tmp = _temporary(target)
        yield tmp
        _sync(tmp)
        with contextlib.suppress(FileNotFoundError):
            os.chmod(tmp, stat.S_IMODE(os.stat(target).st_mode))
        os.replace(tmp, target)
    except BaseException as exc:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        if isinstance(exc, OSError) and exc.errno is not None:
            # Name the file the caller asked for (not the temporary one, nor none).
            raise OSError(exc.errno, exc.strerror, os.fspath(path)) from exc
        raise


def write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` whole (see :func:`replacing`)."""
    with replacing(path) as tmp:
        tmp.write_bytes(data)


def write_text(path: str | os.PathLike[str], text: str, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` whole (see :func:`replacing`)."""
    with replacing(path) as tmp:
        tmp.write_text(text, encoding=encoding)
