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
from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex
from OCP.BRepClass import BRepClass_FaceClassifier
from OCP.BRepExtrema import BRepExtrema_DistShapeShape, BRepExtrema_IsInFace
from OCP.BRepTools import BRepTools
from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d
from OCP.ElSLib import ElSLib
from OCP.Extrema import Extrema_GenLocateExtPS
from OCP.Geom import Geom_OffsetSurface
from OCP.GeomAbs import GeomAbs_Cylinder, GeomAbs_Plane, GeomAbs_Sphere, GeomAbs_Torus
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.GeomAPI import GeomAPI_IntSS, GeomAPI_ProjectPointOnCurve, GeomAPI_ProjectPointOnSurf
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec
from OCP.TopAbs import TopAbs_IN, TopAbs_ON, TopAbs_OUT, TopAbs_REVERSED

from ..core.tolerances import DEFAULT, Tolerances
from ..core.trim_labels import BOUNDARY, INSIDE, OUTSIDE
from ..geometry.boxes import optimal_box
from ..geometry.torus_segment import Torus, local_nearest
from .box_face import whole_box
from .face_boundary import FaceEdges
from .surface_bound import SurfaceBound

_STATES = {TopAbs_IN: INSIDE, TopAbs_ON: BOUNDARY}
NEWTON_PARAMETER_PRECISION = 1e-12
"""Convergence of the seeded Newton search in (u, w): a solver precision, not a threshold."""
_RADIAL = {  # ElSLib's parameters of a point: those of its radial foot on the surface
    GeomAbs_Cylinder: lambda a, p: ElSLib.Parameters_s(a.Cylinder(), p),
    GeomAbs_Sphere: lambda a, p: ElSLib.Parameters_s(a.Sphere(), p),
    GeomAbs_Torus: lambda a, p: ElSLib.Parameters_s(a.Torus(), p),
}
BOX_EDGE_TIE = 1e-10
"""The edges' distance may exceed the global search's by this (mm) on a whole box face."""
EDGE_CLEAR = 1e-6
"""How much farther (mm) than an interior foot every edge must be for that foot to be the
face's nearest point (:meth:`FaceProbe.interior_distance`): DistShapeShape counts a
boundary point within its precision (1e-7) of the nearest distance as a foot too."""
INNER_MARGIN = 1e-4
"""A point of a whole-box face's (u, w) box farther inside than this fraction of the
box's span from each side is inside the face: 10^3 times or more the classifier's
boundary band on the test parts' faces (checked against FClass2d by the tests)."""
SEGMENT_AS_POINT = 1e-7
"""A segment shorter than this (mm, OCCT's Precision::Confusion) has no edge: its
midpoint's distance less half its length stands for it (a lower bound, within 1e-7)."""


class FaceProbe:
    """Distances from points to one trimmed B-rep face and to its untrimmed surface.

    Parameters are the surface's native (u, w). ``tol``: ``classify`` is the 2-D
    classifier's boundary tolerance, ``classify_loose`` the loose one of
    ``state(..., loose=True)``, ``noise`` the distance below which a point is on the face.
    """

    def __init__(self, topods_face, tol: Tolerances = DEFAULT, box=None):
        self.face = topods_face
        self._box_of = box   # () -> (lo, hi): where the face keeps its box (else computed)
        self.sign = -1.0 if topods_face.Orientation() == TopAbs_REVERSED else 1.0
        self.surface = BRep_Tool.Surface_s(topods_face)
        self.adaptor = GeomAdaptor_Surface(self.surface)
        umin, umax, wmin, wmax = BRepTools.UVBounds_s(topods_face)
        self.box = (umin, umax, wmin, wmax)
        self.u_period = self.adaptor.UPeriod() if self.adaptor.IsUPeriodic() else None
        self.w_period = self.adaptor.VPeriod() if self.adaptor.IsVPeriodic() else None
        self.tol = tol
        self._locate = Extrema_GenLocateExtPS(self.adaptor, NEWTON_PARAMETER_PRECISION,
                                              NEWTON_PARAMETER_PRECISION)
        self._dss = BRepExtrema_DistShapeShape()
        self._dss.LoadS2(topods_face)
        self._p, self._du, self._dw, self._q = gp_Pnt(), gp_Vec(), gp_Vec(), gp_Pnt()
        self._bbox = None
        self._fclass = None
        self._project = None
        self._edges = None
        self._natural = None
        self._inner = None
        self._bound = False   # the SurfaceBound, made on first use (None: none applies)
        self._ring = False    # the face's Torus, made on first use (None: not a ring torus)

    # -- surface -----------------------------------------------------------------------
    def normal(self, u: float, w: float) -> np.ndarray:
        """Unit out-of-material normal at (u, w) (zero vector at a singular point).

        Leaves the surface point at (u, w) in ``self._p``.
        """
        self.adaptor.D1(u, w, self._p, self._du, self._dw)
        n = self._du.Crossed(self._dw)
        length = n.Magnitude()
        return self.sign / length * np.array(n.Coord()) if length > 0 else np.zeros(3)

    def wrap(self, u: float, w: float) -> tuple[float, float]:
        """(u, w) brought into the face's parameter box along periodic directions."""
        if self.u_period:
            u = self.box[0] + (u - self.box[0]) % self.u_period
        if self.w_period:
            w = self.box[2] + (w - self.box[2]) % self.w_period
        return u, w

    def project_seeded(self, point, u0: float, w0: float):
        """(u, w, distance) by a local Newton search started at (u0, w0), or None."""
        self._q.SetCoord(float(point[0]), float(point[1]), float(point[2]))
        self._locate.Perform(self._q, float(u0), float(w0))
        if not self._locate.IsDone():
            return None
        u, w = self._locate.Point().Parameter()
        return u, w, math.sqrt(self._locate.SquareDistance())

    def project_global(self, point, whole_surface: bool = False):
        """(u, w, distance) of the nearest point found by OCCT's global search, or None.

        Restricted to the face's parameter box unless ``whole_surface``.
        """
        pnt = gp_Pnt(*map(float, point))
        if whole_surface:
            proj = GeomAPI_ProjectPointOnSurf(pnt, self.surface)
        else:
            # the same search, its surface grid built once per face (Init, then Perform:
            # the same answers, ~5x faster than a projector per point)
            if self._project is None:
                self._project = GeomAPI_ProjectPointOnSurf()
                self._project.Init(self.surface, *self.box)
            proj = self._project
            proj.Perform(pnt)
        if not proj.IsDone() or proj.NbPoints() == 0:
            return None
        u, w = proj.LowerDistanceParameters()
        return u, w, proj.LowerDistance()

    def _surface_bound(self) -> SurfaceBound | None:
        """The face's :class:`.SurfaceBound` (made on first use), or None."""
        if self._bound is False:
            self._bound = SurfaceBound.of(self.adaptor, self.surface)
        return self._bound

    def surface_floor(self, points) -> np.ndarray | None:
        """(M,) lower bounds (mm) of the points' (M, 3) distances to the face (to its whole
        surface: the Bezier patches' boxes, :meth:`.SurfaceBound.floor`), or None where
        no bound applies."""
        bound = self._surface_bound()
        return None if bound is None else bound.floor(points)

    def surface_clear(self, point, u: float, w: float, floor: float) -> bool:
        """Whether no point of the untrimmed surface lies nearer than ``floor`` (mm) to
        ``point``, given its foot at (u, w), proven by bounds without OCCT's global search
        (:mod:`.surface_bound`; False where they cannot say)."""
        bound = self._surface_bound()
        return bound is not None and bound.clear(self.adaptor, point, u, w, floor)

    def signed(self, point, u: float, w: float, dist: float) -> float:
        """``dist`` signed by the side of the surface the point is on (+ out of material)."""
        self.adaptor.D1(u, w, self._p, self._du, self._dw)  # _p: the foot point
        nx, ny, nz = self._du.Crossed(self._dw).Coord()
        qx, qy, qz = self._p.Coord()
        side = self.sign * ((float(point[0]) - qx) * nx + (float(point[1]) - qy) * ny
                            + (float(point[2]) - qz) * nz)  # along the normal, unscaled
        return dist if side >= 0 else -dist

    # -- trimmed face ------------------------------------------------------------------
    def state(self, u: float, w: float, loose: bool = False) -> str:
        """INSIDE / BOUNDARY / OUTSIDE the trimmed face.

        On a face that is its whole parameter box (:meth:`natural`), a point farther
        than :data:`INNER_MARGIN` of the box's span inside it is INSIDE. Elsewhere,
        boundary tolerance ``tol.classify``: OCCT's face classifier built once per face
        (BRepTopAdaptor_FClass2d, ~10x faster per point), with BRepClass_FaceClassifier
        deciding what it finds on the boundary. ``loose``: BRepClass_FaceClassifier with
        ``tol.classify_loose``.
        """
        u, w = self.wrap(u, w)
        if not loose:
            if self._inner is None:
                self._inner = self._inner_box()
            if self._inner[0] < u < self._inner[1] and self._inner[2] < w < self._inner[3]:
                return INSIDE
            if self._fclass is None:
                self._fclass = BRepTopAdaptor_FClass2d(self.face, self.tol.classify)
            state = self._fclass.Perform(gp_Pnt2d(u, w))
            if state in (TopAbs_IN, TopAbs_OUT):
                return _STATES.get(state, OUTSIDE)
        eps = self.tol.classify_loose if loose else self.tol.classify
        fc = BRepClass_FaceClassifier(self.face, gp_Pnt2d(u, w), eps)
        return _STATES.get(fc.State(), OUTSIDE)

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
        if d < self.tol.noise:  # on the face: no side to speak of
            return d, d
        # only a nearest point inside the face has a meaningful side: at an edge or a
        # vertex the face's normal says nothing about where the material is
        sign = 1.0
        for k in range(1, self._dss.NbSolution() + 1):
            if self._dss.SupportTypeShape2(k) != BRepExtrema_IsInFace:
                return d, d
            u, w = self._dss.ParOnFaceS2(k)
            q = np.array(self._dss.PointOnShape2(k).Coord())
            if (np.asarray(point) - q) @ self.normal(u, w) < 0:
                sign = -1.0
        return sign * d, d

    def segment_distance(self, a, b) -> float:
        """Exact distance from the straight segment a-b to the trimmed face (nan if OCCT
        cannot say): BRepExtrema_DistShapeShape of an edge built on the segment; on a
        torus also the face's distances at the segment's points where the whole torus
        is locally nearest (:func:`~cadcnc.geometry.torus_segment.local_nearest`), as
        OCCT's extrema can miss the interior's minimum there (bug28414's torus)."""
        a, b = np.asarray(a, float), np.asarray(b, float)
        length = float(np.linalg.norm(b - a))
        if length <= SEGMENT_AS_POINT:  # no edge: the midpoint, less half the length
            return max(self.face_distance(0.5 * (a + b))[1] - 0.5 * length, 0.0)
        maker = BRepBuilderAPI_MakeEdge(gp_Pnt(*map(float, a)), gp_Pnt(*map(float, b)))
        if not maker.IsDone():
            return math.nan
        self._dss.LoadS1(maker.Edge())
        self._dss.Perform()
        if not self._dss.IsDone() or self._dss.NbSolution() == 0:
            return math.nan
        x = self._dss.Value()
        torus = self._torus()
        if torus is not None:   # OCCT's curve-to-torus extrema can miss the interior's
            d = (b - a) / length   # minimum: the face's distance where it may lie, too
            for s in local_nearest(torus, tuple(a), length, tuple(d)):
                x = min(x, self.face_distance(a + s * d)[1])   # (nan: no lower)
        return x

    def _torus(self) -> Torus | None:
        """The face's torus (a ring torus: major > minor radius), else None."""
        if self._ring is False:
            self._ring = None
            if self.adaptor.GetType() == GeomAbs_Torus:
                g = self.adaptor.Torus()
                o, z = g.Position().Location(), g.Position().Direction()
                if g.MinorRadius() < g.MajorRadius():
                    self._ring = Torus((o.X(), o.Y(), o.Z()), (z.X(), z.Y(), z.Z()),
                                       g.MajorRadius(), g.MinorRadius())
        return self._ring

    def edge_gap(self, point, enough: float = math.inf) -> float:
        """The distance from ``point`` to the face's boundary, or a lower bound of it
        that is at least ``enough`` (:meth:`FaceEdges.gap`: OCCT's projections on the
        edges' curves, nearest boxes first)."""
        return self.edges().gap(point, enough)

    def edges(self) -> FaceEdges:
        """The face's edges (:class:`~.face_edges.FaceEdges`), made once."""
        if self._edges is None:
            self._edges = FaceEdges(self.face)
        return self._edges

    def plane_distance(self, point) -> tuple[float, float] | None:
        """:meth:`face_distance` by closed form on a planar face, or None (not a plane, or
        the foot on the face's boundary: OCCT's DistShapeShape then decides).

        The foot of the perpendicular inside the face (OCCT's classifier): the plane's
        distance, signed. Outside: the nearest point of a plane region to a point off it
        lies on its boundary, so the distance to the nearest edge (:meth:`edge_gap`,
        OCCT's projections on the edges' curves), unsigned as DistShapeShape gives it.
        """
        if self.adaptor.GetType() != GeomAbs_Plane:
            return None
        pnt = gp_Pnt(*map(float, point))
        u, w = ElSLib.Parameters_s(self.adaptor.Plane(), pnt)
        state = self.state(u, w)
        if state == BOUNDARY:
            return None
        n = self.normal(u, w)  # leaves the foot in self._p
        height = float((np.asarray(point, float) - self._p.Coord()) @ n)
        if state == INSIDE:
            d = abs(height)
            return (d, d) if d < self.tol.noise or height >= 0 else (-d, d)
        if self.edges().straight:  # straight edges only: DistShapeShape is as fast
            return None
        d = self.edge_gap(point)
        return (d, d) if math.isfinite(d) else None

    def interior_distance(self, point) -> tuple[float, float] | None:
        """:meth:`face_distance` where the surface's nearest point lies inside the
        trimmed face and OCCT's projections on the face's edges (:meth:`edge_gap`) are all
        farther by :data:`EDGE_CLEAR`: no point of the face is nearer, and no boundary
        point ties. The nearest surface point: on a cylinder, sphere or torus the radial
        foot (ElSLib's parameters of the point, the nearest point of the whole surface);
        elsewhere OCCT's global search over the face's parameter box
        (:meth:`project_global`, the search DistShapeShape runs on the face). On a face
        that is its whole parameter box (:meth:`natural`), a foot on the box's side puts
        no point of the face nearer than the search's distance: the distance is the
        edges', when they are no farther than that by :data:`BOX_EDGE_TIE` (unsigned, as
        DistShapeShape gives a foot on the boundary). None elsewhere (DistShapeShape
        decides)."""
        found = self._analytic_foot(point) if self.adaptor.GetType() in _RADIAL \
            else self.project_global(point)
        if found is None:
            return None
        u, w, d = found
        if not d >= self.tol.noise:
            return None
        if self.state(u, w) != INSIDE:  # on a whole parameter box: its edges' distance
            if self.adaptor.GetType() in _RADIAL or not self.natural():
                return None
            e = self.edge_gap(point)
            return (e, e) if e <= d + BOX_EDGE_TIE else None
        if not self.edge_gap(point, d + EDGE_CLEAR) >= d + EDGE_CLEAR:
            return None
        return self.signed(point, u, w, d), d

    def natural(self) -> bool:
        """Whether the trimmed face is its whole parameter box: one wire whose edges run
        straight along u or w on the box's sides (their pcurves), computed once."""
        if self._natural is None:
            self._natural = whole_box(self.face, self.box)
        return self._natural

    def _inner_box(self) -> tuple[float, float, float, float]:
        """(u0, u1, w0, w1): where :meth:`state` needs no classifier (an empty box
        unless the face is :meth:`natural`)."""
        if not self.natural():
            return (math.inf, -math.inf, math.inf, -math.inf)
        umin, umax, wmin, wmax = self.box
        du, dw = INNER_MARGIN * (umax - umin), INNER_MARGIN * (wmax - wmin)
        return (umin + du, umax - du, wmin + dw, wmax - dw)

    def _analytic_foot(self, point) -> tuple[float, float, float]:
        """(u, w, distance) of the radial foot on a cylinder, sphere or torus: a nearest
        point of the whole surface (on the axis, centre or core circle, one of many)."""
        self._q.SetCoord(float(point[0]), float(point[1]), float(point[2]))
        u, w = _RADIAL[self.adaptor.GetType()](self.adaptor, self._q)
        return u, w, self.adaptor.Value(u, w).Distance(self._q)

    def bbox(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) corners of the face's optimal bounding box, mm (computed once)."""
        if self._bbox is None:
            self._bbox = self._box_of() if self._box_of is not None else \
                optimal_box(self.face, use_triangulation=False)
        return self._bbox


def offset_surface(probe: FaceProbe, offset: float):
    """The face's surface offset by ``offset`` along its out-of-material normal.

    Geom_OffsetSurface offsets along D1U x D1V of the geometric surface; on a REVERSED
    face the material's outside is the other side, hence the sign.
    """
    if offset == 0.0:
        return probe.surface
    return Geom_OffsetSurface(probe.surface, probe.sign * offset)


def intersect(surface_a, surface_b, tol: float):
    """(list of Geom_Curve handles, seconds) from GeomAPI_IntSS with 3-D tolerance ``tol``."""
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
