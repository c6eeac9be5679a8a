"""HAL's samples read back a block of lines at a time (no HAL needed): the same facts as
the whole file read at once, and the commanded and executed positions in a scratch file
past IN_MEMORY_ROWS."""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc.controller.hal import loop
from cadcnc.controller.hal.session import HalError
from cadcnc.core import scratch


def _samples(n: int, tail: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A program of n rows and halsampler's (n + tail, 8) samples of it: a few clipped
    samples, underruns counted up, two tags lost."""
    rng = np.random.default_rng(seed)
    rows = np.cumsum(rng.normal(scale=1e-3, size=(n, 3)), axis=0)
    total = n + tail
    cmd = np.vstack([rows, np.repeat(rows[-1:], tail, axis=0)]) * 1e3
    exe = cmd.copy()
    clipped = rng.choice(total, size=9, replace=False)
    exe[clipped, rng.integers(0, 3, 9)] += 0.004   # 4 nm off
    tags = np.arange(total) + np.cumsum(np.isin(np.arange(total), [17, 40]))
    under = np.cumsum(rng.random(total) < 0.05)
    return rows, np.column_stack([tags, np.round(cmd, 6), np.round(exe, 6), under])


def _whole(rows: np.ndarray, s: np.ndarray) -> dict:
    """The facts from the whole array (what the reader did before it read in blocks)."""
    n = len(rows)
    tags = s[:, 0].astype(np.int64)
    cmd, exe, under = s[:, 1:4] / 1e3, s[:, 4:7] / 1e3, s[:, 7].astype(np.int64)
    m = min(n, len(s))
    off = np.abs(exe - cmd).max(axis=1) > loop.SAMPLE_RES * 0.5
    return dict(read=len(s), underruns=int(under[m - 1] - under[0]),
                overruns=int(np.sum(np.diff(tags) - 1)), clipped=int(off[:m].sum()),
                clipped_tail=int(off[m:].sum()),
                command_error=float(np.abs(cmd[:m] - rows[:m]).max()),
                tracking_error=float(np.abs(exe[:m] - rows[:m]).max()),
                executed_error=float(np.abs(exe[:m] - cmd[:m]).max()), cmd=cmd, exe=exe)


@pytest.mark.parametrize("block, seed", [(7, 1), (50, 2), (1 << 16, 3)])
def test_samples_read_in_blocks_give_the_whole_files_facts(block, seed, monkeypatch,
                                                           tmp_path):
    monkeypatch.setattr(loop, "BLOCK", block)
    monkeypatch.setattr(scratch, "IN_MEMORY_ROWS", 60)
    rows, s = _samples(200, 25, seed)
    path = tmp_path / "samples.txt"
    np.savetxt(path, s, fmt=["%d"] + ["%.6f"] * 6 + ["%d"])
    got = loop._read_samples(path, rows, len(s), 0.001, 1.5, str(tmp_path))
    want = _whole(rows, np.loadtxt(path, ndmin=2))
    assert isinstance(got.executed, np.memmap)
    assert np.array_equal(got.commanded, want.pop("cmd"))
    assert np.array_equal(got.executed, want.pop("exe"))
    assert {k: getattr(got, k) for k in want} == want
    assert got.clipped + got.clipped_tail == 9 and got.overruns == 2


def test_samples_of_the_wrong_count_or_width_are_refused(tmp_path):
    rows, s = _samples(20, 5, 4)
    path = tmp_path / "samples.txt"
    np.savetxt(path, s[:, :7])
    with pytest.raises(HalError, match="gave 25 samples of 7 columns, expected 25 of 8"):
        loop._read_samples(path, rows, 25, 0.001, 1.0, None)
    np.savetxt(path, s)
    with pytest.raises(HalError, match="gave 25 samples of 8 columns, expected 30 of 8"):
        loop._read_samples(path, rows, 30, 0.001, 1.0, None)
    path.write_text("1 2 3\nnot a number\n")
    with pytest.raises(HalError, match="do not read"):
        loop._read_samples(path, rows, 2, 0.001, 1.0, None)


def test_a_saved_stream_is_mapped_and_checked_in_blocks(monkeypatch, tmp_path):
    """A .npy stream is mapped, not read into memory; a non-finite row anywhere is
    refused."""
    monkeypatch.setattr(loop, "BLOCK", 16)
    x = np.cumsum(np.ones((100, 3)), axis=0)
    np.save(tmp_path / "s.npy", x)
    got = loop.read_stream(tmp_path / "s.npy")
    assert not got.flags.owndata and np.array_equal(got, x)   # a view of the mapping
    x[77, 1] = np.inf
    with pytest.raises(HalError, match="finite"):
        loop.read_stream(x)


def test_the_stream_file_for_halstreamer_is_what_savetxt_printed(monkeypatch, tmp_path):
    """Printed a block at a time, the same bytes as ``np.savetxt`` with 9 decimals (what
    halstreamer read before), negative zeros and all."""
    monkeypatch.setattr(loop, "BLOCK", 16)
    x = np.random.default_rng(5).normal(scale=50.0, size=(100, 3))
    x[3] = [-0.0, 0.0, -1e-12]
    loop.write_stream_txt(x, tmp_path / "s.txt")
    np.savetxt(tmp_path / "ref.txt", x, fmt="%.9f", delimiter=" ")
    assert (tmp_path / "s.txt").read_bytes() == (tmp_path / "ref.txt").read_bytes()
