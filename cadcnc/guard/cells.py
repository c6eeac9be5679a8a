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

import numba
import numpy as np
from scipy.spatial import cKDTree

from ..core.trim_labels import OUTSIDE
from .clearance import distance
from .face_boxes import BOUNDED_KINDS, CELL_MM, MAX_CELLS, SLACK, FaceBoxes, bounded, face_cells

__all__ = ["BOUNDED_KINDS", "CELL_MM", "MAX_CELLS", "SLACK", "FaceBoxes", "bounded",
           "face_cells", "HeightCells", "shared", "DROPS", "SEARCH", "REUSE"]

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
        span = max(float(b[:, 3].max()) - self.x0, float(b[:, 4].max()) - self.y0,
                   1e-9)   # mm: boxes of one point still get a span (no / 0 below)
        width = np.maximum(b[:, 3] - b[:, 0], b[:, 4] - b[:, 1])
        self.size = max(float(np.median(width)), span / math.sqrt(MAX_BUCKETS),
                        1e-6)   # mm: a bucket of some size, far below any tool
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


def shared(kind, face):
    """The ``kind`` (HeightCells or BoxTree) of a face, built once, kept on the face and
    shared by every guard of its part (pencil builds a guard per pair; a face is in
    several pairs)."""
    per_face = face.derived.setdefault(__name__, {})
    if kind not in per_face:
        per_face[kind] = kind(face)
    return per_face[kind]
