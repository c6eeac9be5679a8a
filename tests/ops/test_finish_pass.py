"""One guide plane's finishing pass (cadcnc.ops.finish.passes) on the finishing fixtures.

Every fact is measured by OCCT or taken from the fixtures' closed forms
(fixtures/finish_fixtures.json, fixtures/build_finish_fixtures.py), never from the pass.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS_Compound

import cadcnc
from cadcnc.core.job import Job, PairPath, Tool
from cadcnc.interp.cycle import COLLISION
from cadcnc.ops.finish.passes import GuidePlane, pass_cuts
from cadcnc.verification.probe import FaceProbe
from cadcnc.verification.surface_checks import check_surface
from cadcnc.verification.whole_part import check_whole_part
from helpers.fixtures import FIXTURES

FACTS = json.loads((FIXTURES / "finish_fixtures.json").read_text())
R = 3.0
JOB = Job(Tool(R), 1500.0, 0.004, PairPath())
STEP = JOB.step
UM = 1e-3          # mm: the spec's 1 um
EXACT = 1e-8       # mm: what the pass achieves (points moved onto the exact offset curve)
ON_EDGE = 1e-6     # mm: a contact landed on a face's boundary (edge tolerances ~1e-7)
HIT = JOB.tolerances.hit   # mm: the guard stops the ball at R' - HIT from a third face

_parts: dict = {}


def part_of(name: str):
    if name not in _parts:
        _parts[name] = cadcnc.load_step(FIXTURES / FACTS[name]["file"])
    return _parts[name]


def run(name: str, angle: float, offset: float, reverse: bool = False):
    return pass_cuts(part_of(name), FACTS[name]["faces"], GuidePlane(angle, offset), JOB,
                     reverse=reverse)


def distance(shape, p) -> float:
    """OCCT's distance (mm) from point p to a shape (a trimmed face, a compound of edges)."""
    ext = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, p))).Vertex(),
                                     shape)
    assert ext.IsDone()
    return ext.Value()


def boundary(face) -> TopoDS_Compound:
    """The edges of a face as one compound."""
    comp, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(comp)
    exp = TopExp_Explorer(face.topods, TopAbs_EDGE)
    while exp.More():
        builder.Add(comp, exp.Current())
        exp.Next()
    return comp


def check_cuts(name: str, result, plane: GuidePlane):
    """Every point R' from its face (OCCT, trimmed face) within 1 um and on the plane to
    1e-9; the ball clear of every face of the part (whole-part check, material-aware)."""
    part = part_of(name)
    tol = JOB.tolerances
    for cut in result.cuts:
        face = cut.path.faces[0]
        pts = cut.points
        assert np.abs(pts @ plane.normal - plane.offset).max() < 1e-9
        probe = FaceProbe(part.face(face).topods, tol)
        surf = check_surface(probe, face, R, pts, cut.path.uv[:, 0], 8, tol)
        assert np.abs(surf.face_deviation).max() < EXACT <= UM, (name, face, surf.to_dict())
        whole, sweep = check_whole_part(part, {face: probe}, cut.path, [surf], R, tol)
        assert whole.max_depth_mm <= tol.hit, (name, whole.to_dict(), whole.hits)
        assert sweep.proven and sweep.depth_bound_mm <= tol.gouge, sweep


def assert_chained(a, b):
    assert np.linalg.norm(a.points[-1] - b.points[0]) <= 1e-6


@pytest.mark.parametrize("angle,offset", [(0.0, 0.5), (30.0, -4.0)])
def test_slab_pass_is_exact_from_entry_to_exit(angle, offset):
    plane = GuidePlane(angle, offset)
    result = run("slab", angle, offset)
    assert len(result.cuts) == 1 and not result.skipped
    check_cuts("slab", result, plane)
    face = part_of("slab").face(FACTS["slab"]["top"])
    cut = result.cuts[0]
    edges = boundary(face)
    for k in (0, -1):   # the contact lands on the face's boundary at both ends
        assert distance(edges, cut.path.contacts[k, 0]) < ON_EDGE
    # travel along +direction, the whole width of the slab
    s = cut.points @ plane.direction
    assert np.all(np.diff(s) > 0)
    steps = np.linalg.norm(np.diff(cut.points, axis=0), axis=1)
    assert steps.max() <= STEP * (1 + 1e-3)


def test_reverse_interpolates_the_same_cuts_backwards():
    fwd, back = run("slab", 0.0, 0.5), run("slab", 0.0, 0.5, reverse=True)
    a, b = fwd.cuts[0].points, back.cuts[0].points
    assert np.linalg.norm(a[0] - b[-1]) < 1e-9 and np.linalg.norm(a[-1] - b[0]) < 1e-9
    # not the same points flipped, but the same curve: every point of one lies on the
    # polyline of the other within the chord sag
    d = [np.min(np.linalg.norm(b - p, axis=1)) for p in a]
    assert max(d) <= STEP / 2 + 1e-6
    assert not (len(a) == len(b) and np.allclose(a, b[::-1], atol=1e-12))


def test_hole_gives_two_cuts_landed_on_its_edge():
    f = FACTS["hole"]
    (hx, hy), hr = f["hole_axis"], f["hole_radius"]
    plane = GuidePlane(0.0, hy)
    result = run("hole", 0.0, hy)
    assert len(result.cuts) == 2 and not result.skipped
    check_cuts("hole", result, plane)
    for q in (result.cuts[0].path.contacts[-1, 0], result.cuts[1].path.contacts[0, 0]):
        assert abs(math.hypot(q[0] - hx, q[1] - hy) - hr) < ON_EDGE
    back = run("hole", 0.0, hy, reverse=True)
    assert len(back.cuts) == 2
    assert np.linalg.norm(back.cuts[0].points[0] - result.cuts[1].points[-1]) < 1e-9


def test_boss_stops_tangent_to_the_wall_and_resumes_past_it():
    f = FACTS["boss"]
    (bx, by), br = f["boss_axis"], f["boss_radius"]
    plane = GuidePlane(0.0, by)
    result = run("boss", 0.0, by)
    assert len(result.cuts) == 2
    check_cuts("boss", result, plane)
    first, second = result.cuts
    assert first.path.stop_reason == COLLISION and f"face {f['boss_face']}" in \
        first.path.stop_detail
    boss = part_of("boss").face(f["boss_face"]).topods
    for p in (first.points[-1], second.points[0]):
        # the ball (radius R') tangent to the boss: its centre R' + r from the axis
        assert abs(math.hypot(p[0] - bx, p[1] - by) - (br + R - HIT)) < EXACT
        assert abs(distance(boss, p) - (R - HIT)) < EXACT
    assert {s.reason for s in result.skipped} == {COLLISION}
    assert all("offset 2.0000 mm, face 6" in s.detail for s in result.skipped)


def test_tangent_edge_is_crossed_without_stopping():
    f = FACTS["fillet"]
    plane = GuidePlane(0.0, 0.0)
    result = run("fillet", 0.0, 0.0)
    assert [c.path.faces[0] for c in result.cuts] == [f["top"], f["fillet"]]
    check_cuts("fillet", result, plane)
    top, fil = result.cuts
    assert_chained(top, fil)
    assert abs(top.path.contacts[-1, 0][0] - f["tangent_x"]) < ON_EDGE
    # on the fillet the centre runs on the circle of radius r + R' around its axis
    ax, az = f["fillet_axis"]
    rad = np.hypot(fil.points[:, 0] - ax, fil.points[:, 2] - az)
    assert np.abs(rad - (f["fillet_radius"] + R)).max() < EXACT


@pytest.mark.parametrize("angle", [0.0, 30.0])
def test_convex_edge_is_rolled_over_on_the_arc(angle):
    f = FACTS["ridge"]
    plane = GuidePlane(angle, 0.5)
    result = run("ridge", angle, 0.5)
    assert len(result.cuts) == 3 and not result.skipped
    check_cuts("ridge", result, plane)
    left, arc, right = result.cuts
    assert_chained(left, arc)
    assert_chained(arc, right)
    # every arc point R' from the ridge line (x = 0, z = 12, along y), at the cycle step
    d = np.hypot(arc.points[:, 0] - f["edge_x"], arc.points[:, 2] - f["edge_z"])
    assert np.abs(d - R).max() < 1e-9
    steps = np.linalg.norm(np.diff(arc.points, axis=0), axis=1)
    assert steps.max() <= STEP * (1 + 1e-3) and len(arc.points) >= 3
    assert (left.path.faces[0], right.path.faces[0]) == (f["left"], f["right"])


def test_concave_edge_passes_the_tri_tangent_point():
    f = FACTS["valley"]
    plane = GuidePlane(20.0, 1.0)
    result = run("valley", 20.0, 1.0)
    assert len(result.cuts) == 2 and not result.skipped
    check_cuts("valley", result, plane)
    a, b = result.cuts
    assert_chained(a, b)
    joint = b.points[0]
    # the ball touching both planes sits above the valley line at 6 + R' / cos 20 deg
    assert abs(joint[0] - f["edge_x"]) < 1e-9
    assert abs(joint[2] - (f["edge_z"] + R * f["tri_tangent_z_per_offset"])) < 1e-9
    part = part_of("valley")
    for face in f["faces"]:
        assert abs(distance(part.face(face).topods, joint) - R) < EXACT
