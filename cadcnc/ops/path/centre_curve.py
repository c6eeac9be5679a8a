"""The centre curve of a stretch, as the polyline of its tangencies' centres (mm)."""

from __future__ import annotations

import numpy as np

from ...interp.stepper import Tangency

MIN_APART = 1e-7   # mm: centres nearer than this give no direction


def polyline_length(tangencies: list[Tangency]) -> float:
    """Length of the polyline through the tangencies' centres, mm."""
    pts = np.array([t.p for t in tangencies])
    return float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())


def travel_direction(pts: list[Tangency], fallback) -> tuple[float, float, float]:
    """The cut's sense at its start: the unit vector from the first centre of ``pts`` to
    the next one apart from it (mm), else ``fallback`` (the edge's tangent). The centre
    curve can run against the edge's own direction (where the edge turns tighter than
    the ball's offset), so the edge's tangent alone may point the cut off its stretch."""
    p0 = np.asarray(pts[0].p, dtype=float)
    for t in pts[1:]:
        d = np.asarray(t.p, dtype=float) - p0
        n = float(np.linalg.norm(d))
        if n > MIN_APART:
            return tuple(float(v) for v in d / n)
    return tuple(map(float, fallback))
