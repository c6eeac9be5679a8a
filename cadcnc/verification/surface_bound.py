"""A proof that no point of a B-spline surface lies nearer to a point than a given
distance, without OCCT's global search: the gate's sampled cycles (:mod:`.surface_checks`).

The surface (non-rational, not periodic) is split into its Bezier patches (every knot
inserted to the full multiplicity: exact). By the convex hull property each patch lies in
the box of its control points, and its derivatives S_u, S_w, S_uu, S_uw, S_ww in the boxes
of the scaled differences of those control points. For a point p with a foot x0 = (u0, w0)
on the surface (a seeded projection, at distance d):

- patches whose box is at least ``floor`` from p hold no nearer point;
- over the parameter rectangle U spanning the other patches (and x0), the Hessian of
  g = |S - p|^2, 2 [[S_u.S_u + (S - p).S_uu, S_u.S_w + (S - p).S_uw], [..., S_w.S_w +
  (S - p).S_ww]], is bounded below by interval arithmetic on those boxes: when its least
  eigenvalue is at least lam > 0 on every patch U meets, g is strongly convex on U, and
  g(x) >= g(x0) + grad g(x0).(x - x0) + lam/2 |x - x0|^2 there; its minimum over U's
  sides, a closed form per coordinate, bounds g on U from below.

Both at floor^2 or more: no point of the surface (and so of the face, or of OCCT's global
search's answer over the face's box) is nearer than ``floor``. Anything else (a rational
or periodic surface, a Hessian not proven positive) says "not proven" and OCCT decides.
Lengths mm, parameters the surface's own.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from OCP.GeomAbs import GeomAbs_BSplineSurface
from OCP.gp import gp_Pnt, gp_Vec
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

ROUND_OFF = 1e-12
"""Relative widening of the bounds (floating-point round-off of sums of products)."""
_jit = numba.njit(cache=True, nogil=True)
MAX_PATCHES = 20_000
"""More Bezier patches than this: no bound (OCCT decides), to keep the arrays small."""


def _poles(array) -> np.ndarray:
    """(rows, cols, 3) of an OCCT TColgp_Array2OfPnt."""
    return np.array([[array.Value(i, j).Coord() for j in range(array.LowerCol(),
                                                             array.UpperCol() + 1)]
                     for i in range(array.LowerRow(), array.UpperRow() + 1)])


def _bezier_net(surface):
    """(poles (rows, cols, 3), u knots, w knots, degrees) of the surface with every knot at
    multiplicity degree (its Bezier patches side by side), or None (OCCT refused)."""
    piece = surface.Copy()
    p, q = piece.UDegree(), piece.VDegree()
    for insert, knots, degree in ((piece.InsertUKnots, piece.UKnots(), p),
                                  (piece.InsertVKnots, piece.VKnots(), q)):
        values = [knots.Value(k) for k in range(knots.Lower(), knots.Upper() + 1)]
        arr, mults = TColStd_Array1OfReal(1, len(values)), TColStd_Array1OfInteger(
            1, len(values))
        for k, v in enumerate(values, start=1):
            arr.SetValue(k, v)
            mults.SetValue(k, degree)
        insert(arr, mults, 0.0, False)
    us = [piece.UKnot(k) for k in range(1, piece.NbUKnots() + 1)]
    ws = [piece.VKnot(k) for k in range(1, piece.NbVKnots() + 1)]
    poles = _poles(piece.Poles())
    if poles.shape[:2] != ((len(us) - 1) * p + 1, (len(ws) - 1) * q + 1):
        return None
    return poles, np.array(us), np.array(ws), (p, q)


def _hull(values: np.ndarray, scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) (P, 3) of control-point differences ``values`` (P, a, b, 3) scaled by
    ``scale`` (P,): the box of a derivative patch."""
    flat = values.reshape(len(values), -1, 3) * scale[:, None, None]
    return flat.min(axis=1), flat.max(axis=1)


class SurfaceBound:
    """The Bezier patches of a face's surface, their boxes and derivative boxes
    (module doc). ``SurfaceBound.of(adaptor, surface)`` is None where no bound applies."""

    def __init__(self, poles: np.ndarray, us: np.ndarray, ws: np.ndarray, degrees: tuple):
        p, q = degrees
        nets = np.array([[poles[p * i:p * i + p + 1, q * j:q * j + q + 1]
                          for j in range(len(ws) - 1)] for i in range(len(us) - 1)])
        nets = nets.reshape(-1, p + 1, q + 1, 3)
        iu, iw = np.divmod(np.arange(len(nets)), len(ws) - 1)
        self.rect = np.stack([us[iu], us[iu + 1], ws[iw], ws[iw + 1]], axis=1)  # (P, 4)
        self.domain = (us[0], us[-1], ws[0], ws[-1])
        hu, hw = self.rect[:, 1] - self.rect[:, 0], self.rect[:, 3] - self.rect[:, 2]
        flat = nets.reshape(len(nets), -1, 3)
        self.lo, self.hi = flat.min(axis=1), flat.max(axis=1)
        du, dw = np.diff(nets, axis=1), np.diff(nets, axis=2)
        zero = (np.zeros_like(self.lo), np.zeros_like(self.lo))
        parts = [(self.lo, self.hi), _hull(du, p / hu), _hull(dw, q / hw),
                 _hull(np.diff(du, axis=1), p * (p - 1) / hu ** 2) if p > 1 else zero,
                 _hull(np.diff(du, axis=2), p * q / (hu * hw)),
                 _hull(np.diff(dw, axis=2), q * (q - 1) / hw ** 2) if q > 1 else zero]
        # (P, 12, 3): box low, high, then low and high of S_u, S_w, S_uu, S_uw, S_ww
        self.bounds = np.ascontiguousarray(np.stack([x for pair in parts for x in pair],
                                                    axis=1))

    @classmethod
    def of(cls, adaptor, surface) -> "SurfaceBound | None":
        """The bound of a non-rational, non-periodic B-spline surface (``adaptor`` a
        GeomAdaptor_Surface on ``surface``), else None."""
        if adaptor.GetType() != GeomAbs_BSplineSurface:
            return None
        bs = adaptor.BSpline()
        if bs.IsURational() or bs.IsVRational() or bs.IsUPeriodic() or bs.IsVPeriodic():
            return None
        if (bs.NbUKnots() - 1) * (bs.NbVKnots() - 1) > MAX_PATCHES:
            return None
        try:
            net = _bezier_net(bs)
        except Exception:   # noqa: BLE001 - OCCT refused a knot: no bound
            return None
        return None if net is None else cls(*net)

    def floor(self, points: np.ndarray) -> np.ndarray:
        """(M,) a lower bound (mm) of each point's (M, 3) distance to the surface: its
        distance to the nearest patch's box (each patch lies in the box of its control
        points), less the round-off of the boxes."""
        points = np.ascontiguousarray(points, dtype=float).reshape(-1, 3)
        return _box_floor(self.lo, self.hi, points, ROUND_OFF)

    def clear(self, adaptor, point, u0: float, w0: float, floor: float) -> bool:
        """Whether no point of the surface lies nearer than ``floor`` (mm) to ``point``,
        given a point of the surface at (u0, w0) (the foot; module doc). False: not
        proven."""
        if floor <= 0.0:
            return True
        if not (self.domain[0] <= u0 <= self.domain[1]
                and self.domain[2] <= w0 <= self.domain[3]):
            return False   # a foot off the patches: their bounds do not reach it
        pnt, du, dw = gp_Pnt(), gp_Vec(), gp_Vec()
        adaptor.D1(u0, w0, pnt, du, dw)
        px, py, pz = (float(c) for c in point)
        ex, ey, ez = pnt.X() - px, pnt.Y() - py, pnt.Z() - pz
        return bool(_proof(self.bounds, self.rect, px, py, pz, u0, w0,
                           ex * ex + ey * ey + ez * ez,
                           2.0 * (ex * du.X() + ey * du.Y() + ez * du.Z()),
                           2.0 * (ex * dw.X() + ey * dw.Y() + ez * dw.Z()), floor))


@_jit
def _box_floor(lo: np.ndarray, hi: np.ndarray, points: np.ndarray, rel: float) -> np.ndarray:
    """(M,) each point's distance to the nearest of the boxes [lo, hi] (P, 3), less four
    times ``rel`` times the coordinates' size (the round-off of the boxes and of the
    distance; :meth:`SurfaceBound.floor`)."""
    out = np.empty(len(points))
    for m in range(len(points)):
        best, size = np.inf, 1.0
        for i in range(3):
            size = max(size, abs(points[m, i]))
        for k in range(len(lo)):
            g2 = 0.0
            for i in range(3):
                g = max(lo[k, i] - points[m, i], points[m, i] - hi[k, i], 0.0)
                g2 += g * g
            if g2 < best:
                best = g2
        out[m] = max(math.sqrt(best) - rel * size * 4.0, 0.0)
    return out


@_jit
def _square_low(lo: float, hi: float) -> float:
    """The least square of the interval [lo, hi]: 0 where it holds 0."""
    if lo <= 0.0 <= hi:
        return 0.0
    return min(lo * lo, hi * hi)


@_jit
def _product(a: float, b: float, c: float, d: float) -> tuple[float, float]:
    """The interval product [a, b] x [c, d]: (low, high)."""
    p0, p1, p2, p3 = a * c, a * d, b * c, b * d
    return min(min(p0, p1), min(p2, p3)), max(max(p0, p1), max(p2, p3))


@_jit
def _least_eigenvalue(b: np.ndarray, i: int, p: np.ndarray) -> float:
    """A lower bound of the least eigenvalue of the Hessian of |S - p|^2 / 2 over patch
    ``i`` of the bounds ``b`` (P, 12, 3) (interval arithmetic, module doc)."""
    a = c = b_lo = b_hi = 0.0
    for k in range(3):
        e_lo, e_hi = b[i, 0, k] - p[k], b[i, 1, k] - p[k]
        a += _square_low(b[i, 2, k], b[i, 3, k]) + _product(e_lo, e_hi, b[i, 6, k],
                                                            b[i, 7, k])[0]
        c += _square_low(b[i, 4, k], b[i, 5, k]) + _product(e_lo, e_hi, b[i, 10, k],
                                                            b[i, 11, k])[0]
        lo1, hi1 = _product(b[i, 2, k], b[i, 3, k], b[i, 4, k], b[i, 5, k])
        lo2, hi2 = _product(e_lo, e_hi, b[i, 8, k], b[i, 9, k])
        b_lo += lo1 + lo2
        b_hi += hi1 + hi2
    beta = max(abs(b_lo), abs(b_hi))
    scale = abs(a) + abs(c) + beta
    return 0.5 * (a + c) - math.sqrt(0.25 * (a - c) ** 2 + beta * beta) - ROUND_OFF * scale


@_jit
def _proof(b: np.ndarray, rect: np.ndarray, px: float, py: float, pz: float, u0: float,
           w0: float, g0: float, gu: float, gw: float, floor: float) -> bool:
    """The proof of :meth:`SurfaceBound.clear` (module doc): ``b`` (P, 12, 3) the patches'
    boxes and derivative boxes, ``rect`` (P, 4) their (u, w) ranges; g0, (gu, gw) the
    value and gradient of |S - p|^2 at the foot (u0, w0)."""
    p = np.array((px, py, pz))
    near2 = floor * floor * (1.0 + ROUND_OFF)
    u_lo, u_hi, w_lo, w_hi, near = u0, u0, w0, w0, False
    for i in range(len(b)):
        s = 0.0
        for k in range(3):
            g = max(b[i, 0, k] - p[k], p[k] - b[i, 1, k], 0.0)
            s += g * g
        if s < near2:
            near = True
            u_lo, u_hi = min(u_lo, rect[i, 0]), max(u_hi, rect[i, 1])
            w_lo, w_hi = min(w_lo, rect[i, 2]), max(w_hi, rect[i, 3])
    if not near:
        return True
    lam = math.inf
    for i in range(len(b)):
        if rect[i, 0] <= u_hi and rect[i, 1] >= u_lo and rect[i, 2] <= w_hi \
                and rect[i, 3] >= w_lo:
            lam = min(lam, 2.0 * _least_eigenvalue(b, i, p))
    if not lam > 0.0:
        return False
    t = min(max(-gu / lam, u_lo - u0), u_hi - u0)
    low = g0 + gu * t + 0.5 * lam * t * t
    t = min(max(-gw / lam, w_lo - w0), w_hi - w0)
    low += gw * t + 0.5 * lam * t * t
    return low * (1.0 - ROUND_OFF) >= floor * floor


def min_distance_bound(bound: SurfaceBound, adaptor, point, u0: float, w0: float,
                       lo: float, hi: float, steps: int = 40) -> float:
    """The largest floor in [lo, hi] that :meth:`SurfaceBound.clear` proves (bisection;
    ``lo`` when none): for tests and benchmarks, not the gate."""
    if not bound.clear(adaptor, point, u0, w0, lo):
        return lo
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if bound.clear(adaptor, point, u0, w0, mid) else (lo, mid)
    return lo if math.isfinite(lo) else math.nan
