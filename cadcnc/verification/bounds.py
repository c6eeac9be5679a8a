"""Lower bounds of the distance from a straight move to a closed set (pure numpy).

For any non-empty closed set K (a face, a box, the whole part) with distance function
d(x) = min_{q in K} |x - q|:

- **1-Lipschitz**: |d(x) - d(y)| <= |x - y|.
- **Convexity of |x|^2 - d(x)^2**: d(x)^2 = |x|^2 - max_{q in K} (2 x.q - |q|^2), and a
  maximum of affine functions is convex. On the segment x_t = (1 - t) a + t b of length
  L = |b - a| the chord of a convex function lies above it, and
  (1 - t)|a|^2 + t|b|^2 - |x_t|^2 = t (1 - t) L^2, hence

      d(x_t)^2 >= (1 - t) d(a)^2 + t d(b)^2 - t (1 - t) L^2.

  Its minimum over t in [0, 1] is :func:`segment_lower_bound`. The bound is exact when K
  is a single point (then |x|^2 - d^2 is affine), it implies the Lipschitz bound
  (d(a) + d(b) - L) / 2 wherever that is positive, and with d(a) = d(b) = r it gives
  sqrt(r^2 - L^2 / 4) ~ r - L^2 / (8 r): the chord sag of a ball of radius r. Any lower
  bound of d(a) and d(b) may be used in place of the exact values (the bound increases
  with both).

Lengths in mm; docs/notes/gate.md states what the gate proves with these bounds.
"""

from __future__ import annotations

import numpy as np


def segment_lower_bound(da, db, length):
    """Lower bound of the distance to K along segments with end distances ``da``, ``db``.

    Arrays broadcast; every argument >= 0 (nan propagates). Returns the square root of
    min over t in [0, 1] of (1 - t) da^2 + t db^2 - t (1 - t) L^2, clipped at 0.
    """
    da, db, length = (np.asarray(v, float) for v in (da, db, length))
    a, b, l2 = da * da, db * db, length * length
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(l2 > 0, (a - b + l2) / (2.0 * l2), 0.0)
    t = np.clip(t, 0.0, 1.0)
    g = (1.0 - t) * a + t * b - t * (1.0 - t) * l2
    return np.sqrt(np.maximum(g, 0.0))


def end_distance_for(clearance, length):
    """The end distance that proves ``clearance`` on a segment of ``length``.

    Ends at least sqrt(c^2 + L^2 / 4) from K keep the whole segment at least c from it
    (:func:`segment_lower_bound` with da = db); for c <= 0 nothing is needed (0).
    """
    clearance, length = np.asarray(clearance, float), np.asarray(length, float)
    return np.where(clearance > 0, np.sqrt(np.maximum(clearance, 0.0) ** 2
                                           + 0.25 * length * length), 0.0)


def point_box_distance(points: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(N,) Euclidean distance from each point to the axis-aligned box [lo, hi]."""
    gap = np.maximum(np.maximum(lo - points, points - hi), 0.0)
    return np.sqrt((gap * gap).sum(axis=1))


def box_box_distance(lo_a, hi_a, lo_b, hi_b) -> float:
    """Euclidean distance between two axis-aligned boxes (0 when they overlap)."""
    gap = np.maximum(np.maximum(np.asarray(lo_a) - hi_b, np.asarray(lo_b) - hi_a), 0.0)
    return float(np.sqrt((gap * gap).sum()))
