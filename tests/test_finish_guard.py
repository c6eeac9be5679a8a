"""The finishing guard's cheap bounds: every box contains its piece of surface (dense
samples, OCCT evaluation), and the guard never calls clear what the exact guard calls a
hit (random centres about the slab's top, OCCT distances)."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc.geometry.clearance import ClearanceGuard
from cadcnc.ops.finish_guard import BoxTree, FinishGuard, HeightCells, _Boxes

from conftest import FIXTURES


@pytest.fixture(scope="module")
def slab():
    return cadcnc.load_step(FIXTURES / "finish_slab.step")


@pytest.mark.parametrize("face", [5, 1, 2])   # the B-spline top, two extruded sides
def test_every_cell_box_contains_its_surface(slab, face):
    f = slab.face(face)
    boxes = _Boxes(f)
    assert boxes.surface is not None or boxes.curve is not None   # the tight path
    (u0, u1), (w0, w1) = f.u_range, f.w_range
    rng = np.random.default_rng(1)
    for _ in range(40):
        a, b = np.sort(rng.uniform(u0, u1, 2))
        c, d = np.sort(rng.uniform(w0, w1, 2))
        box = np.array(boxes.box(a, b, c, d))
        pts = np.array([f.point(u, w) for u in np.linspace(a, b, 7)
                        for w in np.linspace(c, d, 7)])
        assert (pts >= box[:3]).all() and (pts <= box[3:]).all()
        # and tight: within a tenth of a mm of the samples' own box for small cells
        if (b - a) < 2 and (d - c) < 2:
            assert (box[3:] - pts.max(0)).max() < 0.1


def test_the_finishing_guard_never_clears_a_hit(slab):
    """Centres on and about the top's offset: the finishing guard's margin is >= 0
    exactly where the exact guard's is, and its bounds were used."""
    top = slab.face(5)
    exact = ClearanceGuard(slab, (5,), 3.0, 40.0, 1e-6)
    fast = FinishGuard(slab, (5,), 3.0, 40.0, 1e-6)
    rng = np.random.default_rng(2)
    disagree = 0
    for _ in range(150):
        u, w = rng.uniform(*top.u_range), rng.uniform(*top.w_range)
        p = top.point(u, w) + (3.0 + rng.choice([0.0, -0.5, 0.3])) * top.normal(u, w)
        p[:2] += rng.normal(0.0, 0.5, 2) * rng.choice([0.0, 1.0])
        m_fast, m_exact = fast.margin(p)[0], exact.margin(p)[0]
        assert not (m_fast >= 0.0 > m_exact), (p, m_fast, m_exact)
        disagree += (m_fast < 0.0) != (m_exact < 0.0)
    assert disagree == 0
    assert fast.proven_calls > 50


def test_height_cells_prove_the_shank_clear_over_a_gentle_top(slab):
    cells = HeightCells(slab.face(5))
    top = slab.face(5)
    u, w = np.mean(top.u_range), np.mean(top.w_range)
    p = top.point(u, w) + 3.0 * top.normal(u, w)
    assert cells.shank_clear(p)
    assert not cells.shank_clear(p - (0.0, 0.0, 4.0))   # a centre below the top


def test_box_tree_bounds_the_distance_from_below(slab):
    side = slab.face(1)
    tree = BoxTree(side)
    from cadcnc.verification.probe import shape_distances
    rng = np.random.default_rng(3)
    lo, hi = slab.bounding_box()
    for _ in range(30):
        p = rng.uniform(lo - 5, hi + 5)
        lb = tree.lower_bound(p, 0.0, 1.0)
        if lb is not None:
            assert lb <= shape_distances(side.topods, p[None])[0] + 1e-9
