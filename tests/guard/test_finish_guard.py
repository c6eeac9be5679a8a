"""The finishing guard's cheap bounds: every box contains its piece of surface (dense
samples, OCCT evaluation), and the guard never calls clear what the exact guard calls a
hit (random centres about the slab's top, OCCT distances)."""

from __future__ import annotations

import numpy as np
import pytest

import cadcnc
from cadcnc.guard.box_tree import BoxTree
from cadcnc.guard.cells import FaceBoxes, HeightCells
from cadcnc.guard.clearance import ClearanceGuard
from cadcnc.guard.guard import OperationGuard
from helpers.face_cells import random_cell_boxes
from helpers.fixtures import FIXTURES


@pytest.fixture(scope="module")
def slab():
    return cadcnc.load_step(FIXTURES / "finish_slab.step")


@pytest.mark.parametrize("face", [5, 1, 2])   # the B-spline top, two extruded sides
def test_every_cell_box_contains_its_surface(slab, face):
    f = slab.face(face)
    boxes = FaceBoxes(f)
    assert boxes.surface is not None or boxes.curve is not None   # the tight path
    rng = np.random.default_rng(1)
    for box, pts, (du, dw) in random_cell_boxes(f, boxes, rng, 40):
        assert (pts >= box[:3]).all() and (pts <= box[3:]).all()
        # and tight: within a tenth of a mm of the samples' own box for small cells
        if du < 2 and dw < 2:
            assert (box[3:] - pts.max(0)).max() < 0.1


def test_the_finishing_guard_never_clears_a_hit(slab):
    """Centres on and about the top's offset: the finishing guard's margin is >= 0
    exactly where the exact guard's is, and its bounds were used."""
    top = slab.face(5)
    exact = ClearanceGuard(slab, (5,), 3.0, 40.0, 1e-6)
    fast = OperationGuard(slab, (5,), 3.0, 40.0, 1e-6)
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


def test_grid_boxes_are_the_cells_own_boxes(slab):
    """One knot refinement gives each cell the box of its own Segment's control points."""
    from cadcnc.guard.cells import face_cells
    f = slab.face(5)
    boxes = FaceBoxes(f)
    us, ws = face_cells(f, 2.0)
    grid = boxes.grid(us, ws)
    for i in range(0, len(us) - 1, 3):
        for j in range(0, len(ws) - 1, 3):
            assert np.allclose(grid[i, j], boxes.box(us[i], us[i + 1], ws[j], ws[j + 1]),
                               rtol=0, atol=1e-12)


def test_grid_boxes_of_a_range_past_the_knots_by_round_off(slab):
    """A face's range may pass its surface's last knot by round-off (bug32596_abc_0_13
    face 54: w up to 1 + 2e-16 on knots 0..1, where OCCT's InsertVKnots refused the knot
    and pencil crashed): the refinement clips the grid lines to the knots and gives the
    boxes of the range inside them, which still contain the surface."""
    from cadcnc.guard.cells import face_cells
    f = slab.face(5)
    boxes = FaceBoxes(f)
    us, ws = face_cells(f, 2.0)
    u_lo, u_hi, w_lo, w_hi = boxes.surface.Bounds()
    assert (us[0], us[-1], ws[0], ws[-1]) == pytest.approx((u_lo, u_hi, w_lo, w_hi), abs=1e-9)
    past_u = us.copy()
    past_w = ws.copy()
    past_u[0], past_u[-1] = u_lo - 4 * np.spacing(abs(u_lo) + 1), u_hi + 4 * np.spacing(u_hi + 1)
    past_w[-1] = w_hi + 4 * np.spacing(w_hi + 1)
    exact = boxes.grid(np.clip(us, u_lo, u_hi), np.clip(ws, w_lo, w_hi))
    assert np.array_equal(boxes.grid(past_u, past_w), exact)


def test_the_walls_hang_from_the_top_and_the_top_does_not(slab):
    from cadcnc.guard.walls import hangs_from
    guard = OperationGuard(slab, (5,), 3.0, 40.0, 1e-6)
    assert all(hangs_from(slab.face(k), guard._own_shapes) for k in (1, 2, 3, 4))
    assert not hangs_from(slab.face(6), guard._own_shapes)    # the bottom: a B-spline
    other = OperationGuard(slab, (6,), 3.0, 40.0, 1e-6)           # walls do not hang from it
    assert not any(hangs_from(slab.face(k), other._own_shapes) for k in (1, 2, 3, 4))


def _near_the_rim(top, rng, n):
    """Ball centres about the top's offset near its boundary (within 4 mm of an edge),
    some pushed out over the edge, sideways or down."""
    (u0, u1), (w0, w1) = top.u_range, top.w_range
    out = []
    while len(out) < n:
        u, w = rng.uniform(u0, u1), rng.uniform(w0, w1)
        if min(u - u0, u1 - u, w - w0, w1 - w) > 4.0:
            continue
        p = top.point(u, w) + (3.0 + rng.choice([0.0, -0.3, 0.2, -1e-3])) * top.normal(u, w)
        p[:2] += rng.normal(0.0, 1.0, 2) * rng.choice([0.0, 1.0])
        p[2] -= rng.choice([0.0, 0.0, 0.5, 2.0])
        out.append(p)
    return out


def test_the_wall_proof_never_clears_a_hit(slab):
    """Centres near the rim, where the walls are within R': the finishing guard (walls
    proven in closed form) agrees in sign with the exact guard (OCCT distances)."""
    exact = ClearanceGuard(slab, (5,), 3.0, 40.0, 1e-6)
    fast = OperationGuard(slab, (5,), 3.0, 40.0, 1e-6)
    rng = np.random.default_rng(4)
    hits = 0
    for p in _near_the_rim(slab.face(5), rng, 120):
        m_fast, m_exact = fast.margin(p)[0], exact.margin(p)[0]
        assert not (m_fast >= 0.0 > m_exact), (p, m_fast, m_exact)
        hits += m_exact < 0.0
    assert hits > 5                                            # the test sees hits too
    assert sum(w.cells.searches for w in fast._walls.values() if w is not None) > 20


def test_every_centre_within_the_budget_is_clear(slab):
    """After a clear margin, every centre within the budget is clear for the exact guard
    (random points on spheres of the budget's radius and inside)."""
    exact = ClearanceGuard(slab, (5,), 3.0, 40.0, 1e-6)
    fast = OperationGuard(slab, (5,), 3.0, 40.0, 1e-6)
    top = slab.face(5)
    rng = np.random.default_rng(5)
    budgets = []
    centres = _near_the_rim(top, rng, 40)
    for _ in range(40):
        u, w = rng.uniform(*top.u_range), rng.uniform(*top.w_range)
        centres.append(top.point(u, w) + 3.0 * top.normal(u, w))
    for p in centres:
        if fast.margin(p)[0] < 0.0:
            continue
        b = fast.budget(p)
        budgets.append(b)
        if b <= 0.0:
            continue
        for r in (b * 0.999, b * 0.5):
            d = rng.normal(size=(4, 3))
            for q in p + r * d / np.linalg.norm(d, axis=1)[:, None]:
                assert exact.margin(q)[0] >= 0.0, (p, b, q)
    assert np.count_nonzero(np.array(budgets) > 0.2) > 20


def test_height_cell_budget_is_a_ball_of_proofs(slab):
    """HeightCells.budget(p) = B: the proof holds afresh (a new HeightCells, no cache) at
    centres within B of p."""
    top = slab.face(5)
    cells = HeightCells(top)
    rng = np.random.default_rng(6)
    checked = 0
    for _ in range(60):
        u, w = rng.uniform(*top.u_range), rng.uniform(*top.w_range)
        p = top.point(u, w) + 3.0 * top.normal(u, w)
        b = cells.budget(p)
        if b <= 0.0:
            continue
        for q in p + b * 0.999 * np.vstack([np.eye(3), -np.eye(3)]):
            fresh = HeightCells.__new__(HeightCells)
            fresh.__dict__.update(cells.__dict__, _proof=None)
            assert fresh.budget(q) >= 0.0
            checked += 1
    assert checked > 60


@pytest.fixture(scope="module")
def stepped():
    """A 40 x 30 x 10 box with a 10 x 10 x 5 block on its top: planar walls hang from the
    top's outer edges; the block's walls rise from it."""
    import cadquery as cq
    base = cq.Workplane().box(40, 30, 10)
    shape = base.union(cq.Workplane().box(10, 10, 5).translate((0, 0, 7.5))).val().wrapped
    part = cadcnc.Part(shape, source="stepped box")
    top = [k for k in range(1, len(part) + 1) if part.face(k).kind == "plane"
           and abs(part.face(k).point(*[np.mean(r) for r in (part.face(k).u_range,
                                                            part.face(k).w_range)])[2] - 5.0)
           < 1e-9]
    return part, top[0]


def test_planar_walls_hang_from_the_top_and_rising_ones_do_not(stepped):
    from cadcnc.guard.walls import hangs_from
    part, top = stepped
    guard = OperationGuard(part, (top,), 3.0, 40.0, 1e-6)
    answers = {}
    for k in range(1, len(part) + 1):
        f = part.face(k)
        if k == top or f.kind != "plane":
            continue
        lo, hi = f.u_range, f.w_range
        z = [f.point(u, w)[2] for u in lo for w in hi]
        answers[k] = (min(z), max(z), hangs_from(f, guard._own_shapes))
    hanging = [k for k, (z0, z1, h) in answers.items() if h]
    assert len(hanging) == 4 and all(answers[k][1] == 5.0 for k in hanging)   # the sides
    rising = [k for k, (z0, z1, h) in answers.items() if z0 == 5.0 and z1 == 10.0]
    assert len(rising) == 4 and not any(answers[k][2] for k in rising)          # the block's


def test_planar_wall_proof_never_clears_a_hit(stepped):
    part, top = stepped
    exact = ClearanceGuard(part, (top,), 3.0, 40.0, 1e-6)
    fast = OperationGuard(part, (top,), 3.0, 40.0, 1e-6)
    rng = np.random.default_rng(7)
    hits = 0
    for _ in range(150):
        p = np.array([rng.uniform(-23, 23), rng.uniform(-18, 18),
                      8.0 + rng.choice([0.0, -1e-3, -0.5, 0.3, -3.0])])
        m_fast, m_exact = fast.margin(p)[0], exact.margin(p)[0]
        assert not (m_fast >= 0.0 > m_exact), (p, m_fast, m_exact)
        hits += m_exact < 0.0
    assert hits > 5
    assert sum(w.cells.searches for w in fast._walls.values() if w is not None) > 20


def test_a_stay_down_witness_is_a_real_refutation(slab):
    """Where finish_links finds a face point nearer than R' - tol to a move, OCCT's swept
    distance of that move is below R' - tol too (moves between centres on the top's
    offset, 1-3 mm apart, across the convex and concave parts)."""
    from cadcnc.guard.moves import MoveClearance
    from cadcnc.guard.stay_down import StayDown
    top = slab.face(5)
    stay = StayDown(slab, {5: (top, HeightCells(top))}, 3.0, 40.0, 1e-6)
    moves = MoveClearance(slab, 3.0, 40.0)
    rng = np.random.default_rng(8)
    refuted = 0
    for _ in range(14):
        u, w = rng.uniform(*top.u_range), rng.uniform(*top.w_range)
        a = top.point(u, w) + 3.0 * top.normal(u, w)
        u2 = np.clip(u + rng.uniform(-3, 3), *top.u_range)
        w2 = np.clip(w + rng.uniform(-3, 3), *top.w_range)
        b = top.point(u2, w2) + 3.0 * top.normal(u2, w2)
        before = stay.refuted
        allowed = stay(a, b)
        if stay.refuted > before:
            refuted += 1
            assert not allowed and moves.distance(a, b) < 3.0 - 1e-6, (a, b)
        else:
            assert allowed == moves.clear(a, b, 1e-6)
    assert refuted >= 3
