"""The guard's segment bound (cadcnc/guard/segment_bound.py) against OCCT's exact distances.

On abc_fold (B-spline and revolution faces cut from a real part, fixtures/README.md): the
bound from point distances is never above OCCT's exact segment/face distance, and a guard
using it gives the same hits (sign, depth, detail) as one that always asks OCCT.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt

import cadcnc
import cadcnc.guard.clearance as clearance
from cadcnc.guard.clearance import ClearanceGuard
from cadcnc.guard.segment_bound import interval_bound, segment_lower_bound

from conftest import FIXTURES

FREE_FORM = (6, 7, 8, 14, 15, 16, 18, 19)   # abc_fold's B-spline and revolution faces


@pytest.fixture(scope="module")
def part():
    return cadcnc.load_step(FIXTURES / "abc_fold.step")


def occt_distance(a, b, face) -> float:
    """OCCT's distance (mm) from the segment a..b (a point when a == b) to a face."""
    shape = BRepBuilderAPI_MakeVertex(gp_Pnt(*a)).Vertex() if a == b else \
        BRepBuilderAPI_MakeEdge(gp_Pnt(*a), gp_Pnt(*b)).Edge()
    ext = BRepExtrema_DistShapeShape(shape, face)
    assert ext.IsDone()
    return ext.Value()


def test_interval_bound_is_exact_for_a_point_face_and_never_above_it():
    """A face that is one point q at distance r from the axis, at height c: D(s) =
    sqrt(r^2 + (s - c)^2) in closed form; the bound over [a, b] is at most its minimum
    (r when a <= c <= b), and the lens bound reaches it when both ends see q."""
    rng = np.random.default_rng(1)
    for _ in range(2000):
        r, c = rng.uniform(0.01, 5.0), rng.uniform(-10.0, 10.0)
        a, b = sorted(rng.uniform(-10.0, 10.0, 2))
        exact = r if a <= c <= b else min(math.hypot(r, a - c), math.hypot(r, b - c))
        bound = interval_bound(a, b, math.hypot(r, a - c), math.hypot(r, b - c))
        assert bound <= exact + 1e-9
        assert bound == pytest.approx(exact, abs=1e-9)   # one point: the lens is tight


def test_bound_is_below_occt_segment_distance_near_free_form_faces(part):
    rng = np.random.default_rng(7)
    proven = 0
    for n in range(24):
        k = FREE_FORM[n % len(FREE_FORM)]
        face = part.face(k)
        u, w = rng.uniform(*face.u_range), rng.uniform(*face.w_range)
        p = face.point(u, w) + rng.normal(size=3) * 2.0
        length = rng.uniform(1.0, 20.0)
        top = (p[0], p[1], p[2] + length)
        exact = occt_distance(tuple(p), top, face.topods)

        def point_distance(s):
            q = (p[0], p[1], p[2] + s)
            return occt_distance(q, q, face.topods)

        need = 0.8 * exact
        bound = segment_lower_bound(point_distance, length, need, max_points=24)
        if bound is not None:
            proven += 1
            assert need <= bound <= exact + 1e-9, (k, p, length, bound, exact)
        # a need above the exact distance is never proven
        assert segment_lower_bound(point_distance, length, exact + 1e-5, 24) is None
    assert proven >= 12   # the bound does its work on most of them


def centres(part, n, seed):
    """n ball centres (mm): points of abc_fold's free-form faces and of face 17, moved
    off the face along its normal (either side) by 2 to 6 mm, so that the ball and its
    shank come near, and into, the faces around."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        face = part.face((*FREE_FORM, 17)[i % (len(FREE_FORM) + 1)])
        u, w = rng.uniform(*face.u_range), rng.uniform(*face.w_range)
        p = face.point(u, w) + face.normal(u, w) * rng.choice((-1.0, 1.0)) \
            * rng.uniform(2.0, 6.0)
        out.append(tuple(float(x) for x in p))
    return out


def test_guard_hits_are_those_of_the_exact_guard(part, monkeypatch):
    """Pair (17, 18) with R' 2 and a 5 mm shank: the same centres, in the same order,
    through a guard with the bound and one whose segment distances are all OCCT's."""
    points = centres(part, 80, 3)
    fast = ClearanceGuard(part, (17, 18), 2.0, 5.0)
    got = [fast.margin(p) for p in points]
    monkeypatch.setattr(clearance, "segment_lower_bound", lambda *a, **k: None)
    slow = ClearanceGuard(part, (17, 18), 2.0, 5.0)
    want = [slow.margin(p) for p in points]
    assert fast.bounded_calls > 0 and slow.bounded_calls == 0
    assert fast.exact_calls < slow.exact_calls or fast.bounded_calls > 0
    hits = 0
    for p, (m, detail), (m_exact, detail_exact) in zip(points, got, want):
        assert (m < 0.0) == (m_exact < 0.0), (p, m, m_exact)
        if m_exact < 0.0:
            hits += 1
            assert (m, detail) == (m_exact, detail_exact), p
        else:
            assert m <= m_exact + 1e-9, p   # a lower bound where clear
    assert 5 <= hits <= len(points) - 5   # both answers occur
