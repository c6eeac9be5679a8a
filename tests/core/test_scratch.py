"""Per-period arrays past IN_MEMORY_ROWS live in a nameless scratch file: mapped, gone
with the array, their disk room taken up front (no room: an OutputError naming the
folder and the size, not a fault while the rows are written)."""

from __future__ import annotations

import errno
import os

import numpy as np
import pytest

from cadcnc.core import scratch
from cadcnc.core.errors import OutputError


def test_a_short_array_is_in_memory_and_a_long_one_in_a_nameless_file(monkeypatch,
                                                                       tmp_path):
    monkeypatch.setattr(scratch, "IN_MEMORY_ROWS", 10)
    short = scratch.rows_array(10, str(tmp_path), "rows")
    assert not isinstance(short, np.memmap) and short.shape == (10, 3)
    rows = scratch.rows_array(1000, str(tmp_path), "rows", columns=2)
    rows[:] = 1.0
    assert isinstance(rows, np.memmap) and rows.shape == (1000, 2) and rows.sum() == 2000
    assert list(tmp_path.iterdir()) == []   # nameless: nothing left in the folder


def test_no_room_or_no_folder_is_an_output_error(monkeypatch, tmp_path):
    monkeypatch.setattr(scratch, "IN_MEMORY_ROWS", 10)

    def full(fd, offset, size):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "posix_fallocate", full)
    with pytest.raises(OutputError, match=f"the scratch file of the rows, 0.024 MB in "
                                          f"{tmp_path}: No space left"):
        scratch.rows_array(1000, str(tmp_path), "the rows")
    monkeypatch.undo()
    monkeypatch.setattr(scratch, "IN_MEMORY_ROWS", 10)
    with pytest.raises(OutputError, match="missing"):
        scratch.rows_array(1000, str(tmp_path / "missing"), "the rows")


def test_a_file_system_that_cannot_reserve_still_maps(monkeypatch, tmp_path):
    """posix_fallocate unsupported (or absent, as on macOS): the file is merely sized."""
    monkeypatch.setattr(scratch, "IN_MEMORY_ROWS", 10)

    def unsupported(fd, offset, size):
        raise OSError(errno.EOPNOTSUPP, os.strerror(errno.EOPNOTSUPP))

    monkeypatch.setattr(os, "posix_fallocate", unsupported)
    assert scratch.rows_array(100, str(tmp_path), "rows").shape == (100, 3)
    monkeypatch.delattr(os, "posix_fallocate")
    assert scratch.rows_array(100, str(tmp_path), "rows").shape == (100, 3)
