"""An independent reference for a segment's distance to a trimmed face: OCCT's
point-to-face distances at points along it, the best refined by golden section."""

from __future__ import annotations

import math

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def point_distance(face, p) -> float:
    """OCCT's distance (mm) from point ``p`` to the TopoDS face ``face``."""
    ext = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, p))).Vertex(),
                                     face)
    assert ext.IsDone()
    return ext.Value()


def sampled_segment_distance(face, a, b, n: int = 201) -> float:
    """The least of ``point_distance`` over ``n`` points of the segment a-b (mm), each of
    the three best refined by golden section over its neighbours' interval to 1e-10 of
    the segment."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    s = np.linspace(0.0, 1.0, n)
    f = lambda x: point_distance(face, a + x * (b - a))   # noqa: E731
    d = np.array([f(x) for x in s])
    best = float(d.min())
    for k in np.argsort(d)[:3].tolist():
        lo, hi = s[max(k - 1, 0)], s[min(k + 1, n - 1)]
        c, e = hi - GOLDEN * (hi - lo), lo + GOLDEN * (hi - lo)
        fc, fe = f(c), f(e)
        while hi - lo > 1e-10:
            if fc < fe:
                hi, e, fe = e, c, fc
                c = hi - GOLDEN * (hi - lo)
                fc = f(c)
            else:
                lo, c, fc = c, e, fe
                e = lo + GOLDEN * (hi - lo)
                fe = f(e)
        best = min(best, fc, fe)
    return best
