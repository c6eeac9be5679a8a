"""``TrimGrid.classify_grid`` (a sampling grid's nodes read from the trim grid in one
compiled call, FClass2d asked only in MIXED cells) against ``FaceSurface.classify`` node
by node, on trimmed faces: holes, pockets, periodic ones and a B-spline."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import cadcnc
from cadcnc.geometry.trim_grid import TrimGrid

FIXTURES = Path(__file__).resolve().parents[2] / "fixtures"
CASES = ["finish_hole", "six_pockets", "thin_ring", "finish_wave", "dome_pole"]


@pytest.mark.parametrize("name", CASES)
def test_grid_nodes_agree_with_fclass2d(name):
    """Every face: a 61 x 47 grid over the face's (u, w) box enlarged 3 % each side, so
    that nodes fall inside, outside and beside every trim: 0 disagreements, and the
    face's own ``classify_grid`` (the sampler's) is the same."""
    part = cadcnc.load_step(FIXTURES / f"{name}.step")
    checked = outside = 0
    for face in part.faces:
        grid = TrimGrid.build(face)
        (u0, u1), (w0, w1) = face.u_range, face.w_range
        us = np.linspace(u0 - 0.03 * (u1 - u0), u1 + 0.03 * (u1 - u0), 61)
        ws = np.linspace(w0 - 0.03 * (w1 - w0), w1 + 0.03 * (w1 - w0), 47)
        got = grid.classify_grid(us, ws)
        expected = np.array([[face.classify(u, w) for w in ws] for u in us], dtype=object)
        assert got.shape == (61, 47)
        bad = [(face.number, a, b, expected[a, b], got[a, b])
               for a, b in zip(*np.nonzero(got != expected))]
        assert bad == [], bad[:5]
        assert (face.classify_grid(us, ws) == expected).all()
        checked += got.size
        outside += int((expected == "outside").sum())
    assert checked > 0 and outside > 0   # the trims were met
