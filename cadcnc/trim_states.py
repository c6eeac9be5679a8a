"""Where a parameter point lies with respect to a trimmed face, and a trim grid's cell
labels: plain constants (no numba), so that reading a part needs no compiler.
:mod:`cadcnc.trim` re-exports them beside the grid's compiled reader."""

INSIDE = "inside"
BOUNDARY = "boundary"
OUTSIDE = "outside"
TRIM_STATES = (INSIDE, BOUNDARY, OUTSIDE)

# Cell labels of a trim grid (cadcnc.geometry.trim_grid builds it, ``lookup`` below reads
# it for the compiled kernel and for TrimGrid.cell): small ints, stored as an int8 array.
CELL_OUTSIDE = 0
"""The whole cell is outside the trimmed face (the exact classifier says OUT everywhere)."""
CELL_INSIDE = 1
"""The whole cell is inside the trimmed face (the exact classifier says IN everywhere)."""
CELL_MIXED = 2
"""Near the trim boundary: ask the exact classifier."""
