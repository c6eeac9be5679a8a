"""``written_decimals``: the decimals a program writes, read back, without the text."""

from __future__ import annotations

import numpy as np
import pytest

from cadcnc.io.program_gcode import written_decimals


@pytest.mark.parametrize("digits", [0, 3, 4, 6])
def test_the_same_doubles_as_the_text_read_back(digits):
    """Random coordinates, exact halves and values a few ulps either side of them, signed
    zeros and tiny values: each bit for bit ``float(f"{v:.{digits}f}")`` (-0 as 0)."""
    rng = np.random.default_rng(digits)
    k = rng.integers(-2_000_000, 2_000_000, 20_000)
    half = (k + 0.5) / 10.0 ** digits
    near = np.concatenate([np.nextafter(half, np.inf), np.nextafter(half, -np.inf)])
    values = np.concatenate([rng.uniform(-2000.0, 2000.0, 50_000), half, near,
                             [0.0, -0.0, -1e-9, 1e-300, -5e-5, 5e-5, 1.5e-4, 1e17, -3e16]])
    got = written_decimals(values, digits)
    want = np.array([float(f"{v:.{digits}f}") + 0.0 for v in values.tolist()])
    assert got.view(np.int64).tolist() == want.view(np.int64).tolist()
