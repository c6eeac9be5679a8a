"""A piece's path derivatives from its points, compiled (no OCCT): what the pieces and the
runs are made of, once per stream.

The same arithmetic, in the same order, as the NumPy expressions they replace (the same
floats): a stream's plan costs too little for these small arrays' per-call overhead to
be left in it. Arrays: ``points`` (n, 3) mm, ``s`` (n,) mm arc length from the first
point; curvatures 1/mm.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _norm3(x: float, y: float, z: float) -> float:
    return math.sqrt(x * x + y * y + z * z)


@njit(cache=True, error_model="numpy")
def curvature(points: np.ndarray) -> np.ndarray:
    """(n,) the curvature (1/mm) of the circle through each point and its neighbours
    (the ends take their neighbour's; 0 for fewer than 3 points)."""
    n = len(points)
    out = np.zeros(n)
    if n < 3:
        return out
    for i in range(1, n - 1):
        p, q, r = points[i - 1], points[i], points[i + 1]
        a0, a1, a2 = q[0] - p[0], q[1] - p[1], q[2] - p[2]
        b0, b1, b2 = r[0] - q[0], r[1] - q[1], r[2] - q[2]
        c0, c1, c2 = r[0] - p[0], r[1] - p[1], r[2] - p[2]
        area2 = _norm3(a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)
        out[i] = 2.0 * area2 / (_norm3(a0, a1, a2) * _norm3(b0, b1, b2) * _norm3(c0, c1, c2))
    out[0], out[n - 1] = out[1], out[n - 2]
    return out


@njit(cache=True)
def arc_lengths(points: np.ndarray, kappa: np.ndarray) -> np.ndarray:
    """(n,) arc length from the first point: each chord h of a curve of curvature k is
    an arc of h (1 + k^2 h^2 / 24); the kernel re-run at shorter steps follows the arc."""
    n = len(points)
    out = np.zeros(n)
    total = 0.0
    for i in range(n - 1):
        p, q = points[i], points[i + 1]
        h = _norm3(q[0] - p[0], q[1] - p[1], q[2] - p[2])
        k2 = 0.5 * (kappa[i] * kappa[i] + kappa[i + 1] * kappa[i + 1])
        total += h * (1.0 + k2 * h * h / 24.0)
        out[i + 1] = total
    return out


@njit(cache=True)
def distinct(points: np.ndarray, duplicate: float):
    """The points without consecutive duplicates (closer than ``duplicate`` mm), their
    arc length, curvature and the (n,) mask of the points kept."""
    n = len(points)
    mask = np.ones(n, dtype=np.bool_)
    for i in range(1, n):
        p, q = points[i - 1], points[i]
        mask[i] = _norm3(q[0] - p[0], q[1] - p[1], q[2] - p[2]) > duplicate
    pts = points[mask]
    kappa = curvature(pts)
    return pts, arc_lengths(pts, kappa), kappa, mask


@njit(cache=True)
def _lagrange(p: np.ndarray, s: np.ndarray, a: int, at: int):
    """p' and p'' (3,) at point ``a + at`` (at 0 or 2) of the parabola through points
    a..a+2, in arc lengths from point a."""
    s0, s1, s2 = 0.0, s[a + 1] - s[a], s[a + 2] - s[a]
    x = s0 if at == 0 else s2
    d0, d1, d2 = (s0 - s1) * (s0 - s2), (s1 - s0) * (s1 - s2), (s2 - s0) * (s2 - s1)
    c0, c1, c2 = 2 * x - s1 - s2, 2 * x - s0 - s2, 2 * x - s0 - s1
    first, second = np.empty(3), np.empty(3)
    for j in range(3):
        u, v, w = p[a, j], p[a + 1, j], p[a + 2, j]
        first[j] = u * c0 / d0 + v * c1 / d1 + w * c2 / d2
        second[j] = 2.0 * (u / d0 + v / d1 + w / d2)
    return first, second


@njit(cache=True)
def _end_raw(p: np.ndarray, s: np.ndarray, end: bool):
    """p' (not made unit) and p'' (3,) at the first point (``end`` False) or the last."""
    n = len(p)
    if n < 3:
        return p[n - 1] - p[0], np.zeros(3)
    t, k = _lagrange(p, s, n - 3, 2) if end else _lagrange(p, s, 0, 0)
    if n >= 4:   # p'' of the next three points too: extrapolated onto the end (a ramp of
        k2 = _lagrange(p, s, n - 4 if end else 1, 0)[1]   # curvature is no jump)
        k = 2.0 * k - k2
    return t, k


def end_derivatives(p: np.ndarray, s: np.ndarray, end: bool) -> tuple[np.ndarray,
                                                                      np.ndarray]:
    """Unit tangent and p'' (1/mm) (3,) at the first point (``end`` False) or the last
    of the path through ``p`` (a straight move for 2 points: p'' 0). The tangent is made
    unit by NumPy's vector norm (BLAS's rounding, which the plans were made with)."""
    t, k = _end_raw(p, s, end)
    return t / np.linalg.norm(t), k


@njit(cache=True, error_model="numpy")
def cut_derivatives(p: np.ndarray, s: np.ndarray, t0: np.ndarray, t1: np.ndarray):
    """T (unit), K = p'' (signed), D = |p'''| and the curvature jumps (n, 3) each at a
    cut's points: central differences, the ends' unit tangents ``t0``, ``t1`` (3,)
    given (:func:`end_derivatives`); a jump is a knot's change of K beyond both
    neighbours' (a smooth change is D's)."""
    n = len(p)
    h = np.empty(n - 1)
    d1 = np.empty((n - 1, 3))
    for i in range(n - 1):
        h[i] = s[i + 1] - s[i]
        for j in range(3):
            d1[i, j] = (p[i + 1, j] - p[i, j]) / h[i]
    T = np.empty((n, 3))
    for i in range(1, n - 1):
        for j in range(3):
            T[i, j] = (d1[i - 1, j] * h[i] + d1[i, j] * h[i - 1]) / (h[i - 1] + h[i])
    T[0], T[n - 1] = t0, t1
    for i in range(n):
        r = _norm3(T[i, 0], T[i, 1], T[i, 2])
        for j in range(3):
            T[i, j] = T[i, j] / r
    K, D, jump = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    if n < 3:
        return T, K, D, jump
    for i in range(1, n - 1):
        for j in range(3):
            K[i, j] = 2.0 * (d1[i, j] - d1[i - 1, j]) / (h[i - 1] + h[i])
    K[0], K[n - 1] = K[1], K[n - 2]
    dk = np.abs(K[1:] - K[:-1])                       # (n - 1, 3) per knot
    for i in range(n - 1):
        for j in range(3):
            D[i, j] = dk[i, j] / h[i]
    for i in range(n - 1, 0, -1):                     # each with its neighbour before
        for j in range(3):
            D[i, j] = _max(D[i, j], D[i - 1, j])
    for i in range(n - 1):
        for j in range(3):
            before = dk[i - 1, j] if i > 0 else 0.0
            nb = _max(before, dk[i + 1, j]) if i + 1 < n - 1 else before
            jump[i, j] = _max(dk[i, j] - nb, 0.0)
    for i in range(n - 1, 0, -1):
        for j in range(3):
            jump[i, j] = _max(jump[i, j], jump[i - 1, j])
    return T, K, D, jump


@njit(cache=True, inline="always")
def _max(a: float, b: float) -> float:
    """np.maximum of two floats (a NaN wins)."""
    if a != a or b != b:
        return math.nan
    return a if a >= b else b


@njit(cache=True, error_model="numpy")
def substep_need(points: np.ndarray, s: np.ndarray, caps: np.ndarray, feed: float,
                 V: np.ndarray) -> float:
    """The largest ratio of the speed the feed (mm/s) and the axes' velocities ``V`` (3,)
    allow along the tangent to the accurate step's cap ``caps`` (n,): the tangent as
    np.gradient(points, s) gives it (uniform spacing or not), made unit."""
    n = len(points)
    h = np.empty(n - 1)
    uniform = True
    for i in range(n - 1):
        h[i] = s[i + 1] - s[i]
        uniform = uniform and h[i] == h[0]
    need = -math.inf
    g = np.empty(3)
    for i in range(n):
        for j in range(3):
            if i == 0:
                g[j] = (points[1, j] - points[0, j]) / h[0]
            elif i == n - 1:
                g[j] = (points[n - 1, j] - points[n - 2, j]) / h[n - 2]
            elif uniform:
                g[j] = (points[i + 1, j] - points[i - 1, j]) / (2.0 * h[0])
            else:
                a, b = h[i - 1], h[i]
                g[j] = (-b / (a * (a + b)) * points[i - 1, j]
                        + (b - a) / (a * b) * points[i, j]
                        + a / (b * (a + b)) * points[i + 1, j])
        r = _norm3(g[0], g[1], g[2])
        axes = math.inf
        for j in range(3):
            axes = min(axes, V[j] / abs(g[j] / r))
        need = _max(need, min(axes, feed) / caps[i])
    return need
