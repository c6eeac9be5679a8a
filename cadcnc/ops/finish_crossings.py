"""Where a guide plane's offset curve crosses the boundary of a selected face.

The ball of offset R' touching face F with its centre on the plane ``dot(p, nrm) = off``
has its contact on the curve g(u, w) = (r + R' n) . nrm - off = 0 of F's surface. That
curve enters or leaves the trimmed face where it crosses one of F's boundary edges: a
root of g along the edge (contact on the edge, centre r + R' n_F there). Each edge is
sampled once per face and offset (:class:`FaceEdges`, cached), a plane's roots are
bracketed on the samples and solved with Brent's method on the exact edge to 1e-13 of
its parameter. A crossing is an *entry* when the contact, moving with the centre along
the travel direction, moves into the face. Lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve2d
from OCP.GCPnts import GCPnts_AbscissaPoint
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape
from scipy.optimize import brentq

from ..geometry.face_surface import FaceSurface
from ..geometry.part import Part
from ..interp.cycle import Contact, inverse_exact
from ..interp.vec3 import add

SAMPLE_MM = 0.25
"""Edge sample spacing (mm) for bracketing roots: two crossings of one edge closer than
this (a plane grazing the edge) may be missed; the piece between them is that short."""
ROOT_XTOL = 1e-13


@dataclass
class Crossing:
    """The contact on a boundary edge of ``face`` with the centre on the plane.

    ``t`` edge parameter; ``uv`` contact parameters on the face; ``point`` (3,) centre;
    ``s`` = point . travel direction (mm, signed by the travel sense); ``entry``: the
    contact moves into the face along the travel; ``neighbour``: the other face on the
    edge (None for a free edge). ``used``: consumed by a chain."""

    face: int
    edge_index: int
    t: float
    uv: tuple[float, float]
    point: np.ndarray
    normal: np.ndarray
    s: float
    entry: bool
    neighbour: int | None
    used: bool = field(default=False, compare=False)


class FaceEdges:
    """One face's boundary edges, oriented in the face, sampled for an offset R' (mm)."""

    def __init__(self, part: Part, face: FaceSurface, offset: float, owners):
        self.face = face
        self.offset = offset
        self.edges, self.curves, self.neighbours, self.samples = [], [], [], []
        exp = TopExp_Explorer(face.topods, TopAbs_EDGE)
        while exp.More():
            edge = TopoDS.Edge_s(exp.Current())
            exp.Next()
            if BRep_Tool.Degenerated_s(edge) or BRep_Tool.IsClosed_s(edge, face.topods):
                continue   # a collapsed edge or a seam: not a boundary of the face
            faces = owners.FindFromKey(edge) if owners.Contains(edge) else []
            others = {part.face_number(f) for f in faces} - {face.number}
            curve = BRepAdaptor_Curve2d(edge, face.topods)
            t0, t1 = curve.FirstParameter(), curve.LastParameter()
            length = GCPnts_AbscissaPoint.Length_s(BRepAdaptor_Curve(edge))
            ts = np.linspace(t0, t1, max(9, int(math.ceil(length / SAMPLE_MM)) + 1))
            centres = np.array([self.centre(curve, t)[0] for t in ts])
            self.edges.append(edge)
            self.curves.append(curve)
            self.neighbours.append(others.pop() if len(others) == 1 else None)
            self.samples.append((ts, centres))

    def centre(self, curve, t: float) -> tuple[np.ndarray, tuple[float, float], np.ndarray]:
        """(r + R' n (3,), (u, w), n (3,)) with the contact at edge parameter t."""
        uv = curve.Value(t)
        u, w = uv.X(), uv.Y()
        n = self.face.normal(u, w)
        return self.face.point(u, w) + self.offset * n, (u, w), n

    def crossings(self, nrm: np.ndarray, off: float, travel: np.ndarray) -> list[Crossing]:
        """Every crossing of the plane dot(p, nrm) = off by this face's offset contact
        curve, classified for a centre moving along ``travel`` x ... (see module doc):
        ``travel`` is the pass direction (3,) times the travel sense."""
        out = []
        for k, (curve, (ts, centres)) in enumerate(zip(self.curves, self.samples)):
            g = centres @ nrm - off
            for i in np.nonzero(np.signbit(g[:-1]) != np.signbit(g[1:]))[0]:
                a, b = float(ts[i]), float(ts[i + 1])
                if g[i] == 0.0:
                    t = a
                else:
                    t = brentq(lambda x: float(self.centre(curve, x)[0] @ nrm - off), a, b,
                               xtol=ROOT_XTOL, rtol=4 * np.finfo(float).eps)
                c, uv, n = self.centre(curve, t)
                entry = self._enters(k, t, uv, n, nrm, travel)
                out.append(Crossing(self.face.number, k, t, uv, c, n, float(c @ travel),
                                    entry, self.neighbours[k]))
        return out

    def _enters(self, k: int, t: float, uv, n: np.ndarray, nrm: np.ndarray,
                travel: np.ndarray) -> bool:
        """Whether the contact moves into the face when the centre moves along the
        plane's curve in the travel sense: the centre's tangent is +-(nrm x n), signed
        to agree with ``travel``; the contact's move through the whole shape operator
        (the interpolator's exact inverse), against the face's inward direction."""
        tau = np.cross(nrm, n)
        if tau @ travel < 0.0:
            tau = -tau
        contact = Contact(self.face, self.offset, *uv)
        du, dw = inverse_exact(contact, add(contact.centre(), tuple(map(float, tau))))
        move = du * np.array(contact.ru) + dw * np.array(contact.rw)
        inward = Part._inward_and_normal(self.edges[k], self.face, t)[0]
        return bool(move @ inward > 0.0)


def edge_owners(part: Part) -> TopTools_IndexedDataMapOfShapeListOfShape:
    """Edge -> the faces of ``part`` that contain it."""
    owners = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(part.shape, TopAbs_EDGE, TopAbs_FACE, owners)
    return owners
