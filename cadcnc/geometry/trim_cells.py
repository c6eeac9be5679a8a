"""The trim grid's cell work: the layout, and compiled (numba) band marking, 4-connected
free regions and the MIXED cells' segment lists.

Used by ``trim_grid``: ``segment_lists`` finds every cell a band touches, with the
arithmetic of the vectorised rule it replaced (segments cut into pieces no longer than a
cell, each piece's band-inflated bounding box), and which segments touch it; ``regions``
numbers the free cells' 4-connected regions and picks three cells of each (first, middle,
last in row-major order) for the exact calls; ``segment_blocks`` stores each MIXED cell's
segments for ``cadcnc.interp.kernel.trim_lookup.resolve``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..core.trim_labels import CELL_MIXED, SEGMENT_WORDS, SEGMENTS

_jit = numba.njit(cache=True, nogil=True)


def layout(lo, hi, p, q, face_surface, max_cells: int, target: float) -> tuple[list, list]:
    """Per direction (origin, cell size, count) by trim_grid's resolution rule, and the window
    (start, period, seam): periodic points are wrapped into [start, start + period) before lookup
    (period 0: not periodic); ``seam`` is where FaceSurface.wrap jumps inside a window that
    the grid does not span (lo, hi are widened to hold it), else None."""
    windows = []
    for k, (period, start) in enumerate(((face_surface.u_period, face_surface.u_range[0]),
                                        (face_surface.w_period, face_surface.w_range[0]))):
        window = 0.5 * (lo[k] + hi[k] - (period or 0.0))
        seam = None if period is None else window + (start - window) % period
        if period is None:
            windows.append((0.0, 0.0, None))
        elif max(hi[k], seam) - min(lo[k], seam) > 0.75 * period:
            windows.append((start, period, None))  # the grid spans the wrap range
        else:
            lo[k], hi[k] = min(lo[k], seam), max(hi[k], seam)
            windows.append((window, period, seam))
    full = [w[1] if w[1] and w[2] is None else 0.0 for w in windows]
    span = [hi[k] - lo[k] for k in range(2)]
    domain = [full[k] or span[k] for k in range(2)]
    var = [max(float(np.abs(q[:, k] - p[:, k]).sum()), 1e-9 * span[k])  # > 0: no / 0 below
           for k in range(2)]
    n = 4.0 * var[0] * var[1] * domain[0] * domain[1] / (target * span[0] * span[1]) ** 2
    c = domain[0] * domain[1] / min(max(n, 256.0), float(max_cells))
    # the best cell shape, but no direction finer than max_cells / 16 cells
    cell = [max(math.sqrt(c * var[k] / var[1 - k]), 16.0 * domain[k] / max_cells)
            for k in range(2)]
    while True:
        axes = []
        for k in range(2):
            if full[k]:  # exactly the wrap range [start, start + period)
                count = max(1, math.ceil(full[k] / cell[k]))
                axes.append((windows[k][0], full[k] / count, count))
            else:  # the bands plus >= 1.1 clear cells each side
                count = max(3, math.ceil(span[k] / cell[k]) + 3)
                axes.append((lo[k] - 1.1 * span[k] / (count - 2.2), span[k] / (count - 2.2),
                             count))
        if axes[0][2] * axes[1][2] <= 2 * max_cells:  # counts round up; memory stays bounded
            return axes, windows
        cell = [x * 1.25 for x in cell]


@_jit
def _visit(p: np.ndarray, q: np.ndarray, h: np.ndarray, origin: np.ndarray,
           size: np.ndarray, eps: np.ndarray, nu: int, nw: int, count: np.ndarray,
           ids: np.ndarray, fill: np.ndarray) -> None:
    """Every (cell, segment) pair where a segment p -> q's band (half-widths h, plus eps)
    touches the cell, once: counted in ``count`` (flat cell index) or, with ``ids``
    non-empty, written at ``fill[cell]``. The rule (pieces no longer than a cell, each
    piece's band-inflated bounding box) is the vectorised marking's it replaced."""
    last = np.full(count.size, -1, np.int64)
    for s in range(p.shape[0]):
        steps = max(math.ceil(max(abs(q[s, 0] - p[s, 0]) / size[0],
                                  abs(q[s, 1] - p[s, 1]) / size[1])), 1.0)
        for k in range(int(steps)):
            a = p[s, 0] + k / steps * (q[s, 0] - p[s, 0])
            b = p[s, 0] + (k + 1) / steps * (q[s, 0] - p[s, 0])
            i0 = math.floor((min(a, b) - h[s, 0] - eps[0] - origin[0]) / size[0])
            i1 = math.floor((max(a, b) + h[s, 0] + eps[0] - origin[0]) / size[0])
            a = p[s, 1] + k / steps * (q[s, 1] - p[s, 1])
            b = p[s, 1] + (k + 1) / steps * (q[s, 1] - p[s, 1])
            j0 = math.floor((min(a, b) - h[s, 1] - eps[1] - origin[1]) / size[1])
            j1 = math.floor((max(a, b) + h[s, 1] + eps[1] - origin[1]) / size[1])
            if not (i1 >= 0 and i0 < nu and j1 >= 0 and j0 < nw):
                continue
            for i in range(int(max(i0, 0)), int(min(i1, nu - 1)) + 1):
                for j in range(int(max(j0, 0)), int(min(j1, nw - 1)) + 1):
                    c = i * nw + j
                    if last[c] == s:
                        continue
                    last[c] = s
                    if ids.size:
                        ids[fill[c]] = s
                        fill[c] += 1
                    else:
                        count[c] += 1


@_jit
def segment_lists(p: np.ndarray, q: np.ndarray, h: np.ndarray, origin: np.ndarray,
                  size: np.ndarray, eps: np.ndarray, nu: int, nw: int) -> tuple:
    """(mask (nu, nw) uint8: the cells a band touches; start (nu nw + 1,), ids: the
    segments of flat cell c are ids[start[c]:start[c + 1]]); p, q, h (k, 2); origin, size,
    eps (2,) in (u, w)."""
    count = np.zeros(nu * nw, np.int64)
    _visit(p, q, h, origin, size, eps, nu, nw, count, np.zeros(0, np.int64), count)
    start = np.zeros(nu * nw + 1, np.int64)
    start[1:] = np.cumsum(count)
    ids = np.empty(max(start[-1], 1), np.int64)
    fill = start[:-1].copy()
    _visit(p, q, h, origin, size, eps, nu, nw, count, ids, fill)
    mask = (count > 0).astype(np.uint8).reshape((nu, nw))
    return mask, start, ids


@_jit
def segment_blocks(labels: np.ndarray, start: np.ndarray, ids: np.ndarray, p: np.ndarray,
                   q: np.ndarray, h: np.ndarray, eps: np.ndarray) -> tuple:
    """(codes (nu, nw) int64, fine (m,) float64): ``labels`` with 3 + k on every MIXED cell
    that has segments, ``fine[k:]`` its block [SEGMENTS, n, eps_u, eps_w, n x (p, q, h)]
    for ``cadcnc.interp.kernel.trim_lookup.resolve``."""
    nu, nw = labels.shape
    codes = labels.astype(np.int64)
    total = 0
    for c in range(nu * nw):
        n = start[c + 1] - start[c]
        if n and labels.flat[c] == CELL_MIXED:
            total += 4 + SEGMENT_WORDS * n
    fine = np.empty(total)
    k = 0
    for c in range(nu * nw):
        n = start[c + 1] - start[c]
        if not n or labels.flat[c] != CELL_MIXED:
            continue
        codes.flat[c] = 3 + k
        fine[k], fine[k + 1], fine[k + 2], fine[k + 3] = SEGMENTS, n, eps[0], eps[1]
        for m in range(n):
            s, x = ids[start[c] + m], k + 4 + SEGMENT_WORDS * m
            fine[x], fine[x + 1], fine[x + 2], fine[x + 3] = p[s, 0], p[s, 1], q[s, 0], q[s, 1]
            fine[x + 4], fine[x + 5] = h[s, 0], h[s, 1]
        k += 4 + SEGMENT_WORDS * n
    return codes, fine


@_jit
def regions(mask: np.ndarray) -> tuple:
    """(region (nu, nw) int32, -1 on marked cells; picks (r, 3) int64 flat cell indices):
    the 4-connected regions of unmarked cells, numbered in row-major order of first cell."""
    nu, nw = mask.shape
    flat = mask.ravel()
    region = np.full(nu * nw, -1, np.int32)
    stack = np.empty(nu * nw, np.int32)
    count = 0
    for start in range(nu * nw):
        if flat[start] or region[start] >= 0:
            continue
        region[start] = count
        top = 1
        stack[0] = start
        while top:
            top -= 1
            c = stack[top]
            i, j = c // nw, c % nw
            for n, ok in ((c - nw, i > 0), (c + nw, i < nu - 1), (c - 1, j > 0),
                          (c + 1, j < nw - 1)):
                if ok and not flat[n] and region[n] < 0:
                    region[n] = count
                    stack[top] = n
                    top += 1
        count += 1
    size = np.zeros(count, np.int64)
    picks = np.full((count, 3), -1, np.int64)
    for c in range(nu * nw):
        r = region[c]
        if r >= 0:
            if picks[r, 0] < 0:
                picks[r, 0] = c
            picks[r, 2] = c
            size[r] += 1
    seen = np.zeros(count, np.int64)
    for c in range(nu * nw):
        r = region[c]
        if r >= 0:
            if seen[r] == size[r] // 2:
                picks[r, 1] = c
            seen[r] += 1
    return region.reshape((nu, nw)), picks


@_jit
def paint(labels: np.ndarray, region: np.ndarray, code: np.ndarray) -> None:
    """labels[c] = code[region[c]] on every cell of a region (region >= 0)."""
    flat, reg = labels.ravel(), region.ravel()
    for c in range(reg.size):
        if reg[c] >= 0:
            flat[c] = code[reg[c]]


