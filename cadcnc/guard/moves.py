"""How close a straight move of the tool comes to a part: the swept ball and shank.

The tool is every point within R' of its axis segment, from the ball centre c up to
c + L z (L the shank length, 0 for a ball alone; the shank has the ball's radius, as
for :mod:`.clearance`). Moving c straight from a to b sweeps every point within R' of
the parallelogram a, b, b + L z, a + L z, so the move is clear of the part exactly when
the OCCT distance from that parallelogram (a segment when L = 0 or the move is vertical)
to the part's faces is at least R' - tol. Only faces whose boxes come within reach are
measured. Lengths mm.
"""

from __future__ import annotations

import math

import numpy as np
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakePolygon,
)
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt
from OCP.TopoDS import TopoDS_Compound

from .clearance import face_boxes

FLAT = 1e-9  # mm: a move this short horizontally sweeps a vertical segment


class MoveClearance:
    """Distances from straight tool moves to the faces of ``part`` (boxes built once).

    ``offset`` R' and ``shank`` L (mm)."""

    def __init__(self, part, offset: float, shank: float):
        self.part, self.offset, self.shank = part, float(offset), float(shank)
        self._topods = [f.topods for f in part.faces]
        self._lo, self._hi = face_boxes(part)   # shared with the part's guards

    def distance(self, a, b) -> float:
        """The distance (mm) from the tool axis swept from ``a`` to ``b`` ((3,) ball
        centres) to the nearest face within reach (inf when none comes within R' + 1)."""
        a, b = np.asarray(a, float), np.asarray(b, float)
        top = np.array([0.0, 0.0, self.shank])
        pts = np.array([a, b, b + top, a + top])
        reach = self.offset + 1.0
        lo, hi = pts.min(axis=0) - reach, pts.max(axis=0) + reach
        near = np.nonzero(((self._lo <= hi) & (self._hi >= lo)).all(axis=1))[0]
        if not len(near):
            return math.inf
        comp = TopoDS_Compound()
        builder = BRep_Builder()
        builder.MakeCompound(comp)
        for k in near:
            builder.Add(comp, self._topods[k])
        dist = BRepExtrema_DistShapeShape(_swept(a, b, self.shank), comp)
        if not dist.IsDone():
            return -math.inf  # fail closed: nothing is proven
        return float(dist.Value())

    def clear(self, a, b, tol: float) -> bool:
        """Whether the move a -> b keeps the tool at least R' - ``tol`` from the part."""
        return self.distance(a, b) >= self.offset - tol


def _swept(a: np.ndarray, b: np.ndarray, shank: float):
    """The axis segment swept from a to b: a parallelogram, or a segment."""
    if shank <= 0.0 or math.hypot(*(b[:2] - a[:2])) <= FLAT:
        lo, hi = (a, b) if shank <= 0.0 or a[2] <= b[2] else (b, a)
        hi = hi + np.array([0.0, 0.0, max(shank, 0.0)])
        if np.linalg.norm(hi - lo) <= FLAT:
            hi = lo + np.array([0.0, 0.0, FLAT])
        return BRepBuilderAPI_MakeEdge(gp_Pnt(*map(float, lo)), gp_Pnt(*map(float, hi))).Edge()
    poly = BRepBuilderAPI_MakePolygon()
    for p in (a, b, b + (0, 0, shank), a + (0, 0, shank)):
        poly.Add(gp_Pnt(*map(float, p)))
    poly.Close()
    return BRepBuilderAPI_MakeFace(poly.Wire(), True).Face()
