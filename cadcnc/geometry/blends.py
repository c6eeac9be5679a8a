"""Blend faces of a part: fillets and rolling-ball blends found by their curvature.

A face is a *concave blend* of radius r when, at every sample of a grid over its
parameter box, its largest principal curvature is concave, k_max ~ 1/r > 0 (curvature
sign of docs/method.md: k > 0 bends towards the cutter), the spread of 1/k_max
over the samples is within ``RADIUS_SPREAD`` of r, and its tangent *rails* reach two
faces or more: edges running along the blend's spine (across the cross-section, whose
direction is the k_max principal direction; a hole's wall in two halves is no blend). Tangent edges along the cross-section are its
*ends*. Convex rounds (k_min ~ -1/r) are found the same way so that their tangent rails
are not mistaken for corners. Planes are never blends. Lengths mm, curvatures 1/mm.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.errors import GeometryError
from .part import TANGENT, Part, SharedEdge

GRID = 5                # samples per parameter direction (GRID x GRID over the face's box)
INSET = 0.1             # fraction of the box left out at each side (trims, poles)
RADIUS_SPREAD = 0.1     # (r_max - r_min) / r_max of a blend (variable blends up to 10 %)
RAIL_COS = 0.5          # |edge tangent . cross-section direction| below this: a rail


@dataclass
class Blend:
    """A blend face: its number, radius range (mm), concave or convex, rails and ends.

    ``rails`` / ``ends``: (neighbour face, shared edge) of the tangent edges along the
    spine / along the cross-section.
    """

    face: int
    r_min: float
    r_max: float
    concave: bool
    rails: list[tuple[int, SharedEdge]] = field(default_factory=list)
    ends: list[tuple[int, SharedEdge]] = field(default_factory=list)

    @property
    def umbilic(self) -> bool:
        """A vertex blend (sphere-like, no spine): rails and ends are not told apart."""
        return not self.rails and len(self.ends) >= 3


def face_curvatures(part: Part, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(k_max (m,), k_min (m,)) at the GRID x GRID samples of face n.

    Samples where no normal exists (poles) are left out; 1/mm.
    """
    s = part.face(n)
    (u0, u1), (w0, w1) = s.u_range, s.w_range
    fr = INSET + (1 - 2 * INSET) * np.arange(GRID) / (GRID - 1)
    kmax, kmin = [], []
    for u in u0 + (u1 - u0) * fr:
        for w in w0 + (w1 - w0) * fr:
            try:
                pc = s.principal_curvatures(float(u), float(w))
            except GeometryError:
                continue
            kmax.append(pc.k_max)
            kmin.append(pc.k_min)
    return np.array(kmax), np.array(kmin)


def _radius_range(k: np.ndarray, flat: float) -> tuple[float, float] | None:
    """(r_min, r_max) of curvatures k (all of one sign, beyond ``flat``), else None."""
    if len(k) == 0 or not (np.all(k > flat) or np.all(k < -flat)):
        return None
    r = 1.0 / np.abs(k)
    lo, hi = float(r.min()), float(r.max())
    return (lo, hi) if hi - lo <= RADIUS_SPREAD * hi else None


def _cross_direction(part: Part, n: int, point: np.ndarray, concave: bool) -> np.ndarray:
    """Unit cross-section direction of blend face n near ``point`` (k_max for concave)."""
    s = part.face(n)
    u, w, _ = s.project(point)
    pc = s.principal_curvatures(u, w)
    return pc.d_max if concave else pc.d_min


def find_blend(part: Part, n: int, kmax: np.ndarray, kmin: np.ndarray) -> Blend | None:
    """Face n as a :class:`Blend` from its sampled curvatures, or None when it is not one."""
    if part.face(n).kind == "plane":
        return None
    flat = part.tol.flat_curvature
    # the cross-section is the tighter way: concave when |k_max| dominates, else convex
    is_concave = len(kmax) > 0 and np.abs(kmax).mean() >= np.abs(kmin).mean()
    rng = _radius_range(kmax if is_concave else kmin, 1e3 * flat)
    if rng is None:
        return None
    blend = Blend(n, rng[0], rng[1], bool(is_concave))
    umbilic = np.allclose(kmax, kmin, rtol=RADIUS_SPREAD, atol=0.0)
    for m, edges in part.neighbours(n).items():
        for e in edges:
            if e.edge_class != TANGENT:
                continue
            if umbilic:
                blend.ends.append((m, e))
                continue
            k = len(e.points) // 2
            tangent = e.points[min(k + 1, len(e.points) - 1)] - e.points[max(k - 1, 0)]
            tangent /= np.linalg.norm(tangent) + 1e-300   # no 0 / 0 (a zero chord)
            try:
                cross = _cross_direction(part, n, e.points[k], blend.concave)
            except GeometryError:
                continue
            (blend.rails if abs(tangent @ cross) < RAIL_COS else blend.ends).append((m, e))
    # a concave blend needs rails to two faces; a convex round one (its other side may be
    # a concave edge, as a rounded hole mouth) to one
    # (rails to one face only: half of a hole split in two, not a blend)
    if len({m for m, _ in blend.rails}) < (2 if blend.concave else 1) and not blend.umbilic:
        return None
    return blend


def find_blends(part: Part) -> tuple[dict[int, Blend], dict[int, tuple[float, float]]]:
    """({face: Blend} of every blend face, {face: (k_max min, k_max max)} of curved faces).

    The second map (1/mm) tells where a ball of offset R' cannot touch a face at all:
    min k_max R' >= 1 (the face is tighter than the ball everywhere sampled).
    """
    blends, kranges = {}, {}
    for n in range(1, len(part) + 1):
        if part.face(n).kind == "plane":
            continue
        kmax, kmin = face_curvatures(part, n)
        if len(kmax):
            kranges[n] = (float(kmax.min()), float(kmax.max()))
        blend = find_blend(part, n, kmax, kmin)
        if blend is not None:
            blends[n] = blend
    return blends, kranges
