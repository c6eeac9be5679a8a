"""OCCT's section of faces' offset surfaces by a horizontal plane: loop seeds and counts.

A ball of radius R' touching a face has its centre on the face's offset surface (the
face's points moved R' along their outward normals, OCCT's
``BRepOffset_MakeSimpleOffset`` of the trimmed face: its edges are the offsets of the
face's edges). The waterline loops at height z are the section of those offset faces by
the plane z = const (``BRepAlgoAPI_Section``), its edges joined into wires
(``ShapeAnalysis_FreeBounds.ConnectEdgesToWires``). Finishing takes a seed point on every
closed wire of a face, and counts the wires of the selected faces as the loops it must
find. Lengths mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_CompCurve
from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
from OCP.BRepOffset import BRepOffset_MakeSimpleOffset
from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_HSequenceOfShape

from ..core.errors import GeometryError

JOIN_TOL = 1e-6
"""mm: section edges whose ends are this near are joined into one wire."""
SAMPLE_MM = 0.5
"""mm: the spacing of the points sampled along each section wire (uniform in the wire's
parameter, counted from its length over COARSE points: about this spacing)."""
COARSE = 17


@dataclass
class SectionWire:
    """One wire of a section: ``points`` (K, 3) along it about SAMPLE_MM apart (its ends
    included; a closed wire's last point is its first), ``closed``, ``length`` mm (of a
    COARSE-point polyline: a lower bound)."""

    points: np.ndarray
    closed: bool
    length: float


def offset_face(face, offset: float):
    """The offset of the trimmed TopoDS ``face`` by ``offset`` mm along its outward normal
    (the face's orientation taken into account): a TopoDS_Face."""
    mk = BRepOffset_MakeSimpleOffset(face, float(offset))
    mk.Perform()
    if not mk.IsDone():
        raise GeometryError(f"OCCT could not offset a face by {offset:g} mm")
    exp = TopExp_Explorer(mk.GetResultShape(), TopAbs_FACE)
    if not exp.More():
        raise GeometryError(f"OCCT's offset of a face by {offset:g} mm has no face")
    return TopoDS.Face_s(exp.Current())


def _section_edges(faces, z: float) -> TopTools_HSequenceOfShape:
    seq = TopTools_HSequenceOfShape()
    plane = gp_Pln(gp_Pnt(0.0, 0.0, float(z)), gp_Dir(0.0, 0.0, 1.0))
    for face in faces:
        sec = BRepAlgoAPI_Section(face, plane, False)   # built once, below
        sec.Approximation(False)
        sec.Build()
        if not sec.IsDone():
            raise GeometryError(f"OCCT's section of an offset face at z {z:g} mm failed")
        exp = TopExp_Explorer(sec.Shape(), TopAbs_EDGE)
        while exp.More():
            seq.Append(exp.Current())
            exp.Next()
    return seq


def section_wires(faces, z: float, join: float = JOIN_TOL,
                  spacing: float = SAMPLE_MM) -> list[SectionWire]:
    """The wires of the section of TopoDS ``faces`` (offset faces) by the plane at height
    ``z`` (mm), edges joined where their ends are within ``join`` mm, each sampled about
    ``spacing`` mm apart."""
    edges = _section_edges(faces, z)
    if edges.Length() == 0:
        return []
    wires = TopTools_HSequenceOfShape()
    ShapeAnalysis_FreeBounds.ConnectEdgesToWires_s(edges, join, False, wires)
    out = []
    for i in range(1, wires.Length() + 1):
        curve = BRepAdaptor_CompCurve(TopoDS.Wire_s(wires.Value(i)))
        t0, t1 = curve.FirstParameter(), curve.LastParameter()
        coarse = np.array([curve.Value(t).Coord() for t in np.linspace(t0, t1, COARSE)])
        closed = bool(np.linalg.norm(coarse[-1] - coarse[0]) <= join)
        length = float(np.linalg.norm(np.diff(coarse, axis=0), axis=1).sum())
        count = max(COARSE, int(np.ceil(length / spacing)) + 1)
        pts = np.array([curve.Value(t).Coord() for t in np.linspace(t0, t1, count)])
        out.append(SectionWire(pts, closed, float(length)))
    return out


def loop_count(faces, z: float, join: float = JOIN_TOL) -> tuple[int, int]:
    """(closed, open): how many closed and open wires the section of TopoDS ``faces`` by
    the plane at height ``z`` (mm) has."""
    wires = section_wires(faces, z, join, spacing=10.0)
    closed = sum(w.closed for w in wires)
    return closed, len(wires) - closed
