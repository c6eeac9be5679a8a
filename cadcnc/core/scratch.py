"""Per-period arrays that need not live in memory: a long stream's positions, what HAL
executed. Up to IN_MEMORY_ROWS rows an array is in memory; past that it is mapped from a
nameless scratch file (gone with the array, and with the process if it dies), so that a
stream's memory stays the same whatever its length and the OS pages the rows.
"""

from __future__ import annotations

import errno
import os
import tempfile

import numpy as np

from .errors import OutputError

IN_MEMORY_ROWS = 1 << 18
"""Rows of an array kept in memory; more are mapped from a scratch file (6 MB of 3
float64 columns)."""


def rows_array(rows: int, folder: str | None, what: str, columns: int = 3) -> np.ndarray:
    """(rows, columns) float64, uninitialised: in memory up to IN_MEMORY_ROWS, else mapped
    from a nameless scratch file in ``folder`` (None: the temporary folder TMPDIR names)
    whose room is taken on the disk now. OutputError naming ``what`` (e.g. "the stream's
    positions"), the folder and the size when the disk has no room or the folder is not
    there."""
    if rows <= IN_MEMORY_ROWS:
        return np.empty((rows, columns))
    size = rows * columns * 8
    folder = folder or tempfile.gettempdir()
    try:
        with tempfile.TemporaryFile(dir=folder) as f:
            _reserve(f, size)
            return np.memmap(f, dtype=np.float64, mode="w+", shape=(rows, columns))
    except OSError as e:
        raise OutputError(f"the scratch file of {what}, {size / 1e6:.3g} MB in {folder}: "
                          f"{e.strerror or e}; free some room there or stream fewer "
                          "periods") from None


def _reserve(f, size: int) -> None:
    """The file's ``size`` bytes taken on the disk now (a full disk refuses here, not as
    a fault while the rows are written), or merely set where the system or the file
    system cannot."""
    reserve = getattr(os, "posix_fallocate", None)   # (not on macOS or Windows)
    try:
        if reserve is not None:
            reserve(f.fileno(), 0, size)
            return
    except OSError as e:
        if e.errno not in (errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL):
            raise
    f.truncate(size)
