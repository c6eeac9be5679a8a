"""The stream's check fed in blocks (as a stream is printed and written) gives the verdict
of the whole array at once, and both agree with finite differences taken directly."""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc.verification import stream_check
from cadcnc.verification.stream_check import StreamChecker, check_stream

LIMITS = ((50.0, 40.0, 30.0), (400.0, 300.0, 200.0), (8000.0, 6000.0, 4000.0))
PERIOD = 0.001


def _stream(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    jerk = rng.normal(scale=3000.0, size=(n, 3))
    x = np.cumsum(np.cumsum(np.cumsum(jerk, axis=0) * PERIOD, axis=0) * PERIOD,
                  axis=0) * PERIOD
    x[n // 3] += 1e-4   # one period over every limit
    return x


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_blocks_of_any_size_give_the_whole_arrays_verdict(seed, monkeypatch):
    x = _stream(5000, seed)
    whole = check_stream(x, PERIOD, LIMITS, x[0], x[-1])
    assert not whole.ok
    for order, (kind, _) in enumerate(stream_check.KINDS, 1):   # against np.diff directly
        d = np.abs(np.diff(x, order, axis=0)) / PERIOD ** order
        assert list(whole.peaks[kind].values()) == d.max(axis=0).tolist()
        assert list(whole.over[kind].values()) == (
            d > np.asarray(LIMITS[order - 1]) * (1 + stream_check.STREAM_LIMIT_SLACK)
        ).sum(axis=0).tolist()
    monkeypatch.setattr(stream_check, "CHUNK", 37)
    rng = np.random.default_rng(seed)
    cuts = np.sort(rng.choice(np.arange(1, len(x)), size=40, replace=False))
    checker = StreamChecker(PERIOD, LIMITS)
    for part in np.split(x, np.r_[1, 2, cuts]):   # blocks of 1, 2 and any rows
        checker.feed(part)
    blocks = checker.result(x[0], x[-1])
    assert (blocks.ok, blocks.problems, blocks.peaks, blocks.over) == \
        (whole.ok, whole.problems, whole.peaks, whole.over)


def test_blocks_report_ends_and_a_non_finite_row_by_their_stream_row():
    x = _stream(300, 4)
    checker = StreamChecker(PERIOD, LIMITS)
    checker.feed(x[:100])
    checker.feed(x[100:])
    far = checker.result(x[0] + 1.0, x[-1])
    assert any("first position is 1 mm" in p for p in far.problems)
    y = x.copy()
    y[150, 1] = np.nan
    checker = StreamChecker(PERIOD, LIMITS)
    for part in np.split(y, [100, 200]):
        checker.feed(part)
    assert checker.result(y[0], y[-1]).problems == ["the stream: position 150 is not finite"]
    assert check_stream(y, PERIOD, LIMITS, y[0], y[-1]).problems == \
        ["the stream: position 150 is not finite"]


@pytest.mark.parametrize("rows, shape", [(5.0, "()"), ("abc", "()"), ([1.0, 2.0], "(2,)"),
                                         (np.zeros((4, 2)), "(4, 2)"),
                                         (np.zeros((0, 3)), "(0, 3)")])
def test_what_is_not_rows_of_positions_is_named_by_its_shape(rows, shape):
    """A scalar, text, a flat list or the wrong width: a verdict naming the shape given
    (no exception, no made-up shape)."""
    verdict = check_stream(rows, 0.001, ((1.0,) * 3,) * 3, (0, 0, 0), (0, 0, 0))
    assert not verdict.ok
    assert verdict.problems == [f"the stream: not an (N, 3) array of positions: {shape}"]
