"""Each stop rule of the interpolator, provoked on a fixture built for it."""

from __future__ import annotations

import math

import cadquery as cq
import numpy as np
import pytest

import cadcnc
from cadcnc.core.errors import FacePairError, GeometryError, StartPointError
from cadcnc.interp.cycle import BOUNDARY, CLOSED, CURVATURE, END, MAX_CYCLES, SINGULAR, TANGENT
from cadcnc.ops.path.pair_path import intersection_path
from helpers.fixtures import SIDECAR, load_fixture

KW = dict(feed=1500.0, period=0.004)  # step 0.1 mm


def pair_facts(name, i, j):
    return next(p for p in SIDECAR[name]["pairs"] if p["faces"] == [i, j])


def test_end_reached_with_a_shortened_last_step():
    part = load_fixture("pocket")
    tp = intersection_path(part.face(10), part.face(17), radius=3, **KW)
    assert tp.stop_reason == END
    edge, = part.shared_edges(10, 17)
    assert tp.length == pytest.approx(edge.length, abs=1e-9)  # straight edge: same length
    assert 0 < tp.steps[-1] < 0.1


def test_closed_intersection_completed_once_around():
    part = load_fixture("sphere_cylinder")
    tp = intersection_path(part.face(1), part.face(2), radius=3, **KW)
    assert tp.stop_reason == CLOSED
    np.testing.assert_allclose(tp.points[-1], tp.points[0], atol=1e-12)
    radius = SIDECAR["sphere_cylinder"]["pairs"][0]["closed_form"]["cylinder_radius"] + 3
    assert tp.length == pytest.approx(2 * math.pi * radius, rel=1e-4)


def test_contact_leaving_its_face_stops_on_the_boundary():
    facts = pair_facts("ramp_wall", 3, 7)
    part = load_fixture("ramp_wall")
    tp = intersection_path(part.face(3), part.face(7), radius=3, **KW)
    assert tp.stop_reason == BOUNDARY and "surface 2" in tp.stop_detail
    wall_contact = tp.contacts[-1, 1]
    # the wall's top edge: z = H (1 - y / L); the contact lands on it, at y = 28
    H, L = facts["wall_height_at_y0"], facts["wall_length"]
    # on it within the boundary tolerance (1e-6 mm; the classifier's ON band is +-1 tol)
    assert wall_contact[2] == pytest.approx(H * (1 - wall_contact[1] / L), abs=2e-6)
    assert wall_contact[1] == pytest.approx(facts["contact_leaves_wall_at_y"], abs=1e-3)
    # and no point of the path has a wall contact above the wall
    ys, zs = tp.contacts[:, 1, 1], tp.contacts[:, 1, 2]
    assert np.all(zs <= H * (1 - ys / L) + 2e-6)


def test_faces_becoming_tangent_stop_the_path():
    part = load_fixture("equal_cylinders")
    # start on the ellipse z = x between the two tangent points (0, +-10, 0)
    tp = intersection_path(part.face(1), part.face(2), radius=3, start=(8, -6, 8), **KW)
    assert tp.stop_reason == TANGENT, tp.stop_detail
    end = tp.points[-1]
    assert abs(end[0]) < 0.2 and abs(abs(end[1]) - 13) < 0.01  # next to a tangent point
    assert "tangent" in tp.stop_detail


def test_concave_curvature_tighter_than_the_ball_stops_the_path():
    facts = pair_facts("ellipse_pocket", 7, 8)
    a, b = facts["a"], facts["b"]
    part = load_fixture("ellipse_pocket")
    ball = 5.0
    # start on the flat side of the ellipse, the ball on the floor touching the wall
    tp = intersection_path(part.face(7), part.face(8), radius=ball,
                                  start=(0, -b + ball, facts["floor_z"] + ball), **KW)
    assert tp.stop_reason == CURVATURE, tp.stop_detail
    x, y = tp.contacts[-1, 0, :2]
    t = math.atan2(y / b, x / a)
    k = a * b / (a * a * math.sin(t) ** 2 + b * b * math.cos(t) ** 2) ** 1.5
    assert ball * k == pytest.approx(1.0, abs=0.01)  # stopped where R k reaches 1
    # from the tightest point the path cannot even start
    with pytest.raises(GeometryError, match="tighter than the ball"):
        intersection_path(part.face(7), part.face(8), radius=ball, **KW)


def test_singular_pole_stops_a_guide_surface_pass():
    part = load_fixture("dome_pole")
    guide = cq.Face.makePlane(200, 200, basePnt=(0, 0, 0), dir=(1, 0, 0))
    r = 25 + 3
    c = math.cos(math.radians(45))
    tp = intersection_path(part.face(7), guide, radius=3, offsets=(None, 0.0),
                                  start=(0, r * c, r * c), end=(0, -r * c, r * c), **KW)
    assert tp.stop_reason == SINGULAR, tp.stop_detail
    assert np.linalg.norm(tp.points[-1] - [0, 0, r]) < 0.1       # at the pole
    np.testing.assert_allclose(tp.points[:, 0], 0.0, atol=1e-9)  # the guide carries p
    np.testing.assert_allclose(np.linalg.norm(tp.points, axis=1), r, atol=1e-4)


def test_max_cycles_is_a_stop_with_a_reason():
    part = load_fixture("sphere_cylinder")
    # from a start point alone the length is unknown before running: the limit stops it
    tp0 = intersection_path(part.face(1), part.face(2), radius=3, **KW)
    start = tp0.points[0]
    tp = intersection_path(part.face(1), part.face(2), radius=3, max_cycles=10,
                                  start=tuple(start), **KW)
    assert tp.stop_reason == MAX_CYCLES and len(tp) == 11
    assert not tp.complete and tp.partial_reason.startswith("stopped after 1.000 mm: max_cycles")
    # along the edge the estimate (its length over the step) refuses before running
    with pytest.raises(cadcnc.InputError, match="about 62.83 mm long.*feed 1500.*period"):
        intersection_path(part.face(1), part.face(2), radius=3, max_cycles=10, **KW)
    assert tp0.complete


def test_pairs_a_ball_cannot_follow_are_refused_before_computing():
    part = load_fixture("pocket")
    with pytest.raises(FacePairError, match="not adjacent"):
        intersection_path(part.face(1), part.face(17), radius=3, **KW)
    convex = next(p for p in part.adjacency if part.pair_class(*p) == "convex")
    with pytest.raises(FacePairError, match="convex"):
        intersection_path(part.face(convex[0]), part.face(convex[1]), radius=3, **KW)
    tangent = next(p for p in part.adjacency if part.pair_class(*p) == "tangent")
    with pytest.raises(FacePairError, match="tangent"):
        intersection_path(part.face(tangent[0]), part.face(tangent[1]), radius=3, **KW)


@pytest.mark.parametrize("kw,match", [
    (dict(radius=-1), "radius"), (dict(radius=3, feed=0), "feed"),
    (dict(radius=3, period=float("nan")), "period"), (dict(radius=3, allowance=-0.1), "allowance"),
    (dict(radius=3, start=(1, 2)), "start"),
])
def test_bad_parameters_name_the_parameter(kw, match):
    part = load_fixture("pocket")
    args = KW | kw
    with pytest.raises(cadcnc.InputError, match=match):
        intersection_path(part.face(10), part.face(17), **args)


def test_a_wall_lower_than_the_ball_is_refused_at_the_start():
    """A start where the ball would touch a face beyond its boundary is an error."""
    part = load_fixture("narrow_slot")
    # the slot is 4 wide: a 3 mm ball on the floor against one wall crosses the other wall,
    # and the slot walls are 5 high; a 6 mm ball's wall contact at height 6 is above them
    with pytest.raises(StartPointError, match="outside the face"):
        intersection_path(part.face(3), part.face(4), radius=6, **KW)
