"""The third-face / shank guard against closed forms on the stretch fixtures.

Every fixture's corner is followed by a ball R' = 3 whose centre, on the floor / wall
corner, lies on a straight line; the distances from there to the other walls are read
off the fixtures' construction (fixtures/build_stretch_fixtures.py), not computed here.
"""

from __future__ import annotations

import copy
import json
import math

import pytest

import cadcnc
from cadcnc.guard.clearance import ClearanceGuard
from helpers.fixtures import FIXTURES

SIDECAR = json.loads((FIXTURES / "stretch_fixtures.json").read_text())
TOL = 1e-6
_parts: dict = {}


def part_of(name):
    if name not in _parts:
        _parts[name] = cadcnc.load_step(FIXTURES / SIDECAR[name]["file"])
    return _parts[name]


def guard(name, shank=None, **kw):
    facts = SIDECAR[name]
    return ClearanceGuard(part_of(name), facts["pair"], facts["radius"],
                          facts["shank"] if shank is None else shank, TOL, **kw)


def test_pocket_end_wall_is_hit_by_the_ball_at_its_closed_form_distance():
    facts = SIDECAR["pocket"]
    left = facts["stretches"][0]["start"]["faces"][0]
    g = guard("pocket")
    for x, wall_distance in ((6.0, 1.0), (7.5, 2.5), (7.9999, 2.9999)):
        m, detail = g.margin((x, 8.0, 11.0))
        assert m == pytest.approx(wall_distance - (3.0 - TOL), abs=1e-9)
        assert detail == f"ball touches face {left}"


def test_pocket_corner_is_clear_between_the_end_walls():
    g = guard("pocket")
    for x in (8.0 + 2e-6, 8.5, 12.0, 20.0, 31.5, 32.0 - 2e-6):
        m, detail = g.margin((x, 8.0, 11.0))
        assert m >= 0.0, (x, m, detail)


def test_shank_under_the_overhang_is_a_shank_hit_and_the_ball_alone_is_clear():
    """At x = 23 the shank's axis is 2 mm from the shelf's side x = 25 (margin -1); the
    ball alone is sqrt(2^2 + 3^2) = 3.606 mm from the shelf's lower edge (clear).
    The sidecar lists the shelf's side, underside and top, in that order."""
    faces = SIDECAR["shelf"]["stretches"][0]["end"]["faces"]
    m, detail = guard("shelf").margin((23.0, 8.0, 11.0))
    assert m == pytest.approx(2.0 - (3.0 - TOL), abs=1e-9)
    who, k = detail.split(" touches face ")
    assert who == "shank" and int(k) in faces
    m_ball, _ = guard("shelf", shank=0.0).margin((23.0, 8.0, 11.0))
    assert m_ball >= 0.0
    # raised 0.5 mm under the shelf (underside z = 14), the ball alone hits it by 0.5
    m_up, detail = guard("shelf", shank=0.0).margin((30.0, 8.0, 11.5))
    assert m_up == pytest.approx(2.5 - (3.0 - TOL), abs=1e-9)
    assert detail == f"ball touches face {faces[1]}"


def test_slot_narrower_than_the_ball_hits_the_opposite_wall():
    facts = SIDECAR["slot"]
    (other,) = facts["refusal"]["faces"]
    for x in (1.0, 20.0, 39.0):
        m, detail = guard("slot").margin((x, 11.0, 8.0))
        assert m == pytest.approx(facts["refusal"]["margin"] + TOL, abs=1e-9)
        assert detail == f"ball touches face {other}"


def test_own_overhanging_wall_is_a_shank_hit():
    """The shank crosses the pair's own leaning wall: distance 0, margin -(R' - tol)."""
    facts = SIDECAR["undercut"]
    floor, wall = facts["pair"]
    lean = math.radians(10.0)
    y = 15.0 - 3.0 * math.tan(lean) - 3.0 / math.cos(lean)   # centre 3 from both
    m, detail = guard("undercut").margin((15.0, y, 13.0))
    assert m == pytest.approx(-(3.0 - TOL), abs=1e-7)
    assert detail == f"shank touches face {wall}"


def test_vertical_own_wall_and_its_rim_do_not_count_as_hits():
    """A shank tangent to a vertical wall is 3 mm from the wall's top rim as well: on the
    path (2 µm off towards the wall: more than tol, within the path's own error) it is
    not a hit: the rim belongs to the own wall, whose rule is relative."""
    m, detail = guard("pocket").margin((20.0, 8.0 - 2e-6, 11.0))
    assert m >= 0.0, detail


def test_broad_phase_and_cache_keep_exact_distances_rare():
    """Along a 20 mm run in 0.1 mm steps, far from the end walls, exact distances are
    measured only for faces within reach (the rim), never for all faces."""
    g = guard("pocket")
    n = 200
    for k in range(n):
        g.margin((10.0 + 0.1 * k * 0.5, 8.0, 11.0))
    faces = len(part_of("pocket"))
    assert g.calls == n
    assert g.broad_calls < n / 5
    assert g.exact_calls < n * faces / 4


def test_an_unknown_distance_fails_closed():
    """When OCCT finds no distance, the face counts as hit (never as far away): a third
    face, and the pair's own overhanging wall (whose rule compares two distances)."""
    facts = SIDECAR["undercut"]
    floor, wall = facts["pair"]
    lean = math.radians(10.0)
    p = (15.0, 15.0 - 3.0 * math.tan(lean) - 3.0 / math.cos(lean), 13.0)
    g = guard("undercut")
    g._point_distance = lambda face, q: -math.inf
    g._segment_distance = lambda face, q, *length: (1.0, False)
    assert g._exact(wall, p)[0] == -math.inf
    g._segment_distance = lambda face, q, *length: (-math.inf, False)
    third = next(k for k in range(1, len(part_of("undercut")) + 1) if k not in (floor, wall))
    assert g._exact(third, p)[0] == -math.inf


def occt_only(g: ClearanceGuard) -> ClearanceGuard:
    """The same guard with every closed form switched off (OCCT answers everything); the
    closed forms are shared by the part's guards, so this one gets its own copies."""
    g._analytic = [copy.copy(a) for a in g._analytic]
    for a in g._analytic:
        a.kind = None
    return g


@pytest.mark.parametrize("name", ["pocket", "shelf", "undercut"])
def test_closed_forms_keep_occt_verdicts_and_hit_values(name):
    """Along a line through the fixture's corner (into its end walls, under its shelf),
    the guard with closed forms gives OCCT's verdict at every point, the same margin
    (1e-9 mm) wherever it is a hit, and needs fewer OCCT distances."""
    fast, slow = guard(name), occt_only(guard(name))
    p0 = SIDECAR[name]["stretches"][0]["start"]["p"] if SIDECAR[name]["stretches"] else None
    y, z = (p0[1], p0[2]) if p0 else (8.0, 11.0)
    hits = 0
    for k in range(81):
        p = (-2.0 + 0.5 * k, y, z)
        (m1, d1), (m2, d2) = fast.margin(p), slow.margin(p)
        assert (m1 < 0.0) == (m2 < 0.0), (p, m1, d1, m2, d2)
        if m2 < 0.0:
            hits += 1
            assert m1 == pytest.approx(m2, abs=1e-9) and d1 == d2, (p, d1, d2)
    assert hits, "the line never met a face: the test would be empty"
    assert fast.exact_calls < slow.exact_calls
