"""OCCT's own distances, the reference cadcnc's guard, gate and closed forms are judged by."""

from __future__ import annotations

from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt


def occt_distance(point, shape, to=None) -> float:
    """OCCT's distance (mm) from a point (3,), or the segment from it ``to`` a second point,
    to a shape: BRepExtrema_DistShapeShape."""
    a = gp_Pnt(*map(float, point))
    probe = (BRepBuilderAPI_MakeVertex(a).Vertex() if to is None
             else BRepBuilderAPI_MakeEdge(a, gp_Pnt(*map(float, to))).Edge())
    d = BRepExtrema_DistShapeShape(probe, shape)
    d.Perform()
    if not d.IsDone():
        raise AssertionError("BRepExtrema_DistShapeShape did not finish")
    return d.Value()
