"""Closed-form distances from a point, and from a vertical segment, to analytic faces.

Used by the clearance guard (:mod:`.clearance`) so that OCCT's BRepExtrema is needed
only where no closed form applies. For a plane, cylinder or sphere (and a torus for the
point distance) the nearest point of the whole, untrimmed surface is found in closed
form; the face is a subset of that surface, so when that foot lies strictly inside the
trimmed face (the face's 2-D classifier says IN) the distance to the face equals the
distance to the surface. Otherwise (a foot outside the face or on its boundary, another
kind of surface, a degenerate configuration) the functions return None and the caller
falls back to OCCT. Lengths mm; points are 3-tuples of floats.
"""

from __future__ import annotations

import math

import numpy as np
from OCP.gp import gp_Pnt2d
from OCP.TopAbs import TopAbs_IN

from ..geometry.torus_segment import Torus, core_distances, crossings
from ..interp.vec3 import axpy, dot, norm, sub

EPS = 1e-12   # relative: below this a direction or radius is degenerate
SAMPLE_STEP = 0.01   # mm: a torus's nearest segment point sampled this finely where its
                     # quartic degenerates (the segment meets the axis)


class AnalyticFace:
    """The closed-form data of one face: kind, frame (origin o, axes x, y, z), radii."""

    def __init__(self, face):
        self.face = face
        self.kind = None
        s = face._adaptor
        getter = {"plane": s.Plane, "cylinder": s.Cylinder, "sphere": s.Sphere,
                  "torus": s.Torus}.get(face.kind)
        if getter is None:
            return
        g = getter()
        pos = g.Position()
        self.o = _xyz(pos.Location())
        self.x, self.y, self.z = (_xyz(pos.XDirection()), _xyz(pos.YDirection()),
                                  _xyz(pos.Direction()))
        self.r = g.Radius() if face.kind in ("cylinder", "sphere") else 0.0
        if face.kind == "torus":
            self.r_major, self.r = g.MajorRadius(), g.MinorRadius()
            if self.r >= self.r_major:     # a horn or spindle torus: no simple foot
                return
            self._torus = Torus(self.o, self.z, self.r_major, self.r)
            self._core_key: tuple | None = None
            self._core = None
        self.kind = face.kind
        self._uv = gp_Pnt2d()

    # -- the foot's parameters and the trim ------------------------------------------------
    def _inside(self, q) -> bool:
        """Whether surface point q lies strictly inside the trimmed face."""
        w = sub(q, self.o)
        lx, ly, lz = dot(w, self.x), dot(w, self.y), dot(w, self.z)
        if self.kind == "plane":
            u, v = lx, ly
        elif self.kind == "cylinder":
            u, v = math.atan2(ly, lx), lz
        elif self.kind == "sphere":
            u = math.atan2(ly, lx)
            v = math.atan2(lz, math.hypot(lx, ly))
        else:  # torus
            u = math.atan2(ly, lx)
            v = math.atan2(lz, math.hypot(lx, ly) - self.r_major)
        f = self.face
        if f._classifier is None:
            f.classify(*f.wrap(u, v))          # builds the classifier once
        self._uv.SetCoord(*f.wrap(u, v))
        return f._classifier.Perform(self._uv) == TopAbs_IN

    # -- point -------------------------------------------------------------------------
    def point_distance(self, p, trimmed: bool = True) -> float | None:
        """Distance (mm) from p to the face, or None where no closed form applies;
        ``trimmed=False``: to the whole surface (a lower bound of the face's)."""
        if self.kind is None:
            return None
        foot_d = self._surface_foot(p)
        if foot_d is None:
            return None
        foot, d = foot_d
        return d if not trimmed or self._inside(foot) else None

    def _surface_foot(self, p):
        """(nearest point of the untrimmed surface, distance) or None when not unique."""
        w = sub(p, self.o)
        if self.kind == "plane":
            h = dot(w, self.z)
            return axpy(-h, self.z, p), abs(h)
        if self.kind == "sphere":
            n = norm(w)
            if n < EPS * max(self.r, 1.0):
                return None
            return axpy(self.r / n, w, self.o), abs(n - self.r)
        a = dot(w, self.z)
        radial = axpy(-a, self.z, w)          # w minus its axial part
        rho = norm(radial)
        if rho < EPS * max(self.r, 1.0):
            return None
        if self.kind == "cylinder":
            foot = axpy(self.r / rho, radial, axpy(a, self.z, self.o))
            return foot, abs(rho - self.r)
        # torus: the tube circle's centre in the meridian plane of p, then a sphere
        c = axpy(self.r_major / rho, radial, self.o)
        t = sub(p, c)
        n = norm(t)
        if n < EPS * max(self.r, 1.0):
            return None
        return axpy(self.r / n, t, c), abs(n - self.r)

    # -- vertical segment ----------------------------------------------------------------
    def segment_distance(self, p, length: float, trimmed: bool = True) -> float | None:
        """Distance (mm) from the segment p .. p + length z (global z) to the face, or None
        (``trimmed=False``: to the whole surface, a lower bound; a torus's too).

        Plane, cylinder and sphere: along the segment the signed plane height is linear
        and the squared distance to the axis or centre is a convex quadratic in s, so the
        nearest segment point is an end, the quadratic's vertex, or a crossing of the
        surface (distance 0); the foot of that point decides.
        """
        if self.kind == "torus" and not trimmed:
            return self.segment_lower_bound(p, length)
        if self.kind not in ("plane", "cylinder", "sphere"):
            return None
        if self.kind == "plane":
            h0 = dot(sub(p, self.o), self.z)
            h1 = h0 + length * self.z[2]
            if h0 * h1 <= 0.0 and h0 != h1:
                s = -h0 / self.z[2]
                q = (p[0], p[1], p[2] + s)
                return 0.0 if not trimmed or self._inside(q) else None
            s = 0.0 if abs(h0) < abs(h1) else length
            return self.point_distance((p[0], p[1], p[2] + s), trimmed)
        # squared distance to the axis (cylinder) or centre (sphere): A s^2 + 2 B s + C
        w0 = sub(p, self.o)
        if self.kind == "cylinder":
            w0 = axpy(-dot(w0, self.z), self.z, w0)
            e = axpy(-self.z[2], self.z, (0.0, 0.0, 1.0))
        else:
            e = (0.0, 0.0, 1.0)
        qa, qb, qc = dot(e, e), dot(w0, e), dot(w0, w0)
        r2 = self.r * self.r
        f0, f1 = qc, qa * length * length + 2.0 * qb * length + qc
        s_min = min(max(-qb / qa, 0.0), length) if qa > EPS else 0.0
        fmin = qa * s_min * s_min + 2.0 * qb * s_min + qc
        fmax = max(f0, f1)
        if fmin <= r2 <= fmax:                 # the segment crosses the surface
            disc = qb * qb - qa * (qc - r2)
            if qa <= EPS or disc < 0.0:
                return None
            for s in ((-qb - math.sqrt(disc)) / qa, (-qb + math.sqrt(disc)) / qa):
                if 0.0 <= s <= length and (not trimmed or self._inside((p[0], p[1], p[2] + s))):
                    return 0.0
            return None
        # a tie (several nearest segment points) is fine: any global minimiser whose foot
        # is inside the face gives the face's distance
        if fmin > r2:                          # wholly outside: the vertex or an end
            return self.point_distance((p[0], p[1], p[2] + s_min), trimmed)
        return self.point_distance((p[0], p[1], p[2] + (0.0 if f0 >= f1 else length)), trimmed)


    def segment_lower_bound(self, p, length: float) -> float | None:
        """A lower bound (mm) of the distance from the segment p .. p + length z to a
        torus face: the distance to the whole torus, min over s of |g(s) - r| with g the
        distance to the tube's core circle; None for other kinds or near the axis.

        g^2 = q - 2 R rho + R^2 (q: squared distance to the centre, rho: to the axis,
        both quadratics in s under the square); its critical points solve
        (s + b)^2 rho^2(s) = R^2 (A s + B)^2, a quartic, so g's range over [0, length]
        is the range of its values at the quartic's real roots and at both ends (numpy's
        companion-matrix roots, polished by Newton).
        """
        got = self._core_distances(p, length)
        if got is None:
            return None
        lo, hi = min(got[1]), max(got[1])
        if lo <= self.r <= hi:
            return 0.0
        return lo - self.r if lo > self.r else self.r - hi

    def segment_nearest(self, p, length: float) -> float | None:
        """The s in [0, length] (mm) where the segment p .. p + length z comes nearest the
        whole torus (where it crosses it, a crossing to 1e-9 mm), from the candidates of
        :meth:`segment_lower_bound`; None for other kinds or near the axis. The face's
        distance there bounds the segment's from above: a second opinion where OCCT's
        curve-to-surface extrema misses the minimum (docs/notes/guard-calls.md)."""
        got = self._core_distances(p, length)
        if got is None:
            return self._sampled_nearest(p, length) if self.kind == "torus" else None
        cands, gs, g = got
        first = crossings(self._torus, cands, gs, g, first=True)
        if first:
            return first[0]
        return cands[min(range(len(cands)), key=lambda i: abs(gs[i] - self.r))]

    def segment_interior(self, p, length: float) -> list[float] | None:
        """The distances (mm) from the segment p .. p + length z to a torus face at the
        segment's points where its distance to the whole torus is locally least (both ends,
        the quartic's critical points, the crossings) whose foot lies strictly inside the
        face: every nearest pair of the segment and the face's interior is one of them (a
        torus has one local foot per point off its axis and core). None for other kinds,
        near the axis, or where a foot is not unique: the caller asks OCCT."""
        got = self._core_distances(p, length)
        if got is None:
            return None
        cands, gs, g = got
        out = []
        for s in cands + crossings(self._torus, cands, gs, g):
            foot_d = self._surface_foot((p[0], p[1], p[2] + s))
            if foot_d is None:
                return None
            if self._inside(foot_d[0]):
                out.append(foot_d[1])
        return out

    def _sampled_nearest(self, p, length: float) -> float:
        """Where the segment meets the torus's axis (its quartic degenerates there): the
        s of the least |g - r| over points SAMPLE_STEP mm apart (an upper bound's place,
        enough for a second opinion that only lowers a distance)."""
        s = np.linspace(0.0, length, max(int(math.ceil(length / SAMPLE_STEP)), 1) + 1)
        w = np.stack([p[0] - self.o[0] + 0.0 * s, p[1] - self.o[1] + 0.0 * s,
                      p[2] - self.o[2] + s], axis=1)
        ax = w @ np.asarray(self.z)
        rho = np.linalg.norm(w - np.outer(ax, self.z), axis=1)
        return float(s[int(np.argmin(np.abs(np.hypot(rho - self.r_major, ax) - self.r)))])

    def _core_distances(self, p, length: float) -> tuple[list, list, object] | None:
        """(candidates s, g at each, g) of the vertical segment on a torus
        (:func:`~cadcnc.geometry.torus_segment.core_distances`); None for other kinds or
        where the segment meets the axis."""
        if self.kind != "torus":
            return None
        key = (p[0], p[1], p[2], length)   # the guard asks twice at a centre: the bound,
        if key != self._core_key:           # then the shank's nearest point
            self._core_key, self._core = key, core_distances(self._torus, p, length)
        return self._core


def _xyz(v) -> tuple[float, float, float]:
    return (v.X(), v.Y(), v.Z())
