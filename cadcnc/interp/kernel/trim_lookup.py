"""O(1) trim check: one cell of a precomputed (u, w) label grid (see geometry/trim_grid.py).

The grid is an array of shape (nu, nw); cell (i, j) is the closed box
[u0 + i du, u0 + (i + 1) du] x [w0 + j dw, w0 + (j + 1) dw] in the face's parameters. A MIXED
cell may carry the segments of FClass2d's bands that meet it (answered by a clear move to a
labelled neighbour cell, ``resolve``) or sub-cells. Periodic parameters are first moved into
the grid's window with ``wrap`` (``TrimGrid.window`` gives start and period per direction).
A point beyond the grid is answered by the nearest border cell (the builder guarantees that
this is right). The functions are numba-compiled and live in the kernel-free
``cadcnc.trim``, so that the builder's ``TrimGrid.cell`` reads the grid with the same code.
"""

from __future__ import annotations

from ...trim import (CELL_INSIDE, CELL_MIXED, CELL_OUTSIDE, SEGMENTS,  # noqa: F401
                     lookup, resolve, wrap)
