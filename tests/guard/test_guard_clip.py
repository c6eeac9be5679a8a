"""The guard's OCCT distance of the shank is taken on the segment clipped to the face box's
heights widened by cap (guard/clearance.py ``_segment_distance``): at random ball centres
about bspline_boss's faces, it equals OCCT's distance of the whole segment wherever that is
at most cap, and is a lower bound of it, cap, elsewhere."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt

import cadcnc
from cadcnc.guard.clearance import ClearanceGuard
from helpers.fixtures import FIXTURES


@pytest.mark.parametrize("face,cap", [(4, None), (4, 3.0), (2, None), (5, 6.0)])
def test_clipped_distance_is_exact_below_cap(face, cap):
    part = cadcnc.load_step(FIXTURES / "bspline_boss.step")
    g = ClearanceGuard(part, (4, 5), 3.0, 40.0)
    for a in g._analytic:   # OCCT answers everything
        a.kind = None
    lo, hi = g._lo[face - 1], g._hi[face - 1]
    rng = np.random.default_rng(face)
    exact = 0
    for _ in range(12):
        p = tuple(rng.uniform(lo - 4.0, hi + 4.0).tolist())
        d, _ = g._segment_distance(face, p, None, cap)
        whole = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeEdge(
            gp_Pnt(*p), gp_Pnt(p[0], p[1], p[2] + g.shank)).Edge(),
            part.face(face).topods).Value()
        limit = g.offset + g.reach if cap is None else cap
        if whole <= limit:
            assert abs(d - whole) <= 1e-7
            exact += 1
        else:
            assert d <= whole + 1e-9 and d >= min(whole, limit) - 1e-9
    assert exact >= 1


@pytest.mark.parametrize("name,face", [("bspline_boss.step", 4), ("finish_slab.step", 5)])
def test_rho_above_bounds_the_points_above(name, face):
    """BoxTree.rho_above: no point of the face above z0 is horizontally nearer to p than
    the bound it returns (dense samples of the face, OCCT evaluation)."""
    from cadcnc.guard.box_tree import BoxTree  # noqa: PLC0415

    part = cadcnc.load_step(FIXTURES / name)
    f = part.face(face)
    tree = BoxTree(f)
    (u0, u1), (w0, w1) = f.u_range, f.w_range
    pts = np.array([f.point(u, w) for u in np.linspace(u0, u1, 80)
                    for w in np.linspace(w0, w1, 80)])
    lo, hi = pts.min(0), pts.max(0)
    rng = np.random.default_rng(7)
    proven = 0
    for _ in range(40):
        p = rng.uniform(lo - 3.0, hi + 3.0)
        z0 = rng.uniform(lo[2], hi[2] + 0.5)
        need = rng.uniform(0.5, 4.0)
        rho = tree.rho_above(p, z0, need)
        if rho is None:
            continue
        proven += 1
        assert rho >= need
        above = pts[pts[:, 2] > z0]
        if len(above):
            assert np.hypot(*(above[:, :2] - p[:2]).T).min() >= rho - 1e-9
    assert proven >= 10


@pytest.mark.parametrize("name,pair", [("bspline_boss.step", (4, 5)), ("abc_fold.step", (7, 8))])
def test_face_distance_is_distshapeshape(name, pair):
    """guard/face_distance.py: OCCT's pieces, the edges only where they can win, give the
    distance and the own-edge verdict of BRepExtrema_DistShapeShape of the whole face (to
    1e-12 mm), for random vertical segments about every curved face of the part."""
    from OCP.BRepExtrema import BRepExtrema_IsInFace  # noqa: PLC0415

    from cadcnc.guard.face_distance import FaceDistance  # noqa: PLC0415

    part = cadcnc.load_step(FIXTURES / name)
    g = ClearanceGuard(part, pair, 3.0, 30.0)
    rng = np.random.default_rng(11)
    compared = 0
    for k in range(1, len(part) + 1):
        if part.face(k).kind == "plane":
            continue
        pieces = FaceDistance(part.face(k).topods, g._own_shapes)
        for _ in range(6):
            p = rng.uniform(g._lo[k - 1] - 3.0, g._hi[k - 1] + 3.0)
            z0, z1 = float(p[2]), float(p[2] + rng.uniform(0.0, 10.0))
            got = pieces.distance(p, z0, z1)
            ext = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeEdge(
                gp_Pnt(p[0], p[1], z0), gp_Pnt(p[0], p[1], z1)).Edge(), part.face(k).topods)
            own = all(ext.SupportTypeShape2(n) != BRepExtrema_IsInFace
                      and g._own_shapes.Contains(ext.SupportOnShape2(n))
                      for n in range(1, ext.NbSolution() + 1))
            if got is None:
                continue
            compared += 1
            assert abs(got[0] - ext.Value()) <= 1e-12 * max(1.0, ext.Value())
            assert got[1] == own
    assert compared >= 40
