"""The ball against every face along a polyline: at its points and along its straight moves.

One :class:`Polyline` measures a polyline of ball centres against the faces of a part:

- **points** (``hit`` given): the exact distance d_k from each point to each face k whose
  box comes within R' + hit of it, skipping points the 1-Lipschitz bound already proves
  farther than that;
- **moves** (``allowance`` given): a lower bound of the distance from every straight move
  to every face (:mod:`.bounds`): from the ends' distances first, then from midpoints, then
  by the exact segment-to-face distance, until the move is proven at least
  ``clearance`` = R' - allowance from the face or found closer;
- **membership**: which points lie in the material (:mod:`.material`). It is classified
  at the first point and again only after a move that may touch the boundary: a move
  whose lower bound is > 0 crosses no face, so its ends lie on the same side.

The depth of the ball into face k at a point outside the material is R' - d_k; inside,
R' + d for the nearest face (d the distance to the whole part). Lengths in mm.
"""

from __future__ import annotations

import math

import numpy as np

from .bounds import end_distance_for, point_box_distance, segment_lower_bound
from .material import IN, ON, OUT, Material, PartFaces

FAR_MARGIN = 1e-9
"""How far (mm) beyond what a face must be proven to keep a loose box must be for the
faces' shared first test (:meth:`Polyline._far`) to settle it."""
FAR_BLOCK = 2_000_000
"""Face-point distances computed at once by that test (memory: ~5 arrays of this many)."""
EXACT_SLACK = 1e-7
"""How far (mm) OCCT's exact segment distance may sit outside the interval the samples
allow before it is distrusted (its extrema converge to ~1e-9 mm)."""
MAX_LEVEL = 3  # a move is bisected at most 3 times (7 midpoints) before the exact step
_STATE = {OUT: 0, ON: 1, IN: 2, None: -1}


class Polyline:
    """Distances from a polyline ``points`` (N, 3) to every face of ``faces`` (see module).

    ``ball``: R'. ``hit``: report points whose depth into a face exceeds it (None: moves
    only). ``allowance``: the depth a move may reach (None: points only).
    ``known``: {face: (unsigned, signed) (N,) distances} measured elsewhere (the pair's
    faces at the centres). ``anchors``: (match (N,) index into the anchor points,
    anchor points (K, 3), {face: (K,) distances, nan where unknown}): distances known at
    nearby points, which bound these by the Lipschitz rule. ``floors``: {face: (N,) lower
    bounds of the points' distances} proven elsewhere (:func:`~.whole_part.before_floors`).
    """

    def __init__(self, faces: PartFaces, material: Material, points, ball: float, *,
                 hit: float | None = None, allowance: float | None = None,
                 known: dict | None = None, anchors=None, floors: dict | None = None,
                 progress=None, stage: str = "whole part"):
        self.faces, self.material = faces, material
        self.points = np.asarray(points, float).reshape(-1, 3)
        bad = np.nonzero(~np.isfinite(self.points).all(axis=1))[0]
        if len(bad):  # nothing is proven about a position that is not one
            raise ValueError(f"{stage}: position {int(bad[0])} is not finite "
                             f"({self.points[bad[0]].tolist()})")
        self.ball, self.hit, self.allowance = float(ball), hit, allowance
        # a ball no larger than the allowance (R' <= limit): still prove R'/2, so that a
        # move touches no face, stays out of the material and reaches less than R' deep
        self.clearance = None if allowance is None else max(self.ball - allowance,
                                                            0.5 * self.ball)
        self.known, self.anchors, self.floors = known or {}, anchors, floors or {}
        self.progress, self.stage = progress, stage
        n = len(self.points)
        self.length = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        self.travel = np.concatenate([[0.0], np.cumsum(self.length)])
        self.samples: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self.seg: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self.evaluated = self.exact_moves = 0
        self.d_up = np.full(n, np.inf)  # smallest exact distance to any face
        self.d_face = np.zeros(n, int)  # the face it belongs to
        self.seg_lb = np.full(max(n - 1, 0), np.inf)
        self.seg_meas = np.full(max(n - 1, 0), np.inf)
        self.seg_face = np.zeros(max(n - 1, 0), int)
        self.faces_near = 0

    # -- the run -----------------------------------------------------------------------
    def run(self) -> "Polyline":
        pts, n = self.points, len(self.points)
        reach = self.ball + (self.hit or 0.0) if self.hit is not None else 0.0
        if self.clearance is not None and n > 1:
            reach = max(reach, float(end_distance_for(self.clearance, self.length.max())))
        self.d_lb = np.full(n, reach)  # faces out of reach are at least this far
        near = set(self.faces.near(pts.min(axis=0), pts.max(axis=0), reach)) | set(self.known)
        near = sorted(near)
        self.faces_near = len(near)
        far = self._far(near)
        for count, k in enumerate(near, 1):
            if self.progress:
                self.progress(count, len(near), self.stage)
            if k in far:  # what _face concludes from the loose box alone
                self.d_lb = np.minimum(self.d_lb, point_box_distance(pts, *self.faces.loose[k]))
            else:
                self._face(k)
        self._membership()
        return self

    def _far(self, near: list[int]) -> set[int]:
        """The faces of ``near`` (not known) whose loose box alone proves every point and
        move clear, by :meth:`_face`'s first test for all faces at once, with
        :data:`FAR_MARGIN` to spare (a face within it takes :meth:`_face`'s own test)."""
        pts, n, length = self.points, len(self.points), self.length
        base = self.ball + self.hit if self.hit is not None else 0.0
        todo = [k for k in near if k not in self.known]
        out: set[int] = set()
        step = max(1, FAR_BLOCK // max(n, 1))
        for i in range(0, len(todo), step):
            ks = np.array(todo[i:i + step])
            lo, hi = self.faces.loose[ks, 0][:, None], self.faces.loose[ks, 1][:, None]
            gap = np.maximum(np.maximum(lo - pts[None], pts[None] - hi), 0.0)
            box = np.sqrt((gap * gap).sum(axis=2))  # (faces, points)
            clear = (box >= base + FAR_MARGIN).all(axis=1)
            if self.clearance is not None and n > 1:
                seg = segment_lower_bound(box[:, :-1], box[:, 1:], length[None])
                clear &= (seg >= self.clearance + FAR_MARGIN).all(axis=1)
            out.update(ks[clear].tolist())
        return out

    def _reach(self, box):
        """(need (N,), near_seg (N-1,)): the distance each point must be proven to keep,
        and the moves the box ``box`` (N,) distances cannot prove."""
        n, length = len(self.points), self.length
        near_seg = np.zeros(max(n - 1, 0), bool)
        if self.clearance is not None and n > 1:
            near_seg = ~(segment_lower_bound(box[:-1], box[1:], length) >= self.clearance)
        return self._need(near_seg), near_seg

    def _need(self, near_seg: np.ndarray) -> np.ndarray:
        """(N,) the distance each point must be proven to keep: its own, and at the ends
        of the moves ``near_seg`` (N-1,) the one that proves the move by its ends."""
        n = len(self.points)
        need = np.full(n, self.ball + self.hit if self.hit is not None else 0.0)
        if self.clearance is not None and n > 1:
            ends = np.where(near_seg, end_distance_for(self.clearance, self.length), 0.0)
            need[:-1] = np.maximum(need[:-1], ends)
            need[1:] = np.maximum(need[1:], ends)
        return need

    def _proven(self, k: int, lb: np.ndarray, near_seg: np.ndarray, need: np.ndarray):
        """(near_seg, need, inner) without the moves the bounds already prove: the surface's
        patch boxes raise ``lb`` where it falls short (in place), then a move whose ends'
        ``lb`` prove it (one end near the face, the other far enough: the symmetric
        ``need`` asks both to be far) or the anchors it passes (:meth:`_inner`) is proven
        without any distance."""
        short = np.nonzero(lb < need)[0]
        if k in self.floors:   # a floored point's move may be proven by its other end's
            near = np.nonzero(self.floors[k] > 0.0)[0]
            short = np.union1d(short, np.clip(np.r_[near - 1, near + 1], 0, len(lb) - 1))
        if len(short):
            floor = self.faces.probe(k).surface_floor(self.points[short])
            if floor is not None:
                lb[short] = np.maximum(lb[short], floor)
        if self.clearance is None or not near_seg.any():
            return near_seg, need, None
        c = self.clearance
        ends = segment_lower_bound(lb[:-1], lb[1:], self.length) >= c
        inner = self._inner(k, lb, near_seg & ~ends)
        proven = (ends | (inner >= c)) & near_seg
        if not proven.any():
            return near_seg, need, inner
        near_seg = near_seg & ~proven
        return near_seg, self._need(near_seg), inner

    def _inner(self, k: int, lb: np.ndarray, near_seg: np.ndarray) -> np.ndarray:
        """(N-1,) a lower bound of each move's distance to face k from the anchors it
        passes (0 where none is known): the anchor points matched between its ends (the
        centres a written move stands for) at their feet on the move, each at its known
        distance less its offset from the move (Lipschitz), and the convexity bound on
        each piece between feet (:func:`segment_lower_bound`, ends at ``lb``). Only for
        the moves ``near_seg`` (those their ends' ``lb`` leave unproven)."""
        out = np.zeros(len(self.length))
        if self.anchors is None:
            return out
        match, where, dists = self.anchors
        if k not in dists:
            return out
        known, pts = dists[k], self.points
        for s in np.nonzero(near_seg & (np.diff(match) >= 2))[0]:
            idx = np.arange(match[s] + 1, match[s + 1])
            idx = idx[np.isfinite(known[idx])]
            a, ab, L = pts[s], pts[s + 1] - pts[s], self.length[s]
            if not len(idx) or not L > 0.0:
                continue
            t = np.clip((where[idx] - a) @ ab / (L * L), 0.0, 1.0)
            e = known[idx] - np.linalg.norm(where[idx] - (a + t[:, None] * ab), axis=1)
            order = np.argsort(t, kind="stable")
            t = np.r_[0.0, t[order], 1.0]
            e = np.maximum(np.r_[lb[s], e[order], lb[s + 1]], 0.0)
            out[s] = float(segment_lower_bound(e[:-1], e[1:], np.diff(t) * L).min())
        return out

    def _face(self, k: int) -> None:
        pts, n = self.points, len(self.points)
        if k in self.known:
            box = np.zeros(n)
        else:  # the loose box first: the optimal one costs ~4 ms a face
            box = point_box_distance(pts, *self.faces.loose[k])
            need, near_seg = self._reach(box)
            if not (box < need).any() and not near_seg.any():
                self.d_lb = np.minimum(self.d_lb, box)
                return
            box = np.maximum(box, point_box_distance(pts, *self.faces.box(k)))
        need, near_seg = self._reach(box)
        inner = None
        if k in self.known:
            d, sd = (np.array(a, float) for a in self.known[k])
            have = np.ones(n, bool)
            lb, ub = d.copy(), d.copy()
        else:
            d, sd, have = np.full(n, np.inf), np.full(n, np.inf), np.zeros(n, bool)
            lb, ub = box.copy(), np.full(n, np.inf)
            self._anchor(k, lb, ub)
            if k in self.floors:
                np.maximum(lb, self.floors[k], out=lb)
            near_seg, need, inner = self._proven(k, lb, near_seg, need)
            self._points(k, d, sd, have, lb, need)
        self.d_lb = np.minimum(self.d_lb, np.where(have, d, lb))
        closer = have & (d < self.d_up)
        self.d_up[closer], self.d_face[closer] = d[closer], k
        if have.any():
            self.samples[k] = (np.nonzero(have)[0], d[have], sd[have])
        if self.clearance is not None and n > 1:
            self._moves(k, d, sd, have, lb, np.minimum(ub, np.where(have, d, np.inf)),
                        near_seg, inner)

    def _anchor(self, k, lb, ub) -> None:
        """Lower and upper bounds from distances known at nearby points (Lipschitz)."""
        if self.anchors is None:
            return
        match, where, dists = self.anchors
        if k not in dists:
            return
        known = dists[k][match]
        gap = np.linalg.norm(self.points - where[match], axis=1)
        ok = np.isfinite(known)
        lb[ok] = np.maximum(lb[ok], known[ok] - gap[ok])
        ub[ok] = np.minimum(ub[ok], known[ok] + gap[ok])

    def _points(self, k, d, sd, have, lb, need) -> None:
        """Exact distances where the bounds cannot prove ``need``; Lipschitz skipping."""
        cand = np.nonzero(lb < need)[0]
        if not len(cand):
            return
        top, pts = float(need.max()), self.points
        travel = self.travel[cand]   # the candidates' travel, once (not per exact distance)
        i, e = 0, -1
        while i < len(cand):
            j = cand[i]
            if e >= 0:
                lb[j] = max(lb[j], d[e] - float(np.linalg.norm(pts[j] - pts[e])))
            if lb[j] >= need[j]:
                i += 1
                continue
            sd[j], d[j] = self.faces.distance(k, pts[j])
            have[j], lb[j] = True, d[j]
            self.evaluated += 1
            i += 1
            if math.isfinite(d[j]):  # an unmeasured distance proves nothing further on
                e = j
                stop = np.searchsorted(travel, travel[i - 1] + d[j] - top, side="left")
                if stop > i:  # these are proven by the travel from j alone
                    skipped = cand[i:stop]
                    lb[skipped] = np.maximum(lb[skipped], d[j] - (travel[i:stop]
                                                                  - travel[i - 1]))
                    i = stop

    # -- moves -------------------------------------------------------------------------
    def _moves(self, k, d, sd, have, lb, ub, near_seg, inner=None) -> None:
        """Bound every move's distance to face k (``inner``: the bounds from the anchors
        the moves pass, :meth:`_inner`); refine the ones not proven."""
        c, length, pts = self.clearance, self.length, self.points
        low = np.where(have, d, lb)
        seg_lb = segment_lower_bound(low[:-1], low[1:], length)
        if inner is not None:
            seg_lb = np.maximum(seg_lb, inner)
        meas = np.minimum(ub[:-1], ub[1:])
        exact = np.zeros(len(length), bool)
        probe = self.faces.probe(k)
        for s in np.nonzero(near_seg & ~(seg_lb >= c))[0]:
            for j in (s, s + 1):
                if not have[j]:
                    sd[j], d[j] = self.faces.distance(k, pts[j])
                    have[j] = True
                    self.evaluated += 1
            da, db = d[s], d[s + 1]
            seg_lb[s] = float(segment_lower_bound(da, db, length[s]))
            meas[s] = min(da, db) if not (math.isnan(da) or math.isnan(db)) else math.nan
            if seg_lb[s] >= c or not meas[s] >= c:
                continue  # proven by its ends, or already too close at an end
            seg_lb[s], meas[s], exact[s] = self._refine(k, probe, pts[s], pts[s + 1], da, db)
        failed = np.nonzero(~(seg_lb >= c))[0]
        if len(failed):  # the worst failing move gets the exact step, for the report
            finite = np.where(np.isnan(meas[failed]), -np.inf, meas[failed])
            w = int(failed[np.argmin(finite)])
            if not exact[w] and np.isfinite(meas[w]):
                x = probe.segment_distance(pts[w], pts[w + 1])
                self.exact_moves += 1
                if math.isfinite(x) and x <= meas[w] + EXACT_SLACK:
                    meas[w], seg_lb[w], exact[w] = x, min(seg_lb[w], x), True
        self.seg[k] = (seg_lb, meas, exact)
        closer = meas < self.seg_meas
        self.seg_meas[closer], self.seg_face[closer] = meas[closer], k
        nan = np.isnan(meas)
        self.seg_meas[nan], self.seg_face[nan] = np.nan, k
        self.seg_lb = np.minimum(self.seg_lb, seg_lb)

    def _refine(self, k, probe, a, b, da, db) -> tuple[float, float, bool]:
        """(lower bound, smallest distance found, exact?) for the move a-b (ends >= c)."""
        c = self.clearance
        length, m = float(np.linalg.norm(b - a)), min(da, db)
        levels = [lv for lv in range(1, MAX_LEVEL + 1)
                  if segment_lower_bound(m, m, length / 2 ** lv) >= c]
        pieces, found = [(a, b, da, db)], m
        for _ in range(levels[0] if levels else 1):  # without hope, one midpoint: a cheap
            split = []                                # way to find a failing move
            for p, q, dp, dq in pieces:
                mid = 0.5 * (p + q)
                dm = self.faces.distance(k, mid)[1]
                self.evaluated += 1
                if not dm >= c:
                    bound = float(segment_lower_bound(dp, dq, np.linalg.norm(q - p)))
                    return min(bound, dm), dm, False
                found = min(found, dm)
                split += [(p, mid, dp, dm), (mid, q, dm, dq)]
            pieces = split
        bound = min(float(segment_lower_bound(dp, dq, np.linalg.norm(q - p)))
                    for p, q, dp, dq in pieces)
        if bound >= c:
            return bound, found, False
        x = probe.segment_distance(a, b)  # the exact step
        self.exact_moves += 1
        if not math.isfinite(x):
            return math.nan, math.nan, False
        if x > found + EXACT_SLACK:  # OCCT missed a closer point than a sample: distrust it
            return bound, found, False
        return min(x, found), min(x, found), True

    # -- membership --------------------------------------------------------------------
    def _membership(self) -> None:
        """State (0 out, 1 on, 2 in, -1 unknown) of every point; inside points' depth."""
        n = len(self.points)
        conn = segment_lower_bound(self.d_lb[:-1], self.d_lb[1:], self.length)
        if self.clearance is not None:
            conn = np.fmax(conn, self.seg_lb)
        starts = np.concatenate([[0], np.nonzero(~(conn > 0))[0] + 1]) if n else []
        self.state = np.full(n, -1)
        before = self.material.classified
        for s, e in zip(starts, list(starts[1:]) + [n]):
            self.state[s:e] = _STATE[self.material.state(self.points[s])]
        self.classified = self.material.classified - before
        # inside points: the distance to the whole part and its face
        self.inside = np.full(n, np.nan)
        self.inside_face = np.zeros(n, int)
        for j in np.nonzero(self.state == 2)[0]:
            face, _, unsigned = self.faces.nearest(self.points[j])
            self.inside[j], self.inside_face[j] = unsigned, face
