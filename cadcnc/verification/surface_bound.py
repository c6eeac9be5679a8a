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

import numpy as np
from OCP.GeomAbs import GeomAbs_BSplineSurface
from OCP.gp import gp_Pnt, gp_Vec
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

ROUND_OFF = 1e-12
"""Relative widening of the bounds (floating-point round-off of sums of products)."""
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
        self.su = _hull(du, p / hu)
        self.sw = _hull(dw, q / hw)
        self.suw = _hull(np.diff(du, axis=2), p * q / (hu * hw))
        zero = (np.zeros_like(self.lo), np.zeros_like(self.lo))
        self.suu = _hull(np.diff(du, axis=1), p * (p - 1) / hu ** 2) if p > 1 else zero
        self.sww = _hull(np.diff(dw, axis=2), q * (q - 1) / hw ** 2) if q > 1 else zero

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

    def clear(self, adaptor, point, u0: float, w0: float, floor: float) -> bool:
        """Whether no point of the surface lies nearer than ``floor`` (mm) to ``point``,
        given a point of the surface at (u0, w0) (the foot; module doc). False: not
        proven."""
        if floor <= 0.0:
            return True
        if not (self.domain[0] <= u0 <= self.domain[1]
                and self.domain[2] <= w0 <= self.domain[3]):
            return False   # a foot off the patches: their bounds do not reach it
        p = np.asarray(point, float)
        gap = np.maximum(np.maximum(self.lo - p, p - self.hi), 0.0)
        near = np.einsum("ij,ij->i", gap, gap) < floor * floor * (1.0 + ROUND_OFF)
        if not near.any():
            return True
        r = self.rect[near]
        box = (min(r[:, 0].min(), u0), max(r[:, 1].max(), u0),
               min(r[:, 2].min(), w0), max(r[:, 3].max(), w0))
        meets = np.nonzero((self.rect[:, 0] <= box[1]) & (self.rect[:, 1] >= box[0])
                           & (self.rect[:, 2] <= box[3]) & (self.rect[:, 3] >= box[2]))[0]
        lam = self._least_eigenvalue(meets, p)
        if not lam > 0.0:
            return False
        pnt, du, dw = gp_Pnt(), gp_Vec(), gp_Vec()
        adaptor.D1(u0, w0, pnt, du, dw)
        e = np.array(pnt.Coord()) - p
        low = float(e @ e)
        for x0, lo, hi, grad in ((u0, box[0], box[1], 2.0 * float(e @ du.Coord())),
                                 (w0, box[2], box[3], 2.0 * float(e @ dw.Coord()))):
            t = min(max(-grad / lam, lo - x0), hi - x0)
            low += grad * t + 0.5 * lam * t * t
        return low * (1.0 - ROUND_OFF) >= floor * floor

    def _least_eigenvalue(self, idx: np.ndarray, p: np.ndarray) -> float:
        """A lower bound of the least eigenvalue of g's Hessian over the patches ``idx``
        (interval arithmetic, module doc)."""
        e = (self.lo[idx] - p, self.hi[idx] - p)
        su, sw = [(b[0][idx], b[1][idx]) for b in (self.su, self.sw)]
        a = _square_low(su) + _product(e, (self.suu[0][idx], self.suu[1][idx]))[0]
        c = _square_low(sw) + _product(e, (self.sww[0][idx], self.sww[1][idx]))[0]
        b_lo, b_hi = (x + y for x, y in zip(_product(su, sw),
                                            _product(e, (self.suw[0][idx], self.suw[1][idx]))))
        a, c = a.sum(axis=1), c.sum(axis=1)
        beta = np.maximum(np.abs(b_lo.sum(axis=1)), np.abs(b_hi.sum(axis=1)))
        scale = np.abs(a) + np.abs(c) + beta
        least = 0.5 * (a + c) - np.sqrt(0.25 * (a - c) ** 2 + beta ** 2) - ROUND_OFF * scale
        return 2.0 * float(least.min())


def _product(x: tuple, y: tuple) -> tuple[np.ndarray, np.ndarray]:
    """The interval product of (low, high) arrays, componentwise."""
    prods = (x[0] * y[0], x[0] * y[1], x[1] * y[0], x[1] * y[1])
    return (np.minimum(np.minimum(prods[0], prods[1]), np.minimum(prods[2], prods[3])),
            np.maximum(np.maximum(prods[0], prods[1]), np.maximum(prods[2], prods[3])))


def _square_low(x: tuple) -> np.ndarray:
    """The least square of each interval (low, high): 0 where it holds 0."""
    lo, hi = x
    return np.where((lo <= 0.0) & (hi >= 0.0), 0.0, np.minimum(lo * lo, hi * hi))


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
