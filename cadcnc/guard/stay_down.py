"""Zigzag links: a stay-down move refuted cheaply before the exact check.

A zigzag stays down between two pass ends only where the straight move of ball and shank
is verified clear of the part (:class:`~cadcnc.guard.moves.MoveClearance`,
OCCT's distance from the swept axis to the faces: at least R' - tol). Most such moves on
a convex face are refused by a few µm: the chord cuts under the offset. :class:`StayDown`
first looks for a witness: a point of a selected face nearer than R' - tol to a point of
the move (its quarter points), found by Newton's method for the foot from the nearest of
the face's cell centres (:class:`~cadcnc.guard.cells.HeightCells`) and kept only when
it lies inside the face's trims. A witness proves the exact distance below R' - tol, so
the exact check would refuse the move too; without one, the exact check decides. Lengths mm.
"""

from __future__ import annotations

import numpy as np

from ..core.trim_labels import OUTSIDE
from .moves import MoveClearance

NEWTON = 6
"""Newton steps towards the foot of a point on a face (the witness is valid at any step)."""
AT = (0.5, 0.25, 0.75)
"""Where along the move the witness is looked for (fractions of its length)."""


class StayDown:
    """``stay_down(a, b)`` for :func:`~cadcnc.program.linking.linked` (module doc):
    ``faces`` {face number: (FaceSurface, HeightCells or None)} of the selected faces."""

    def __init__(self, part, faces: dict, offset: float, shank: float, tol: float):
        self.moves = MoveClearance(part, offset, shank)
        self.faces, self.offset, self.tol = faces, float(offset), float(tol)
        self.limit = self.offset - self.tol
        self.refuted = self.exact = 0

    def __call__(self, a, b) -> bool:
        a, b = np.asarray(a, float), np.asarray(b, float)
        for t in AT:
            m = a + t * (b - a)
            if any(cells is not None and witness(face, cells, m, self.limit)
                   for face, cells in self.faces.values()):
                self.refuted += 1
                return False
        self.exact += 1
        return self.moves.clear(a, b, self.tol)


def witness(face, cells, m: np.ndarray, limit: float) -> bool:
    """Whether a point of ``face`` inside its trims lies nearer than ``limit`` to ``m``."""
    if cells.tree is None:
        return False
    i = int(cells.tree.query(m)[1])
    if np.linalg.norm(cells.points[i] - m) < limit:
        return True
    (u0, u1), (w0, w1) = face.u_range, face.w_range
    u, w = (float(x) for x in cells.uv[i])
    for _ in range(NEWTON):
        r, ru, rw, ruu, ruw, rww = (np.array(v) for v in face.derivative_tuples(u, w))
        e = r - m
        g = np.array([e @ ru, e @ rw])
        off = ru @ rw + e @ ruw
        h = np.array([[ru @ ru + e @ ruu, off], [off, rw @ rw + e @ rww]])
        try:
            du, dw = np.linalg.solve(h, -g)
        except np.linalg.LinAlgError:
            return False
        u, w = min(max(u + du, u0), u1), min(max(w + dw, w0), w1)
    return face.classify(u, w) != OUTSIDE and \
        float(np.linalg.norm(np.array(face.point(u, w)) - m)) < limit
