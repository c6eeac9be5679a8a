"""The trim grid's cell work: the layout, and compiled (numba) band marking, 4-connected
free regions and the MIXED cells' sub-cells.

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


def layout(lo, hi, p, q, face_surface, max_cells: int, target: float) -> tuple[list, list]:
    """Per direction (origin, cell size, count) by trim_grid's resolution rule, and the window (start,
    period, seam): periodic points are wrapped into [start, start + period) before lookup
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
    var = [max(float(np.abs(q[:, k] - p[:, k]).sum()), 1e-9 * span[k]) for k in range(2)]
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


@_jit
def _touches(p0: float, p1: float, q0: float, q1: float, a0: float, a1: float,
             b0: float, b1: float) -> bool:
    """Whether segment (p0, p1) -> (q0, q1) meets the closed box [a0, b0] x [a1, b1]
    (Liang-Barsky clipping)."""
    t0, t1 = 0.0, 1.0
    for d0, lo, hi in ((q0 - p0, a0 - p0, b0 - p0), (q1 - p1, a1 - p1, b1 - p1)):
        if d0 == 0.0:
            if lo > 0.0 or hi < 0.0:
                return False
        else:
            ta, tb = lo / d0, hi / d0
            if ta > tb:
                ta, tb = tb, ta
            t0, t1 = max(t0, ta), min(t1, tb)
            if t0 > t1:
                return False
    return True


@_jit
def _merge(label: int, labels: np.ndarray, mask: np.ndarray, i: int, j: int) -> int:
    """``label`` (-1 none yet, -2 conflicting) merged with free cell (i, j)'s, if any."""
    nu, nw = mask.shape
    if not (0 <= i < nu and 0 <= j < nw) or mask[i, j]:
        return label
    other = labels[i, j]
    if other == 2 or label == -2 or (label >= 0 and label != other):
        return -2
    return other


@_jit
def _label_strips(fine: np.ndarray, off: int, n: int, across_u: bool, labels: np.ndarray,
                  mask: np.ndarray, i: int, j: int) -> int:
    """Label the runs of free strips of cell (i, j) (n strips across u if ``across_u``,
    else across w) from the cells beside them; returns the sub-cells left unresolved."""
    di, dj = (1, 0) if across_u else (0, 1)
    common = _merge(_merge(-1, labels, mask, i + dj, j + di), labels, mask, i - dj, j - di)
    unresolved, c = 0, 0
    while c < n:
        if fine[off + c] != 0:
            c += 1
            continue
        e = c
        while e + 1 < n and fine[off + e + 1] == 0:
            e += 1
        label = common
        if c == 0:
            label = _merge(label, labels, mask, i - di, j - dj)
        if e == n - 1:
            label = _merge(label, labels, mask, i + di, j + dj)
        for k in range(c, e + 1):
            fine[off + k] = 2 + label if label >= 0 else 4
        unresolved += 0 if label >= 0 else e - c + 1
        c = e + 1
    return unresolved


@_jit
def refine(mask: np.ndarray, labels: np.ndarray, p: np.ndarray, q: np.ndarray,
           h: np.ndarray, origin: np.ndarray, size: np.ndarray, eps: np.ndarray,
           budget: int, square: int) -> tuple:
    """Sub-cells for the marked cells: (codes (nu, nw) int64, fine (m,) int64, unresolved).

    Each marked cell gets Ru x Rw <= ``budget`` sub-cells shaped by the bands' variation in
    it (a band along u or w, such as a seam, gets thin strips across it), at most ``square``
    where neither shape is a strip; a sub-cell is marked if a segment's band (the
    segment met by the sub-cell inflated by h + eps: FClass2d's ON test) touches it. Free
    sub-cells connected inside the cell take the label of the free (labelled) cells beside
    them, if those agree; else they stay CELL_MIXED (``unresolved`` counts them). ``codes``
    is ``labels`` with 3 + offset on marked cells; ``fine[offset:]`` holds Ru, Rw and the
    Ru x Rw labels (row-major).
    """
    nu, nw = mask.shape
    index = np.full((nu, nw), -1, np.int64)   # the marked cells, numbered
    m = 0
    for i in range(nu):
        for j in range(nw):
            if mask[i, j]:
                index[i, j] = m
                m += 1
    var = np.zeros((m, 2))
    for s in range(p.shape[0]):   # the bands' variation per cell (shape heuristic)
        i0 = max(int(math.floor((min(p[s, 0], q[s, 0]) - h[s, 0] - origin[0]) / size[0])), 0)
        i1 = min(int(math.floor((max(p[s, 0], q[s, 0]) + h[s, 0] - origin[0]) / size[0])), nu - 1)
        j0 = max(int(math.floor((min(p[s, 1], q[s, 1]) - h[s, 1] - origin[1]) / size[1])), 0)
        j1 = min(int(math.floor((max(p[s, 1], q[s, 1]) + h[s, 1] - origin[1]) / size[1])), nw - 1)
        n = max((i1 - i0 + 1) * (j1 - j0 + 1), 1)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                if index[i, j] >= 0:
                    var[index[i, j], 0] += abs(q[s, 0] - p[s, 0]) / size[0] / n
                    var[index[i, j], 1] += abs(q[s, 1] - p[s, 1]) / size[1] / n
    codes = labels.astype(np.int64)
    shape = np.zeros((m, 2), np.int64)
    total = 0
    for i in range(nu):
        for j in range(nw):
            k = index[i, j]
            if k >= 0:
                ratio = (var[k, 1] + 1e-3) / (var[k, 0] + 1e-3)
                n = budget
                ru = min(max(int(round(math.sqrt(n * ratio))), 1), n)
                if 1 < ru < n:  # not a strip: a band across the cell, fewer sub-cells
                    n = square
                    ru = min(max(int(round(math.sqrt(n * ratio))), 1), n)
                shape[k, 0], shape[k, 1] = ru, max(n // ru, 1)
                codes[i, j] = 3 + total
                total += 2 + shape[k, 0] * shape[k, 1]
    fine = np.zeros(total, np.int64)
    for i in range(nu):
        for j in range(nw):
            k = index[i, j]
            if k >= 0:
                fine[codes[i, j] - 3] = shape[k, 0]
                fine[codes[i, j] - 2] = shape[k, 1]
    for s in range(p.shape[0]):   # mark sub-cells met by a band
        i0 = max(int(math.floor((min(p[s, 0], q[s, 0]) - h[s, 0] - eps[0] - origin[0])
                                / size[0])), 0)
        i1 = min(int(math.floor((max(p[s, 0], q[s, 0]) + h[s, 0] + eps[0] - origin[0])
                                / size[0])), nu - 1)
        j0 = max(int(math.floor((min(p[s, 1], q[s, 1]) - h[s, 1] - eps[1] - origin[1])
                                / size[1])), 0)
        j1 = min(int(math.floor((max(p[s, 1], q[s, 1]) + h[s, 1] + eps[1] - origin[1])
                                / size[1])), nw - 1)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                k = index[i, j]
                if k < 0:
                    continue
                off, ru, rw = codes[i, j] - 1, shape[k, 0], shape[k, 1]
                su, sw = size[0] / ru, size[1] / rw
                cu, cw = origin[0] + i * size[0], origin[1] + j * size[1]
                a0 = max(int(math.floor((min(p[s, 0], q[s, 0]) - h[s, 0] - cu) / su)) - 1, 0)
                a1 = min(int(math.floor((max(p[s, 0], q[s, 0]) + h[s, 0] - cu) / su)) + 1, ru - 1)
                b0 = max(int(math.floor((min(p[s, 1], q[s, 1]) - h[s, 1] - cw) / sw)) - 1, 0)
                b1 = min(int(math.floor((max(p[s, 1], q[s, 1]) + h[s, 1] - cw) / sw)) + 1, rw - 1)
                for a in range(a0, a1 + 1):
                    for b in range(b0, b1 + 1):
                        if fine[off + a * rw + b] == 0 and _touches(
                                p[s, 0], p[s, 1], q[s, 0], q[s, 1],
                                cu + a * su - h[s, 0] - eps[0], cw + b * sw - h[s, 1] - eps[1],
                                cu + (a + 1) * su + h[s, 0] + eps[0],
                                cw + (b + 1) * sw + h[s, 1] + eps[1]):
                            fine[off + a * rw + b] = 1
    unresolved = 0
    stack = np.empty(budget, np.int64)
    comp = np.empty(budget, np.int64)
    for i in range(nu):   # free sub-cells: 4-connected components inside the cell
        for j in range(nw):
            mi = index[i, j]
            if mi < 0:
                continue
            off, ru, rw = codes[i, j] - 1, shape[mi, 0], shape[mi, 1]
            if ru == 1 or rw == 1:   # strips: runs between marked ones
                unresolved += _label_strips(fine, off, ru * rw, rw == 1, labels, mask, i, j)
            for c in range(ru * rw):   # 0 free, 1 marked -> 2 + label, or 4 unresolved
                if fine[off + c] != 0:
                    continue
                fine[off + c] = 5   # in the current component
                top, k, label = 1, 0, -1
                stack[0] = c
                while top:
                    top -= 1
                    x = stack[top]
                    comp[k] = x
                    k += 1
                    a, b = x // rw, x % rw
                    for na, nb in ((a - 1, b), (a + 1, b), (a, b - 1), (a, b + 1)):
                        if 0 <= na < ru and 0 <= nb < rw:
                            y = off + na * rw + nb
                            if fine[y] == 0:
                                fine[y] = 5
                                stack[top] = na * rw + nb
                                top += 1
                        else:   # the neighbouring cell
                            ni = i + (na >= ru) - (na < 0)
                            nj = j + (nb >= rw) - (nb < 0)
                            label = _merge(label, labels, mask, ni, nj)
                for m in range(k):
                    fine[off + comp[m]] = 2 + label if label >= 0 else 4
                unresolved += 0 if label >= 0 else k
            for c in range(ru * rw):   # to CELL_* codes
                v = fine[off + c]
                fine[off + c] = v - 2 if v in (2, 3) else 2
    return codes, fine, unresolved
