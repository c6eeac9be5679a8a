"""Boxes of a face's surface over a grid of cells, halved lazily: a lower bound of the
distance from the tool's axis segment to a face without OCCT.

The distance from the tool's segment to a face is at least its distance to any box
containing the face. :class:`BoxTree` keeps the boxes of the face's surface over a grid of
cells (:class:`~cadcnc.guard.cells.FaceBoxes`) and, lazily, over their quarters, eighths ...
down to ``DEPTH`` halvings: a query prunes every box at least R' - tol from the segment
and descends into the others; when every branch is pruned, the least pruned distance is a
lower bound of the face's distance (after ``VISITS`` boxes, the boxes left count as they
are). A box still too near at the finest level returns None: the caller asks OCCT.
Lengths mm.
"""

from __future__ import annotations

import math

import numpy as np

from .cells import CELL_MM, FaceBoxes, face_cells

DEPTH = 5
"""Halvings of a BoxTree cell at most (1 mm cells down to about 0.03 mm)."""
VISITS = 400
"""Boxes a BoxTree query halves, at most (then the boxes left count as they are)."""


class BoxTree:
    """Boxes of a face's surface over a grid of cells, halved lazily (module doc)."""

    def __init__(self, face, cell_mm: float = CELL_MM):
        self.source = FaceBoxes(face)
        self.us, self.ws = face_cells(face, cell_mm)
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
        px, py, pz = float(p[0]), float(p[1]), float(p[2])
        top = pz + length
        while stack:
            node, dist = stack.pop()
            if node[4] == DEPTH or visits > VISITS:
                if dist < need:
                    return None
                best = min(best, dist)
                continue
            for kid, b in self._children(node):
                visits += 1
                # the distance from the segment to the box b (6,), inline: a third of
                # the query's time was the call
                dx = max(b[0] - px, px - b[3], 0.0)
                dy = max(b[1] - py, py - b[4], 0.0)
                dz = max(b[2] - top, pz - b[5], 0.0)
                dist = math.sqrt(dx * dx + dy * dy + dz * dz)
                if dist >= want:
                    best = min(best, dist)
                else:
                    stack.append((kid, dist))
        return best

    def rho_above(self, p, z0: float, need: float) -> float | None:
        """A lower bound >= ``need`` (mm) of the horizontal distance from ``p`` to the
        face's points above the height ``z0``, or None when the boxes cannot prove one
        (math.inf when no box reaches above z0). Boxes whose top is at most z0 drop out;
        the others nearer than ``need`` horizontally are halved (at most ``DEPTH`` times,
        ``VISITS`` boxes): the height cells' proof (:mod:`.cells`) on finer boxes."""
        px, py = float(p[0]), float(p[1])
        lo, hi = self.top[:, 0:3], self.top[:, 3:6]
        gap = np.maximum(np.maximum(lo[:, :2] - (px, py), (px, py) - hi[:, :2]), 0.0)
        d = np.sqrt((gap * gap).sum(axis=1))
        above = hi[:, 2] > z0
        far = above & (d >= need)
        best = float(d[far].min()) if far.any() else math.inf
        nw = len(self.ws) - 1
        stack = [(self.us[i // nw], self.us[i // nw + 1], self.ws[i % nw], self.ws[i % nw + 1], 0)
                 for i in np.nonzero(above & ~far)[0].tolist()]
        visits = 0
        while stack:
            node = stack.pop()
            if node[4] == DEPTH or visits > VISITS:
                return None
            for kid, b in self._children(node):
                visits += 1
                if b[5] <= z0:
                    continue
                dx = max(b[0] - px, px - b[3], 0.0)
                dy = max(b[1] - py, py - b[4], 0.0)
                dist = math.sqrt(dx * dx + dy * dy)
                if dist >= need:
                    best = min(best, dist)
                else:
                    stack.append(kid)
        return best
