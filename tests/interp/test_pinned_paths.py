"""Every fixture pair's path is pinned: a change of behaviour shows, in either direction.

fixtures/pinned_paths.npz was written by fixtures/build_pinned_paths.py (R 3 mm, 1.5 in
narrow_slot; f = 0.1 mm). Points and contact parameters must agree to 1e-12 (mm, or
native parameter units); the eq. 16 bounds to 1e-12 relative to the
path's largest bound. A change made on purpose
regenerates the file in the same commit.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers.fixtures import FIXTURES, load_fixture
from helpers.pinned import CASES, compute

PINNED = np.load(FIXTURES / "pinned_paths.npz")


def test_every_concave_pair_is_pinned():
    assert {f"{key}_points" for key, *_ in CASES} == {k for k in PINNED.files
                                                      if k.endswith("_points")}


@pytest.mark.parametrize("key, name, i, j", CASES, ids=[c[0] for c in CASES])
def test_fixture_path_is_unchanged(key, name, i, j):
    tp = compute(load_fixture(name), name, i, j)
    points, uv = PINNED[f"{key}_points"], PINNED[f"{key}_uv"]
    assert tp.points.shape == points.shape
    np.testing.assert_allclose(tp.points, points, rtol=0, atol=1e-12)
    np.testing.assert_allclose(tp.uv, uv, rtol=0, atol=1e-12)
    eq16 = PINNED[f"{key}_eq16"]
    # relative to each bound's own scale: a per-element 1e-12 on values 1e-6 below their
    # neighbours compares last-digit noise of the cancellation (1e-18 mm seen across builds)
    np.testing.assert_allclose(np.stack([b.eq16 for b in tp.bounds]), eq16, rtol=1e-12,
                               atol=1e-12 * float(np.abs(eq16).max()))
