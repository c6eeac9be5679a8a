"""Each grid point's reach along a run (compiled): the speed limits held over it and the
path's derivatives' extremes over it, as :mod:`.topp` and :mod:`.plan_once` need them.

:func:`erode` holds each squared speed limit w_k over s_k +- sqrt(w_k) W (a motion
averaged over W s that kept every limit where it was is then within them where it is);
:func:`boxes` gives the smallest and largest of a quantity over each point's range of s,
from sliding-window queues (:func:`enqueue`, :func:`dequeue`; also :mod:`.topp`'s).
Both are linear or n log n in the grid, however far a point reaches. Lengths mm,
squared speeds mm²/s², windows s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def _reach(s, k: int, r: float, ordered: bool) -> tuple:
    """(first, last): the run of grid points around k whose distance from s[k] is within
    ``r``, stopping at the first one that is not (by bisection when ``ordered``)."""
    n = len(s)
    if not ordered:
        first = k
        while first > 0 and s[k] - s[first - 1] <= r:
            first -= 1
        last = k
        while last < n - 1 and s[last + 1] - s[k] <= r:
            last += 1
        return first, last
    lo, hi = 0, k   # the first j <= k with s[k] - s[j] <= r
    while lo < hi:
        mid = (lo + hi) // 2
        if s[k] - s[mid] <= r:
            hi = mid
        else:
            lo = mid + 1
    first = lo
    lo, hi = k, n - 1   # the last j >= k with s[j] - s[k] <= r
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if s[mid] - s[k] <= r:
            lo = mid
        else:
            hi = mid - 1
    return first, lo


@njit(cache=True, error_model="numpy")
def erode(s, wl, window: float):
    """Each limit w_k applied over s_k +- sqrt(w_k) window: a motion averaged over
    ``window`` s whose every speed kept the limits is then within them where it is.
    Each reach is the run of points from k within the distance (found by bisection where
    ``s`` is non-decreasing, as a run's grid is, else walked), and the ranges' minima are
    kept in a segment tree (O(n log n) however far a limit reaches)."""
    n = len(s)
    out = wl.copy()
    tree = np.full(2 * n, np.inf)   # tree[n + j]: leaf j; a node's tag covers its leaves
    ordered = True
    for k in range(n - 1):
        if s[k + 1] < s[k]:
            ordered = False
            break
    for k in range(n):
        r = math.sqrt(wl[k]) * window
        if not math.isfinite(r):
            continue
        first, last = _reach(s, k, r, ordered)
        a, b = first + n, last + n + 1
        while a < b:
            if a & 1:
                tree[a] = min(tree[a], wl[k])
                a += 1
            if b & 1:
                b -= 1
                tree[b] = min(tree[b], wl[k])
            a >>= 1
            b >>= 1
    for j in range(n):
        x = np.inf
        node = j + n
        while node >= 1:
            x = min(x, tree[node])
            node >>= 1
        if x < np.inf:
            out[j] = min(out[j], x)
    return out


@njit(cache=True, error_model="numpy")
def enqueue(q, head: int, tail: int, values, k: int, sign: float) -> int:
    """Put point k at the tail of the sliding-window queue ``q`` (indices, holding
    ``q[head:tail]``), first dropping the points it outlasts: with ``sign`` 1 those whose
    value is at most ``values[k]`` (the queue's head is then the window's largest), with
    -1 those at least it (the smallest). The new tail."""
    while tail > head and sign * values[q[tail - 1]] <= sign * values[k]:
        tail -= 1
    q[tail] = k
    return tail + 1


@njit(cache=True, error_model="numpy")
def dequeue(q, head: int, tail: int, first: int) -> int:
    """Drop the points before ``first`` from the head of the queue ``q``; the new head."""
    while head < tail and q[head] < first:
        head += 1
    return head


@njit(cache=True, error_model="numpy")
def boxes(s, x, lo_s, hi_s):
    """(lo, hi) (n, 3): the smallest and largest x over s in [lo_s[k], hi_s[k]] (each
    range holding s[k]; ranges widened to a monotone sequence, then a sliding window)."""
    n = len(s)
    first = np.empty(n, dtype=np.int64)   # the ranges as index windows, monotone
    last = np.empty(n, dtype=np.int64)
    j = n - 1
    for k in range(n - 1, -1, -1):
        j = min(j, k)
        while j > 0 and s[j - 1] >= lo_s[k]:
            j -= 1
        first[k] = j if k == n - 1 else min(j, first[k + 1])
    j = 0
    for k in range(n):
        j = max(j, k)
        while j + 1 < n and s[j + 1] <= hi_s[k]:
            j += 1
        last[k] = j if k == 0 else max(j, last[k - 1])
    lo, hi = np.empty((n, 3)), np.empty((n, 3))
    qmin = np.empty(n, dtype=np.int64)
    qmax = np.empty(n, dtype=np.int64)
    for i in range(3):
        xi = x[:, i]
        h1 = t1 = h2 = t2 = 0   # queue heads and tails (exclusive)
        nxt = 0
        for k in range(n):
            while nxt <= last[k]:
                t1 = enqueue(qmin, h1, t1, xi, nxt, -1.0)
                t2 = enqueue(qmax, h2, t2, xi, nxt, 1.0)
                nxt += 1
            h1 = dequeue(qmin, h1, t1, first[k])
            h2 = dequeue(qmax, h2, t2, first[k])
            lo[k, i] = xi[qmin[h1]]
            hi[k, i] = xi[qmax[h2]]
    return lo, hi
