"""The guard of a finishing pass: the third-face guard, with cheap proofs and a budget.

A finishing pass follows one face F with the ball; :class:`~cadcnc.geometry.clearance.
ClearanceGuard` checks at every ball centre p the third faces (every face but F) and the
shank against F itself. Cheap, sound proofs stand in for OCCT's distances:

- **The shank against F**: :class:`~cadcnc.ops.finish_cells.HeightCells` (the cell boxes
  of F above the centre are horizontally further from it than F is; see that module).
- **Third faces** near the tool (the sides of the followed face, a wall): the distance
  from the tool's segment to a face is at least its distance to any box containing the
  face. :class:`BoxTree` keeps the boxes of the face's surface over a grid of cells and,
  lazily, over their quarters, eighths ... down to ``DEPTH`` halvings: a query prunes every
  box at least R' - tol from the segment (an exact segment-to-box distance) and descends
  into the others; when every branch is pruned, the least pruned distance is a lower
  bound of the face's distance, and the clearance it gives is >= 0 without an OCCT
  distance (after ``VISITS`` boxes, the boxes left count as they are). A box still too
  near at the finest level (the tool really near the face) falls back to the exact
  distance. A face with closed forms (plane, cylinder, sphere) uses them first.
- **Walls hanging from F's edge** (:mod:`.finish_walls`): cleared in closed form where
  the tool rides along the edge they share with F, where boxes cannot clear them.

**The budget.** After a clear margin at p, :meth:`FinishGuard.budget` returns a radius
within which every centre is known clear (docs/interpolator.md): the least of the broad
phase's reach left, every near third face's cached margin (1-Lipschitz) or wall proof,
the own face's proofs (the face wholly below the centre; the height cells' cached proof;
its cached margin, 2-Lipschitz) and the ball's distance to the own face's edges
(1-Lipschitz). The compiled stepper then commits the steps inside it without asking.
Lengths mm.
"""

from __future__ import annotations

import math

import numpy as np

from ..geometry.clearance import BOX_SLACK, ClearanceGuard, _dist
from .finish_cells import BOUNDED_KINDS, CELL_MM, HeightCells, _Boxes, _cells
from .finish_cells import shared as _shared
from .finish_walls import WallProof, hangs_from

__all__ = ["BoxTree", "FinishGuard", "HeightCells", "_Boxes", "finish_guard"]

DEPTH = 5
"""Halvings of a BoxTree cell at most (1 mm cells down to about 0.03 mm)."""
VISITS = 400
"""Boxes a BoxTree query halves, at most (then the boxes left count as they are)."""


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
        self.top = self.source.grid(self.us, self.ws).reshape(-1, 6)
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

    def lower_bound(self, p, length: float, need: float, want: float = 0.0) -> float | None:
        """A lower bound >= ``need`` (mm) of the distance from the segment p .. p +
        length z to the face, or None when the boxes cannot prove one. Boxes nearer than
        ``want`` (>= need) are halved while they may be, so that the bound comes out near
        ``want`` where it can (a larger budget); a box at the last level, or met after
        ``VISITS`` boxes, counts with its own distance."""
        want = max(want, need)
        lo, hi = self.top[:, 0:3], self.top[:, 3:6]
        q = np.asarray(p, float)
        gap = np.maximum(np.maximum(lo - (q + (0.0, 0.0, length)), 0.0),
                         np.maximum(q - hi, 0.0))
        d = np.sqrt((gap * gap).sum(axis=1))
        far = d >= want
        best = float(d[far].min()) if far.any() else math.inf
        nw = len(self.ws) - 1
        stack = [((self.us[i // nw], self.us[i // nw + 1], self.ws[i % nw],
                   self.ws[i % nw + 1], 0), float(d[i])) for i in np.nonzero(~far)[0].tolist()]
        visits = 0
        while stack:
            node, dist = stack.pop()
            if node[4] == DEPTH or visits > VISITS:
                if dist < need:
                    return None
                best = min(best, dist)
                continue
            for kid, box in self._children(node):
                visits += 1
                dist = _segment_box(p, length, box)
                if dist >= want:
                    best = min(best, dist)
                else:
                    stack.append((kid, dist))
        return best


class FinishGuard(ClearanceGuard):
    """The guard of a pass following one face (``pair`` = (face,)), or of a pair's path:
    the own-face rule proven by :class:`HeightCells`, third faces by closed forms,
    :class:`BoxTree` and :class:`~cadcnc.ops.finish_walls.WallProof` where they can, and
    a :meth:`budget` (module doc)."""

    def __init__(self, part, pair, offset: float, shank: float, tol: float = 1e-6,
                 reach: float | None = None, own_tol: float = 1e-3):
        super().__init__(part, pair, offset, shank, tol, reach, own_tol)
        self._cells = {k: _shared(HeightCells, part.face(k)) for k in self.pair
                       if self._own_rule[k] and part.face(k).kind in BOUNDED_KINDS}
        self._trees: dict = {}
        self._walls: dict = {}
        self.proven_calls = 0

    def height_cells(self, k: int) -> HeightCells | None:
        """The height cells of followed face k (None when it has none)."""
        return self._cells.get(k)

    def _wall(self, k: int) -> WallProof | None:
        """The proof of third face k when it hangs from the followed face, else None."""
        if k not in self._walls:
            self._walls[k] = WallProof(self._faces[k - 1], self.threshold) \
                if hangs_from(self._faces[k - 1], self._own_shapes) else None
        return self._walls[k]

    def _exact(self, k: int, p) -> tuple[float, str]:
        if k not in self.pair:
            wall = self._wall(k)
            if wall is not None and wall.budget(p) >= 0.0:
                self.proven_calls += 1
                self._bound[k] = (p, 0.0, 1.0)
                return 0.0, "tool"
        return super()._exact(k, p)

    def _segment_distance(self, k: int, p, length: float | None = None):
        """As ClearanceGuard's, with a third face's box tree between its closed forms
        (first: exact and cheaper) and OCCT's distance."""
        if k not in self.pair and self._faces[k - 1].kind in BOUNDED_KINDS:
            d = self._closed_segment_distance(k, p, self.shank if length is None else length)
            if d is not None:
                return d, False
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
        if self._cells[k].budget(p) >= 0.0:
            self.proven_calls += 1
            return self.tol
        return None

    def budget(self, p) -> float:
        """A radius (mm) around ``p``, just found clear by :meth:`margin`, within which
        every centre is clear (module doc); 0 when nothing is cached."""
        if self._broad_at is None:
            return 0.0
        p = (float(p[0]), float(p[1]), float(p[2]))
        if _dist(p, self._broad_at) > 0.5 * self.reach:   # room for a larger budget
            self._broad_phase(p)
        room = self.reach - _dist(p, self._broad_at)
        for k in self._near:
            if room <= 0.0:
                break
            p0, m0, slope = self._bound[k]
            mine = (m0 - slope * _dist(p, p0)) / slope
            if k in self.pair:
                top = self._hi[k - 1][2] - BOX_SLACK
                if top <= p[2]:            # the face wholly below the centre
                    mine = max(mine, p[2] - top)
                elif k in self._cells and self.shank > 0.0:
                    mine = max(mine, self._cells[k].budget(p))
                e0, d0 = self._edge_bound.get(k, (None, None))
                mine = min(mine, -1.0 if e0 is None else d0 - _dist(p, e0) - self.own_threshold)
            elif self._walls.get(k) is not None:
                mine = max(mine, self._walls[k].budget(p))
            room = min(room, mine)
        return max(room, 0.0)


def finish_guard(part, face: int, job) -> FinishGuard:
    """The guard of cuts on ``face`` for a finishing ``job`` (its R', shank, ``hit``)."""
    return FinishGuard(part, (face,), job.tool.offset, job.tool.shank, job.tolerances.hit)
