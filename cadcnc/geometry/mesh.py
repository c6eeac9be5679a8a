"""Triangle meshes of faces and shapes, for pictures and checks (never for toolpath
geometry)."""

from __future__ import annotations

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.TopAbs import TopAbs_REVERSED
from OCP.TopLoc import TopLoc_Location


def face_triangles(face) -> np.ndarray | None:
    """(T, 3, 3) corners (mm) of the triangles OCCT's mesh holds for a TopoDS face, each
    wound by the face's orientation (counter-clockwise seen from outside), or None when
    the face has no mesh (run BRepMesh_IncrementalMesh first)."""
    loc = TopLoc_Location()
    tri = BRep_Tool.Triangulation_s(face, loc)
    if tri is None:
        return None
    trsf = loc.Transformation()
    nodes = np.array([tri.Node(i).Transformed(trsf).Coord()
                      for i in range(1, tri.NbNodes() + 1)])
    idx = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)]) - 1
    if face.Orientation() == TopAbs_REVERSED:
        idx = idx[:, ::-1]
    return nodes[idx]


def tessellate(topods, tolerance: float = 0.05, angular: float = 0.2):
    """(vertices (n, 3) mm, triangles (m, 3) int) of a face or shape, via CadQuery.

    ``tolerance`` (mm) is the chordal deflection, ``angular`` (rad) the angular one.
    """
    import cadquery as cq  # ~2.3 s to import: only pictures need it

    verts, tris = cq.Shape.cast(topods).tessellate(tolerance, angular)
    v = np.array([x.toTuple() for x in verts], dtype=float).reshape(-1, 3)
    return v, np.array(tris, dtype=int).reshape(-1, 3)
