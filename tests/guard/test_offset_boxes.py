"""Offset faces get sound cell boxes (guard/face_boxes.py): every box of an offset of a
B-spline contains its piece of surface (dense samples, OCCT evaluation), its normal box
contains the normal, and the guard with the height cells on the offset face never calls
clear what the exact guard (OCCT distances only) calls a hit. The part: bspline_boss
offset outward by 1 mm (OCCT's offset shape: its B-spline faces become offset surfaces),
the corner case of ``python -m benchmarks profile corner``."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.BRepOffset import BRepOffset_Skin
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffsetShape
from OCP.GeomAbs import GeomAbs_Intersection

import cadcnc
from cadcnc.geometry.part import Part
from cadcnc.guard.cells import FaceBoxes, HeightCells, bounded
from cadcnc.guard.clearance import ClearanceGuard
from cadcnc.guard.face_boxes import face_cells, normal_box
from cadcnc.guard.guard import OperationGuard
from helpers.face_cells import random_cell_boxes
from helpers.fixtures import FIXTURES


@pytest.fixture(scope="module")
def offset_boss():
    maker = BRepOffsetAPI_MakeOffsetShape()
    maker.PerformByJoin(cadcnc.load_step(FIXTURES / "bspline_boss.step").shape, 1.0, 1e-6,
                        BRepOffset_Skin, False, False, GeomAbs_Intersection)
    part = Part(maker.Shape())
    assert [part.face(k).kind for k in (2, 4)] == ["offset", "offset"]
    return part


@pytest.mark.parametrize("face", [2, 4])
def test_every_offset_box_contains_its_surface(offset_boss, face):
    f = offset_boss.face(face)
    assert bounded(f)
    boxes = FaceBoxes(f)
    assert boxes.offset is not None and abs(abs(boxes.offset) - 1.0) < 1e-9
    rng = np.random.default_rng(3)
    for box, pts, _ in random_cell_boxes(f, boxes, rng, 30):
        assert (pts >= box[:3]).all() and (pts <= box[3:]).all()
    us, ws = face_cells(f, 1.0)
    grid = boxes.grid(us, ws)
    for _ in range(300):   # the refined grid: each cell's box holds its points, tightly
        i, j = rng.integers(len(us) - 1), rng.integers(len(ws) - 1)
        pts = np.array([f.point(u, w) for u in np.linspace(us[i], us[i + 1], 4)
                        for w in np.linspace(ws[j], ws[j + 1], 4)])
        assert (pts >= grid[i, j, :3]).all() and (pts <= grid[i, j, 3:]).all()
        assert (grid[i, j, 3:] - pts.max(0)).max() < 0.1   # a 1 mm offset adds little


def test_normal_box_contains_the_normal(offset_boss):
    f = offset_boss.face(4)
    boxes = FaceBoxes(f)
    surface = boxes.surface
    (u0, u1), (w0, w1) = f.u_range, f.w_range
    rng = np.random.default_rng(4)
    from cadcnc.guard.face_boxes import _poles_2d  # noqa: PLC0415 - the test's own probe
    for _ in range(20):
        a, b = np.sort(rng.uniform(u0, u1, 2))
        c, d = np.sort(rng.uniform(w0, w1, 2))
        piece = surface.Copy()
        piece.Segment(a, b, c, d)
        lo, hi = normal_box(_poles_2d(piece.Poles()))
        for u in np.linspace(a, b, 5):
            for w in np.linspace(c, d, 5):
                n = (boxes._point(u, w) - np.array(surface.Value(u, w).Coord())) / boxes.offset
                assert (n >= lo).all() and (n <= hi).all()


@pytest.mark.slow  # about 17 s
def test_offset_cells_never_clear_a_hit(offset_boss):
    """Ball centres around the offset corner (faces 4 and 5, R' 2, a 30 mm shank): where the
    height cells prove the own-face rule, OCCT's exact margin of face 4 is >= 0; and the
    operation guard's verdict is the exact guard's at every centre."""
    cells = HeightCells(offset_boss.face(4))
    fast = OperationGuard(offset_boss, (4, 5), 2.0, 30.0)
    exact = ClearanceGuard(offset_boss, (4, 5), 2.0, 30.0)
    rng = np.random.default_rng(5)
    proven = 0
    for _ in range(16):
        t = rng.uniform(0.0, 2 * np.pi)
        r, z = rng.uniform(14.0, 20.0), rng.uniform(20.0, 26.0)
        p = (r * np.cos(t), r * np.sin(t), z)
        if cells.budget(p) >= 0.0:
            proven += 1
            d_p = exact._point_distance(4, p)
            d_seg, _ = exact._segment_distance(4, p, None, d_p)
            assert d_seg - (d_p - exact.tol) >= 0.0
        assert (fast.margin(p)[0] >= 0.0) == (exact.margin(p)[0] >= 0.0)
    assert proven >= 4
