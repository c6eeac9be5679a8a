"""Faces that are planes in all but name: their twin on a true plane, checked against OCCT.

A face's surface may be a plane without being typed one: an extrusion of a planar curve
along a direction in its plane (the sides of a slab extruded from a B-spline top), a
B-spline whose poles lie in a plane. OCCT's exact distance to such a face
(``BRepExtrema_DistShapeShape``, ~2 ms a point) has the closed form of a planar region
(:meth:`~.probe.FaceProbe.plane_distance`, OCCT's classifier and edge projections).
:func:`planar_twin` builds the same region on a ``Geom_Plane``: the face's own wires
(edges and their 3-D curves unchanged), the plane oriented as the surface, and accepts it
only when OCCT says the surface lies within :data:`PLANAR_TOL` of that plane, the twin
is a valid face of the same area, and its distances agree with DistShapeShape's on the
original face at probe points (:func:`_agrees`). Lengths in mm.
"""

from __future__ import annotations

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.BRepTools import BRepTools
from OCP.GeomAbs import GeomAbs_Plane
from OCP.GeomLib import GeomLib_IsPlanarSurface
from OCP.gp import gp_Ax3, gp_Dir, gp_Pln
from OCP.GProp import GProp_GProps
from OCP.TopAbs import TopAbs_FORWARD, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from ..core.tolerances import Tolerances
from .probe import FaceProbe

PLANAR_TOL = 1e-10
"""How far (mm) the surface may leave its plane (GeomLib_IsPlanarSurface): far below the
1e-9 mm to which the gate's depths must match the reference gate's."""
AGREE = 1e-9
"""The twin's distances must match DistShapeShape's on the face within this (mm)."""
AREA_REL = 1e-2
"""The twin's area must match the face's within this fraction: OCCT integrates the two
surfaces differently (up to 5e-4 apart on the slab's sides); a twin that kept the wrong
side of a wire would be far off (the distances at points then decide)."""


def planar_twin(probe: FaceProbe, tol: Tolerances) -> FaceProbe | None:
    """A :class:`FaceProbe` of ``probe``'s trimmed face rebuilt on its plane, or None
    (already a plane, not planar, or the twin fails a check: module doc)."""
    if probe.adaptor.GetType() == GeomAbs_Plane:
        return None
    test = GeomLib_IsPlanarSurface(probe.surface, PLANAR_TOL)
    if not test.IsPlanar():
        return None
    try:
        twin = _rebuilt(probe, test.Plan())
    except Exception:  # noqa: BLE001 - no twin: OCCT's distance is used
        return None
    if twin is None:
        return None
    twin_probe = FaceProbe(twin, tol)
    return twin_probe if _agrees(probe, twin_probe) else None


def _rebuilt(probe: FaceProbe, plane: gp_Pln):
    """The face's wires on ``plane`` oriented as the surface's D1U x D1V, or None."""
    face = probe.face
    umin, umax, wmin, wmax = probe.box
    probe.adaptor.D1(0.5 * (umin + umax), 0.5 * (wmin + wmax), probe._p, probe._du, probe._dw)
    n = probe._du.Crossed(probe._dw)
    if n.Magnitude() <= 0:
        return None
    axis = plane.Position()
    direction = axis.Direction()
    if gp_Dir(n).Dot(direction) < 0:
        direction = direction.Reversed()
    oriented = gp_Pln(gp_Ax3(axis.Location(), direction))
    forward = TopoDS.Face_s(face.Oriented(TopAbs_FORWARD))  # wires as on the surface
    outer = BRepTools.OuterWire_s(forward)
    maker = BRepBuilderAPI_MakeFace(oriented, outer, True)
    explorer = TopExp_Explorer(forward, TopAbs_WIRE)
    while explorer.More():
        wire = TopoDS.Wire_s(explorer.Current())
        if not wire.IsSame(outer):
            maker.Add(wire)
        explorer.Next()
    if not maker.IsDone():
        return None
    twin = maker.Face()
    twin.Orientation(face.Orientation())
    if not BRepCheck_Analyzer(twin).IsValid():
        return None
    return twin


def _area(face) -> float:
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, props)
    return props.Mass()


def _agrees(probe: FaceProbe, twin: FaceProbe) -> bool:
    """About the same area, and the twin's closed-form distances (signed and unsigned)
    equal DistShapeShape's on the original face at points scattered around the face and
    at points 1 mm off either side of the surface over its parameter box (feet inside the
    face and outside it, near its boundary)."""
    a, b = _area(probe.face), _area(twin.face)
    if not (a > 0 and abs(a - b) <= AREA_REL * a):
        return False
    lo, hi = twin.bbox()
    centre, size = 0.5 * (lo + hi), float(np.linalg.norm(hi - lo)) + 1.0
    points = list(centre + 0.6 * size * np.random.default_rng(0).uniform(-1, 1, (6, 3)))
    umin, umax, wmin, wmax = probe.box
    for u in np.linspace(umin, umax, 4):
        for w in np.linspace(wmin, wmax, 3):
            n = probe.normal(u, w)  # leaves the surface point in probe._p
            q = np.array(probe._p.Coord())
            points += [q + n, q - n]
    for p in points:
        closed = twin.plane_distance(p)
        exact = probe.face_distance(p)
        if closed is not None and not (abs(closed[0] - exact[0]) <= AGREE
                                       and abs(closed[1] - exact[1]) <= AGREE):
            return False
    return True
