"""Where a parameter point lies with respect to a trimmed face: one spelling for every layer.

The geometry layer's classifier, the interpolator's boundary rule and verification's OCCT
classifier all answer with these three strings.
"""

INSIDE = "inside"
BOUNDARY = "boundary"
OUTSIDE = "outside"
TRIM_STATES = (INSIDE, BOUNDARY, OUTSIDE)
