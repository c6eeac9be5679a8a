"""The ball at every cutter centre against every face of the part (OCCT distances).

A face whose optimal bounding box, grown by the ball radius, misses a centre cannot touch
the ball there. Otherwise the exact point-to-face distance d is computed (signed only where
the nearest point lies inside the face); as d is 1-Lipschitz along the path, the next
d - R' - hit mm of travel cannot hit that face and are skipped without loss. The pair's own
faces reuse their per-face check. A distance OCCT cannot compute counts as a hit of
unknown (nan) depth, never as a miss. Lengths in mm.
"""

from __future__ import annotations

import numpy as np

from ..tolerances import Tolerances
from .probe import FaceProbe
from .records import SurfaceCheck, WholePartCheck, WholePartHit, cycle_ranges


def check_whole_part(part, probes: dict[int, FaceProbe], toolpath,
                     surfaces: list[SurfaceCheck], ball: float, tol: Tolerances,
                     progress=None) -> WholePartCheck:
    """Every face of ``part`` against the ball of radius ``ball`` (R') at every centre.

    ``probes``: the pair's probes (others are made here); ``surfaces``: the pair's checks.
    A face is hit where the ball reaches deeper than ``tol.hit`` into it.
    """
    pts = toolpath.points
    travel = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    hits, evaluated = [], 0
    pair = {s.face: s for s in surfaces}
    for n in range(1, len(part) + 1):
        if progress:
            progress("whole part", n, len(part))
        if n in pair:
            s = pair[n]
            depth = ball - (s.face_deviation + s.offset)
            evaluated += len(pts)
        else:
            probe = probes.get(n) or FaceProbe(part.face(n).topods, tol)
            depth, count = _face_depths(probe, pts, travel, ball, tol.hit)
            evaluated += count
        hit = _hit(n, n in pair, depth, tol.hit)
        if hit is not None:
            hits.append(hit)
    return WholePartCheck(hits=hits, faces_checked=len(part), distances_evaluated=evaluated,
                          ball_radius_mm=ball, hit_tolerance_mm=tol.hit)


def _face_depths(probe: FaceProbe, pts: np.ndarray, travel: np.ndarray, ball: float,
                 hit_tol: float) -> tuple[np.ndarray, int]:
    """(N,) depth of the ball into one face (-inf where it cannot reach), distances used."""
    lo, hi = probe.bbox()
    near = np.all((pts >= lo - ball - hit_tol) & (pts <= hi + ball + hit_tol), axis=1)
    depth = np.full(len(pts), -np.inf)
    skip_until, evaluated = -np.inf, 0
    for k in np.nonzero(near)[0]:
        if travel[k] < skip_until:
            continue
        sd, _ = probe.face_distance(pts[k])
        evaluated += 1
        depth[k] = ball - sd
        if np.isfinite(sd):  # an unmeasured distance proves nothing about the next ones
            skip_until = travel[k] + (sd - ball - hit_tol)
    return depth, evaluated


def _hit(face: int, followed: bool, depth: np.ndarray, hit_tol: float) -> WholePartHit | None:
    """The face's hit record, or None when the ball stays within ``hit_tol`` of it."""
    unknown = np.isnan(depth)
    hit = np.nonzero((depth > hit_tol) | unknown)[0]
    if not len(hit):
        return None
    if unknown.any():
        worst, deep = int(np.argmax(unknown)), float("nan")
    else:
        worst = int(hit[np.argmax(depth[hit])])
        deep = float(depth[worst])
    return WholePartHit(face=face, followed=followed, depth_mm=deep, worst_cycle=worst,
                        n_cycles=len(hit), cycles=cycle_ranges(hit))
