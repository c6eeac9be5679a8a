"""A face's boundary edges as the finishing passes read them: each edge's curve on the face
(u, w at the edge parameter t), its length, the face on its other side and the inward
direction, with OCCT's topology behind this one fence. Lengths mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d
from OCP.GCPnts import GCPnts_AbscissaPoint
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from .face_surface import FaceSurface
from .part import Part


@dataclass(eq=False)
class BoundaryEdge:
    """One boundary edge of ``face``, oriented in it. ``t0`` .. ``t1``: its parameter
    range; ``length`` (mm); ``neighbour``: the other face's number (None: a free edge, or
    one shared by more than two faces)."""

    topods: object
    face: FaceSurface
    t0: float
    t1: float
    length: float
    neighbour: int | None
    _curve: object

    def uv(self, t: float) -> tuple[float, float]:
        """The face parameters (u, w) of the edge's point at parameter t."""
        p = self._curve.Value(t)
        return p.X(), p.Y()

    def inward(self, t: float) -> np.ndarray:
        """(3,) unit direction into the face, normal to the edge, at parameter t."""
        return Part.inward_and_normal(self.topods, self.face, t)[0]

    def same(self, other: "BoundaryEdge") -> bool:
        """Whether both are the same edge of the part (seen from either face)."""
        return bool(self.topods.IsSame(other.topods))


def boundary_edges(part: Part, face: FaceSurface) -> list[BoundaryEdge]:
    """The face's boundary edges in its own order, without collapsed edges and seams
    (neither bounds the face)."""
    owners = part.edge_map()   # edge -> the faces holding it
    out = []
    exp = TopExp_Explorer(face.topods, TopAbs_EDGE)
    while exp.More():
        edge = TopoDS.Edge_s(exp.Current())
        exp.Next()
        if BRep_Tool.Degenerated_s(edge) or BRep_Tool.IsClosed_s(edge, face.topods):
            continue
        faces = owners.FindFromKey(edge) if owners.Contains(edge) else []
        others = {part.face_number(f) for f in faces} - {face.number}
        curve = BRepAdaptor_Curve2d(edge, face.topods)
        length = GCPnts_AbscissaPoint.Length_s(BRepAdaptor_Curve(edge))
        out.append(BoundaryEdge(edge, face, curve.FirstParameter(), curve.LastParameter(),
                                length, others.pop() if len(others) == 1 else None, curve))
    return out
