"""O(1) trim check: one cell of a precomputed (u, w) label grid (see geometry/trim_grid.py).

The grid is an array of shape (nu, nw); cell (i, j) is the closed box
[u0 + i du, u0 + (i + 1) du] x [w0 + j dw, w0 + (j + 1) dw] in the face's parameters. A MIXED
cell may carry the segments of FClass2d's bands that meet it (answered by a clear move to a
labelled neighbour cell, ``resolve``) or sub-cells. Periodic parameters are first moved into
the grid's window with ``wrap`` (``TrimGrid.window`` gives start and period per direction).
A point beyond the grid is answered by the nearest border cell (the builder guarantees that
this is right). The builder's ``TrimGrid.cell`` reads the grid with these same compiled functions.
"""

import math

import numba
import numpy as np

from ...core.trim_labels import CELL_INSIDE, CELL_MIXED, CELL_OUTSIDE, SEGMENT_WORDS, SEGMENTS  # noqa: F401

# -- Reading a trim grid: cadcnc.geometry.trim_grid builds it; the compiled kernel
# (cadcnc.interp.kernel) and TrimGrid.cell both read it with these numba functions.
_jit = numba.njit(cache=True, nogil=True, _nrt=False)
_FAR = 1e15  # |index| beyond this (or NaN/inf): no cell, ask the exact classifier


@_jit
def wrap(x: float, start: float, period: float) -> float:
    """``x`` moved by whole periods into [start, start + period); unchanged if period <= 0."""
    if period > 0.0:
        return start + (x - start) % period
    return x


@_jit
def touches(p0: float, p1: float, q0: float, q1: float, a0: float, a1: float,
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
def resolve(codes: np.ndarray, fine: np.ndarray, k: int, u0: float, w0: float, du: float,
            dw: float, i: int, j: int, u: float, w: float) -> int:
    """The label of (u, w) in MIXED cell (i, j) from its segment list at ``fine[k:]``
    ([SEGMENTS, n, eps_u, eps_w, then n x (p, q, h)]): the label of a labelled neighbour
    cell reached by an axis-parallel move from (u, w) to the shared side whose rectangle,
    inflated by each segment's half-widths (+ eps), meets none of the cell's segments
    (the connected set it sweeps meets no band: FClass2d's answer is the neighbour's);
    CELL_MIXED if no move is clear (within a band, or boxed in)."""
    nu, nw = codes.shape
    n, eu, ew = int(fine[k + 1]), fine[k + 2], fine[k + 3]
    cu0, cw0 = u0 + i * du, w0 + j * dw
    cu1, cw1 = cu0 + du, cw0 + dw
    if not (cu0 <= u <= cu1 and cw0 <= w <= cw1):
        return CELL_MIXED
    for d in range(4):
        ni = i - 1 if d == 0 else (i + 1 if d == 1 else i)
        nj = j - 1 if d == 2 else (j + 1 if d == 3 else j)
        if not (0 <= ni < nu and 0 <= nj < nw):
            continue
        label = codes[ni, nj]
        if label != CELL_INSIDE and label != CELL_OUTSIDE:
            continue
        a0 = cu0 if d == 0 else u
        b0 = cu1 if d == 1 else u
        a1 = cw0 if d == 2 else w
        b1 = cw1 if d == 3 else w
        clear = True
        for s in range(n):
            x = k + 4 + SEGMENT_WORDS * s
            hx, hy = fine[x + 4] + eu, fine[x + 5] + ew
            if touches(fine[x], fine[x + 1], fine[x + 2], fine[x + 3],
                       a0 - hx, a1 - hy, b0 + hx, b1 + hy):
                clear = False
                break
        if clear:
            return int(label)
    return CELL_MIXED


@_jit
def lookup(codes: np.ndarray, fine: np.ndarray, u0: float, w0: float, du: float,
           dw: float, nu: int, nw: int, u: float, w: float) -> int:
    """The label (CELL_*) of (u, w), periodic parameters already wrapped (``wrap``).

    ``codes`` (nu, nw) holds CELL_* or, on a resolvable MIXED cell, 3 + k: ``fine[k]`` is
    SEGMENTS (a segment list, ``resolve``) or Ru > 0, with Rw and Ru x Rw sub-cell labels
    (row-major) after it. u0, w0: the grid's lower corner, du, dw: its cell sizes, in the
    surface's parameters; a point beyond the grid reads its nearest border cell. Non-finite
    input gives CELL_MIXED.
    """
    x = (u - u0) / du
    y = (w - w0) / dw
    if not (abs(x) < _FAR and abs(y) < _FAR):
        return CELL_MIXED
    i = min(max(int(math.floor(x)), 0), nu - 1)
    j = min(max(int(math.floor(y)), 0), nw - 1)
    code = int(codes[i, j])
    if code < 3:
        return code
    k = code - 3
    if fine[k] < 0:
        return resolve(codes, fine, k, u0, w0, du, dw, i, j, u, w)
    ru, rw = int(fine[k]), int(fine[k + 1])
    a = min(max(int(math.floor((x - i) * ru)), 0), ru - 1)
    b = min(max(int(math.floor((y - j) * rw)), 0), rw - 1)
    return int(fine[k + 2 + a * rw + b])


@_jit
def lookup_grid(codes: np.ndarray, fine: np.ndarray, u0: float, w0: float, du: float,
                dw: float, nu: int, nw: int, window: np.ndarray, us: np.ndarray,
                ws: np.ndarray, out: np.ndarray) -> None:
    """``out[a, b]`` = the label of (``us[a]``, ``ws[b]``) (``lookup``), each wrapped first
    into ``window`` (u start, u period, w start, w period; period 0: not periodic).
    ``out``: (len(us), len(ws)) int64; a sampling grid's labels in one call."""
    for a in range(len(us)):
        u = wrap(us[a], window[0], window[1])
        for b in range(len(ws)):
            out[a, b] = lookup(codes, fine, u0, w0, du, dw, nu, nw, u,
                               wrap(ws[b], window[2], window[3]))
