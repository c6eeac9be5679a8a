"""What the stock simulation asks of OCCT: the part (or a stock solid) as numbered
triangles, and the exact distance from a point to the part's faces.

The simulation (:mod:`cadcnc.simulation`) holds no OCCT: it meets these triangles with its
rays and asks :func:`exact_depths` for the points it suspects of a gouge, so a reported
depth is OCCT's, not the mesh's. Lengths mm.
"""

from __future__ import annotations

import numpy as np
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepOffset import BRepOffset_Skin
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffsetShape
from OCP.GeomAbs import GeomAbs_Arc
from OCP.gp import gp_Pnt
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Compound

from ..core.errors import InputError
from ..geometry.mesh import face_triangles
from ..geometry.part import Part, load_step

ANGULAR = 0.1   # rad: the mesh's angular deflection


def shape_triangles(shape, deflection: float, number=None) -> tuple[np.ndarray, np.ndarray]:
    """(triangles (T, 3, 3) mm wound outward, face numbers (T,)) of ``shape`` meshed within
    ``deflection`` mm; ``number(face)``: a face's number (default: 1, 2, ... in order)."""
    BRepMesh_IncrementalMesh(shape, deflection, False, ANGULAR, True)
    tris, faces = [], []
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    i = 0
    while exp.More():
        face = TopoDS.Face_s(exp.Current())
        i += 1
        t = face_triangles(face)
        if t is not None and len(t):
            tris.append(t)
            faces.append(np.full(len(t), number(face) if number else i, np.int32))
        exp.Next()
    if not tris:
        raise InputError("the solid has no meshable face")
    return np.concatenate(tris), np.concatenate(faces)


def part_triangles(part: Part, deflection: float) -> tuple[np.ndarray, np.ndarray]:
    """The part's triangles and their face numbers (1..N, as everywhere in cadcnc)."""
    return shape_triangles(part.shape, deflection, part.face_number)


def offset_triangles(part: Part, margin: float, deflection: float):
    """The triangles of the part grown by ``margin`` mm (OCCT's offset, arcs at edges)."""
    maker = BRepOffsetAPI_MakeOffsetShape()
    maker.PerformByJoin(part.shape, float(margin), 1e-6, BRepOffset_Skin, False, False,  # tol mm
                        GeomAbs_Arc)
    if not maker.IsDone():
        raise InputError(f"OCCT cannot offset the part by {margin:g} mm: give --stock box "
                         "or a stock STEP file")
    return shape_triangles(maker.Shape(), deflection)


def step_triangles(path, deflection: float):
    """The triangles of the solid in the STEP file ``path`` (the stock)."""
    return shape_triangles(load_step(path).shape, deflection)


class PartDistance:
    """OCCT's exact distance from points to the part's faces (the faces as one compound)."""

    def __init__(self, part: Part):
        self.part = part
        self.compound = TopoDS_Compound()
        builder = BRep_Builder()
        builder.MakeCompound(self.compound)
        for f in part.faces:
            builder.Add(self.compound, f.topods)

    def __call__(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(distance (n,) mm, nearest face number (n,)) of ``points`` (n, 3)."""
        dist, face = np.empty(len(points)), np.zeros(len(points), np.int32)
        for i, p in enumerate(np.asarray(points, float)):
            vertex = BRepBuilderAPI_MakeVertex(gp_Pnt(*p)).Vertex()
            d = BRepExtrema_DistShapeShape(vertex, self.compound)
            if not d.IsDone() or d.NbSolution() == 0:
                dist[i] = np.nan
                continue
            dist[i] = d.Value()
            support = d.SupportOnShape2(1)
            if support.ShapeType() == TopAbs_FACE:
                face[i] = self.part.face_number(support)
            else:   # on an edge or a vertex: the first face holding it
                for n, f in enumerate(self.part.faces, 1):
                    exp = TopExp_Explorer(f.topods, support.ShapeType())
                    while exp.More():
                        if exp.Current().IsSame(support):
                            face[i] = n
                            break
                        exp.Next()
                    if face[i]:
                        break
        return dist, face
