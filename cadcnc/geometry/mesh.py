"""Triangle meshes of faces and shapes, for pictures only (never for toolpath geometry)."""

from __future__ import annotations

import numpy as np


def tessellate(topods, tolerance: float = 0.05, angular: float = 0.2):
    """(vertices (n, 3) mm, triangles (m, 3) int) of a face or shape, via CadQuery.

    ``tolerance`` (mm) is the chordal deflection, ``angular`` (rad) the angular one.
    """
    import cadquery as cq  # ~2.3 s to import: only pictures need it

    verts, tris = cq.Shape.cast(topods).tessellate(tolerance, angular)
    v = np.array([x.toTuple() for x in verts], dtype=float).reshape(-1, 3)
    return v, np.array(tris, dtype=int).reshape(-1, 3)
