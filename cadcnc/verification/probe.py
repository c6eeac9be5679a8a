"""OCCT primitives for :mod:`cadcnc.verification`: projections, trims, distances, IntSS.

Everything here is computed by OpenCASCADE itself, independently of the interpolator's
own arithmetic: the point of verification is a second opinion from different code. The
only things taken from cadcnc are the TopoDS shapes (``FaceSurface.topods``) and the
path's parameters used as *seeds* (never trusted as answers). Lengths in mm.
"""

from __future__ import annotations

import math
import time

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Tool
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepClass import BRepClass_FaceClassifier
from OCP.BRepExtrema import BRepExtrema_DistShapeShape, BRepExtrema_IsInFace
from OCP.BRepTools import BRepTools
from OCP.Extrema import Extrema_GenLocateExtPS
from OCP.Geom import Geom_OffsetSurface
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.GeomAPI import GeomAPI_IntSS, GeomAPI_ProjectPointOnCurve, GeomAPI_ProjectPointOnSurf
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec
from OCP.TopAbs import TopAbs_IN, TopAbs_ON, TopAbs_REVERSED

IN, ON, OUT = "in", "on", "out"
_STATES = {TopAbs_IN: IN, TopAbs_ON: ON}


class FaceProbe:
    """Distances from points to one trimmed B-rep face and to its untrimmed surface.

    ``offset`` is the face's offset distance along its out-of-material normal.
    ``classify_tol`` (mm) is the 2-D classifier's boundary tolerance.
    """

    def __init__(self, topods_face, classify_tol: float = 1e-7):
        self.face = topods_face
        self.sign = -1.0 if topods_face.Orientation() == TopAbs_REVERSED else 1.0
        self.surface = BRep_Tool.Surface_s(topods_face)
        self.adaptor = GeomAdaptor_Surface(self.surface)
        umin, umax, vmin, vmax = BRepTools.UVBounds_s(topods_face)
        self.box = (umin, umax, vmin, vmax)
        self.u_period = self.adaptor.UPeriod() if self.adaptor.IsUPeriodic() else None
        self.v_period = self.adaptor.VPeriod() if self.adaptor.IsVPeriodic() else None
        self.classify_tol = classify_tol
        self._locate = Extrema_GenLocateExtPS(self.adaptor, 1e-12, 1e-12)
        self._dss = BRepExtrema_DistShapeShape()
        self._dss.LoadS2(topods_face)
        self._p, self._du, self._dv = gp_Pnt(), gp_Vec(), gp_Vec()

    # -- surface -----------------------------------------------------------------------
    def normal(self, u: float, v: float) -> np.ndarray:
        """Unit out-of-material normal at (u, v) (zero vector at a singular point)."""
        self.adaptor.D1(u, v, self._p, self._du, self._dv)
        n = np.cross(self._du.Coord(), self._dv.Coord())
        length = np.linalg.norm(n)
        return self.sign * n / length if length > 0 else n

    def wrap(self, u: float, v: float) -> tuple[float, float]:
        if self.u_period:
            u = self.box[0] + (u - self.box[0]) % self.u_period
        if self.v_period:
            v = self.box[2] + (v - self.box[2]) % self.v_period
        return u, v

    def project_seeded(self, point, u0: float, v0: float):
        """(u, v, distance) by a local Newton search started at (u0, v0), or None."""
        self._locate.Perform(gp_Pnt(*point), float(u0), float(v0))
        if not self._locate.IsDone():
            return None
        u, v = self._locate.Point().Parameter()
        return u, v, math.sqrt(self._locate.SquareDistance())

    def project_global(self, point, whole_surface: bool = False):
        """(u, v, distance) of the nearest point found by OCCT's global search, or None.

        Restricted to the face's parameter box unless ``whole_surface``.
        """
        pnt = gp_Pnt(*map(float, point))
        if whole_surface:
            proj = GeomAPI_ProjectPointOnSurf(pnt, self.surface)
        else:
            proj = GeomAPI_ProjectPointOnSurf(pnt, self.surface, *self.box)
        if not proj.IsDone() or proj.NbPoints() == 0:
            return None
        u, v = proj.LowerDistanceParameters()
        return u, v, proj.LowerDistance()

    def signed(self, point, u: float, v: float, dist: float) -> float:
        """``dist`` signed by the side of the surface the point is on (+ out of material)."""
        foot = np.array(self.adaptor.Value(u, v).Coord())
        side = (np.asarray(point) - foot) @ self.normal(u, v)
        return dist if side >= 0 else -dist

    # -- trimmed face ------------------------------------------------------------------
    def state(self, u: float, v: float) -> str:
        """in / on / out of the trimmed face (BRepClass_FaceClassifier)."""
        u, v = self.wrap(u, v)
        fc = BRepClass_FaceClassifier(self.face, gp_Pnt2d(u, v), self.classify_tol)
        return _STATES.get(fc.State(), OUT)

    def face_distance(self, point) -> tuple[float, float]:
        """(signed distance, unsigned) from ``point`` to the trimmed face, boundary included.

        BRepExtrema_DistShapeShape of a vertex against the face. Signed (out of material
        +) only where the nearest point lies inside the face; where it lies on the face's
        boundary the distance is returned unsigned (positive).
        """
        vertex = BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, point))).Vertex()
        self._dss.LoadS1(vertex)
        self._dss.Perform()
        if not self._dss.IsDone() or self._dss.NbSolution() == 0:
            return math.nan, math.nan
        d = self._dss.Value()
        if d < 1e-12:
            return d, d
        # only a nearest point inside the face has a meaningful side: at an edge or a
        # vertex the face's normal says nothing about where the material is
        sign = 1.0
        for k in range(1, self._dss.NbSolution() + 1):
            if self._dss.SupportTypeShape2(k) != BRepExtrema_IsInFace:
                return d, d
            u, v = self._dss.ParOnFaceS2(k)
            q = np.array(self._dss.PointOnShape2(k).Coord())
            if (np.asarray(point) - q) @ self.normal(u, v) < 0:
                sign = -1.0
        return sign * d, d

    def bbox(self) -> tuple[np.ndarray, np.ndarray]:
        box = Bnd_Box()
        BRepBndLib.AddOptimal_s(self.face, box, False, False)
        xmin, ymin, zmin, xmax, ymax, zmax = box.Get()
        return np.array([xmin, ymin, zmin]), np.array([xmax, ymax, zmax])


def offset_surface(probe: FaceProbe, offset: float):
    """The face's surface offset by ``offset`` along its out-of-material normal.

    Geom_OffsetSurface offsets along D1U x D1V of the geometric surface; on a REVERSED
    face the material's outside is the other side, hence the sign.
    """
    if offset == 0.0:
        return probe.surface
    return Geom_OffsetSurface(probe.surface, probe.sign * offset)


def intersect(surface_a, surface_b, tol: float = 1e-7):
    """(list of Geom_Curve handles, seconds) from GeomAPI_IntSS."""
    t0 = time.perf_counter()
    inter = GeomAPI_IntSS(surface_a, surface_b, tol)
    seconds = time.perf_counter() - t0
    if not inter.IsDone():
        return [], seconds
    return [inter.Line(k) for k in range(1, inter.NbLines() + 1)], seconds


def curve_params(curve, points) -> np.ndarray:
    """Parameter of the nearest point of ``curve`` to each point (nan where none)."""
    out = np.full(len(points), np.nan)
    for k, p in enumerate(points):
        proj = GeomAPI_ProjectPointOnCurve(gp_Pnt(*map(float, p)), curve)
        if proj.NbPoints():
            out[k] = proj.LowerDistanceParameter()
    return out


def sample_curve(curve, t0: float, t1: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(n,) parameters and (n, 3) points of ``curve`` evenly in parameter over [t0, t1]."""
    ts = np.linspace(t0, t1, n)
    return ts, np.array([curve.Value(float(t)).Coord() for t in ts])


def project_on_curve(curve, point, t_lo: float, t_hi: float):
    """(parameter, distance) of the nearest point of ``curve`` on [t_lo, t_hi], or None."""
    proj = GeomAPI_ProjectPointOnCurve(gp_Pnt(*map(float, point)), curve, t_lo, t_hi)
    if not proj.NbPoints():
        return None
    return proj.LowerDistanceParameter(), proj.LowerDistance()


def shape_distances(shape, points) -> np.ndarray:
    """(N,) distance from each point to a TopoDS shape (an edge, a face), by DistShapeShape."""
    dss = BRepExtrema_DistShapeShape()
    dss.LoadS2(shape)
    out = np.full(len(points), np.nan)
    for k, p in enumerate(points):
        dss.LoadS1(BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, p))).Vertex())
        dss.Perform()
        if dss.IsDone():
            out[k] = dss.Value()
    return out
