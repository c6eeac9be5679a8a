"""Named tolerances, in one place. Lengths in mm, angles in radians unless the name says deg."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from .errors import InputError

STRETCH_TANGENT_MARGIN = 2.0
"""The stretch search's tangent limit over the interpolator's (``stretch_tangent_sin``)."""
STRETCH_LIMIT_SHARE = 0.1
"""The accuracy of a stretch limit over the gouge limit (``stretch_limit``)."""
STREAM_LIMIT_SLACK = 1e-6
"""Relative: a streamed position's finite-difference velocity, acceleration or jerk may
exceed the machine's limit by this share (round-off), not more
(:mod:`cadcnc.verification.stream_check`)."""
STREAM_END = 1e-9
"""mm: a stream's first and last positions lie this close to the program's first and last
points (the .txt's 9 decimals)."""
CONFUSION = 1e-7
"""mm: OCCT's ``Precision::Confusion()``, the precision given to OCCT where it asks for one
(building a face, projecting a point to (u, w)): points this close are one point to OCCT."""
VERTICAL = 1e-12
"""|1 - |d_z|| of a unit direction below this: the direction is vertical (round-off of a
unit vector's z; the guard's walls and shank rule, waterline's horizontal planes)."""
STREAM_BLEND = 10.0
"""mm: the stream's default ``--blend`` (a link's corners rounded within it where that
plans faster). Measured on the default machine (docs/controller.md): links rounded within
1 or 5 mm never planned faster there; within 10 to 20 mm the tall ones do."""


@dataclass(frozen=True)
class Tolerances:
    """Every threshold cadcnc uses. Pass a modified copy (``dataclasses.replace``) to change one.

    Geometry and interpolation:

    - ``singular``: the *singularity ratio* s = |r_u x r_w| / (|r_u|^2 + |r_w|^2) (0 at a
      singular point: sphere pole, cone apex, collapsed B-spline edge; 1/2 on a square
      parameter grid) below this means no normal exists at the point.
    - ``near_singular``: the interpolator stops (reason "singular") when a contact's
      singularity ratio falls below this: the 2x2 inverse is ill-posed there.
    - ``flat_curvature`` (1/mm): |k| below this is treated as zero curvature; the curvature
      sphere degenerates to the offset tangent plane.
    - ``tangent_sin``: |n1 x n2| below this means the two faces are tangent, the
      intersection direction is undefined (sin of ~0.57 deg).
    - ``stretch_tangent_sin`` (derived, not set): the stretch search's tangent rule: a
      corner position is feasible only where |n1 x n2| (at its exact contacts) is at least
      STRETCH_TANGENT_MARGIN (2) times ``tangent_sin``. Near tangency the interpolator's centre strays from the offset
      intersection curve along its ill-conditioned direction (by ~2 um at sin 0.01, still
      on both offset surfaces), so its own |n1 x n2| reads a few per cent off the exact
      value; the margin keeps a cut started at a tangent limit from stopping there.
    - ``stretch_limit`` (derived, not set): a stretch limit (where a corner's ball
      position turns infeasible) is located until the last feasible and the first
      infeasible centre are this close, and the feasible one kept: STRETCH_LIMIT_SHARE (a
      tenth) of ``gouge``, 1e-4 mm. A cut ends at most this short of the exact limit; the
      ball there is the exact limit's moved by at most this, so the material it leaves is
      at most this thick, a tenth of what the gate lets a program cut too deep and of
      the ``accuracy`` every point keeps, and a thousandth of the 0.1 mm step.
    - ``tangent_edge_deg``: a dihedral angle within this of 180 deg classifies an edge
      sample as tangent/smooth.
    - ``start`` (mm): the initial tangency is solved to this residual.
    - ``on_boundary`` (mm): a contact within this of the trimmed face's boundary is on it
      (converted to (u, w) with the surface's resolution). With radius 0 the contacts run
      along the boundary itself, so this must exceed the interpolation error there.
    - ``end_reached`` (mm): a full step that lands this close to the end point (either
      side) has reached it; no extra zero-length step is emitted.
    - ``diverged`` (mm): the carried error |p - (q + R' n)| above which the interpolator
      stops rather than emit a point computed from a lost state.
    - ``curvature_near`` (ratio): a step that loses track (carried error past
      ``diverged``) where R' k along the track is within this of 1 is stopped as the
      curvature limit, its true cause: there the contact moves 1 / (1 - R' k) times as
      fast as the centre and no step keeps it.
    - ``accuracy`` (mm): the accuracy a written path promises: every point within this of
      both offset surfaces, and the chord between points within it too.
    - ``closed`` (mm): a curve (edge, intersection branch, polyline) whose ends are closer
      than this is a loop.
    - ``sewing`` (mm): the faces of a surface model (no solid) are sewn at this tolerance:
      edges closer than it are merged (docs/notes/surface_models.md); the largest edge tolerance
      after sewing is reported.

    Verification and gates:

    - ``gouge`` (mm): the gouge limit: a ball reaching deeper than this into any face, at a
      cutter centre or anywhere along a straight move, fails the whole-part gate and
      ``cadcnc verify`` (1 um). Finite and > 0: no value switches the gate off.
    - ``hausdorff`` (mm): the largest Hausdorff distance ``cadcnc verify`` accepts between
      the path polyline and OCCT's intersection of the offset surfaces over the path's own
      span (chord sag included). 0.01 mm: ten times ``accuracy``; the fixtures measure
      1.2e-4 mm at the default step f = 0.1 mm and 3.1e-3 mm at f = 0.5 mm, while a path
      on the wrong part or with a skipped stretch is off by 0.02 mm or more; at f = 1 mm
      (0.0125 mm on bspline_boss) the chords are coarser than this promises.
    - ``coverage`` (fraction, <= 1): the least curve coverage ``cadcnc verify`` accepts:
      the fraction of OCCT's intersection curve, over the path's own span, within 0.6
      step of a cutter centre (1.0 on every fixture; one skipped step in 100 fails).
    - ``hit`` (mm): a ball reaching deeper than this into a face is reported as a hit
      (below it is tangency round-off).
    - ``off_face`` (mm): a contact whose trimmed-face distance exceeds its surface distance
      by more than this touches only the surface's extension (reported as off the face).
    - ``noise`` (mm): differences below this are round-off (start tangency solved to 1e-9,
      OCCT's intersection curve ~5e-9).
    - ``classify`` (mm): boundary tolerance of verification's 2-D face classifier.
    - ``classify_loose`` (mm): the looser classifier used to say where a stopped path's
      last contacts lie.
    - ``intersection`` (mm): the tolerance OCCT's GeomAPI_IntSS is given for the reference
      intersection of the offset surfaces.
    """

    singular: float = 1e-9
    near_singular: float = 1e-4
    flat_curvature: float = 1e-9
    tangent_sin: float = 1e-2
    tangent_edge_deg: float = 1.0
    start: float = 1e-9
    on_boundary: float = 1e-6
    end_reached: float = 1e-7
    diverged: float = 0.5
    curvature_near: float = 1e-3
    accuracy: float = 1e-3
    closed: float = 1e-6
    gouge: float = 1e-3
    hausdorff: float = 1e-2
    coverage: float = 0.99
    hit: float = 1e-6
    off_face: float = 1e-6
    noise: float = 1e-8
    classify: float = 1e-7
    classify_loose: float = 1e-4
    intersection: float = 1e-7
    sewing: float = 1e-2

    @property
    def stretch_tangent_sin(self) -> float:
        return STRETCH_TANGENT_MARGIN * self.tangent_sin

    @property
    def stretch_limit(self) -> float:
        return STRETCH_LIMIT_SHARE * self.gouge

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if not (isinstance(value, (int, float)) and not isinstance(value, bool)
                    and math.isfinite(value) and value > 0):
                raise InputError(f"tolerance {f.name} must be a finite number > 0, got "
                                 f"{value!r}")
            lo, hi = BOUNDS.get(f.name, (0.0, math.inf))
            if not lo <= value <= hi:
                raise InputError(f"tolerance {f.name} must lie in [{lo:g}, {hi:g}] (a looser "
                                 f"value would let the checks pass what they exist to refuse; "
                                 f"docs/reliability.md), got {value:g}")


BOUNDS: dict[str, tuple[float, float]] = {
    "gouge": (0.0, 0.1),
    "hit": (0.0, 1e-3),
    "hausdorff": (0.0, 0.1),
    "coverage": (0.5, 1.0),
    "off_face": (0.0, 1e-3),
    "noise": (0.0, 1e-5),
    "classify": (0.0, 1e-4),
    "classify_loose": (0.0, 1e-2),
    "intersection": (0.0, 1e-4),
    "sewing": (0.0, 0.1),
}
"""The allowed range of every tolerance that loosens a check (mm; ``coverage`` a fraction;
every tolerance is > 0 besides):
past these the checks would pass what they exist to refuse. docs/reliability.md has the
same table and the reasons; a test enforces each row."""
CHORD_TOLERANCE_MAX = 0.1
"""mm: the largest G-code chord tolerance (``--tolerance``, also G64 P's ceiling)."""


DEFAULT = Tolerances()
