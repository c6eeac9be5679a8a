"""O(1) trim check: one cell of a precomputed (u, w) label grid (see geometry/trim_grid.py).

The grid is an int8 array of shape (nu, nw); cell (i, j) is the closed box
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


def lookup(grid: np.ndarray, u0: float, w0: float, du: float, dw: float, nu: int, nw: int,
           u: float, w: float) -> int:
    """The label (CELL_*) of the cell holding (u, w), periodic parameters already wrapped.

    ``grid`` is (nu, nw) int8; u0, w0 the grid's lower corner and du, dw its cell sizes, in
    the surface's parameter units. Non-finite input gives CELL_MIXED.
    """
    x = (u - u0) / du
    y = (w - w0) / dw
    if not (abs(x) < _FAR and abs(y) < _FAR):
        return CELL_MIXED
    i = min(max(int(math.floor(x)), 0), nu - 1)
    j = min(max(int(math.floor(y)), 0), nw - 1)
    return int(grid[i, j])
