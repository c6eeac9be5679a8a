"""The third-face and shank guard of every operation, and its one factory :func:`guard_for`.

:class:`OperationGuard` is :class:`~cadcnc.guard.clearance.ClearanceGuard` (at every ball
centre p: every third face no nearer than R' - tol to the ball or its shank, and the shank
no nearer to the followed faces than the ball) with cheap, sound proofs standing in for
OCCT's distances, so that OCCT runs only where the tool really is near a face:

- **The shank against a followed face**: :class:`~cadcnc.guard.cells.HeightCells` (the
  cell boxes of the face above the centre are horizontally further from it than the face),
  then on a face without closed forms the same proof on its box tree's finer boxes
  (:meth:`~cadcnc.guard.box_tree.BoxTree.rho_above`), then OCCT.
- **Third faces** near the tool: closed forms (plane, cylinder, sphere) first, then a
  :class:`~cadcnc.guard.box_tree.BoxTree` lower bound, then OCCT.
- **OCCT** gets the shank clipped to the face box's heights (widened by what can decide)
  and, on a face with B-spline edges, only the edges whose bound can win
  (:mod:`~cadcnc.guard.face_distance`). Offsets of B-splines have cell boxes too
  (:mod:`~cadcnc.guard.face_boxes`).
- **Walls hanging from a followed face's edge** (:mod:`.walls`): cleared in closed form
  where the tool rides along the edge they share with the face.

**The budget.** After a clear margin at p, :meth:`OperationGuard.budget` returns a radius
within which every centre is known clear (docs/method.md): the least of the broad phase's
reach left, every near third face's cached margin (1-Lipschitz) or wall proof, the own
faces' proofs (the face wholly below the centre; the height cells' cached proof; its cached
margin, 2-Lipschitz) and the ball's distance to the own faces' edges (1-Lipschitz). The
compiled stepper then commits the steps inside it without asking. Lengths mm.
"""

from __future__ import annotations

import math

from ..core.tolerances import DEFAULT
from .box_tree import BoxTree
from .cells import HeightCells, bounded, shared
from .clearance import BOX_SLACK, ClearanceGuard, distance
from .walls import WallProof, hangs_from

__all__ = ["OperationGuard", "guard_for", "PAIR_OWN_SHARE", "FINISH_OWN_SHARE"]

PAIR_OWN_SHARE = 0.7
"""Path and pencil: the share of the gouge limit by which the ball may come nearer than R'
to its own faces' edges, so that a stretch ending there passes the gate of the program as
written: of the limit, the G64 P blending takes 0.1 (``io.gcode.BLEND_SHARE``), the
rounding of the written coordinates up to 0.1 and the chords between points the rest."""
FINISH_OWN_SHARE = 1.0
"""Finishing: the share of the gouge limit for the followed face's edges (a pass ends on a
face's edge only where the next face takes over or the pass stops; its chords are short)."""


class OperationGuard(ClearanceGuard):
    """The guard of a pass following one face (``pair`` = (face,)), or of a pair's path:
    the own-face rule proven by :class:`HeightCells`, third faces by closed forms,
    :class:`BoxTree` and :class:`~cadcnc.guard.walls.WallProof` where they can, and
    a :meth:`budget` (module doc)."""

    def __init__(self, part, pair, offset: float, shank: float, tol: float = DEFAULT.hit,
                 reach: float | None = None, own_tol: float = DEFAULT.gouge):
        super().__init__(part, pair, offset, shank, tol, reach, own_tol)
        self._cells = {k: shared(HeightCells, part.face(k)) for k in self.pair
                       if self._own_rule[k] and bounded(part.face(k))}
        self._trees: dict = {}
        self._walls: dict = {}
        self._last_point: tuple = (None, None, None)   # (face, p, d(p, face))

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

    def _segment_distance(self, k: int, p, length: float | None = None,
                          cap: float | None = None):
        """As ClearanceGuard's, with a third face's box tree between its closed forms
        (first: exact and cheaper) and OCCT's distance."""
        if k not in self.pair and bounded(self._faces[k - 1]):
            d = self._closed_segment_distance(k, p, self.shank if length is None else length)
            if d is not None:
                return d, False
            if k not in self._trees:
                self._trees[k] = shared(BoxTree, self._faces[k - 1])
            lb = self._trees[k].lower_bound(p, self.shank if length is None else length,
                                            self.threshold)
            if lb is not None:
                self.proven_calls += 1
                return lb, False
        return super()._segment_distance(k, p, length, cap)

    def _own_bound(self, k: int, p) -> float | None:
        """A lower bound of own face k's margin: closed forms, the height cells' proof, or
        on a face without closed forms (B-spline, offset; where OCCT's shank distance costs
        10-100 ms) the same proof on its box tree (finer boxes) against the exact d(p, face):
        points of the face at most p_z high are at least d(p, face) from the shank (p is
        nearest to them), the others at least their horizontal distance rho, so the margin
        is at least min(d_p, rho) - d_p + tol, >= 0 when rho >= d_p - tol."""
        m = super()._own_bound(k, p)
        if m is not None or k not in self._cells or self.shank <= 0.0:
            return m
        if self._cells[k].budget(p) >= 0.0:
            self.proven_calls += 1
            return self.tol
        if self._analytic[k - 1].kind is not None:   # OCCT is cheap there (under 1 ms)
            return None
        d_p = self._point_distance(k, p)
        if not math.isfinite(d_p):
            return None
        if k not in self._trees:
            self._trees[k] = shared(BoxTree, self._faces[k - 1])
        rho = self._trees[k].rho_above(p, p[2], d_p - self.tol)
        if rho is None:
            return None
        self.proven_calls += 1
        return min(d_p, rho) - d_p + self.tol

    def _point_distance(self, k: int, p) -> float:
        """As ClearanceGuard's, the last answer kept (the own-face rule asks it twice)."""
        if self._last_point[:2] != (k, p):
            self._last_point = (k, p, super()._point_distance(k, p))
        return self._last_point[2]

    def budget(self, p) -> float:
        """A radius (mm) around ``p``, just found clear by :meth:`margin`, within which
        every centre is clear (module doc); 0 when nothing is cached."""
        if self._broad_at is None:
            return 0.0
        p = (float(p[0]), float(p[1]), float(p[2]))
        if distance(p, self._broad_at) > 0.5 * self.reach:   # room for a larger budget
            self._broad_phase(p)
        room = self.reach - distance(p, self._broad_at)
        for k in self._near:
            if room <= 0.0:
                break
            p0, m0, slope = self._bound[k]
            mine = (m0 - slope * distance(p, p0)) / slope
            if k in self.pair:
                top = self._hi[k - 1][2] - BOX_SLACK
                if top <= p[2]:            # the face wholly below the centre
                    mine = max(mine, p[2] - top)
                elif k in self._cells and self.shank > 0.0:
                    mine = max(mine, self._cells[k].budget(p))
                e0, d0 = self._edge_bound.get(k, (None, None))
                mine = min(mine, -1.0 if e0 is None else d0 - distance(p, e0) - self.own_threshold)
            elif self._walls.get(k) is not None:
                mine = max(mine, self._walls[k].budget(p))
            room = min(room, mine)
        return max(room, 0.0)


def guard_for(part, faces: tuple[int, ...], job, *, own_share: float = PAIR_OWN_SHARE,
              reach: float | None = None, shank: float | None = None) -> OperationGuard:
    """The guard of ``job`` (its tool's R' and shank length, or ``shank`` mm; its
    tolerances: ``hit`` for third faces, ``own_share`` x ``gouge`` for the followed faces'
    edges) while the ball follows ``faces`` of ``part``: the pair of a path or pencil cut,
    or the one face of a finishing pass. ``reach``: the broad phase's radius (mm)."""
    return OperationGuard(part, tuple(faces), job.tool.offset,
                          job.tool.shank if shank is None else shank, job.tolerances.hit,
                          reach, own_share * job.tolerances.gouge)
