"""The stream's own limit check (``stream._peaks``, compiled) finds the same largest
finite differences, at the same periods, as NumPy's repeated ``diff`` over the same
blocks: on smooth and rounded (tied) positions, across a block's edge, and with a
position that is not a number (its block's order skipped)."""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc.controller import stream


def _reference(positions: np.ndarray, chunk: int):
    peak, where = np.zeros((3, 3)), np.zeros((3, 3), dtype=np.int64)
    for start in range(0, max(len(positions) - 1, 1), chunk):
        block = positions[start:start + chunk + 3]
        for k in range(1, 4):
            if len(block) <= k:
                continue
            d = np.abs(np.diff(block, k, axis=0))
            top = d.max(axis=0)
            if np.isnan(top).any():
                continue
            row = d.argmax(axis=0)
            better = top > peak[k - 1]
            peak[k - 1][better] = top[better]
            where[k - 1][better] = start + row[better] + k
    return peak, where


@pytest.mark.parametrize("n", [1, 2, 4, 1000, 2 * 977 + 5])
@pytest.mark.parametrize("kind", ["smooth", "nan", "ties"])
def test_peaks_as_numpy(n, kind, monkeypatch):
    monkeypatch.setattr(stream, "CHUNK", 977)   # several blocks
    rng = np.random.default_rng(n)
    x = np.cumsum(np.cumsum(rng.normal(size=(n, 3)), axis=0), axis=0)
    if kind == "nan" and n > 3:
        x[n // 2, 1] = np.nan
    if kind == "ties":
        x = np.round(x)
    got, want = stream._peaks(x), _reference(x, 977)
    assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
    if n > 3 and kind != "nan":
        assert got[0].min() > 0.0
