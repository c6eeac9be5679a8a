"""Named tolerances, in one place. Lengths in mm, angles in radians unless the name says deg."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Tolerances:
    """Thresholds used across cadcnc. Pass a modified copy (``dataclasses.replace``) to change one.

    - ``singular``: |r_u x r_w| / (|r_u| |r_w|) below this is a singular parameter point
      (sphere pole, cone apex, collapsed B-spline edge): no normal exists there.
    - ``flat_curvature`` (1/mm): |k| below this is treated as zero curvature; the curvature
      sphere degenerates to the offset tangent plane.
    - ``tangent_sin``: |n1 x n2| below this means the two faces are tangent, the
      intersection direction is undefined (sin of ~0.57 deg).
    - ``tangent_edge_deg``: a dihedral angle within this of 180 deg classifies an edge
      sample as tangent/smooth.
    - ``start`` (mm): the initial tangency is solved to this residual.
    - ``on_boundary`` (mm): a contact within this of the trimmed face's boundary is on it
      (converted to (u, w) with the surface's resolution). With radius 0 the contacts run
      along the boundary itself, so this must exceed the interpolation error there.
    - ``end_reached`` (mm): a full step that lands this close to the end point (either
      side) has reached it; no extra zero-length step is emitted.
    - ``near_singular``: the interpolator stops (reason "singular") when a contact's
      |r_u x r_w| / (|r_u|^2 + |r_w|^2) falls below this: the 2x2 inverse is ill-posed there.
    - ``diverged`` (mm): the carried error |p - (q + R' n)| above which the interpolator
      stops rather than emit a point computed from a lost state.
    """

    singular: float = 1e-9
    flat_curvature: float = 1e-9
    tangent_sin: float = 1e-2
    tangent_edge_deg: float = 1.0
    start: float = 1e-9
    on_boundary: float = 1e-6
    end_reached: float = 1e-7
    near_singular: float = 1e-4
    diverged: float = 0.5


DEFAULT = Tolerances()
