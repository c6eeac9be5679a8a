"""The trim grid's cell work, compiled (numba): band marking and 4-connected free regions.

Used by ``trim_grid``: ``mark`` sets every cell a band touches, with the arithmetic of the
vectorised rule it replaces (segments cut into pieces no longer than a cell, each piece's
band-inflated bounding box); ``regions`` numbers the free cells' 4-connected regions and
picks three cells of each (first, middle, last in row-major order) for the exact calls.
"""

from __future__ import annotations

import math

import numba
import numpy as np

_jit = numba.njit(cache=True, nogil=True)


@_jit
def mark(mask: np.ndarray, p: np.ndarray, q: np.ndarray, h: np.ndarray,
         origin: np.ndarray, size: np.ndarray, eps: np.ndarray) -> None:
    """Set ``mask`` (nu, nw) uint8 where a segment p -> q's box band (half-widths h, plus
    eps) touches; p, q, h (k, 2); origin, size, eps (2,) in (u, w)."""
    nu, nw = mask.shape
    for s in range(p.shape[0]):
        steps = max(math.ceil(max(abs(q[s, 0] - p[s, 0]) / size[0],
                                  abs(q[s, 1] - p[s, 1]) / size[1])), 1.0)
        for k in range(int(steps)):
            lo = np.empty(2, np.int64)
            hi = np.empty(2, np.int64)
            clear = False
            for d, n in ((0, nu), (1, nw)):
                a = p[s, d] + k / steps * (q[s, d] - p[s, d])
                b = p[s, d] + (k + 1) / steps * (q[s, d] - p[s, d])
                i0 = math.floor((min(a, b) - h[s, d] - eps[d] - origin[d]) / size[d])
                i1 = math.floor((max(a, b) + h[s, d] + eps[d] - origin[d]) / size[d])
                if not (i1 >= 0 and i0 < n):
                    clear = True
                lo[d] = int(min(max(i0, 0), n - 1)) if not clear else 0
                hi[d] = int(min(max(i1, 0), n - 1)) if not clear else -1
            if clear:
                continue
            for i in range(lo[0], hi[0] + 1):
                for j in range(lo[1], hi[1] + 1):
                    mask[i, j] = 1


@_jit
def regions(mask: np.ndarray) -> tuple:
    """(region (nu, nw) int64, -1 on marked cells; picks (r, 3) int64 flat cell indices):
    the 4-connected regions of unmarked cells, numbered in row-major order of first cell."""
    nu, nw = mask.shape
    region = np.full((nu, nw), -1, np.int64)
    stack = np.empty(nu * nw, np.int64)
    count = 0
    for start in range(nu * nw):
        if mask.flat[start] or region.flat[start] >= 0:
            continue
        region.flat[start] = count
        top = 1
        stack[0] = start
        while top:
            top -= 1
            c = stack[top]
            i, j = c // nw, c % nw
            for ni, nj in ((i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1)):
                if 0 <= ni < nu and 0 <= nj < nw:
                    n = ni * nw + nj
                    if not mask.flat[n] and region.flat[n] < 0:
                        region.flat[n] = count
                        stack[top] = n
                        top += 1
        count += 1
    size = np.zeros(count, np.int64)
    picks = np.full((count, 3), -1, np.int64)
    for c in range(nu * nw):
        r = region.flat[c]
        if r >= 0:
            if picks[r, 0] < 0:
                picks[r, 0] = c
            picks[r, 2] = c
            size[r] += 1
    seen = np.zeros(count, np.int64)
    for c in range(nu * nw):
        r = region.flat[c]
        if r >= 0:
            if seen[r] == size[r] // 2:
                picks[r, 1] = c
            seen[r] += 1
    return region, picks
