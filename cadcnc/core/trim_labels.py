"""Where a parameter point lies with respect to a trimmed face, and a trim grid's cell labels:
one spelling for every layer.

The geometry layer's classifier, the interpolator's boundary rule and verification's OCCT
classifier all answer with these three strings. The compiled reader of a trim grid is
:mod:`cadcnc.interp.kernel.trim_lookup`; these names need no compiler.
"""

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
SEGMENTS = -1.0
"""Marker (first word of a MIXED cell's block in ``fine``) of a segment list."""
SEGMENT_WORDS = 6  # per segment: p (2), q (2), half-widths (2)
