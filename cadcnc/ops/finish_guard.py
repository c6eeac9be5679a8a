"""The guard of a finishing pass: the third-face guard, with a cheap proof for the shank.

A finishing pass follows one face F with the ball; :class:`~cadcnc.geometry.clearance.
ClearanceGuard` checks at every ball centre p that the shank (the segment S from p up to
p + L z) comes no nearer to F than the ball does, minus tol: dist(S, F) >= d_p - tol
with d_p = dist(p, F). On a free-form face that took two OCCT distances per point.

**The bound.** Split F's points q by height. If q_z <= p_z, p is the point of S nearest
to q, so dist(q, S) = |q - p| >= d_p. If q_z > p_z, dist(q, S) is at least q's
horizontal distance rho(q) from p. Hence dist(S, F) >= min(d_p, rho_min), rho_min the
least rho over the points of F above p_z, and the margin dist(S, F) - d_p + tol is at
least tol (clear) whenever rho_min >= d_p. :class:`HeightCells` bounds both sides
without OCCT distances:

- rho_min from below: F's surface over a grid of cells of its (u, w) box, each with a
  box containing the surface over the cell (:class:`_Boxes`: a B-spline cut to the cell
  and boxed by its control points, convex hull property; closed forms for elementary
  surfaces; widened by ``SLACK``). Only cells whose top is
  above p_z count; rho_min >= the least horizontal distance from p to their boxes.
- d_p from above: |p - q| for a point q of the trimmed face (the cells' centres that
  lie inside its trims; the nearest one, found again only when the bound falls short).

When the two do not prove it (a steep face, a bump higher than the centre within R'),
the exact OCCT check runs as before.

**Third faces** near the tool (the sides of the followed face, a wall): the distance from
the tool's segment to a face is at least its distance to any box containing the face.
:class:`BoxTree` keeps OCCT's boxes of the face's surface over a grid of cells and, lazily,
over their quarters, eighths ... down to ``DEPTH`` halvings: a query prunes every box at
least R' - tol from the segment (an exact segment-to-box distance) and descends into the
others; when every branch is pruned, the least pruned distance is a lower bound of the
face's distance, and the clearance it gives is >= 0 without an OCCT distance. A box
still too near at the finest level (the tool really near the face, e.g. on the edge it
shares with the followed face), or more than ``VISITS`` boxes looked at, falls back to
the exact distance. Lengths mm.
"""

from __future__ import annotations

import math
import weakref

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BndLib import BndLib_AddSurface
from OCP.GeomAbs import GeomAbs_BSplineCurve
from scipy.spatial import cKDTree

from ..geometry.clearance import ClearanceGuard
from ..trim import OUTSIDE

CELL_MM = 1.0
"""About this many mm of surface per cell side (at most ``MAX_CELLS`` cells)."""
MAX_CELLS = 20_000
SLACK = 1e-4
"""mm added to every cell box (OCCT's boxes are computed in floating point)."""
BOUNDED_KINDS = ("bspline", "bezier", "plane", "cylinder", "cone", "sphere", "torus",
                 "extrusion")
"""Surface kinds whose cell boxes OCCT computes from control points or closed forms (an
extrusion: from its curve's)."""
DEPTH = 5
"""Halvings of a BoxTree cell at most (1 mm cells down to about 0.03 mm)."""
VISITS = 400
"""Boxes a BoxTree query looks at, at most, before it gives up (the exact distance runs)."""


def _cells(face, cell_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """The (u, w) grid lines of about ``cell_mm`` cells over a face's box (at most
    ``MAX_CELLS`` cells): (us, ws)."""
    from .finish_plan import _extent

    (u0, u1), (w0, w1) = face.u_range, face.w_range
    lu, lw = _extent(face)
    nu = max(1, math.ceil(lu / cell_mm))
    nw = max(1, math.ceil(lw / cell_mm))
    if nu * nw > MAX_CELLS:
        f = math.sqrt(nu * nw / MAX_CELLS)
        nu, nw = max(1, int(nu / f)), max(1, int(nw / f))
    return np.linspace(u0, u1, nu + 1), np.linspace(w0, w1, nw + 1)


class _Boxes:
    """Boxes of a face's surface over (u, w) ranges, widened by SLACK. A B-spline surface
    (or an extrusion of a B-spline curve) is cut to the range (``Segment``, exact knot
    insertion) and boxed by the control points of that piece: the convex hull property,
    tight as the range shrinks. Other kinds: OCCT's ``BndLib_AddSurface.Add``."""

    def __init__(self, face):
        self.face, self.surface, self.curve = face, None, None
        try:
            if face.kind == "bspline":
                self.surface = face._adaptor.BSpline()
            elif face.kind == "extrusion" and face._adaptor.BasisCurve().GetType() == \
                    GeomAbs_BSplineCurve:
                self.curve = face._adaptor.BasisCurve().BSpline()
                self.axis = np.array(face._adaptor.Direction().Coord())
        except Exception:   # noqa: BLE001 - any trouble: OCCT's generic boxes
            self.surface = self.curve = None
        if not self._agrees():
            self.surface = self.curve = None

    def _agrees(self) -> bool:
        """Whether the B-spline evaluates as the face (no placement left out)."""
        if self.surface is None and self.curve is None:
            return True
        (u0, u1), (w0, w1) = self.face.u_range, self.face.w_range
        for u in np.linspace(u0, u1, 3):
            for w in np.linspace(w0, w1, 3):
                got = np.array(self.surface.Value(u, w).Coord()) if self.surface is not None \
                    else np.array(self.curve.Value(u).Coord()) + w * self.axis
                if np.linalg.norm(got - self.face.point(u, w)) > 1e-9:
                    return False
        return True

    def box(self, u0: float, u1: float, w0: float, w1: float) -> tuple:
        """(xmin, ymin, zmin, xmax, ymax, zmax) containing the surface over the range."""
        if self.surface is not None:
            piece = self.surface.Copy()
            piece.Segment(u0, u1, w0, w1)
            poles = piece.Poles()
            pts = np.array([poles.Value(i, j).Coord()
                            for i in range(poles.LowerRow(), poles.UpperRow() + 1)
                            for j in range(poles.LowerCol(), poles.UpperCol() + 1)])
        elif self.curve is not None:
            piece = self.curve.Copy()
            piece.Segment(u0, u1)
            poles = piece.Poles()
            base = np.array([poles.Value(i).Coord()
                             for i in range(poles.Lower(), poles.Upper() + 1)])
            pts = np.vstack([base + w0 * self.axis, base + w1 * self.axis])
        else:
            b = Bnd_Box()
            BndLib_AddSurface.Add_s(self.face._adaptor, u0, u1, w0, w1, 0.0, b)
            pts = np.array(b.Get()).reshape(2, 3)
        lo, hi = pts.min(axis=0) - SLACK, pts.max(axis=0) + SLACK
        return (*lo.tolist(), *hi.tolist())


def _segment_box(p, length: float, b) -> float:
    """Distance (mm) from the segment p .. p + length z to the box b (6,)."""
    dx = max(b[0] - p[0], p[0] - b[3], 0.0)
    dy = max(b[1] - p[1], p[1] - b[4], 0.0)
    dz = max(b[2] - (p[2] + length), p[2] - b[5], 0.0)
    return math.sqrt(dx * dx + dy * dy + dz * dz)


class BoxTree:
    """Boxes of a face's surface over a grid of cells, halved lazily (module doc)."""

    def __init__(self, face, cell_mm: float = CELL_MM):
        self.source = _Boxes(face)
        self.us, self.ws = _cells(face, cell_mm)
        self.top = np.array([[self.source.box(self.us[i], self.us[i + 1], self.ws[j],
                                              self.ws[j + 1]) for j in range(len(self.ws) - 1)]
                             for i in range(len(self.us) - 1)]).reshape(-1, 6)
        self._sub: dict = {}

    def _children(self, node):
        """The four halves of a cell (u0, u1, w0, w1, level), with their boxes."""
        if node not in self._sub:
            u0, u1, w0, w1, level = node
            um, wm = 0.5 * (u0 + u1), 0.5 * (w0 + w1)
            kids = [(a, b, c, d, level + 1) for a, b in ((u0, um), (um, u1))
                    for c, d in ((w0, wm), (wm, w1))]
            self._sub[node] = [(k, self.source.box(*k[:4])) for k in kids]
        return self._sub[node]

    def lower_bound(self, p, length: float, need: float) -> float | None:
        """A lower bound >= ``need`` (mm) of the distance from the segment p .. p +
        length z to the face, or None when the boxes cannot prove one."""
        lo, hi = self.top[:, 0:3], self.top[:, 3:6]
        q = np.asarray(p, float)
        gap = np.maximum(np.maximum(lo - (q + (0.0, 0.0, length)), 0.0),
                         np.maximum(q - hi, 0.0))
        d = np.sqrt((gap * gap).sum(axis=1))
        best = float(d.min()) if len(d) else math.inf
        near = np.nonzero(d < need)[0]
        if not len(near):
            return best
        nw = len(self.ws) - 1
        stack = [(self.us[i // nw], self.us[i // nw + 1], self.ws[i % nw],
                  self.ws[i % nw + 1], 0) for i in near.tolist()]
        best, visits = math.inf, 0
        while stack:
            node = stack.pop()
            if node[4] == DEPTH:
                return None
            for kid, box in self._children(node):
                visits += 1
                dist = _segment_box(p, length, box)
                if dist >= need:
                    best = min(best, dist)
                else:
                    stack.append(kid)
            if visits > VISITS:
                return None
        return min(best, float(d[d >= need].min()) if (d >= need).any() else math.inf)


class HeightCells:
    """Cell boxes of one face's surface (above) and points of the trimmed face."""

    def __init__(self, face, cell_mm: float = CELL_MM):
        us, ws = _cells(face, cell_mm)
        nu, nw = len(us) - 1, len(ws) - 1
        boxes, inside, source = [], [], _Boxes(face)
        for i in range(nu):
            for j in range(nw):
                boxes.append(source.box(us[i], us[i + 1], ws[j], ws[j + 1]))
                u, w = 0.5 * (us[i] + us[i + 1]), 0.5 * (ws[j] + ws[j + 1])
                if face.classify(u, w) != OUTSIDE:
                    inside.append(face.point(u, w))
        b = np.array(boxes)   # (n, 6): xmin ymin zmin xmax ymax zmax
        order = np.argsort(-b[:, 5])
        b = b[order]
        self.top = b[:, 5]                                 # (n,) descending
        self.lo = b[:, 0:2]                                # (n, 2)
        self.hi = b[:, 3:5]
        self.points = np.array(inside) if inside else np.zeros((0, 3))
        self.tree = cKDTree(self.points) if inside else None
        self._near = self.points[0] if inside else None

    def shank_clear(self, p) -> bool:
        """Whether the shank above the ball centre ``p`` provably comes no nearer to the
        face than the ball does (module doc)."""
        if self.tree is None:
            return False
        p = np.asarray(p, float)
        above = int(np.searchsorted(-self.top, -p[2]))   # cells with top > p_z
        if above == 0:
            return True
        gap = np.maximum(np.maximum(self.lo[:above] - p[:2], p[:2] - self.hi[:above]), 0.0)
        rho = math.sqrt(float((gap * gap).sum(axis=1).min()))
        if rho >= float(np.linalg.norm(p - self._near)):
            return True
        self._near = self.points[self.tree.query(p)[1]]
        return rho >= float(np.linalg.norm(p - self._near))


class FinishGuard(ClearanceGuard):
    """The third-face guard of a pass following one face (``pair`` = (face,)), whose own
    face rule is proven by :class:`HeightCells` where it can (module doc)."""

    def __init__(self, part, pair, offset: float, shank: float, tol: float = 1e-6,
                 reach: float | None = None, own_tol: float = 1e-3):
        super().__init__(part, pair, offset, shank, tol, reach, own_tol)
        self._cells = {k: _shared(HeightCells, part.face(k)) for k in self.pair
                       if self._own_rule[k] and part.face(k).kind in BOUNDED_KINDS}
        self._trees: dict = {}
        self.proven_calls = 0

    def _segment_distance(self, k: int, p, length: float | None = None):
        if k not in self.pair and self._faces[k - 1].kind in BOUNDED_KINDS:
            if k not in self._trees:
                self._trees[k] = _shared(BoxTree, self._faces[k - 1])
            lb = self._trees[k].lower_bound(p, self.shank if length is None else length,
                                            self.threshold)
            if lb is not None:
                self.proven_calls += 1
                return lb, False
        return super()._segment_distance(k, p, length)

    def _own_bound(self, k: int, p) -> float | None:
        m = super()._own_bound(k, p)
        if m is not None or k not in self._cells or self.shank <= 0.0:
            return m
        if self._cells[k].shank_clear(p):
            self.proven_calls += 1
            return self.tol
        return None


_SHARED: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _shared(kind, face):
    """The ``kind`` (HeightCells or BoxTree) of a face, built once and shared by every guard
    of its part (pencil builds a guard per pair; a face is in several pairs)."""
    per_face = _SHARED.setdefault(face, {})
    if kind not in per_face:
        per_face[kind] = kind(face)
    return per_face[kind]


def finish_guard(part, face: int, job) -> FinishGuard:
    """The guard of cuts on ``face`` for a finishing ``job`` (its R', shank, ``hit``)."""
    return FinishGuard(part, (face,), job.tool.offset, job.tool.shank, job.tolerances.hit)
