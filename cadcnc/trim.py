"""Where a parameter point lies with respect to a trimmed face: one spelling for every layer.

The geometry layer's classifier, the interpolator's boundary rule and verification's OCCT
classifier all answer with these three strings.
"""

INSIDE = "inside"
BOUNDARY = "boundary"
OUTSIDE = "outside"
TRIM_STATES = (INSIDE, BOUNDARY, OUTSIDE)

# Cell labels of a trim grid (cadcnc.geometry.trim_grid builds it, the compiled kernel's
# cadcnc.interp.kernel.trim_lookup reads it): small ints, stored as an int8 array.
CELL_OUTSIDE = 0
"""The whole cell is outside the trimmed face (the exact classifier says OUT everywhere)."""
CELL_INSIDE = 1
"""The whole cell is inside the trimmed face (the exact classifier says IN everywhere)."""
CELL_MIXED = 2
"""Near the trim boundary: ask the exact classifier."""
