"""Cell boxes of a face's surface, and the proof that the shank clears the face a pass follows.

A finishing pass follows one face F with the ball; the guard's own-face rule
(:class:`~cadcnc.guard.clearance.ClearanceGuard`) asks, at every ball centre p, that
the shank (the segment S from p up to p + L z) comes no nearer to F than the ball does,
minus tol: dist(S, F) >= d_p - tol with d_p = dist(p, F). On a free-form face OCCT needs
two distances per point for it; the bound below needs none where it holds.

**The bound.** Split F's points q by height. If q_z <= p_z, p is the point of S nearest
to q, so dist(q, S) = |q - p| >= d_p. If q_z > p_z, dist(q, S) is at least q's
horizontal distance from p. Hence dist(S, F) >= min(d_p, rho), rho the least horizontal
distance from p to the points of F above p_z, and the margin dist(S, F) - d_p + tol is at
least tol (clear) whenever rho >= d_p. :class:`HeightCells` bounds both without OCCT:

- rho from below: F's surface over a grid of cells of its (u, w) box, each with a box
  containing the surface over the cell (:class:`FaceBoxes`: the B-spline's control points
  over the cell, convex hull property; closed forms for elementary surfaces; widened by
  ``SLACK``). Only cells whose top is above the height asked count; rho >= the least
  horizontal distance from p to their boxes (a compiled search over xy buckets).
- d_p from above: D = |p - q| for a point q of the trimmed face (the cells' centres
  that lie inside its trims; the nearest one).

**The budget.** The bound is Lipschitz: computed at p0 for the cells above z0 = p0_z -
drop (rho0), it holds at every centre p with p_z >= z0 and rho0 - |p_xy - p0_xy| >=
|p - q| (the cells above p_z are among those above z0, and rho moves by at most the
horizontal move). :meth:`HeightCells.budget` returns the radius around p within which that
stays true, min(p_z - z0, (rho0 - |p_xy - p0_xy| - D) / 2), so the compiled stepper need
not ask again inside it; the search runs again only when a centre leaves the cached proof.
When it fails (a steep face, a bump higher than the centre within R'), the exact OCCT
check runs. Lengths mm.
"""

from __future__ import annotations

import math
import weakref

import numba
import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BndLib import BndLib_AddSurface
from OCP.GeomAbs import GeomAbs_BSplineCurve
from scipy.spatial import cKDTree

from ..trim import OUTSIDE
from .clearance import distance

CELL_MM = 1.0
"""About this many mm of surface per cell side (at most ``MAX_CELLS`` cells)."""
MAX_CELLS = 20_000
SLACK = 1e-4
"""mm added to every cell box (OCCT's boxes are computed in floating point)."""
BOUNDED_KINDS = ("bspline", "bezier", "plane", "cylinder", "cone", "sphere", "torus",
                 "extrusion")
"""Surface kinds whose cell boxes OCCT computes from control points or closed forms (an
extrusion: from its curve's)."""
DROPS = (2.0, 1.0, 0.5, 0.2, 0.0)
"""mm: a proof cached at p0 counts the cells above p0_z - drop (it holds for centres down
to that height); the drop that gives the largest budget is kept."""
SEARCH = 2.0
"""mm searched beyond D + 2 DROP: a cached proof survives horizontal moves of about this."""
REUSE = 0.3
"""mm: a cached proof whose budget falls below this is searched again (a fresh one may
give more)."""
MAX_BUCKETS = 200_000
_DROPS = np.array(DROPS)


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


def _poles_2d(array) -> np.ndarray:
    """(rows, cols, 3) of an OCCT TColgp_Array2OfPnt."""
    return np.array([[array.Value(i, j).Coord() for j in range(array.LowerCol(),
                                                             array.UpperCol() + 1)]
                     for i in range(array.LowerRow(), array.UpperRow() + 1)])


def _support(flat: np.ndarray, degree: int, cuts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first, last) pole index (0-based) of the basis functions not zero on each span
    [cuts[i], cuts[i + 1]] of a B-spline with the flat knot sequence ``flat``: function j
    lives on (flat[j], flat[j + degree + 1])."""
    n_poles = len(flat) - degree - 1
    first = np.searchsorted(flat[degree + 1:degree + 1 + n_poles], cuts[:-1], side="right")
    last = np.searchsorted(flat[:n_poles], cuts[1:], side="left") - 1
    return first, np.maximum(last, first)


class FaceBoxes:
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
        try:
            return self._box(u0, u1, w0, w1)
        except Exception:   # noqa: BLE001 - OCCT refused the cut (a range past the knots)
            return self._generic_box(u0, u1, w0, w1)

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
            pts = _poles_2d(piece.Poles()).reshape(-1, 3)
        elif self.curve is not None:
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
        poles = _poles_2d(piece.Poles())
        fu, lu = _support(_flat(piece.UKnotSequence()), piece.UDegree(), us)
        fw, lw = _support(_flat(piece.VKnotSequence()), piece.VDegree(), ws)
        out = np.empty((len(us) - 1, len(ws) - 1, 6))
        for i in range(len(us) - 1):
            strip = poles[fu[i]:lu[i] + 1]
            lo_i, hi_i = strip.min(axis=0), strip.max(axis=0)      # (cols, 3)
            for j in range(len(ws) - 1):
                out[i, j, :3] = lo_i[fw[j]:lw[j] + 1].min(axis=0) - SLACK
                out[i, j, 3:] = hi_i[fw[j]:lw[j] + 1].max(axis=0) + SLACK
        return out


def _flat(seq) -> np.ndarray:
    return np.array([seq.Value(k) for k in range(seq.Lower(), seq.Upper() + 1)])


@numba.njit(cache=True, nogil=True)
def _rho(px: float, py: float, z0: float, cap: float, x0: float, y0: float, size: float,
         nx: int, ny: int, bucket_top: np.ndarray, start: np.ndarray, members: np.ndarray,
         boxes: np.ndarray) -> float:
    """min(cap, the least horizontal distance (mm) from (px, py) to a box (n, 6) whose top
    is above z0): buckets of ``size`` mm from (x0, y0), nx by ny, each with the greatest
    top of its boxes and their indices members[start[b]:start[b + 1]]."""
    i0 = max(int(math.floor((px - cap - x0) / size)), 0)
    i1 = min(int(math.floor((px + cap - x0) / size)), nx - 1)
    j0 = max(int(math.floor((py - cap - y0) / size)), 0)
    j1 = min(int(math.floor((py + cap - y0) / size)), ny - 1)
    best = cap
    for i in range(i0, i1 + 1):
        bx0 = x0 + i * size
        dx = max(bx0 - px, px - (bx0 + size), 0.0)
        for j in range(j0, j1 + 1):
            b = i * ny + j
            if bucket_top[b] <= z0:
                continue
            by0 = y0 + j * size
            dy = max(by0 - py, py - (by0 + size), 0.0)
            if dx * dx + dy * dy >= best * best:
                continue
            for t in range(start[b], start[b + 1]):
                k = members[t]
                if boxes[k, 5] <= z0:
                    continue
                ex = max(boxes[k, 0] - px, px - boxes[k, 3], 0.0)
                ey = max(boxes[k, 1] - py, py - boxes[k, 4], 0.0)
                d = math.sqrt(ex * ex + ey * ey)
                if d < best:
                    best = d
    return best


@numba.njit(cache=True, nogil=True)
def _nearest(px: float, py: float, pz: float, points: np.ndarray) -> int:
    """The index of the point of ``points`` (n, 3) nearest to (px, py, pz) (the first of
    equals; squared distances summed x, y, z, as scipy's k-d tree)."""
    best, k = math.inf, -1
    for i in range(points.shape[0]):
        dx, dy, dz = points[i, 0] - px, points[i, 1] - py, points[i, 2] - pz
        d = dx * dx + dy * dy + dz * dz
        if d < best:
            best, k = d, i
    return k


@numba.njit(cache=True, nogil=True)
def _best_drop(px: float, py: float, pz: float, need: float, widen: float, share: float,
               best: float, drops: np.ndarray, search: float, x0: float, y0: float,
               size: float, nx: int, ny: int, bucket_top: np.ndarray, start: np.ndarray,
               members: np.ndarray, boxes: np.ndarray) -> tuple:
    """The proof search of a budget: for each drop (decreasing, the last 0), rho0 =
    :func:`_rho` of the cells above pz - drop within need + widen drop + search; the drop
    whose proof min(drop, share (rho0 - need)) beats ``best`` (rho0 >= need), stopping once
    a proof reaches its drop. Returns (best, index of the drop kept or -1, its rho0, rho
    searches made). First rho at drop 0: the cells above pz are among those above any
    lower height, so when they come nearer than ``need`` no drop can prove anything."""
    rho_0 = _rho(px, py, pz - 0.0, need + widen * 0.0 + search, x0, y0, size, nx, ny,
                 bucket_top, start, members, boxes)
    if rho_0 < need:
        return best, -1, 0.0, 1
    kept, kept_rho, searches = -1, 0.0, 1
    for i in range(drops.shape[0]):
        drop = drops[i]
        if drop == 0.0:
            rho0 = rho_0
        else:
            searches += 1
            rho0 = _rho(px, py, pz - drop, need + widen * drop + search, x0, y0, size, nx,
                        ny, bucket_top, start, members, boxes)
        if rho0 >= need and min(drop, share * (rho0 - need)) > best:
            best = min(drop, share * (rho0 - need))
            kept, kept_rho = i, rho0
            if best >= drop:    # a smaller drop cannot give more
                break
    return best, kept, kept_rho, searches


class HeightCells:
    """Cell boxes of one face's surface in xy buckets, and points of the trimmed face
    (module doc)."""

    def __init__(self, face, cell_mm: float = CELL_MM):
        us, ws = face_cells(face, cell_mm)
        self.boxes = np.ascontiguousarray(FaceBoxes(face).grid(us, ws).reshape(-1, 6))
        uc, wc = 0.5 * (us[1:] + us[:-1]), 0.5 * (ws[1:] + ws[:-1])
        self.uv = np.array([(u, w) for u in uc for w in wc if face.classify(u, w) != OUTSIDE])
        inside = [face.point(u, w) for u, w in self.uv.tolist()]
        self.points = np.array(inside) if inside else np.zeros((0, 3))
        self.tree = cKDTree(self.points) if inside else None
        self._bucket()
        self._proof: tuple | None = None   # (x0, y0, z0, rho0, q): the cached proof
        self.searches = 0

    def _bucket(self) -> None:
        """xy buckets about a cell's size: each box listed in every bucket it overlaps."""
        b = self.boxes
        self.x0, self.y0 = float(b[:, 0].min()), float(b[:, 1].min())
        span = max(float(b[:, 3].max()) - self.x0, float(b[:, 4].max()) - self.y0, 1e-9)
        width = np.maximum(b[:, 3] - b[:, 0], b[:, 4] - b[:, 1])
        self.size = max(float(np.median(width)), span / math.sqrt(MAX_BUCKETS), 1e-6)
        self.nx = int(math.floor((float(b[:, 3].max()) - self.x0) / self.size)) + 1
        self.ny = int(math.floor((float(b[:, 4].max()) - self.y0) / self.size)) + 1
        i0 = np.floor((b[:, 0] - self.x0) / self.size).astype(int).clip(0, self.nx - 1)
        i1 = np.floor((b[:, 3] - self.x0) / self.size).astype(int).clip(0, self.nx - 1)
        j0 = np.floor((b[:, 1] - self.y0) / self.size).astype(int).clip(0, self.ny - 1)
        j1 = np.floor((b[:, 4] - self.y0) / self.size).astype(int).clip(0, self.ny - 1)
        pairs = [(i * self.ny + j, k) for k in range(len(b))
                 for i in range(i0[k], i1[k] + 1) for j in range(j0[k], j1[k] + 1)]
        pairs.sort()
        keys = np.array([p[0] for p in pairs], dtype=np.int64)
        self.members = np.array([p[1] for p in pairs], dtype=np.int64)
        self.start = np.searchsorted(keys, np.arange(self.nx * self.ny + 1)).astype(np.int64)
        self.bucket_top = np.full(self.nx * self.ny, -np.inf)
        np.maximum.at(self.bucket_top, keys, b[self.members, 5])

    def rho(self, p, z0: float, cap: float) -> float:
        """min(cap, least horizontal distance (mm) from p to the cell boxes topping z0)."""
        self.searches += 1
        return _rho(float(p[0]), float(p[1]), float(z0), float(cap), self.x0, self.y0,
                    self.size, self.nx, self.ny, self.bucket_top, self.start, self.members,
                    self.boxes)

    def budget(self, p) -> float:
        """The radius (mm, >= 0) around the ball centre ``p`` within which the shank provably
        comes no nearer to the face than the ball does (module doc), or -1.0 when the cells
        cannot prove it at p."""
        if self.tree is None:
            return -1.0
        px, py, pz = float(p[0]), float(p[1]), float(p[2])
        best = -1.0
        if self._proof is not None:
            x0, y0, z0, rho0, q = self._proof
            if pz >= z0:
                room = rho0 - math.hypot(px - x0, py - y0) - distance(p, q)
                if room >= 0.0:
                    best = min(pz - z0, 0.5 * room)
                    if best >= REUSE:
                        return best
        q = tuple(self.points[_nearest(px, py, pz, self.points)].tolist())
        d = distance(p, q)
        best, kept, rho0 = self.best_drop(px, py, pz, d, 2.0, 0.5, best)
        if kept >= 0:
            self._proof = (px, py, pz - DROPS[kept], rho0, q)
        elif best < 0.0:
            self._proof = None
        return best

    def best_drop(self, px: float, py: float, pz: float, need: float, widen: float,
                  share: float, best: float) -> tuple[float, int, float]:
        """(best, index in DROPS of the drop kept or -1, its rho0): the proof search of a
        budget over the cells (:func:`_best_drop`)."""
        best, kept, rho0, searches = _best_drop(
            px, py, pz, float(need), widen, share, best, _DROPS, SEARCH, self.x0, self.y0,
            self.size, self.nx, self.ny, self.bucket_top, self.start, self.members,
            self.boxes)
        self.searches += searches
        return best, kept, rho0

    def shank_clear(self, p) -> bool:
        """Whether the shank above the ball centre ``p`` provably comes no nearer to the
        face than the ball does (module doc)."""
        return self.budget(p) >= 0.0


_SHARED: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def shared(kind, face):
    """The ``kind`` (HeightCells or BoxTree) of a face, built once and shared by every guard
    of its part (pencil builds a guard per pair; a face is in several pairs)."""
    per_face = _SHARED.setdefault(face, {})
    if kind not in per_face:
        per_face[kind] = kind(face)
    return per_face[kind]
