"""Boxes containing a face's surface over (u, w) ranges: :class:`FaceBoxes`, the cells of
:class:`~cadcnc.guard.cells.HeightCells` and :class:`~cadcnc.guard.box_tree.BoxTree`.

A B-spline surface (or an extrusion of a B-spline curve) is cut to the range and boxed by
its control points (the convex hull property); elementary surfaces by OCCT's closed forms.
**An offset surface** r = b + d n of a non-rational B-spline b (OCCT's offset faces, made
by ``BRepOffsetAPI_MakeOffsetShape`` and read from STEP) is boxed from its basis: over a
range, b lies in the box of the basis's control points there, and its normal n = b_u x
b_w / |b_u x b_w| in a box found by interval arithmetic: b_u is a positive combination of
the differences of neighbouring control points along u (their hull, up to a positive
factor that leaves n unchanged), b_w along w; the cross product of the two difference
boxes bounds b_u x b_w up to a positive factor, and its box divided by the bounds of its
length bounds n. The box of r is then the basis box plus d times the normal box: tight
as the range shrinks (a normal cone of a few degrees over a 1 mm cell), where widening by
|d| every way would add |d| to every side. A box whose differences can vanish (the
normal box reaching the origin) takes n anywhere in [-1, 1]. Lengths mm.
"""

from __future__ import annotations

import math

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BndLib import BndLib_AddSurface
from OCP.GeomAbs import GeomAbs_BSplineCurve, GeomAbs_BSplineSurface
from OCP.gp import gp_Pnt, gp_Vec

from ..geometry import bspline_blob

CELL_MM = 1.0
"""About this many mm of surface per cell side (at most ``MAX_CELLS`` cells)."""
MAX_CELLS = 20_000
SLACK = 1e-4
"""mm added to every cell box (OCCT's boxes are computed in floating point)."""
BOUNDED_KINDS = ("bspline", "bezier", "plane", "cylinder", "cone", "sphere", "torus",
                 "extrusion")
"""Surface kinds whose cell boxes OCCT computes from control points or closed forms (an
extrusion: from its curve's). An offset of a non-rational B-spline is bounded too
(:func:`bounded`, module doc)."""

def face_cells(face, cell_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """The (u, w) grid lines of about ``cell_mm`` cells over a face's box (at most
    ``MAX_CELLS`` cells): (us, ws)."""
    (u0, u1), (w0, w1) = face.u_range, face.w_range
    lu, lw = face.parameter_lengths()
    nu = max(1, math.ceil(lu / cell_mm))
    nw = max(1, math.ceil(lw / cell_mm))
    if nu * nw > MAX_CELLS:
        f = math.sqrt(nu * nw / MAX_CELLS)
        nu, nw = max(1, int(nu / f)), max(1, int(nw / f))
    return np.linspace(u0, u1, nu + 1), np.linspace(w0, w1, nw + 1)


def _net(surface) -> np.ndarray:
    """(rows, cols, 3) the poles of a Geom_BSplineSurface: read in one call where
    :func:`~cadcnc.geometry.bspline_blob.surface` can (checked against OCCT), else pole
    by pole (the same numbers)."""
    read = bspline_blob.surface(surface)
    return read[0] if read is not None else _poles_2d(surface.Poles())


def _poles_2d(array) -> np.ndarray:
    """(rows, cols, 3) of an OCCT TColgp_Array2OfPnt."""
    return np.array([[array.Value(i, j).Coord() for j in range(array.LowerCol(),
                                                             array.UpperCol() + 1)]
                     for i in range(array.LowerRow(), array.UpperRow() + 1)])


def pole_support(flat: np.ndarray, degree: int, cuts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first, last) pole index (0-based) of the basis functions not zero on each span
    [cuts[i], cuts[i + 1]] of a B-spline with the flat knot sequence ``flat``: function j
    lives on (flat[j], flat[j + degree + 1])."""
    n_poles = len(flat) - degree - 1
    first = np.searchsorted(flat[degree + 1:degree + 1 + n_poles], cuts[:-1], side="right")
    last = np.searchsorted(flat[:n_poles], cuts[1:], side="left") - 1
    return first, np.maximum(last, first)


ROUND_OFF = 1e-12
"""Relative widening of a normal box: the round-off of its products and divisions."""
def bounded(face) -> bool:
    """Whether :class:`FaceBoxes` boxes ``face`` soundly: a kind of BOUNDED_KINDS, or an
    offset of a non-rational B-spline that evaluates as the face (module doc)."""
    if face.kind in BOUNDED_KINDS:
        return True
    if face.kind != "offset":
        return False
    kept = face.derived   # the answer is kept on the face
    if __name__ not in kept:
        kept[__name__] = FaceBoxes(face).offset is not None
    return kept[__name__]


class FaceBoxes:
    """Boxes of a face's surface over (u, w) ranges, widened by SLACK. A B-spline surface
    (or an extrusion of a B-spline curve) is cut to the range (``Segment``, exact knot
    insertion) and boxed by the control points of that piece: the convex hull property,
    tight as the range shrinks; an offset of a B-spline by its basis's control points and
    normal box (module doc; ``offset`` d, mm, else None). Other kinds: OCCT's
    ``BndLib_AddSurface.Add``."""

    def __init__(self, face):
        self.face, self.surface, self.curve, self.offset = face, None, None, None
        try:
            if face.kind == "bspline":
                self.surface = face._adaptor.BSpline()
            elif face.kind == "offset":
                basis = face._adaptor.BasisSurface()
                if basis.GetType() == GeomAbs_BSplineSurface:
                    surface = basis.BSpline()
                    if not (surface.IsURational() or surface.IsVRational()):
                        self.surface, self.offset = surface, float(face._adaptor.OffsetValue())
            elif face.kind == "extrusion" and face._adaptor.BasisCurve().GetType() == \
                    GeomAbs_BSplineCurve:
                self.curve = face._adaptor.BasisCurve().BSpline()
                self.axis = np.array(face._adaptor.Direction().Coord())
        except Exception:   # noqa: BLE001 - any trouble: OCCT's generic boxes
            self.surface = self.curve = self.offset = None
        if not self._agrees():
            self.surface = self.curve = self.offset = None

    def _agrees(self) -> bool:
        """Whether the B-spline evaluates as the face (no placement left out)."""
        if self.surface is None and self.curve is None:
            return True
        (u0, u1), (w0, w1) = self.face.u_range, self.face.w_range
        for u in np.linspace(u0, u1, 3):
            for w in np.linspace(w0, w1, 3):
                got = self._point(u, w) if self.surface is not None \
                    else np.array(self.curve.Value(u).Coord()) + w * self.axis
                if np.linalg.norm(got - self.face.point(u, w)) > 1e-9:   # mm: OCCT's to round-off
                    return False
        return True

    def _point(self, u: float, w: float) -> np.ndarray:
        """The B-spline's point at (u, w), moved by the offset along its normal (OCCT's
        Geom_OffsetSurface: D1U ^ D1V normalised)."""
        if self.offset is None:
            return np.array(self.surface.Value(u, w).Coord())
        p, du, dw = gp_Pnt(), gp_Vec(), gp_Vec()
        self.surface.D1(u, w, p, du, dw)
        n = np.cross(du.Coord(), dw.Coord())
        return np.array(p.Coord()) + self.offset * n / np.linalg.norm(n)

    def box(self, u0: float, u1: float, w0: float, w1: float) -> tuple:
        """(xmin, ymin, zmin, xmax, ymax, zmax) containing the surface over the range."""
        try:
            return self._box(u0, u1, w0, w1)
        except Exception:   # noqa: BLE001 - OCCT refused the cut (a range past the knots)
            if self.offset is not None:   # OCCT's box of an offset is sampled: the whole net's
                return self._net_box(_net(self.surface))
            return self._generic_box(u0, u1, w0, w1)

    def _net_box(self, net: np.ndarray) -> tuple:
        """The box (6 floats, widened by SLACK) of the surface whose (or whose basis's)
        control net over the range is ``net`` (rows, cols, 3)."""
        pts = net.reshape(-1, 3)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        if self.offset is not None:
            n_lo, n_hi = normal_box(net)
            d = self.offset
            lo, hi = lo + np.minimum(d * n_lo, d * n_hi), hi + np.maximum(d * n_lo, d * n_hi)
        return (*(lo - SLACK).tolist(), *(hi + SLACK).tolist())

    def _generic_box(self, u0: float, u1: float, w0: float, w1: float) -> tuple:
        """OCCT's box of the face's surface over the range (any kind), widened by SLACK."""
        b = Bnd_Box()
        BndLib_AddSurface.Add_s(self.face._adaptor, u0, u1, w0, w1, 0.0, b)
        x0, y0, z0, x1, y1, z1 = b.Get()    # floats: numpy's overhead was 4/5 of a cell's time
        return (min(x0, x1) - SLACK, min(y0, y1) - SLACK, min(z0, z1) - SLACK,
                max(x0, x1) + SLACK, max(y0, y1) + SLACK, max(z0, z1) + SLACK)

    def _box(self, u0: float, u1: float, w0: float, w1: float) -> tuple:
        if self.surface is None and self.curve is None:
            return self._generic_box(u0, u1, w0, w1)
        if self.surface is not None:
            piece = self.surface.Copy()
            piece.Segment(u0, u1, w0, w1)
            return self._net_box(_net(piece))
        if self.curve is not None:
            piece = self.curve.Copy()
            piece.Segment(u0, u1)
            poles = piece.Poles()
            base = np.array([poles.Value(i).Coord()
                             for i in range(poles.Lower(), poles.Upper() + 1)])
            pts = np.vstack([base + w0 * self.axis, base + w1 * self.axis])
        lo, hi = pts.min(axis=0) - SLACK, pts.max(axis=0) + SLACK
        return (*lo.tolist(), *hi.tolist())

    def grid(self, us: np.ndarray, ws: np.ndarray) -> np.ndarray:
        """(len(us) - 1, len(ws) - 1, 6) the boxes of every cell of the grid: for a
        B-spline surface, one refinement (every grid line inserted as a knot, then the
        control points that live on each cell: the same as ``box`` cell by cell); else
        ``box`` per cell."""
        if self.surface is None or self.surface.IsUPeriodic() or self.surface.IsVPeriodic():
            return self._cell_by_cell(us, ws)
        try:
            return self._refined(us, ws)
        except Exception:   # noqa: BLE001 - OCCT refused a knot: box cell by cell
            return self._cell_by_cell(us, ws)

    def _cell_by_cell(self, us: np.ndarray, ws: np.ndarray) -> np.ndarray:
        return np.array([[self.box(us[i], us[i + 1], ws[j], ws[j + 1])
                          for j in range(len(ws) - 1)] for i in range(len(us) - 1)])

    def _refined(self, us: np.ndarray, ws: np.ndarray) -> np.ndarray:
        from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal
        piece = self.surface.Copy()
        # a face's range can pass its surface's knots by round-off (a relative 2e-16):
        # OCCT refuses a knot outside them
        u_lo, u_hi, w_lo, w_hi = piece.Bounds()
        us, ws = np.clip(us, u_lo, u_hi), np.clip(ws, w_lo, w_hi)
        for cuts, insert, degree in ((us, piece.InsertUKnots, piece.UDegree()),
                                     (ws, piece.InsertVKnots, piece.VDegree())):
            knots, mults = TColStd_Array1OfReal(1, len(cuts)), TColStd_Array1OfInteger(
                1, len(cuts))
            for k, c in enumerate(cuts, start=1):
                knots.SetValue(k, float(c))
                mults.SetValue(k, degree)
            insert(knots, mults, 0.0, False)
        poles = _net(piece)
        fu, lu = pole_support(flat_knots(piece.UKnotSequence()), piece.UDegree(), us)
        fw, lw = pole_support(flat_knots(piece.VKnotSequence()), piece.VDegree(), ws)
        out = np.empty((len(us) - 1, len(ws) - 1, 6))
        if self.offset is not None:
            for i in range(len(us) - 1):
                for j in range(len(ws) - 1):
                    out[i, j] = self._net_box(poles[fu[i]:lu[i] + 1, fw[j]:lw[j] + 1])
            return out
        for i in range(len(us) - 1):
            strip = poles[fu[i]:lu[i] + 1]
            lo_i, hi_i = strip.min(axis=0), strip.max(axis=0)      # (cols, 3)
            for j in range(len(ws) - 1):
                out[i, j, :3] = lo_i[fw[j]:lw[j] + 1].min(axis=0) - SLACK
                out[i, j, 3:] = hi_i[fw[j]:lw[j] + 1].max(axis=0) + SLACK
        return out


def flat_knots(seq) -> np.ndarray:
    return np.array([seq.Value(k) for k in range(seq.Lower(), seq.Upper() + 1)])




def _times(a_lo, a_hi, b_lo, b_hi) -> tuple[np.ndarray, np.ndarray]:
    """The interval product [a_lo, a_hi] x [b_lo, b_hi] (componentwise arrays)."""
    prods = np.array([a_lo * b_lo, a_lo * b_hi, a_hi * b_lo, a_hi * b_hi])
    return prods.min(axis=0), prods.max(axis=0)


def _directions(diffs: np.ndarray) -> np.ndarray:
    """The differences (..., 3) as unit vectors (n, 3), the zero ones left out: b_u is a
    positive combination of them as of the differences, and their box is tighter where
    the net's spacing varies."""
    diffs = diffs.reshape(-1, 3)
    length = np.linalg.norm(diffs, axis=1)
    keep = length > 0.0
    return diffs[keep] / length[keep, None]


def normal_box(net: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(low (3,), high (3,)) containing the unit normal b_u x b_w / |b_u x b_w| of a
    non-rational B-spline b over the range whose control net is ``net`` (rows, cols, 3):
    the interval cross product of the boxes of the net's differences along u and along w
    (as unit vectors),
    divided by the bounds of its length (module doc); [-1, 1] where it may vanish."""
    du, dw = _directions(net[1:] - net[:-1]), _directions(net[:, 1:] - net[:, :-1])
    whole = (np.full(3, -1.0), np.full(3, 1.0))
    if not len(du) or not len(dw):
        return whole
    a_lo, a_hi, b_lo, b_hi = du.min(axis=0), du.max(axis=0), dw.min(axis=0), dw.max(axis=0)
    c_lo, c_hi = np.empty(3), np.empty(3)
    for i, (j, k) in enumerate(((1, 2), (2, 0), (0, 1))):   # c_i = a_j b_k - a_k b_j
        p_lo, p_hi = _times(a_lo[j], a_hi[j], b_lo[k], b_hi[k])
        q_lo, q_hi = _times(a_lo[k], a_hi[k], b_lo[j], b_hi[j])
        c_lo[i], c_hi[i] = p_lo - q_hi, p_hi - q_lo
    short = math.sqrt(float((np.maximum(np.maximum(c_lo, -c_hi), 0.0) ** 2).sum()))
    long = math.sqrt(float(np.maximum(c_lo * c_lo, c_hi * c_hi).sum()))
    if not short > 0.0 or not math.isfinite(long):
        return whole
    n_lo = np.where(c_lo >= 0.0, c_lo / long, c_lo / short)
    n_hi = np.where(c_hi >= 0.0, c_hi / short, c_hi / long)
    pad = ROUND_OFF * (1.0 + np.abs(n_lo) + np.abs(n_hi))     # the divisions' round-off
    return np.clip(n_lo - pad, -1.0, 1.0), np.clip(n_hi + pad, -1.0, 1.0)
