"""Steppers that re-run a program's cuts on the part, for the per-period stream.

:func:`stepper_factory` is the OCCT side of :func:`cadcnc.controller.stream.stream_program`:
for cut k it builds a fresh stepper on the same two surfaces (a pair's two faces, or a
finishing pass's face and its guide plane, vertical for a raster pass, horizontal for a
waterline loop, recovered from the cut's own points),
from the cut's first point and contact parameters, landing on its last point, at the
machine's period, without record, guard or boundary rule (the cut was checked when
computed, and the stream is gated again). A convex roll-over arc (a closed form, no
stepper) gets None: the stream interpolates its points.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..interp.compiled import new_stepper
from ..interp.stepper import Tangency
from .finish.loops import Level
from .finish.pass_setup import guide_face, guide_half_size
from .finish.passes import GuidePlane

END_REACHED = 1e-12  # mm
ROLLED = "rolled over"   # the stop detail of a convex roll-over arc (ops/finish/transitions.py)


def _tangency(path, k: int) -> Tangency:
    return Tangency(tuple(map(float, path.points[k])), tuple(map(float, path.uv[k, 0])),
                    tuple(map(float, path.uv[k, 1])))


def guide_plane_of(path) -> GuidePlane | None:
    """The vertical guide plane a finishing cut's centres lie on: the pass direction from
    the change of the plane's u parameter along the cut's chord (None if it has none)."""
    chord = path.points[-1] - path.points[0]
    du = float(path.uv[-1, 1, 0] - path.uv[0, 1, 0])
    flat = np.hypot(chord[0], chord[1])
    if flat < 1e-9 or abs(du) < 1e-9:   # mm, rad: no horizontal travel, no turn
        return None
    direction = chord[:2] / flat * math.copysign(1.0, du)
    angle = math.degrees(math.atan2(direction[1], direction[0]))
    normal = np.array([-direction[1], direction[0], 0.0])
    return GuidePlane(angle, float(path.points[0] @ normal))


LEVEL_TOL = 1e-6   # mm: a waterline cut's centres at one height (a landing ends within nm)


def level_of(path) -> Level | None:
    """The horizontal guide plane of a waterline cut (its centres at one height, the
    guide's parameters their x and y, as :func:`~.finish.loops.level_cuts` builds it),
    else None (a raster pass: :func:`guide_plane_of`)."""
    pts, guide = path.points, path.uv[:, 1]
    if np.ptp(pts[:, 2]) > LEVEL_TOL or np.abs(guide - pts[:, :2]).max() > LEVEL_TOL:
        return None
    return Level(float(pts[0, 2]))


def stepper_factory(part):
    """``steppers(cut_index, segment, period)`` for the cuts of programs on ``part``."""
    lo, hi = part.bounding_box()

    def steppers(k: int, segment, period: float):
        path = segment.path
        i, j = path.faces
        if path.stop_detail.startswith(ROLLED) or i is None:
            return None
        job = replace(path.job, period=period)
        s1 = part.face(i)
        if j is None:
            plane = level_of(path) or guide_plane_of(path)
            if plane is None:
                return None
            s2 = guide_face(plane, guide_half_size(plane, lo, hi), job,
                            whole=True)   # (check_boundary=False)
        else:
            s2 = part.face(j)
        start, end = _tangency(path, 0), _tangency(path, len(path) - 1)
        tangent = path.points[1] - path.points[0]
        # the stream lands on the end itself (not "reached" 0.1 um before it)
        tol = replace(job.tolerances, end_reached=END_REACHED)
        return new_stepper(s1, s2, job.offsets, start, feed=job.feed, period=period,
                       direction=tuple(map(float, tangent)), end=end, tol=tol,
                       max_cycles=10 ** 9, record=False, check_boundary=False)

    return steppers
