"""A cheap, sound proof that a vertical wall under the followed face's edge is clear.

The sides of a finished face (a slab's walls) hang from the edge E they share with the
followed face F. Near that edge the tool is within R' of the wall (the ball touches F at
E), so a box bound cannot clear the wall and OCCT's distance would run at every step there;
the guard's rule counts it clear because the wall's nearest points are on E (a contact
on an edge of F belongs to F's own rules).

**The structure** (checked once per wall K by :func:`hangs_from`): K's generators are
vertical (an extrusion along Z, a vertical plane), and the top of every vertical run of K
lies on an edge or vertex of F: every other edge of K is either a vertical generator
whose top vertex is one of F's, or a lower boundary (K lies above it), its pcurve a graph
across the generators (a line not along them, or a B-spline whose poles run strictly one
way: a monotone control polygon gives a monotone curve) classified once just above and
below.

**The proof at a centre p** (segment S from p up to p + L z), with z0 <= p_z and rho0
the least horizontal distance from p to K's cell boxes topping z0
(:class:`~cadcnc.guard.cells.HeightCells`): if rho0 >= R' - tol, every point q of K
is either at least R' - tol from S (q above z0, or on a run whose top is above z0: its
box, and so the whole vertical run, is that far horizontally), or lies on a run whose
top t (on F's edge) is at most z0 <= p_z, and then |p - q| >= |p - t| with equality only
at t. So K's nearest points, when nearer than R' - tol, are on F's edge: clear under the
guard's rule. It holds for every centre p' with p'_z >= z0 and rho0 - |p'_xy - p_xy| >=
R' - tol, hence :meth:`WallProof.budget` = min(p_z - z0, rho0 - (R' - tol)). Lengths mm.
"""

from __future__ import annotations

import math

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d
from OCP.GeomAbs import GeomAbs_BSplineCurve, GeomAbs_Line
from OCP.TopAbs import TopAbs_EDGE, TopAbs_VERTEX
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedMapOfShape

from ..core.tolerances import VERTICAL
from ..core.trim_labels import INSIDE, OUTSIDE
from .cells import DROPS, REUSE, HeightCells, shared

PROBE = 1e-4       # the classification's step off an edge, as a fraction of the v range


def _frame(face) -> tuple[np.ndarray, np.ndarray] | None:
    """(up, across) unit directions in the face's (u, w) parameters when its surface's
    generators are vertical lines (u, w) + t up mapped to p + t z: an extrusion along Z,
    or a vertical plane; else None."""
    if face.kind == "extrusion":
        dz = face._adaptor.Direction().Z()
        if abs(abs(dz) - 1.0) > VERTICAL:
            return None
        return np.array([0.0, dz]), np.array([1.0, 0.0])
    if face.kind == "plane":
        pos = face._adaptor.Plane().Position()
        up = np.array([pos.XDirection().Z(), pos.YDirection().Z()])
        if abs(np.linalg.norm(up) - 1.0) > VERTICAL:
            return None
        return up, np.array([up[1], -up[0]])
    return None


def hangs_from(face, own_shapes) -> bool:
    """Whether ``face``'s generators are vertical (an extrusion along Z, a vertical plane)
    and its every vertical run tops out on one of ``own_shapes`` (a
    TopTools_IndexedMapOfShape of the followed faces' edges and vertices; module doc).
    Anything unusual answers False (no proof: the exact check runs)."""
    frame = _frame(face)
    if frame is None:
        return False
    edges = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(face.topods, TopAbs_EDGE, edges)
    (u0, u1), (w0, w1) = face.u_range, face.w_range
    step = PROBE * max(u1 - u0, w1 - w0)
    try:
        for n in range(1, edges.Extent() + 1):
            edge = TopoDS.Edge_s(edges.FindKey(n))
            if own_shapes.Contains(edge):
                continue
            if BRep_Tool.Degenerated_s(edge) or not _lower_or_vertical(face, edge, frame, step,
                                                                        own_shapes):
                return False
    except Exception:   # noqa: BLE001 - any trouble reading the topology: no proof
        return False
    return True


def _lower_or_vertical(face, edge, frame, step: float, own_shapes) -> bool:
    """Whether a (not own) edge of the wall is a vertical generator whose top vertex is
    own, or a lower boundary whose pcurve is a graph across the generators (module doc)."""
    curve = BRepAdaptor_Curve(edge)
    if curve.GetType() == GeomAbs_Line and abs(abs(curve.Line().Direction().Z()) - 1.0) \
            <= VERTICAL:
        verts = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(edge, TopAbs_VERTEX, verts)
        tops = [verts.FindKey(k) for k in range(1, verts.Extent() + 1)]
        z = [BRep_Tool.Pnt_s(TopoDS.Vertex_s(v)).Z() for v in tops]
        return own_shapes.Contains(tops[int(np.argmax(z))])
    up, across = frame
    pcurve = BRepAdaptor_Curve2d(edge, face.topods)
    if not _monotone(pcurve, across):
        return False
    mid = pcurve.Value(0.5 * (pcurve.FirstParameter() + pcurve.LastParameter()))
    u, v = mid.X(), mid.Y()
    # the wall lies above a lower boundary: inside one probe up, outside one probe down
    return face.classify(u + step * up[0], v + step * up[1]) == INSIDE and \
        face.classify(u - step * up[0], v - step * up[1]) == OUTSIDE


def _monotone(pcurve, across: np.ndarray) -> bool:
    """Whether a pcurve runs strictly one way ``across`` the generators (a line not along
    them, or a B-spline whose poles do: a monotone control polygon, a monotone curve)."""
    kind = pcurve.GetType()
    if kind == GeomAbs_Line:
        d = pcurve.Line().Direction()
        return abs(d.X() * across[0] + d.Y() * across[1]) > VERTICAL
    if kind == GeomAbs_BSplineCurve:
        poles = pcurve.BSpline().Poles()
        h = np.diff([poles.Value(k).X() * across[0] + poles.Value(k).Y() * across[1]
                     for k in range(poles.Lower(), poles.Upper() + 1)])
        return bool((h > 0).all() or (h < 0).all())
    return False


class WallProof:
    """The cached proof that a wall hanging from the followed face is clear (module doc)."""

    def __init__(self, face, need: float):
        self.cells = shared(HeightCells, face)
        self.need = float(need)       # R' - tol
        self._proof: tuple | None = None   # (x0, y0, z0, rho0)

    def budget(self, p) -> float:
        """The radius (mm, >= 0) around ``p`` within which the wall is clear, or -1.0."""
        px, py, pz = float(p[0]), float(p[1]), float(p[2])
        best = -1.0
        if self._proof is not None:
            x0, y0, z0, rho0 = self._proof
            room = rho0 - math.hypot(px - x0, py - y0) - self.need
            if pz >= z0 and room >= 0.0:
                best = min(pz - z0, room)
                if best >= REUSE:
                    return best
        best, kept, rho0 = self.cells.best_drop(px, py, pz, self.need, 1.0, 1.0, best)
        if kept >= 0:
            self._proof = (px, py, pz - DROPS[kept], rho0)
        return best
