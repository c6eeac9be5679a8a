"""The shank against a torus surface model whose segment distance OCCT gets wrong
(fixtures/torus_surface.step: OCCT test data bug28414, one full torus face).

At the first centre of ``cadcnc finish ... --faces 1 --radius 3 --stepover 2`` the shank
(straight up, 10 R) comes within 0.71 mm of the face by OCCT's point-to-face distances
along it, while OCCT's segment-to-face distance says 2.99 mm. The guard passed the centre
on OCCT's word; it now takes a torus's second opinion (the face's distance where the
segment comes nearest the whole torus, in closed form) and sees the shank hit by as much
as the points along it show (docs/notes/guard-calls.md).
"""

from __future__ import annotations

import numpy as np
import pytest
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt

import cadcnc
from cadcnc.guard import FINISH_OWN_SHARE, guard_for
from helpers.fixtures import FIXTURES

R = 3.0
CENTRE = np.array([-24.28685105, -8.0, 113.73716078])   # the finish program's first centre
ON_AXIS = np.array([-37.8412, 0.0, 116.4141])   # a centre whose shank meets the torus's axis


@pytest.fixture(scope="module")
def torus():
    part = cadcnc.load_step(FIXTURES / "torus_surface.step")
    job = cadcnc.Job(cadcnc.Tool(R), 1500.0, 0.004, cadcnc.Pencil())
    return part, job, _sampled_shank_distance(part, job.tool.shank)


def _sampled_shank_distance(part, shank: float, centre=CENTRE) -> float:
    """The least OCCT point-to-face distance over 200 points of the shank's axis."""
    face = part.face(1).topods
    out = np.inf
    for z in centre[2] + np.linspace(0.0, shank, 200):
        v = BRepBuilderAPI_MakeVertex(gp_Pnt(centre[0], centre[1], float(z))).Vertex()
        x = BRepExtrema_DistShapeShape(v, face)
        x.Perform()
        out = min(out, x.Value())
    return out


def test_points_along_the_shank_come_within_a_millimetre_of_the_torus(torus):
    assert torus[2] < 0.72


def test_the_guard_sees_the_shank_cross_the_torus(torus):
    part, job, reach = torus
    guard = guard_for(part, (1,), job, own_share=FINISH_OWN_SHARE)
    margin, detail = guard.margin(tuple(CENTRE))
    assert "shank" in detail and margin <= reach - job.tool.offset + 1e-3


def test_the_guard_sees_the_shank_where_it_meets_the_torus_axis(torus):
    """Where the vertical shank meets the torus's axis (y = 0 here) the closed form's
    quartic degenerates; the second opinion samples the segment instead (cut 28's last
    centre: the shank 2.84 mm from the face by the points along it)."""
    part, job, _ = torus
    reach = _sampled_shank_distance(part, job.tool.shank, ON_AXIS)
    assert reach < job.tool.offset - 0.1
    margin, detail = guard_for(part, (1,), job, own_share=FINISH_OWN_SHARE).margin(
        tuple(ON_AXIS))
    assert "shank" in detail and margin <= reach - job.tool.offset + 1e-3
