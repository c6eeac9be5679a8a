"""O(1) trim check: one cell of a precomputed (u, w) label grid (see geometry/trim_grid.py).

The grid is an array of shape (nu, nw), MIXED cells possibly split in sub-cells; cell (i, j)
is the closed box
[u0 + i du, u0 + (i + 1) du] x [w0 + j dw, w0 + (j + 1) dw] in the face's parameters.
Periodic parameters are first moved into the grid's window with ``wrap`` (``TrimGrid.window``
gives start and period per direction). A point beyond the grid is answered by the nearest
border cell (the builder guarantees that this is right). Pure numpy/math:
``numba.njit(lookup)`` and ``numba.njit(wrap)`` compile as they are.
"""

from __future__ import annotations

import math

import numpy as np

from ...trim import CELL_INSIDE, CELL_MIXED, CELL_OUTSIDE  # noqa: F401 (re-exported)

_FAR = 1e15  # |index| beyond this (or NaN/inf): no cell, ask the exact classifier


def wrap(x: float, start: float, period: float) -> float:
    """``x`` moved by whole periods into [start, start + period); unchanged if period <= 0."""
    if period > 0.0:
        return start + (x - start) % period
    return x


def lookup(codes: np.ndarray, fine: np.ndarray, u0: float, w0: float, du: float,
                dw: float, nu: int, nw: int, u: float, w: float) -> int:
    """The label (CELL_*) of the cell or sub-cell holding (u, w), periodic parameters already
    wrapped (``TrimGrid.kernel_args`` gives the leading arguments).

    ``codes`` (nu, nw) holds CELL_* or, on a MIXED cell split in Ru x Rw sub-cells, 3 + k
    where ``fine[k]``, ``fine[k + 1]`` are Ru, Rw and ``fine[k + 2:]`` the sub-cells' labels
    (row-major); u0, w0 the grid's lower corner and du, dw its cell sizes, in the surface's
    parameter units. Non-finite input gives CELL_MIXED.
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
    ru, rw = int(fine[k]), int(fine[k + 1])
    a = min(max(int(math.floor((x - i) * ru)), 0), ru - 1)
    b = min(max(int(math.floor((y - j) * rw)), 0), rw - 1)
    return int(fine[k + 2 + a * rw + b])
