"""Steep-shallow's raster part on the boss (wl_boss, R 2, --scallop 0.05): the planes that
pass beside the boss top (8 < |y| < 10) climb the wall on one side and descend it on the
other, where the wall's top is a free edge. Their chains start in the order along the
pass: the descended wall's chain goes on into the fillet at its foot, and the fillet's
entry there (at the same s) starts no second cut of it. Before, it could, the fillet was
cut twice, the plane failed its self-check and was not cut, which left 0.108 mm at the
fillet's foot near (-5.88, -9.30, 5).

Judged by closed forms of the part: the fillet (torus, tube r 3 round the circle r 11,
z 8), the wall (r 8); a ball of R' 2 touching the fillet has its centre 1 from that
circle, touching the wall r 10 from the axis."""

from __future__ import annotations

import functools
import json
import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

import cadcnc
from cadcnc.core.job import Job, Raster, Tool
from cadcnc.ops.finish.passes import GuidePlane, pass_cuts
from cadcnc.ops.finish.raster import plan_for_job
from cadcnc.program.program import FAILED
from helpers.fixtures import FIXTURES

FACTS = json.loads((FIXTURES / "waterline_fixtures.json").read_text())["boss"]
R, H = 2.0, 0.05                                        # ball radius, scallop limit (mm)
WALL = FACTS["boss_radius"] + R                         # centre radius on the wall: 10
TUBE_R = FACTS["boss_radius"] + FACTS["fillet_radius"]  # the fillet's tube circle: r 11
TUBE_Z = FACTS["plate"] + FACTS["fillet_radius"]        # at z 8
INNER = FACTS["fillet_radius"] - R                      # centres 1 from that circle
WORST = (-5.879, -9.297)   # (x, y) where 0.108 mm was left before


@functools.cache
def boss_passes():
    """The raster job of steep-shallow on the boss (its faces, R 2, scallop 0.05), its two
    planes either side of WORST's y, and their passes (zigzag: odd planes reversed)."""
    part = cadcnc.load_step(FIXTURES / FACTS["file"])
    job = Job(Tool(R, 0.0, None), 1500.0, 0.004, Raster(tuple(FACTS["faces"]), None, H,
                                                       0.0, "zigzag"), source=part.source)
    plan, _ = plan_for_job(part, job)
    offsets = np.asarray(plan.offsets)
    k = int(np.searchsorted(offsets, WORST[1]))
    return [(float(offsets[j]), pass_cuts(part, job.operation.faces,
                                          GuidePlane(0.0, float(offsets[j])), job,
                                          reverse=j % 2 == 1)) for j in (k - 1, k)]


def test_the_planes_beside_the_boss_top_pass_their_self_check():
    planes = boss_passes()
    assert planes[0][0] < WORST[1] < planes[1][0]
    for y, res in planes:
        assert 8.0 < abs(y) < WALL
        assert not [s for s in res.skipped if s.reason == FAILED], res.skipped
        assert res.cuts


def test_their_cuts_lie_on_the_offsets_and_cover_the_fillet_once():
    """Every cut point on the plane and R' from its face (closed forms, 1e-9 mm); per side
    of the boss the fillet's cuts span x from the wall's foot to the plate's, without
    overlap (their lengths along x add up to that span), and the wall is climbed and
    descended once each, from z 8 to the top edge z 15."""
    for y, res in boss_passes():
        fillet = {1: [], -1: []}
        walls = []
        for cut in res.cuts:
            p = cut.points
            assert np.abs(p[:, 1] - y).max() <= 1e-9
            r = np.hypot(p[:, 0], p[:, 1])
            side = int(np.sign(p[:, 0].mean()))
            if cut.path.faces[0] == FACTS["fillet"]:
                assert np.abs(np.hypot(r - TUBE_R, p[:, 2] - TUBE_Z) - INNER).max() <= 1e-9
                assert (r <= TUBE_R + 1e-9).all() and (p[:, 2] <= TUBE_Z + 1e-9).all()
                fillet[side].append((p[:, 0].min(), p[:, 0].max()))
            else:
                assert cut.path.faces[0] == FACTS["wall"]
                assert np.abs(r - WALL).max() <= 1e-9
                walls.append((side, p[:, 2].min(), p[:, 2].max()))
        lo, hi = math.sqrt(WALL ** 2 - y * y), math.sqrt(TUBE_R ** 2 - y * y)
        for side, spans in fillet.items():
            assert spans, f"plane y {y}: no cut of the fillet at x {side:+d}"
            a, b = sorted((side * lo, side * hi))
            assert min(s[0] for s in spans) <= a + 1e-9 and max(s[1] for s in spans) >= b - 1e-9
            assert abs(sum(s[1] - s[0] for s in spans) - (b - a)) <= 1e-6, spans
        assert sorted((s, round(z0, 9), round(z1, 9)) for s, z0, z1 in walls) == [
            (-1, TUBE_Z, FACTS["boss_top"]), (1, TUBE_Z, FACTS["boss_top"])]


def test_the_fillet_between_them_is_within_the_scallop():
    """The material left on the fillet between the two planes, up to 40 deg of slope
    (raster's region: steep-shallow keeps its cuts to 45 deg and beyond), by the balls of
    these two planes alone (others only cut more): the exact centre curves (their cuts lie
    on them, above) where the fillet's cuts run, 800 centres to 45 deg each side (<= 2.1
    µm apart: the gaps between their balls overstate it by < 3e-7 mm), and for each
    fillet point p (normal N) the smallest t at which p + t N enters a ball: at most the
    limit, within the report's 1e-6."""
    planes = boss_passes()
    (y0, _), (y1, _) = planes
    beta = np.linspace(0.0, math.radians(45.0), 800)   # the centre's angle on the tube
    r, z = TUBE_R - INNER * np.sin(beta), TUBE_Z - INNER * np.cos(beta)
    centres = []
    for y, res in planes:
        for cut in res.cuts:
            c = cut.points
            if cut.path.faces[0] != FACTS["fillet"]:
                continue
            b = np.arctan2(TUBE_R - np.hypot(c[:, 0], c[:, 1]), TUBE_Z - c[:, 2])
            run = (beta >= b.min() - 1e-9) & (beta <= b.max() + 1e-9)
            x = np.sign(c[:, 0].mean()) * np.sqrt(r[run] ** 2 - y * y)
            centres.append(np.stack([x, np.full_like(x, y), z[run]], 1))
    assert centres, "neither plane cut the fillet"
    centres = np.vstack(centres)
    alpha, theta = (a.ravel() for a in np.meshgrid(np.radians(np.linspace(0.0, 40.0, 41)),
                                                   np.radians(np.linspace(0.0, 360.0, 2881))))
    radial = np.stack([np.cos(theta), np.sin(theta), np.zeros_like(theta)], 1)
    up = np.array([0.0, 0.0, 1.0])
    rf = FACTS["fillet_radius"]
    p = (TUBE_R - rf * np.sin(alpha))[:, None] * radial + (TUBE_Z - rf * np.cos(alpha))[:, None] * up
    n = np.sin(alpha)[:, None] * radial + np.cos(alpha)[:, None] * up
    q = p + R * n
    between = (q[:, 1] > y0) & (q[:, 1] < y1)
    p, n, q = p[between], n[between], q[between]
    assert len(p) > 1000
    near = np.hypot(q[:, 0] - WORST[0], q[:, 1] - WORST[1]) < 0.5
    assert near.any()
    left = np.full(len(p), np.inf)
    for i, ids in enumerate(cKDTree(centres).query_ball_point(q, R)):
        w = centres[ids] - p[i]
        a = w @ n[i]
        b2 = np.einsum("kj,kj->k", w, w) - a * a
        inside = b2 < R * R
        if inside.any():
            left[i] = max(0.0, float((a[inside] - np.sqrt(R * R - b2[inside])).min()))
    assert np.isfinite(left).all()
    assert left.max() <= H + 1e-6, (left.max(), p[np.argmax(left)])


def on_offset(p: np.ndarray) -> np.ndarray:
    """(N,) whether each centre (N, 3) is R' from the boss (closed forms, 1e-9 mm): on the
    fillet's, the wall's, the top edge's (a torus round the circle r 8, z 15) or the top's
    offset, within their ranges."""
    r, z = np.hypot(p[:, 0], p[:, 1]), p[:, 2]
    top, rb, e = FACTS["boss_top"], FACTS["boss_radius"], 1e-9
    fillet = (np.abs(np.hypot(r - TUBE_R, z - TUBE_Z) - INNER) <= e) & (z <= TUBE_Z + e)
    wall = (np.abs(r - WALL) <= e) & (z >= TUBE_Z - e) & (z <= top + e)
    edge = (np.abs(np.hypot(r - rb, z - top) - R) <= e) & (r >= rb - e) & (z >= top - e)
    flat = (np.abs(z - top - R) <= e) & (r <= rb + e)
    return fillet | wall | edge | flat


def test_a_plane_just_inside_the_top_rolls_back_down_over_its_edge():
    """y 7.8772 (a plane of the raster part at --scallop 0.2) crosses the top (r 8) over
    x +-1.40 only, near its edge's tangent: the roll from the top back down onto the wall
    solved each arc point's edge parameter in a bracket round the whole arc, which held
    two roots (h > 0 only between them) and never changed sign: the chain failed. Now the
    pass is one chain from the plate's foot to the other: fillet, wall, the arc over the
    edge, the top, the arc back, wall, fillet; every point R' from the boss."""
    y = 7.8772
    part = cadcnc.load_step(FIXTURES / FACTS["file"])
    job = Job(Tool(R, 0.0, None), 1500.0, 0.004, Raster(tuple(FACTS["faces"]), None, 0.2,
                                                       0.0, "zigzag"), source=part.source)
    res = pass_cuts(part, job.operation.faces, GuidePlane(0.0, y), job)
    assert not [s for s in res.skipped if s.reason == FAILED], res.skipped
    assert len(res.cuts) == 7
    for a, b in zip(res.cuts, res.cuts[1:]):
        assert np.linalg.norm(a.points[-1] - b.points[0]) <= 1e-9
    p = np.vstack([c.points for c in res.cuts])
    assert np.abs(p[:, 1] - y).max() <= 1e-9 and on_offset(p).all()
    foot = math.sqrt(TUBE_R ** 2 - y * y)
    assert np.allclose([p[0, 0], p[-1, 0]], [-foot, foot], atol=1e-9)
    assert p[:, 2].max() == pytest.approx(FACTS["boss_top"] + R, abs=1e-9)
