"""Finishing passes run either way cover the same stretches, travel their way, and a pass
that does not is caught by the operation's self-check; planes grazing edges and vertices.

Facts are closed forms of the fixtures (fixtures/finish_fixtures.json) or the forward
pass compared with the reverse one, interpolated independently from the other end.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import cadcnc
import cadcnc.ops.finish.crossings as crossings_module
import cadcnc.ops.finish.passes as pass_module
from cadcnc.core.job import Job, PairPath, Raster, Tool
from cadcnc.ops.finish.check import pass_problems
from cadcnc.ops.finish.pass_setup import pass_setup
from cadcnc.ops.finish.passes import GuidePlane, pass_cuts
from cadcnc.ops.finish.raster import plan_for_job
from cadcnc.ops.finish.shortcut import finish
from cadcnc.program.program import FAILED, CutSegment
from helpers.fixtures import FIXTURES

FACTS = json.loads((FIXTURES / "finish_fixtures.json").read_text())
UM = 1e-3
_parts: dict = {}


def part_of(name: str):
    if name not in _parts:
        _parts[name] = cadcnc.load_step(FIXTURES / FACTS[name]["file"])
    return _parts[name]


def job_of(radius: float, faces=None, angle: float = 0.0, stepover: float = 2.0) -> Job:
    """A finishing job (``faces`` given: the plan's), or a bare pass's."""
    op = PairPath() if faces is None else Raster(tuple(faces), stepover, None, angle,
                                                 "zigzag")
    return Job(Tool(radius), 1500.0, 0.004, op)


def rolled(cut) -> bool:
    return cut.path.stop_detail.startswith("rolled over")


def assert_same_stretches(fwd, back, plane):
    """The reverse pass cuts the forward pass's stretches in the opposite order, each
    from the other end (within 1 um) and on the same face (a roll-over arc, which
    belongs to the edge, on either of its faces), and every cut travels its pass's way."""
    assert not [s for s in fwd.skipped + back.skipped if s.reason == FAILED]
    assert len(fwd.cuts) == len(back.cuts), ([c.path.faces for c in fwd.cuts],
                                             [c.path.faces for c in back.cuts])
    for a, b in zip(fwd.cuts, back.cuts[::-1]):
        assert rolled(a) == rolled(b)
        if not rolled(a):
            assert a.path.faces[0] == b.path.faces[0]
        assert np.linalg.norm(a.points[0] - b.points[-1]) < UM
        assert np.linalg.norm(a.points[-1] - b.points[0]) < UM
    for res, sense in ((fwd, 1.0), (back, -1.0)):
        for cut in res.cuts:
            s = cut.points @ (sense * plane.direction)
            assert np.diff(s).min() >= -1e-9, (sense, cut.path.faces)


# -- the reported case: a box with two rounded top edges, across (angle 90), R 2 --------------
def test_rounded_box_reversed_cuts_round_top_round_backwards():
    f = FACTS["rounded"]
    plane, job = GuidePlane(90.0, -13.5), job_of(2.0)
    fwd = pass_cuts(part_of("rounded"), f["faces"], plane, job)
    back = pass_cuts(part_of("rounded"), f["faces"], plane, job, reverse=True)
    lo, hi = f["rounds"]
    assert [c.path.faces[0] for c in fwd.cuts] == [lo, f["top"], hi]
    assert [c.path.faces[0] for c in back.cuts] == [hi, f["top"], lo]
    assert_same_stretches(fwd, back, plane)
    # each round's cut: centres on the circle r + R' about its axis, from the side's
    # bottom of the round (y = +-(6 + r + R'), z = 1) to the top (y = +-6, z = 5 + R')
    for cut, (ay, az) in ((back.cuts[0], f["round_axes_yz"][1]),
                          (back.cuts[2], f["round_axes_yz"][0])):
        rad = np.hypot(cut.points[:, 1] - ay, cut.points[:, 2] - az)
        assert np.abs(rad - (f["round_radius"] + 2.0)).max() < 1e-8
    np.testing.assert_allclose(back.cuts[0].points[0], [13.5, 12.0, 1.0], atol=1e-9)
    np.testing.assert_allclose(back.cuts[2].points[-1], [13.5, -12.0, 1.0], atol=1e-9)


# -- every plane of a zigzag on the fixtures with several faces ---------------------------------
@pytest.mark.parametrize("name,angle", [("fillet", 0.0), ("ridge", 30.0), ("valley", 30.0),
                                        ("rounded", 90.0), ("rounded", 30.0)])
def test_reverse_covers_the_same_stretches_on_every_plane(name, angle):
    part, faces = part_of(name), FACTS[name]["faces"]
    job = job_of(3.0, faces, angle)
    plan, _ = plan_for_job(part, job)
    assert len(plan.offsets) >= 8
    multi = 0
    for off in plan.offsets:
        plane = GuidePlane(angle, float(off))
        fwd = pass_cuts(part, faces, plane, job)
        back = pass_cuts(part, faces, plane, job, reverse=True)
        assert_same_stretches(fwd, back, plane)
        multi += len({c.path.faces[0] for c in fwd.cuts}) > 1
    assert multi >= len(plan.offsets) // 2   # the planes do cross several faces


# -- the self-check ----------------------------------------------------------------------------
def _flipped(cut: CutSegment) -> CutSegment:
    path = cut.path
    from dataclasses import replace
    return CutSegment(replace(path, points=path.points[::-1].copy()), at_limit=cut.at_limit)


def test_self_check_finds_a_backwards_cut_a_gap_and_a_stretch_cut_twice():
    f = FACTS["rounded"]
    part, plane, job = part_of("rounded"), GuidePlane(90.0, -13.5), job_of(2.0)
    setup = pass_setup(part, f["faces"], job)
    travel = plane.direction
    cross = {k: e.crossings(plane.normal, plane.offset, travel)
             for k, e in setup.edges.items()}
    cuts = pass_cuts(part, f["faces"], plane, job).cuts
    assert pass_problems(cuts, cross, [], travel) == []
    assert "goes back" in " ".join(pass_problems([cuts[0], cuts[1], _flipped(cuts[2])],
                                                 cross, [], travel))
    assert "not covered" in " ".join(pass_problems(cuts[:2], cross, [], travel))
    # the gap accounted for by a skipped stretch is not a problem
    s = cuts[2].points @ travel
    assert pass_problems(cuts[:2], cross, [(s[0], s[-1])], travel) == []
    assert "both cover" in " ".join(pass_problems(cuts + cuts[2:], cross, [], travel))


ACROSS = GuidePlane(90.0, 0.0).normal   # the planes' normal at angle 90


def _travel_signed(n, travel):
    """The orientation finishing used before (planes at angle 90): +-(nrm x n) signed by
    the travel, undefined where the centre's curve is vertical (the bottom of a round)."""
    t = np.cross(ACROSS, n)
    t /= np.linalg.norm(t)
    return -t if t @ travel < 0.0 else t


def test_a_wrong_pass_is_listed_failed_and_the_program_is_not_complete(monkeypatch):
    """With the old orientation (the reported bug) the reversed passes over the rounded
    box go wrong: the operation drops those planes, lists them failed, and the program
    is not complete, where without the check it was wrong and marked complete."""
    monkeypatch.setattr(pass_module, "pass_tangent", _travel_signed)
    monkeypatch.setattr(crossings_module, "pass_tangent", _travel_signed)
    wp = __import__("cadquery").Workplane().box(30, 20, 10).edges("|X and >Z").fillet(4)
    prog = finish(wp, wp.faces(">Z or %CYLINDER"), radius=2.0, stepover=4.0, angle=90.0)
    failed = [s for s in prog.skipped if s.reason == FAILED]
    assert failed and all("self-check" in s.detail and "(reversed)" in s.detail
                          for s in failed)
    assert not prog.complete
    for cut in prog.cuts:   # what is left travels its way
        d = np.diff(cut.points[:, 1])
        assert (d >= -1e-9).all() or (d <= 1e-9).all()


# -- planes grazing an edge or a vertex --------------------------------------------------------
@pytest.fixture(scope="module")
def disc():
    """A cylinder r 10, z 0..5: its top, a disc bounded by one circular edge."""
    import cadquery as cq

    wp = cq.Workplane().circle(10).extrude(5)
    part = cadcnc.Part.from_cadquery(wp)
    return part, part.face_number(wp.faces(">Z").val())


@pytest.mark.parametrize("depth", [1e-2, 1e-3, 1e-4, 1e-6])
def test_a_plane_nearly_tangent_to_a_curved_edge_crosses_it_twice(disc, depth):
    """The plane y = 10 - depth crosses the disc's edge at x = +-sqrt(100 - y^2), as
    little as 2.8e-2 mm apart (depth 1e-6), well inside one 0.25 mm edge sample."""
    part, top = disc
    job = job_of(3.0)
    plane = GuidePlane(0.0, 10.0 - depth)
    edges = pass_setup(part, [top], job).edges[top]
    got = sorted(edges.crossings(plane.normal, plane.offset, plane.direction),
                 key=lambda c: c.s)
    x = math.sqrt(100.0 - (10.0 - depth) ** 2)
    assert [c.entry for c in got] == [True, False]
    np.testing.assert_allclose([c.point for c in got],
                               [[-x, 10 - depth, 8.0], [x, 10 - depth, 8.0]], atol=1e-9)
    res = pass_cuts(part, [top], plane, job)
    assert not res.skipped and len(res.cuts) == (1 if 2 * x > 1e-4 else 0)
    for cut in res.cuts:
        np.testing.assert_allclose(cut.points[[0, -1]], [c.point for c in got], atol=1e-9)


@pytest.mark.parametrize("offset", [10.0, 10.0 + 1e-9, 10.0 + 1e-3])
def test_a_plane_grazing_or_missing_a_curved_edge_cuts_nothing_and_fails_nothing(disc, offset):
    part, top = disc
    res = pass_cuts(part, [top], GuidePlane(0.0, offset), job_of(3.0))
    assert not res.cuts and not res.skipped


@pytest.mark.parametrize("inside", [0.1, 0.05, 1e-3, 0.0, -1e-3])
def test_a_plane_at_or_near_a_vertex_cuts_the_corner_exactly(inside):
    """A box's top (x -15..15, y -10..10, z 5) and a plane at 45 deg passing ``inside``
    mm inside its corner (15, -10): the corner chord, 2 * inside long, entering on the
    edge y = -10 and leaving on x = 15 (travel along (1, 1) / sqrt 2); at or outside the
    corner nothing is cut and nothing fails."""
    import cadquery as cq

    wp = cq.Workplane().box(30, 20, 10)
    part = cadcnc.Part.from_cadquery(wp)
    top = part.face_number(wp.faces(">Z").val())
    plane = GuidePlane(45.0, 0.0)
    corner = float(np.array([15.0, -10.0, 0.0]) @ plane.normal)
    plane = GuidePlane(45.0, corner + inside)
    res = pass_cuts(part, [top], plane, job_of(3.0))
    assert not [s for s in res.skipped if s.reason == FAILED]
    if inside <= 0.0:
        assert not res.cuts
        return
    assert len(res.cuts) == 1
    h = inside * math.sqrt(2.0)
    ends = res.cuts[0].points[[0, -1]]
    np.testing.assert_allclose(ends, [[15.0 - h, -10.0, 8.0], [15.0, -10.0 + h, 8.0]],
                               atol=1e-9)
