"""The judge's reading of surface models (``coverage_oracle.py``): sewn, numbered in the
file's order, material side by the spec's rules. Shares no code with cadcnc.

A shape with no solid is sewn (``BRepBuilderAPI_Sewing``, 0.01 mm) so that neighbouring
faces share edges. Face n keeps its number, the n-th face of ``TopExp::MapShapes`` of the
shape as read, through ``Sewing::Modified``. The material side (issue 10): a closed shell
encloses it (the shell's volume, ``BRepGProp``, is negative when its faces point inward:
then every face is flipped); an open shell has it on the side its normals point away
from, chosen so that most of its area faces +Z (area sampled on a 5 x 5 grid per face,
inside the trimmed face).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
from OCP.BRepGProp import BRepGProp
from OCP.BRepTools import BRepTools
from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d
from OCP.GeomLProp import GeomLProp_SLProps
from OCP.gp import gp_Pnt2d
from OCP.GProp import GProp_GProps
from OCP.TopAbs import (
    TopAbs_EDGE,
    TopAbs_FACE,
    TopAbs_IN,
    TopAbs_REVERSED,
    TopAbs_SHELL,
    TopAbs_SOLID,
)
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

SEWING_TOL = 1e-2  # mm: export gaps close, far below any feature a ball follows


@dataclass
class Sewn:
    """A surface model as the judge reads it: the sewn shape, and per file face number
    its face in the sewn shape and whether its outward normal is flipped."""

    shape: object
    faces: dict          # number -> TopoDS_Face (as in ``shape``)
    flip: dict           # number -> bool
    rules: list          # per shell: "closed shell" / "open shell" (+ ", flipped")


def sew_model(shape) -> Sewn | None:
    """The sewn model of a shape without a solid, or None for a solid."""
    if TopExp_Explorer(shape, TopAbs_SOLID).More():
        return None
    before, after = TopTools_IndexedMapOfShape(), TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, before)
    sewing = BRepBuilderAPI_Sewing(SEWING_TOL)
    for n in range(1, before.Extent() + 1):   # face by face: Modified() answers per face
        sewing.Add(before.FindKey(n))
    sewing.Perform()
    sewn = sewing.SewedShape()
    TopExp.MapShapes_s(sewn, TopAbs_FACE, after)
    faces = {}
    for n in range(1, before.Extent() + 1):
        f = before.FindKey(n)
        g = sewing.Modified(f) if sewing.IsModified(f) else f
        k = after.FindIndex(g)
        if k == 0:
            raise ValueError(f"face {n} is lost in sewing")
        faces[n] = TopoDS.Face_s(after.FindKey(k))
    number = {after.FindIndex(f): n for n, f in faces.items()}
    flip, rules = {n: False for n in faces}, []
    explorer = TopExp_Explorer(sewn, TopAbs_SHELL)
    while explorer.More():
        shell = explorer.Current()
        members = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(shell, TopAbs_FACE, members)
        numbers = [number[after.FindIndex(members.FindKey(k))]
                   for k in range(1, members.Extent() + 1)]
        inward = _closed(shell) and _volume(shell) < 0.0
        rule = "closed shell" if _closed(shell) else "open shell"
        if not _closed(shell):
            inward = _area_facing_z(shell) < 0.0
        for n in numbers:
            flip[n] = inward
        rules.append(rule + (", flipped" if inward else ""))
        explorer.Next()
    return Sewn(sewn, faces, flip, rules)


def _closed(shell) -> bool:
    """No free edge: every edge of the shell has two faces."""
    emap = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shell, TopAbs_EDGE, TopAbs_FACE, emap)
    return all(emap.FindFromIndex(k).Size() >= 2 or BRep_Tool.Degenerated_s(
        TopoDS.Edge_s(emap.FindKey(k))) for k in range(1, emap.Extent() + 1))


def _volume(shell) -> float:
    """Signed volume enclosed by a closed shell as its faces are oriented, mm^3."""
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(BRepBuilderAPI_MakeSolid(TopoDS.Shell_s(shell)).Solid(),
                                 props)
    return props.Mass()


def _area_facing_z(shell, n: int = 5) -> float:
    """Area with outward normal z > 0 minus area with z < 0 (sampled), mm^2."""
    total = 0.0
    explorer = TopExp_Explorer(shell, TopAbs_FACE)
    while explorer.More():
        face = TopoDS.Face_s(explorer.Current())
        surface = BRep_Tool.Surface_s(face)
        umin, umax, vmin, vmax = BRepTools.UVBounds_s(face)
        classifier = BRepTopAdaptor_FClass2d(face, 1e-7)  # Precision::Confusion()
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(face, props)
        signs = []
        for u in umin + (umax - umin) * (np.arange(n) + 0.5) / n:
            for v in vmin + (vmax - vmin) * (np.arange(n) + 0.5) / n:
                if classifier.Perform(gp_Pnt2d(u, v)) != TopAbs_IN:
                    continue
                lp = GeomLProp_SLProps(surface, u, v, 1, 1e-9)  # normal's resolution
                if lp.IsNormalDefined():
                    z = lp.Normal().Z() * (-1.0 if face.Orientation() == TopAbs_REVERSED
                                           else 1.0)
                    signs.append(np.sign(z))
        if signs:
            total += props.Mass() * float(np.mean(signs))
        explorer.Next()
    return total
