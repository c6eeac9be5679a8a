"""The distance from the tool's vertical segment to a face, OCCT's, with the face's edges
asked only where they can win.

``BRepExtrema_DistShapeShape(segment, face)`` measures the segment against the face's
interior and against every edge of the face; on a B-spline face most of its time goes to
edges far from the answer (a line against an 18-pole B-spline edge: 10-35 ms in
``Extrema_ExtCC``, where the face's interior takes 1.2 ms): their bounding boxes enclose
the segment, so its own box pruning keeps them. :class:`FaceDistance` asks OCCT for the
same pieces itself, cheapest first:

- the segment's interior against the face's interior (``BRepExtrema_ExtCF``), and each end
  of the segment against it (``BRepExtrema_ExtPF``): a nearest pair with neither point on
  the face's boundary; taken as DistShapeShape takes them (``_inside``: each search's
  least distance, where its foot classifies IN);
- each edge of the face (``BRepExtrema_DistShapeShape(segment, edge)``, its vertices
  included), in the order of a sound lower bound of its distance, skipped once the bound
  exceeds the least distance so far (by more than OCCT's 1e-7 mm: not even a tie). The
  bound is the segment's distance to boxes of the edge's B-spline (or Bezier) curve, one
  per knot span: the span lies in the hull of the control points that live on it (the
  convex hull property; weights are positive), widened by SLACK. Other curves are always
  asked (a line or a circle costs 0.1 ms).

The distance is the least of these (every nearest pair of a segment and a face is one of
them); a contact counts as the pair's own (``own``) when every piece within 1e-7 mm of the
least is an edge or vertex of faces i or j, as ``ClearanceGuard`` reads OCCT's supports.
``None`` where OCCT does not answer a piece or finds the segment parallel to the surface:
the caller then asks ``BRepExtrema_DistShapeShape`` of the whole face. Lengths mm.
"""

from __future__ import annotations

import math

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex
from OCP.BRepClass import BRepClass_FaceClassifier
from OCP.BRepExtrema import BRepExtrema_DistShapeShape, BRepExtrema_ExtCF, BRepExtrema_ExtPF
from OCP.GeomAbs import GeomAbs_BezierCurve, GeomAbs_BSplineCurve
from OCP.gp import gp_Pnt, gp_Pnt2d
from OCP.TopAbs import TopAbs_EDGE, TopAbs_IN
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedMapOfShape

from .face_boxes import SLACK, flat_knots, pole_support

SOLUTION = 1e-7
"""mm: OCCT's precision (``Precision::Confusion``): pieces this near the least distance
are solutions too (``BRepExtrema_DistShapeShape`` keeps them)."""


def _poles(array) -> np.ndarray:
    return np.array([array.Value(i).Coord() for i in range(array.Lower(), array.Upper() + 1)])


def span_boxes(edge) -> np.ndarray | None:
    """(n, 6) boxes containing the edge's curve, one per knot span (widened by SLACK), or
    None when it is no (non-periodic) B-spline or Bezier curve."""
    curve = BRepAdaptor_Curve(edge)
    kind = curve.GetType()
    if kind == GeomAbs_BezierCurve:
        pts = _poles(curve.Bezier().Poles())
        return np.concatenate([pts.min(0) - SLACK, pts.max(0) + SLACK])[None, :]
    if kind != GeomAbs_BSplineCurve:
        return None
    spline = curve.BSpline()   # placed as the edge (the adaptor's copy)
    if spline.IsPeriodic():
        return None
    pts, flat = _poles(spline.Poles()), flat_knots(spline.KnotSequence())
    degree = spline.Degree()
    cuts = np.unique(np.clip(flat, curve.FirstParameter(), curve.LastParameter()))
    if len(cuts) < 2:
        return None
    first, last = pole_support(flat, degree, cuts)
    return np.array([np.concatenate([pts[a:b + 1].min(0) - SLACK, pts[a:b + 1].max(0) + SLACK])
                     for a, b in zip(first.tolist(), last.tolist())])


class FaceDistance:
    """The distance from vertical segments to one face (module doc); ``own_shapes``: the
    edges and vertices of the pair's faces (an OCCT indexed map)."""

    def __init__(self, face, own_shapes, closed=None):
        self.face = TopoDS.Face_s(face)
        self.own_shapes = own_shapes
        self.closed = closed   # a torus's AnalyticFace: the interior in closed form
        edges = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(self.face, TopAbs_EDGE, edges)
        # a degenerated edge (a surface's pole) is a point: its vertex ends the edges beside it
        self.edges = [edges.FindKey(e) for e in range(1, edges.Extent() + 1)
                      if not BRep_Tool.Degenerated_s(TopoDS.Edge_s(edges.FindKey(e)))]
        self.boxes = [span_boxes(TopoDS.Edge_s(e)) for e in self.edges]
        # worth it only where an edge can be skipped (OCCT's line-circle extrema cost 0.1 ms),
        # or where the interior has a closed form
        self.useful = closed is not None or any(b is not None for b in self.boxes)
        self.classifier = BRepClass_FaceClassifier()
        self.tolerance = BRep_Tool.Tolerance_s(self.face)

    def lower_bounds(self, p, z0: float, z1: float) -> np.ndarray:
        """(edges,) a lower bound of each edge's distance from the segment (-inf: none)."""
        out = np.full(len(self.edges), -math.inf)
        for i, b in enumerate(self.boxes):
            if b is None:
                continue
            dx = np.maximum(np.maximum(b[:, 0] - p[0], p[0] - b[:, 3]), 0.0)
            dy = np.maximum(np.maximum(b[:, 1] - p[1], p[1] - b[:, 4]), 0.0)
            dz = np.maximum(np.maximum(b[:, 2] - z1, z0 - b[:, 5]), 0.0)
            out[i] = float(np.sqrt(dx * dx + dy * dy + dz * dz).min())
        return out

    def distance(self, p, z0: float, z1: float) -> tuple[float, bool] | None:
        """(distance, own) from the segment (p_x, p_y) x [z0, z1] to the face, or None
        (module doc)."""
        ends = [BRepBuilderAPI_MakeVertex(gp_Pnt(p[0], p[1], z)).Vertex()
                for z in ((z0, z1) if z1 > z0 else (z0,))]
        seg = BRepBuilderAPI_MakeEdge(gp_Pnt(p[0], p[1], z0), gp_Pnt(p[0], p[1], z1)).Edge() \
            if z1 > z0 else ends[0]
        pieces = self._interior(p, z0, z1, seg, ends)
        if pieces is None:
            return None
        best = min((d for d, _ in pieces), default=math.inf)
        bounds = self.lower_bounds(p, z0, z1)
        for i in np.argsort(bounds, kind="stable").tolist():
            if bounds[i] > best + SOLUTION:
                break
            ext = BRepExtrema_DistShapeShape(seg, self.edges[i])
            if not ext.IsDone() or ext.NbSolution() == 0:
                return None
            own = all(self.own_shapes.Contains(ext.SupportOnShape2(n))
                      for n in range(1, ext.NbSolution() + 1))
            pieces.append((ext.Value(), own))
            best = min(best, ext.Value())
        if not pieces:
            return None
        return best, all(own for d, own in pieces if d <= best + SOLUTION)

    def _interior(self, p, z0: float, z1: float, seg, ends) -> list | None:
        """(distance, False) of every nearest pair of the segment and the face's interior:
        OCCT's extrema, or a torus's closed form (:meth:`.AnalyticFace.segment_interior`);
        None where either cannot answer."""
        if self.closed is not None:
            got = self.closed.segment_interior((p[0], p[1], z0), z1 - z0)
            return None if got is None else [(d, False) for d in got]
        pieces: list[tuple[float, bool]] = []
        if z1 > z0:
            ext = BRepExtrema_ExtCF(TopoDS.Edge_s(seg), self.face)
            if not ext.IsDone():
                return None
            if not ext.IsParallel():   # parallel: its least is met at an end or an edge
                pieces += self._inside(ext, ext.ParameterOnFace)
        for v in ends:
            ext = BRepExtrema_ExtPF(TopoDS.Vertex_s(v), self.face)
            if not ext.IsDone():
                return None
            pieces += self._inside(ext, ext.Parameter)
        return pieces

    def _inside(self, ext, parameter) -> list[tuple[float, bool]]:
        """The interior pieces of an extrema search as ``BRepExtrema_DistShapeShape`` takes
        them: its least distance, kept where the foot classifies IN the face (at the face's
        tolerance; ON belongs to the edges)."""
        n = ext.NbExt()
        if n == 0:
            return []
        dist = [math.sqrt(ext.SquareDistance(i)) for i in range(1, n + 1)]
        least = min(dist)
        out = []
        for i, d in enumerate(dist, start=1):
            if d - least < SOLUTION:
                u, v = parameter(i)
                self.classifier.Perform(self.face, gp_Pnt2d(u, v), self.tolerance)
                if self.classifier.State() == TopAbs_IN:
                    out.append((d, False))
        return out
