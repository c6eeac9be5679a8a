"""Links between cuts: retract to a clearance height, rapid across, plunge at feed.

Heights are ball-centre Z in mm. A link from the end a of one cut to the start b of the
next is the polyline a -> (a.x, a.y, z_safe) -> (b.x, b.y, z_safe) -> (b.x, b.y, b.z +
approach) -> b: the retract and the move across are rapids, the last part a feed move at
the plunge feed (``approach`` mm above b, or all of the descent when z_safe is lower).
The program's first cut is reached the same way from above its start, and the last cut
leaves straight up to z_safe. Whether a link clears the part is decided by the gouge gate,
which checks every move of the program, links included.
"""

from __future__ import annotations

import numpy as np

from .program import CutSegment, LinkSegment

APPROACH = 2.0
"""mm above a cut's start where the rapid descent ends and the plunge at feed begins."""
JOINED = 1e-9
"""mm: a cut that starts where the previous one ended continues without a link."""


def _descent(xy: np.ndarray, z_from: float, z_to: float, approach: float):
    """Points and flags from (xy, z_from) down to (xy, z_to): rapid, then feed."""
    pts, rapid = [], []
    z_mid = z_to + approach
    if z_from > z_mid:
        pts.append((*xy, z_mid))
        rapid.append(True)
    pts.append((*xy, z_to))
    rapid.append(False)
    return pts, rapid


def link(a: np.ndarray, b: np.ndarray, z_safe: float, approach: float = APPROACH
         ) -> LinkSegment:
    """The link from point ``a`` (a cut's end) to ``b`` (the next cut's start), (3,) mm."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    top = max(z_safe, a[2], b[2])
    pts = [tuple(a)]
    rapid = []
    if top > a[2]:
        pts.append((a[0], a[1], top))
        rapid.append(True)
    if np.hypot(*(b[:2] - a[:2])) > 0.0:
        pts.append((b[0], b[1], top))
        rapid.append(True)
    down, flags = _descent(b[:2], top, b[2], approach)
    pts += down
    rapid += flags
    return LinkSegment(np.array(pts), np.array(rapid))


def approach(b: np.ndarray, z_safe: float, approach: float = APPROACH) -> LinkSegment:
    """From above ``b`` at z_safe down to b (rapid, then feed for the last ``approach``)."""
    b = np.asarray(b, dtype=float)
    top = max(z_safe, b[2] + approach)
    down, flags = _descent(b[:2], top, b[2], approach)
    return LinkSegment(np.array([(b[0], b[1], top), *down]), np.array(flags))


def retract(a: np.ndarray, z_safe: float) -> LinkSegment:
    """From ``a`` straight up to z_safe (a rapid)."""
    a = np.asarray(a, dtype=float)
    return LinkSegment(np.array([a, (a[0], a[1], max(z_safe, a[2]))]), np.array([True]))


def linked(cuts: list[CutSegment], z_safe: float, approach_mm: float = APPROACH) -> list:
    """``cuts`` in order with an approach before the first, a link between each two, and a
    retract after the last: the segments of a program."""
    if not cuts:
        return []
    out: list = [approach(cuts[0].points[0], z_safe, approach_mm)]
    for k, cut in enumerate(cuts):
        gap = np.linalg.norm(cut.points[0] - cuts[k - 1].points[-1]) if k else 0.0
        if gap > JOINED:
            out.append(link(cuts[k - 1].points[-1], cut.points[0], z_safe, approach_mm))
        out.append(cut)
    out.append(retract(cuts[-1].points[-1], z_safe))
    return out
