"""A shared edge walked by arc length: point and unit tangent at s mm from its start.

The stretch finder anchors its tangency samples on planes normal to a shared concave
edge; it needs points at even spacing along the edge and a little beyond its ends
(where the offset curve may still be feasible), so past the ends the edge is continued
along its end tangents. Distances in mm, along the edge's own direction.
"""

from __future__ import annotations

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.GCPnts import GCPnts_AbscissaPoint
from OCP.gp import gp_Pnt, gp_Vec


class EdgeCurve:
    """Arc-length access to a :class:`~cadcnc.geometry.part.SharedEdge`'s curve."""

    def __init__(self, shared_edge):
        self.curve = BRepAdaptor_Curve(shared_edge.edge)
        self.t0, self.t1 = self.curve.FirstParameter(), self.curve.LastParameter()
        self.length = float(GCPnts_AbscissaPoint.Length_s(self.curve))
        self.closed = bool(shared_edge.closed)

    def _at_param(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        p, v = gp_Pnt(), gp_Vec()
        self.curve.D1(t, p, v)
        d = np.array(v.Coord())
        return np.array(p.Coord()), d / np.linalg.norm(d)

    def param(self, s: float) -> float:
        """The curve parameter at arc length s (0 <= s <= length), mm."""
        if s <= 0.0:
            return self.t0
        if s >= self.length:
            return self.t1
        return GCPnts_AbscissaPoint(self.curve, s, self.t0).Parameter()

    def point_tangent(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """(point (3,), unit tangent (3,)) at arc length s; beyond the ends of an open edge,
        the end point moved along its tangent (a closed edge wraps around)."""
        if self.closed:
            s = s % self.length
        elif s < 0.0 or s > self.length:
            end = 0.0 if s < 0.0 else self.length
            p, d = self._at_param(self.param(end))
            return p + (s - end) * d, d
        return self._at_param(self.param(s))
