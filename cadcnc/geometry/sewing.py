"""Sew a surface model's faces into consistently oriented shells, keeping the file's numbers.

A STEP surface model (shells, or loose faces with no shared edges) has no adjacency until
its faces are sewn: OCCT's ``BRepBuilderAPI_Sewing`` merges edges that lie within the
sewing tolerance (mm) of each other, which may replace every face by a new one. Face
numbers must stay those of the file (``TopExp::MapShapes`` of the shape as read), so each
sewn face is mapped back to its original index through ``Sewing::IsModified/Modified``.
Each connected shell is then oriented consistently (``ShapeFix_Shell::FixFaceOrientation``
alone: no other repair that could replace a face): every shared edge is used in opposite
directions by its two faces, which :func:`inconsistent_edges` counts.
"""

from __future__ import annotations

from dataclasses import dataclass

from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
from OCP.ShapeFix import ShapeFix_Shell
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_SHELL
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Shape, TopoDS_Shell
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

from ..core.errors import StepFileError


@dataclass
class Sewn:
    """The result of sewing: ``shells`` (TopoDS_Shell, each consistently oriented),
    ``numbers`` (one list per shell: the file's 1-based face number of each face, in the
    shell's own order), the ``tolerance`` used and the largest edge tolerance after sewing
    (``edge_tolerance``, mm: it bounds every gap between sewn faces, the file's own
    included), and ``free_edges`` (edges of one face
    only: an open shell's border, or a gap wider than the tolerance)."""

    shells: list
    numbers: list[list[int]]
    tolerance: float
    edge_tolerance: float
    free_edges: int
    n_faces: int
    face_map: TopTools_IndexedMapOfShape  # the sewn faces; index = the file's face number


def file_faces(shape: TopoDS_Shape) -> TopTools_IndexedMapOfShape:
    """The faces of ``shape`` numbered 1..N in ``TopExp::MapShapes`` order (the file's)."""
    fmap = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, fmap)
    return fmap


def sew(shape: TopoDS_Shape, tolerance: float, source: str = "<shape>") -> Sewn:
    """Sew every face of ``shape`` at ``tolerance`` (mm) and orient each shell.

    StepFileError when sewing drops a face (degenerate within the tolerance), so that no
    face number silently disappears.
    """
    original = file_faces(shape)
    n = original.Extent()
    sewing = BRepBuilderAPI_Sewing(tolerance)
    for k in range(1, n + 1):
        sewing.Add(original.FindKey(k))
    sewing.Perform()
    result = sewing.SewedShape()
    # the sewn face of each original face, in the file's order: the key of the map
    sewn = TopTools_IndexedMapOfShape()
    for k in range(1, n + 1):
        face = original.FindKey(k)
        new = sewing.Modified(face) if sewing.IsModified(face) else face
        if new.IsNull() or new.ShapeType() != TopAbs_FACE or sewn.Add(new) != k:
            raise StepFileError(f"{source}: sewing at {tolerance:g} mm lost face {k} "
                                "(degenerate within the sewing tolerance, or a duplicate)")
    shells = [_oriented(s) for s in _shells_of(result)]
    shells = [s for group in shells for s in group]
    numbers = []
    for shell in shells:
        ids = []
        exp = TopExp_Explorer(shell, TopAbs_FACE)
        while exp.More():
            ids.append(sewn.FindIndex(exp.Current()))
            exp.Next()
        numbers.append(ids)
    found = sorted(k for ids in numbers for k in ids)
    if found != list(range(1, n + 1)):
        missing = sorted(set(range(1, n + 1)) - set(found))
        raise StepFileError(f"{source}: after sewing, faces {missing} belong to no shell")
    return Sewn(shells, numbers, tolerance, _largest_edge_tolerance(result),
                sewing.NbFreeEdges(), n, sewn)


def _shells_of(result: TopoDS_Shape) -> list[TopoDS_Shell]:
    """The shells of the sewn shape; a face left on its own becomes a shell of one face."""
    shells = []
    exp = TopExp_Explorer(result, TopAbs_SHELL)
    while exp.More():
        shells.append(TopoDS.Shell_s(exp.Current()))
        exp.Next()
    builder = BRep_Builder()
    exp = TopExp_Explorer(result, TopAbs_FACE, TopAbs_SHELL)  # faces outside any shell
    while exp.More():
        shell = TopoDS_Shell()
        builder.MakeShell(shell)
        builder.Add(shell, exp.Current())
        shells.append(shell)
        exp.Next()
    return shells


def _oriented(shell: TopoDS_Shell) -> list[TopoDS_Shell]:
    """The shell with its faces oriented consistently (one shell per connected piece)."""
    fix = ShapeFix_Shell()
    fix.FixFaceOrientation(shell, True, False)
    out = fix.Shape()
    if out.ShapeType() == TopAbs_SHELL:
        return [TopoDS.Shell_s(out)]
    return _shells_of(out)


def _largest_edge_tolerance(shape: TopoDS_Shape) -> float:
    emap = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, emap)
    return max((BRep_Tool.Tolerance_s(TopoDS.Edge_s(emap.FindKey(k)))
                for k in range(1, emap.Extent() + 1)), default=0.0)


def inconsistent_edges(shape: TopoDS_Shape) -> int:
    """Edges shared by two faces that both use them in the same direction (0 when every
    shell of ``shape`` is consistently oriented); seams and free edges are not counted."""
    emap = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, emap)
    bad = 0
    for k in range(1, emap.Extent() + 1):
        edge, faces = emap.FindKey(k), list(emap.FindFromIndex(k))
        if len(faces) != 2 or faces[0].IsSame(faces[1]):
            continue
        uses = [_use(face, edge) for face in _as_found(shape, faces)]
        bad += uses[0] is not None and uses[0] == uses[1]
    return bad


def _as_found(shape, faces):
    """The faces as explored from ``shape`` (orientation composed through its shells)."""
    out = []
    for face in faces:
        exp = TopExp_Explorer(shape, TopAbs_FACE)
        while exp.More():
            if exp.Current().IsSame(face):
                out.append(exp.Current())
                break
            exp.Next()
    return out


def _use(face, edge):
    """The orientation with which ``face`` (as oriented in its shell) uses ``edge``."""
    exp = TopExp_Explorer(face, TopAbs_EDGE)
    while exp.More():
        if exp.Current().IsSame(edge):
            return exp.Current().Orientation()
        exp.Next()
    return None
