"""What every guide plane of one finishing job shares, built once: faces, edges, guards.

:class:`PassSetup` holds the selected faces, their boundary edges sampled for R'
(:class:`~cadcnc.ops.finish.crossings.FaceEdges`) and one third-face guard per selected
face; :func:`pass_setup` caches it per part (weakly), faces and tool, so that the planes
of one operation share it. :func:`guide_face` is a plane as the interpolator's second
surface. Lengths mm.
"""

from __future__ import annotations

from itertools import product
from typing import Sequence

import numpy as np

from ...core.errors import InputError
from ...core.job import Job
from ...geometry.face_surface import FaceSurface
from ...geometry.guide_plane import plane_surface
from ...geometry.part import Part
from ...guard import FINISH_OWN_SHARE, guard_for
from .crossings import FaceEdges

GUIDE_MARGIN = 10.0  # mm beyond the part's bounding box: the guide face's half size


class PassSetup:
    """What every plane of one finishing job shares: the selected faces, their boundary
    edges sampled for R' (:class:`~cadcnc.ops.finish.crossings.FaceEdges`) and one guard
    per face (``guard(face)``: that face followed, every other face a third face)."""

    def __init__(self, part: Part, faces: Sequence[int], job: Job, guarded: bool = True):
        self.part, self.job = part, job
        self.faces = tuple(dict.fromkeys(int(f) for f in faces))
        if not self.faces:
            raise InputError("a finishing pass needs at least one face")
        self.surfaces = {f: part.face(f) for f in self.faces}
        self.edges = {f: FaceEdges(part, s, job.tool.offset)
                      for f, s in self.surfaces.items()}
        self._guards = {f: guard_for(part, (f,), job, own_share=FINISH_OWN_SHARE)
                        for f in self.faces} if guarded else {}
        self.box = part.bounding_box()

    def guide_size(self, plane) -> float:
        """The half size (mm) of ``plane``'s guide square (:func:`guide_half_size`)."""
        return guide_half_size(plane, *self.box)

    def guard(self, face: int):
        """The guard of cuts on ``face`` (None when the setup is unguarded)."""
        return self._guards.get(face)


def pass_setup(part: Part, faces: Sequence[int], job: Job) -> PassSetup:
    """The :class:`PassSetup` of ``part``, ``faces`` and the job's tool, built once."""
    key = (tuple(dict.fromkeys(int(f) for f in faces)), job.tool, job.tolerances)
    per_part = part.derived.setdefault(__name__, {})   # kept with the part
    if key not in per_part:
        per_part[key] = PassSetup(part, faces, job)
    return per_part[key]


def guide_half_size(plane, lo: np.ndarray, hi: np.ndarray) -> float:
    """Half size (mm) of ``plane``'s guide square (:func:`guide_face`, centred on the
    plane's point nearest the origin) holding the part's bounding box ``lo``, ``hi`` (3,)
    with GUIDE_MARGIN to spare: at least the box's diagonal, more for a part away from
    the origin (else its passes would leave the guide and stop short)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    corners = np.array(list(product(*zip(lo, hi))))
    reach = float(np.max(np.linalg.norm(corners - plane.offset * plane.normal, axis=1)))
    return max(float(np.linalg.norm(hi - lo)), reach) + GUIDE_MARGIN


def guide_face(plane, size: float, job: Job, whole: bool = False) -> FaceSurface:
    """The guide plane as a square face of half size ``size`` (mm), centred on the
    plane's point nearest the origin; u along the pass direction. ``whole``: for steppers
    that check no boundary (its trim grid not built: :attr:`FaceSurface.whole`)."""
    return plane_surface(plane.offset * plane.normal, plane.normal, plane.direction, size,
                         job.tolerances, whole)
