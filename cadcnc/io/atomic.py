"""Atomic file writes: a failed or interrupted run never leaves a half-written file.

The bytes go to a temporary file in the destination's folder, which replaces the
destination only once complete (``os.replace``).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from ..core.errors import OutputError

NAME_MAX = 255  # bytes in one file name on common file systems
_TEMP_ROOM = 16  # bytes the temporary name adds: ".", mkstemp's 8 characters, ".tmp", a dot


def temp_prefix(path: Path) -> str:
    """The prefix of a temporary file beside ``path``: ``.NAME.``, NAME shortened so that
    the temporary name fits NAME_MAX bytes whenever the destination's name does."""
    name = os.fsencode(Path(path).name)[:NAME_MAX - _TEMP_ROOM]
    return "." + os.fsdecode(name) + "."


@contextlib.contextmanager
def atomic_write(path, mode: str = "w", newline: str | None = None):
    """Open a temporary file beside ``path``; on success it replaces ``path``.

    On any exception the temporary file is removed and ``path`` is left as it was.
    ``OSError`` from creating or replacing the file becomes :class:`OutputError`.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(f"{path}: cannot write, folder {folder} does not exist")
    try:
        fd, tmp = tempfile.mkstemp(prefix=temp_prefix(path), suffix=".tmp", dir=folder)
    except OSError as e:
        raise OutputError(f"{path}: cannot write ({e.strerror})") from e
    try:
        kwargs = {} if "b" in mode else {"encoding": "utf-8", "newline": newline}
        with os.fdopen(fd, mode, **kwargs) as fh:
            yield fh
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException as e:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(e, OSError):
            raise OutputError(f"{path}: cannot write ({e.strerror or e})") from e
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_text(path, text: str) -> None:
    with atomic_write(path) as fh:
        fh.write(text)


def write_bytes(path, data: bytes) -> None:
    with atomic_write(path, "wb") as fh:
        fh.write(data)
