"""Many points of a pcurve and of its face's surface in one compiled pass (trim-grid build).

FClass2d samples each edge's pcurve (2-D) and the curve on the surface (3-D) at about a
thousand parameters per face; one OCCT call per point from Python costs about 0.6 us, most
of a trim grid's build. These evaluate the same geometry in numba: B-spline (rational,
periodic) and line pcurves; plane, cylinder, cone, sphere, torus and B-spline surfaces,
in the surface's own frame (the face's location is a rigid motion: distances, the only
use of the 3-D points, are kept; a scaling location gives None). They agree with OCCT to
round-off (about 1e-15 relative), not bit for bit: ``trim_grid`` uses them where its rules
have a margin far above that, checks two points against OCCT, and falls back to OCCT's own
calls otherwise. Anything else gives None (the caller evaluates with OCCT).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from OCP.GeomAbs import (
    GeomAbs_BSplineCurve,
    GeomAbs_BSplineSurface,
    GeomAbs_Cone,
    GeomAbs_Cylinder,
    GeomAbs_Line,
    GeomAbs_Plane,
    GeomAbs_Sphere,
    GeomAbs_Torus,
)
from OCP.gp import gp_Trsf

from . import bspline_blob

_jit = numba.njit(cache=True, nogil=True)


def _values(seq) -> list:
    return [seq.Value(i) for i in range(seq.Lower(), seq.Upper() + 1)]


def _flat(sequence) -> np.ndarray:
    """A non-periodic B-spline's flat knot vector from its KnotSequence (one call)."""
    return np.array(_values(sequence), dtype=float)


@_jit
def basis(knots: np.ndarray, degree: int, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(span (n,) int, N (n, degree + 1)): the non-zero B-spline basis functions at each t
    (knots: the flat, non-periodic knot vector; t clamped into its range; The NURBS Book,
    A2.1 and A2.2)."""
    p, m = degree, len(knots)
    lo, hi = knots[p], knots[m - p - 1]
    span = np.empty(len(t), np.int64)
    out = np.zeros((len(t), p + 1))
    left, right = np.empty(p + 1), np.empty(p + 1)
    for k in range(len(t)):
        x = min(max(t[k], lo), hi)
        s = min(max(np.searchsorted(knots, x, side="right") - 1, p), m - p - 2)
        span[k] = s
        out[k, 0] = 1.0
        for j in range(1, p + 1):
            left[j] = x - knots[s + 1 - j]
            right[j] = knots[s + j] - x
            saved = 0.0
            for r in range(j):
                temp = out[k, r] / (right[r + 1] + left[j - r])
                out[k, r] = saved + right[r + 1] * temp
                saved = left[j - r] * temp
            out[k, j] = saved
    return span, out


def _wrap(t: np.ndarray, first: float, last: float, periodic: bool) -> np.ndarray:
    """Periodic parameters moved into [first, last); others unchanged (float64 copy)."""
    return first + np.mod(t - first, last - first) if periodic else np.array(t, dtype=float)


@_jit
def _curve_points(knots: np.ndarray, degree: int, poles: np.ndarray, weights: np.ndarray,
                  t: np.ndarray) -> np.ndarray:
    """(n, d) points of a B-spline curve with poles (m, d) and weights (m,) (empty: not
    rational) at parameters t (n,)."""
    span, n = basis(knots, degree, t)
    out = np.zeros((len(t), poles.shape[1]))
    for k in range(len(t)):
        w = 0.0
        for r in range(degree + 1):
            i = span[k] - degree + r
            b = n[k, r] * (weights[i] if weights.size else 1.0)
            w += b
            for d in range(poles.shape[1]):
                out[k, d] += b * poles[i, d]
        if weights.size:
            for d in range(poles.shape[1]):
                out[k, d] /= w
    return out


@_jit
def _patch_points(ku: np.ndarray, kv: np.ndarray, p: int, q: int, poles: np.ndarray,
                  weights: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(n, 3) points of a B-spline surface with poles (nu, nv, 3) and weights (nu, nv)
    (empty: not rational) at (u, v) (n,) each."""
    su, bu = basis(ku, p, u)
    sv, bv = basis(kv, q, v)
    out = np.zeros((len(u), 3))
    for k in range(len(u)):
        w = 0.0
        for a in range(p + 1):
            for b in range(q + 1):
                i, j = su[k] - p + a, sv[k] - q + b
                c = bu[k, a] * bv[k, b] * (weights[i, j] if weights.size else 1.0)
                w += c
                out[k, 0] += c * poles[i, j, 0]
                out[k, 1] += c * poles[i, j, 1]
                out[k, 2] += c * poles[i, j, 2]
        if weights.size:
            out[k] /= w
    return out


def pcurve_points(c2, t: np.ndarray) -> np.ndarray | None:
    """(n, 2) points of a BRepAdaptor_Curve2d at parameters t, or None if not supported."""
    kind = c2.GetType()
    if kind == GeomAbs_Line:
        line = c2.Line()
        (x, y), (dx, dy) = line.Location().Coord(), line.Direction().Coord()
        return np.column_stack([x + t * dx, y + t * dy])
    if kind != GeomAbs_BSplineCurve:
        return None
    bs = c2.BSpline()
    periodic = bs.IsPeriodic()
    first, last = bs.FirstParameter(), bs.LastParameter()
    if periodic:  # the same curve with flat, clamped knots (OCCT inserts them exactly)
        bs = bs.Copy()
        bs.SetNotPeriodic()
    read = bspline_blob.curve2d(bs)  # all numbers in one OCCT call; None: pole by pole
    if read is not None:
        poles, weights, knots, mults = read
        flat = np.repeat(knots, mults)  # bs is not periodic here: its KnotSequence
    else:
        poles = np.array([bs.Pole(i).Coord() for i in range(1, bs.NbPoles() + 1)])
        weights = (np.array([bs.Weight(i) for i in range(1, bs.NbPoles() + 1)])
                   if bs.IsRational() else np.zeros(0))
        flat = _flat(bs.KnotSequence())
    return _curve_points(flat, bs.Degree(), poles, weights, _wrap(t, first, last, periodic))


def _frame(ax3) -> tuple[np.ndarray, ...]:
    return tuple(np.array(v.Coord()) for v in (ax3.Location(), ax3.XDirection(),
                                                ax3.YDirection(), ax3.Direction()))


def surface_points(adaptor, uv: np.ndarray, data=None) -> np.ndarray | None:
    """(n, 3) points S(u, w) of a BRepAdaptor_Surface at uv (n, 2), in the surface's frame
    before the face's (rigid) location; None if not supported. ``data``: the face's
    SurfaceData (geometry/surface_data.py), whose B-spline poles are then not read again."""
    trsf: gp_Trsf = adaptor.Trsf()
    if abs(abs(trsf.ScaleFactor()) - 1.0) > 1e-15:   # a scale, not round-off of 1
        return None
    s, kind = adaptor.Surface(), adaptor.GetType()
    if data is not None and kind == GeomAbs_BSplineSurface and \
            data.kind == int(GeomAbs_BSplineSurface) and not any(data.ints[3:5]):
        p, q, rational = int(data.ints[1]), int(data.ints[2]), bool(data.ints[5])
        weights = data.weights if rational else np.zeros((0, 0))
        return _patch_points(data.knots_u, data.knots_v, p, q, data.poles, weights,
                             uv[:, 0].copy(), uv[:, 1].copy()) + data.params[20:23]
    u, w = uv[:, 0:1], uv[:, 1:2]
    if kind == GeomAbs_Plane:
        o, x, y, _ = _frame(s.Plane().Position())
        return o + u * x + w * y
    if kind in (GeomAbs_Cylinder, GeomAbs_Cone, GeomAbs_Sphere, GeomAbs_Torus):
        return _elementary(s, kind, u, w)
    if kind != GeomAbs_BSplineSurface:
        return None
    bs = s.BSpline()
    per_u, per_v = bs.IsUPeriodic(), bs.IsVPeriodic()
    (u0, u1, v0, v1) = bs.Bounds()
    if per_u or per_v:
        bs = bs.Copy()
        if per_u:
            bs.SetUNotPeriodic()
        if per_v:
            bs.SetVNotPeriodic()
    p, q, nu, nv = bs.UDegree(), bs.VDegree(), bs.NbUPoles(), bs.NbVPoles()
    poles = np.array([[bs.Pole(i, j).Coord() for j in range(1, nv + 1)]
                      for i in range(1, nu + 1)])
    weights = (np.array([[bs.Weight(i, j) for j in range(1, nv + 1)]
                         for i in range(1, nu + 1)])
               if bs.IsURational() or bs.IsVRational() else np.zeros((0, 0)))
    return _patch_points(_flat(bs.UKnotSequence()), _flat(bs.VKnotSequence()), p, q, poles,
                         weights, _wrap(uv[:, 0], u0, u1, per_u), _wrap(uv[:, 1], v0, v1, per_v))


def _elementary(s, kind, u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """ElSLib's formulas for the cylinder, cone, sphere and torus."""
    if kind == GeomAbs_Cylinder:
        g = s.Cylinder()
        code, a, b = 0, g.Radius(), 0.0
    elif kind == GeomAbs_Cone:
        g = s.Cone()
        code, a, b = 1, g.RefRadius(), g.SemiAngle()
    elif kind == GeomAbs_Sphere:
        g = s.Sphere()
        code, a, b = 2, g.Radius(), 0.0
    else:
        g = s.Torus()
        code, a, b = 3, g.MajorRadius(), g.MinorRadius()
    return _revolved(code, np.array([v for axis in _frame(g.Position()) for v in axis]), a,
                     b, u.ravel().copy(), w.ravel().copy())


@_jit
def _revolved(code: int, frame: np.ndarray, a: float, b: float, u: np.ndarray,
              w: np.ndarray) -> np.ndarray:
    """o + R(w) (cos u x + sin u y) + H(w) z for the cylinder (0), cone (1), sphere (2),
    torus (3); frame: o, x, y, z (12,); a, b: the radii or angle."""
    out = np.empty((len(u), 3))
    for k in range(len(u)):
        cu, su = math.cos(u[k]), math.sin(u[k])
        if code == 0:
            r, z = a, w[k]
        elif code == 1:
            r, z = a + w[k] * math.sin(b), w[k] * math.cos(b)
        elif code == 2:
            r, z = a * math.cos(w[k]), a * math.sin(w[k])
        else:
            r, z = a + b * math.cos(w[k]), b * math.sin(w[k])
        for d in range(3):
            out[k, d] = frame[d] + r * (cu * frame[3 + d] + su * frame[6 + d]) + z * frame[9 + d]
    return out
