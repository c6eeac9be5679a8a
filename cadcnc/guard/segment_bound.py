"""A lower bound of the distance from the tool's vertical segment to a face, from a few
point distances: the third-face guard's cheap stand-in for OCCT's curve/surface extrema.

The segment is S = {p + s z, 0 <= s <= L}; D(s) (mm) the distance from p + s z to the face
F (a closed set), known at a few heights s_i. The open ball of radius D(s_i) around
p + s_i z holds no point of F, so for s between two samples a < b (D_a = D(a), D_b = D(b)):

- **Lipschitz**: D is 1-Lipschitz, D(s) >= max(D_a - (s - a), D_b - (b - s)) >= the mean
  of the two, (D_a + D_b - (b - a)) / 2; also D(s) >= D_a - (b - a) and D_b - (b - a).
- **Lens**: when the two spheres meet on a circle (radius rho > 0, on the plane at height
  t), every point of [a, b] lies in the union of the two balls, and the nearest point of
  the union's boundary to p + s z is on that circle (on the sphere of a, the points outside
  the ball of b are those under the plane, and the distance from a point of the axis above
  a to them grows as they go down; likewise for b): D(s) >= sqrt(rho^2 + (s - t)^2), at
  least rho (t in [a, b]), D_b (t > b) or D_a (t < a). Along a wall parallel to the axis
  at D ~ R' + m this lets samples lie about 2 sqrt(2 R' m) apart instead of 2 m; for a
  face nearest at one point it is the exact minimum.

:func:`segment_lower_bound` halves the interval of least bound until every interval's
bound reaches ``need`` (then the least of them is a lower bound of min D over S: every s
lies in some interval), or gives up after ``max_points`` samples (None: the caller asks
OCCT). Lengths mm.
"""

from __future__ import annotations

import heapq
import math
from typing import Callable

MAX_POINTS = 12
"""Point distances one bound may sample (OCCT's vertex/face distance costs about 1/20 of
its segment/face distance on a B-spline or revolution face)."""
SAFETY = 1e-6
"""mm: the bound must clear ``need`` by this much (OCCT's distances carry round-off), else
the caller measures exactly; it also comes off the bound returned."""


def interval_bound(a: float, b: float, d_a: float, d_b: float) -> float:
    """A lower bound (mm) of the distance to the face from every point p + s z, a <= s <= b,
    given the distances d_a, d_b at s = a and s = b (module doc: Lipschitz and lens)."""
    h = b - a
    bound = max(0.5 * (d_a + d_b - h), d_a - h, d_b - h)
    if h > 0.0 and d_a > 0.0 and d_b > 0.0:
        t = (d_a * d_a - d_b * d_b + h * h) / (2.0 * h)   # the circle's height above a
        rho2 = d_a * d_a - t * t
        if rho2 > 0.0:
            off = t - min(max(t, 0.0), h)   # how far the circle's plane is past [a, b]
            bound = max(bound, math.sqrt(rho2 + off * off))
    return bound


def segment_lower_bound(point_distance: Callable[[float], float], length: float,
                        need: float, max_points: int = MAX_POINTS) -> float | None:
    """A lower bound >= ``need`` (mm) of the distance from the segment s in [0, length]
    to a face, or None when ``max_points`` samples cannot prove one. ``point_distance(s)``
    is the face's distance (mm) from the segment's point at s (any non-finite value:
    None, the caller measures exactly)."""
    need = need + SAFETY
    d0, d1 = point_distance(0.0), point_distance(length)
    if not math.isfinite(d0 + d1) or min(d0, d1) < need:
        return None   # an end point itself is too near: the exact answer is wanted
    heap = [(interval_bound(0.0, length, d0, d1), 0.0, length, d0, d1)]
    used = 2
    while heap[0][0] < need:
        if used >= max_points:
            return None
        _, a, b, d_a, d_b = heapq.heappop(heap)
        m = 0.5 * (a + b)
        d_m = point_distance(m)
        used += 1
        if not math.isfinite(d_m) or d_m < need:
            return None
        heapq.heappush(heap, (interval_bound(a, m, d_a, d_m), a, m, d_a, d_m))
        heapq.heappush(heap, (interval_bound(m, b, d_m, d_b), m, b, d_m, d_b))
    return heap[0][0] - SAFETY
