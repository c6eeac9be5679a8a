"""A trimmed face's boundary, for distances from points to it (OCCT's curve projections).

:class:`FaceEdges` keeps, per edge of a face, its box (``BRepBndLib::Add``), its ends and
an OCCT projector initialised once on its 3-D curve over its range: a projection per
point then reuses the curve's adaptor and sampling (the same answers as a projector made
for each point, ``GeomAPI_ProjectPointOnCurve(P, C, t0, t1)``, at about a third of its
cost). Lengths in mm.
"""

from __future__ import annotations

import math

from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Tool
from OCP.BRepBndLib import BRepBndLib
from OCP.GeomAbs import GeomAbs_Line
from OCP.GeomAdaptor import GeomAdaptor_Curve
from OCP.GeomAPI import GeomAPI_ProjectPointOnCurve
from OCP.gp import gp_Pnt
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS


class FaceEdges:
    """The non-degenerate edges of a face: per edge its box (x0, y0, z0, x1, y1, z1), its
    two ends, and a projector (None without a 3-D curve); whether every edge is straight."""

    def __init__(self, face):
        self._boxes: list[tuple] = []
        self._ends: list[tuple] = []
        self.projectors: list = []
        curves = []
        explorer = TopExp_Explorer(face, TopAbs_EDGE)
        while explorer.More():
            edge, box = TopoDS.Edge_s(explorer.Current()), Bnd_Box()
            BRepBndLib.Add_s(edge, box, False)
            if not box.IsVoid() and not BRep_Tool.Degenerated_s(edge):
                t0, t1 = BRep_Tool.Range_s(edge)
                curve = BRep_Tool.Curve_s(edge, t0, t1)
                self._boxes.append(box.Get())
                self._ends.append(() if curve is None
                                  else tuple(curve.Value(t).Coord() for t in (t0, t1)))
                self.projectors.append(_projector(curve, t0, t1))
                curves.append(curve)
            explorer.Next()
        self.straight = all(c is not None and GeomAdaptor_Curve(c).GetType() == GeomAbs_Line
                            for c in curves)
        self._pnt = gp_Pnt()

    def gap(self, point, enough: float = math.inf) -> float:
        """The distance from ``point`` to the boundary, or a lower bound of it that is at
        least ``enough``: edges in order of their box's distance; an edge nearer than
        ``enough`` and the best so far counts by OCCT's projection on its curve over its
        range and the distances to its ends (inf without edges). Plain floats: a face
        has a few edges, too few for numpy to pay."""
        x, y, z = (float(c) for c in point)
        lower = [math.sqrt(max(x0 - x, x - x1, 0.0) ** 2 + max(y0 - y, y - y1, 0.0) ** 2
                           + max(z0 - z, z - z1, 0.0) ** 2)
                 for x0, y0, z0, x1, y1, z1 in self._boxes]
        best = math.inf
        for i in sorted(range(len(lower)), key=lower.__getitem__):
            if lower[i] >= best:
                break
            projector = self.projectors[i]
            if lower[i] >= enough or projector is None:  # far enough, or no curve: its box
                best = min(best, lower[i])
                if lower[i] >= enough:
                    break
                continue
            self._pnt.SetCoord(x, y, z)
            projector.Perform(self._pnt)
            found = projector.LowerDistance() if projector.NbPoints() else math.inf
            best = min(best, found, *(math.dist((x, y, z), end) for end in self._ends[i]))
        return best


def _projector(curve, t0: float, t1: float):
    """OCCT's projector onto ``curve`` over [t0, t1], initialised once (None: no curve)."""
    if curve is None:
        return None
    projector = GeomAPI_ProjectPointOnCurve()
    projector.Init(curve, t0, t1)
    return projector
