"""The shank: where only the shank would touch the part, nothing is cut (docs/reliability.md).

A floor-wall corner runs under a roof that hangs from the wall: the ball fits the corner
everywhere (the roof is 9 mm above it), but under the roof the shank (10 R long) would
pass through it. The gate checks the ball only; the operations' guard checks the shank
while cutting and the plunges and retracts of the links. Judged independently: OCCT's
distance from the shank's axis segment, at samples along every written move, to the part
is at least R' less the gouge limit.
"""

from __future__ import annotations

import math

import cadquery as cq
import numpy as np
import pytest
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt

import cadcnc
from helpers.programs import pencil_run

R = 3.0
ROOF = (10.0, 22.0)   # the roof covers y in [0, 10] from z 22 up; the corner is at z 10


@pytest.fixture(scope="module")
def roofed():
    base = cq.Workplane().box(20, 20, 10, centered=False)
    wall = cq.Workplane().box(10, 20, 40, centered=False)
    roof = cq.Workplane().box(25, ROOF[0], 5, centered=False).translate((0, 0, ROOF[1]))
    part = cadcnc.Part.from_cadquery(base.union(wall).union(roof).val())
    return part, pencil_run(part, radius=R)


def shank_distance(part, p: np.ndarray, length: float) -> float:
    """OCCT's distance (mm) from the shank's axis segment p .. p + length z to the part."""
    edge = BRepBuilderAPI_MakeEdge(gp_Pnt(*map(float, p)),
                                   gp_Pnt(float(p[0]), float(p[1]), float(p[2] + length))).Edge()
    ext = BRepExtrema_DistShapeShape(edge, part.shape)
    assert ext.IsDone()
    return ext.Value()


def samples(points: np.ndarray, spacing: float) -> np.ndarray:
    out = [points[:1]]
    for a, b in zip(points[:-1], points[1:]):
        n = max(1, math.ceil(np.linalg.norm(b - a) / spacing))
        out.append(a + np.linspace(0, 1, n + 1)[1:, None] * (b - a))
    return np.vstack(out)


def test_only_the_shank_would_touch_under_the_roof(roofed):
    part, _ = roofed
    under = np.array([13.0, 5.0, 13.0])    # the floor-wall corner's ball centre, under the roof
    ball = BRepExtrema_DistShapeShape(
        BRepBuilderAPI_MakeEdge(gp_Pnt(*under), gp_Pnt(*(under + 1e-6))).Edge(), part.shape)
    assert ball.Value() >= R - 1e-6                      # the ball itself fits
    assert shank_distance(part, under, 10 * R) < R - 1.0  # its shank runs into the roof


def test_every_written_move_keeps_the_shank_clear(roofed):
    part, program = roofed
    floor = [c for c in program.cuts if np.allclose(c.points[:, 2], 13.0, atol=1e-5)]
    assert floor and min(c.points[:, 1].min() for c in floor) >= ROOF[0] + R - 1e-3
    limit = R - program.job.tolerances.gouge
    for seg in program.segments:
        for p in samples(seg.points, 0.5)[::3]:
            assert shank_distance(part, p, program.job.tool.shank) >= limit, (seg.kind, p)
