"""Faces that are their whole parameter box (the natural bounds of their surface).

On such a face every point of the (u, w) box belongs to the face, so OCCT's global
search over the box (:meth:`~.probe.FaceProbe.project_global`) searches the face itself,
and a foot it finds on the box's side lies on the face's edges
(:meth:`~.probe.FaceProbe.interior_distance`).
"""

from __future__ import annotations

from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve2d
from OCP.GeomAbs import GeomAbs_Line
from OCP.TopAbs import TopAbs_EDGE, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

ISO_DIRECTION, ISO_SIDE = 1e-12, 1e-9
"""A pcurve runs along u (or w) when its direction's other component is below
ISO_DIRECTION, and lies on the box's side when within ISO_SIDE of it (parameter units)."""


def whole_box(face, box) -> bool:
    """Whether ``face`` is the whole (u, w) box ``box`` = (umin, umax, wmin, wmax): one
    wire (no hole) whose edges all run straight along u or w (their pcurves on the face)
    on the box's sides, degenerate ones (a pole) aside."""
    wires = TopExp_Explorer(face, TopAbs_WIRE)
    wires.Next()
    if wires.More():  # a second wire: a hole
        return False
    umin, umax, wmin, wmax = box
    edges, explorer = [], TopExp_Explorer(face, TopAbs_EDGE)
    while explorer.More():
        edges.append(TopoDS.Edge_s(explorer.Current()))
        explorer.Next()
    for edge in (e for e in edges if not BRep_Tool.Degenerated_s(e)):
        curve = BRepAdaptor_Curve2d(edge, face)
        if curve.GetType() != GeomAbs_Line:
            return False
        (x, y), (dx, dy) = curve.Line().Location().Coord(), curve.Line().Direction().Coord()
        along_w = abs(dx) <= ISO_DIRECTION and min(abs(x - umin), abs(x - umax)) <= ISO_SIDE
        along_u = abs(dy) <= ISO_DIRECTION and min(abs(y - wmin), abs(y - wmax)) <= ISO_SIDE
        if not (along_u or along_w):
            return False
    return True
