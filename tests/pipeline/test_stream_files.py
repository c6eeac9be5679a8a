"""A stream's files are made a block of periods at a time: the same bytes as the whole
array saved and printed at once, and each .txt's numbers still checked as printed."""

from __future__ import annotations

import io
from types import SimpleNamespace

import numpy as np
import pytest

from cadcnc.controller.machine import Machine
from cadcnc.controller.stream import stream_text
from cadcnc.pipeline import streaming


def _program(positions):
    segment = SimpleNamespace(points=positions)
    return SimpleNamespace(segments=[segment])


@pytest.mark.parametrize("rows", [1, 5, 1000])
def test_the_files_are_the_whole_arrays_bytes(rows, monkeypatch):
    monkeypatch.setattr(streaming, "WRITE_ROWS", 7)
    t = np.arange(rows) * 1e-3
    positions = np.c_[np.sin(t), np.cos(t), 0.5 * t] * 0.1
    want = io.BytesIO()
    np.save(want, positions)
    assert b"".join(streaming._npy_chunks(positions)) == want.getvalue()
    text = "".join(streaming._txt_chunks(_program(positions), Machine.default(),
                                         positions, "s.txt"))
    assert text == stream_text(positions)


def test_a_printed_block_over_the_limits_is_refused(monkeypatch):
    monkeypatch.setattr(streaming, "WRITE_ROWS", 64)
    positions = np.zeros((500, 3))
    positions[300:, 0] = 0.01   # a 10 mm/s step in one period: far over any acceleration
    chunks = streaming._txt_chunks(_program(positions), Machine.default(), positions,
                                   "s.txt")
    with pytest.raises(streaming._PrintedOver) as over:
        list(chunks)
    assert "s.txt: acceleration of axis X" in over.value.problems[0]
    assert "at period 298" in over.value.problems[0]


def test_a_mapped_streams_files_are_the_arrays_bytes(monkeypatch, tmp_path):
    """A long stream's positions in a scratch file give the files of the same array in
    memory, byte for byte."""
    from cadcnc.core import scratch

    monkeypatch.setattr(scratch, "IN_MEMORY_ROWS", 10)
    monkeypatch.setattr(streaming, "WRITE_ROWS", 7)
    t = np.arange(100) * 1e-3
    positions = np.c_[np.sin(t), np.cos(t), 0.5 * t] * 0.1
    mapped = scratch.rows_array(len(positions), str(tmp_path), "the positions")
    mapped[:] = positions
    assert isinstance(mapped, np.memmap)
    assert b"".join(streaming._npy_chunks(mapped)) == b"".join(
        streaming._npy_chunks(positions))
    program = _program(positions)
    assert "".join(streaming._txt_chunks(program, Machine.default(), mapped, "s.txt")) == \
        stream_text(positions)
