"""Random parameter cells of a face, for the tests that a cell's box holds its surface."""

from __future__ import annotations

import numpy as np


def random_cell_boxes(face, boxes, rng, n: int):
    """n random parameter cells of ``face``: (box (6,) from ``boxes.box``, points (49, 3)
    of the face sampled on the cell, (du, dw)), for the box-holds-its-surface tests."""
    (u0, u1), (w0, w1) = face.u_range, face.w_range
    out = []
    for _ in range(n):
        a, b = sorted(rng.uniform(u0, u1, 2))
        c, d = sorted(rng.uniform(w0, w1, 2))
        pts = [face.point(u, w) for u in np.linspace(a, b, 7) for w in np.linspace(c, d, 7)]
        out.append((np.array(boxes.box(a, b, c, d)), np.array(pts), (b - a, d - c)))
    return out
