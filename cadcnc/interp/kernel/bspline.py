"""B-spline and Bezier evaluation (rational and periodic) up to third derivatives, compiled.

Mirrors OCCT's ``BSplSLib`` / ``BSplCLib`` as ``GeomAdaptor_Surface`` / ``GeomAdaptor_Curve``
call them, span choice included: a parameter exactly on a knot uses the span to its right,
except that an evaluation exactly at the adaptor's last bound (the face's UVBounds for a
surface, the curve's first/last parameter for a curve) within ``POS_TOL`` of a knot uses
the span to its left, as OCCT's ``LocalD2`` does (it matters where a C1 knot sits on a
face edge: second derivatives jump there).

Arrays (all float64 unless said): ``knots`` flat, multiplicities expanded (OCCT's
``KnotSequence``; for a periodic direction the extended sequence of length n + 2p + 1);
``poles`` (n_u, n_v, 3) in mm; ``weights`` (n_u, n_v), ones when not rational. A curve
uses ``poles[:, 0, :]`` and ``weights[:, 0]``. ``work`` is caller-owned scratch (see
``WORK_SIZE`` in evaluators.py); nothing here allocates.
"""

from __future__ import annotations

import math

import numba
import numpy as np

MAX_DEGREE = 25
"""OCCT's BSplCLib::MaxDegree()."""
POS_TOL = 0.5e-9
"""Precision::PConfusion() / 2: how close to a knot counts as on it in OCCT's LocalD2."""
BASIS_SCRATCH = (MAX_DEGREE + 1) * (MAX_DEGREE + 6)
"""Floats of work one call of ``basis_derivatives`` needs for its tables."""

_jit = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)


@_jit
def normalize_periodic(t: float, first: float, last: float) -> float:
    """t moved by whole periods into [first, last] (BSplCLib_CacheParams' normalisation)."""
    period = last - first
    if t < first:
        return t + period * (math.floor((first - t) / period) + 1.0)
    if t > last:
        return t - period * (math.floor((t - last) / period) + 1.0)
    return t


@_jit
def find_span(knots: np.ndarray, p: int, t: float, side: int) -> int:
    """Index k of the flat-knot span [knots[k], knots[k + 1]) used to evaluate at t.

    side 0: the span holding t (t on a knot: the span to its right; t outside the knot
    range: the first or last span). side +1 / -1: OCCT's local evaluation at a bound: t
    within POS_TOL of a knot takes the span right / left of that knot.
    """
    lo = p
    hi = knots.shape[0] - p - 2
    if t >= knots[hi + 1]:
        k = hi
    elif t < knots[lo]:
        k = lo
    else:
        a = lo
        b = hi + 1
        while b - a > 1:  # knots[a] <= t < knots[b]
            m = (a + b) // 2
            if t < knots[m]:
                b = m
            else:
                a = m
        k = a
    if side == 0:
        return k
    if abs(t - knots[k + 1]) <= POS_TOL:
        kappa = knots[k + 1]
    elif abs(t - knots[k]) <= POS_TOL:
        kappa = knots[k]
    else:
        return k
    if side > 0:  # last span starting at kappa
        k = lo
        while k < hi and knots[k + 1] <= kappa:
            k += 1
    else:  # span ending at kappa
        k = hi
        while k > lo and knots[k] >= kappa:
            k -= 1
    return k


@_jit
def near_knot(knots: np.ndarray, p: int, t: float) -> bool:
    """True when t is within POS_TOL of a knot of the valid range."""
    k = find_span(knots, p, t, np.int64(0))  # np.int64: no literal-typed specialisation
    return abs(t - knots[k]) <= POS_TOL or abs(t - knots[k + 1]) <= POS_TOL


@_jit
def basis_derivatives(knots: np.ndarray, k: int, t: float, p: int, nd: int,
                      work: np.ndarray, tmp: int, ders: int) -> None:
    """Non-zero basis functions N_{k-p..k, p} and their derivatives up to order nd at t.

    Writes work[ders + i * (p + 1) + j] = d^i N_{k-p+j} / dt^i for i <= nd (higher orders
    than p are zero). Uses work[tmp : tmp + BASIS_SCRATCH] as tables (The NURBS Book,
    algorithm A2.3).
    """
    q = p + 1
    left = tmp
    right = tmp + q
    ndu = tmp + 2 * q          # (p+1) x (p+1): basis (upper) and knot differences (lower)
    a = ndu + q * q            # 2 x (p+1)
    work[ndu] = 1.0
    for j in range(1, p + 1):
        work[left + j] = t - knots[k + 1 - j]
        work[right + j] = knots[k + j] - t
        saved = 0.0
        for r in range(j):
            work[ndu + j * q + r] = work[right + r + 1] + work[left + j - r]
            temp = work[ndu + r * q + j - 1] / work[ndu + j * q + r]
            work[ndu + r * q + j] = saved + work[right + r + 1] * temp
            saved = work[left + j - r] * temp
        work[ndu + j * q + j] = saved
    for j in range(q):
        work[ders + j] = work[ndu + j * q + p]
    for i in range(1, nd + 1):
        for j in range(q):
            work[ders + i * q + j] = 0.0
    for r in range(q):
        s1 = 0
        s2 = 1
        work[a] = 1.0
        for i in range(1, min(nd, p) + 1):
            d = 0.0
            rk = r - i
            pk = p - i
            if r >= i:
                work[a + s2 * q] = work[a + s1 * q] / work[ndu + (pk + 1) * q + rk]
                d = work[a + s2 * q] * work[ndu + rk * q + pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = i - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                work[a + s2 * q + j] = ((work[a + s1 * q + j] - work[a + s1 * q + j - 1])
                                       / work[ndu + (pk + 1) * q + rk + j])
                d += work[a + s2 * q + j] * work[ndu + (rk + j) * q + pk]
            if r <= pk:
                work[a + s2 * q + i] = -work[a + s1 * q + i - 1] / work[ndu + (pk + 1) * q + r]
                d += work[a + s2 * q + i] * work[ndu + r * q + pk]
            work[ders + i * q + r] = d
            s1, s2 = s2, s1
    f = float(p)
    for i in range(1, min(nd, p) + 1):
        for j in range(q):
            work[ders + i * q + j] *= f
        f *= p - i


@_jit
def binomial(n: int, k: int) -> float:
    """n choose k for the small orders used here (n <= 3)."""
    c = 1.0
    for i in range(k):
        c = c * (n - i) / (i + 1)
    return c


@_jit
def surface_derivatives(knots_u: np.ndarray, knots_v: np.ndarray, poles: np.ndarray,
                        weights: np.ndarray, p: int, q: int, periodic_u: bool,
                        periodic_v: bool, rational: bool, u: float, v: float, side_u: int,
                        side_v: int, order: int, work: np.ndarray, out: np.ndarray) -> None:
    """S^(k,l)(u, v) for k + l <= order (<= 3) into out rows in the D3 layout.

    Rows: 0 r, 1 r_u, 2 r_v, 3 r_uu, 4 r_uv, 5 r_vv, then (order 3) 6 r_uuu, 7 r_uuv,
    8 r_uvv, 9 r_vvv. u, v already normalised for periodic directions; side_u, side_v as in
    ``find_span``.
    """
    n_u = poles.shape[0]
    n_v = poles.shape[1]
    ku = find_span(knots_u, p, u, side_u)
    kv = find_span(knots_v, q, v, side_v)
    du = min(order, p)
    dv = min(order, q)
    nu_off = 0
    nv_off = nu_off + 4 * (MAX_DEGREE + 1)
    acc = nv_off + 4 * (MAX_DEGREE + 1)      # homogeneous sums A[k, l, 0:4], 4 x 4 x 4
    row = acc + 64                           # one row of poles: T[l, 0:4], 4 x 4
    tmp = row + 16
    basis_derivatives(knots_u, ku, u, p, du, work, tmp, nu_off)
    basis_derivatives(knots_v, kv, v, q, dv, work, tmp, nv_off)
    for i in range(64):
        work[acc + i] = 0.0
    for a in range(p + 1):
        iu = ku - p + a
        if periodic_u:
            iu = iu % n_u
        for i in range(16):
            work[row + i] = 0.0
        for b in range(q + 1):
            iv = kv - q + b
            if periodic_v:
                iv = iv % n_v
            wgt = weights[iu, iv] if rational else 1.0
            x = poles[iu, iv, 0] * wgt
            y = poles[iu, iv, 1] * wgt
            z = poles[iu, iv, 2] * wgt
            for l in range(dv + 1):
                nb = work[nv_off + l * (q + 1) + b]
                work[row + 4 * l] += nb * x
                work[row + 4 * l + 1] += nb * y
                work[row + 4 * l + 2] += nb * z
                work[row + 4 * l + 3] += nb * wgt
        for k in range(du + 1):
            na = work[nu_off + k * (p + 1) + a]
            for l in range(min(dv, order - k) + 1):
                for c in range(4):
                    work[acc + 16 * k + 4 * l + c] += na * work[row + 4 * l + c]
    _rational_surface(work, acc, order, rational, out)


@_jit
def _rational_surface(work: np.ndarray, acc: int, order: int, rational: bool,
                      out: np.ndarray) -> None:
    """Derivatives of A/W from the homogeneous sums at work[acc] (The NURBS Book A4.4)."""
    for n in range(order + 1):
        for l in range(n + 1):
            k = n - l
            r = _row(k, l)
            for c in range(3):
                val = work[acc + 16 * k + 4 * l + c]
                if rational:
                    for j in range(1, l + 1):
                        val -= (binomial(l, j) * work[acc + 4 * j + 3]
                                * out[_row(k, l - j), c])
                    for i in range(1, k + 1):
                        bi = binomial(k, i)
                        val -= bi * work[acc + 16 * i + 3] * out[_row(k - i, l), c]
                        for j in range(1, l + 1):
                            val -= (bi * binomial(l, j) * work[acc + 16 * i + 4 * j + 3]
                                    * out[_row(k - i, l - j), c])
                    val /= work[acc + 3]
                out[r, c] = val


@_jit
def _row(k: int, l: int) -> int:
    """Row of d^(k+l) / du^k dv^l in the D3 layout (orders by total degree, u first)."""
    n = k + l
    return n * (n + 1) // 2 + l


@_jit
def curve_derivatives(knots: np.ndarray, poles: np.ndarray, weights: np.ndarray, p: int,
                      periodic: bool, rational: bool, t: float, side: int, order: int,
                      work: np.ndarray, out: np.ndarray) -> None:
    """C(t) and its derivatives up to ``order`` (<= 3) into out[0..order] ((4, 3) or more).

    Curve poles are poles[:, 0, :], weights[:, 0]; t already normalised when periodic.
    """
    n = poles.shape[0]
    k = find_span(knots, p, t, side)
    d = min(order, p)
    ders = 0
    acc = ders + 4 * (MAX_DEGREE + 1)        # A[i, 0:4], 4 x 4
    tmp = acc + 16
    basis_derivatives(knots, k, t, p, d, work, tmp, ders)
    for i in range(16):
        work[acc + i] = 0.0
    for a in range(p + 1):
        ip = k - p + a
        if periodic:
            ip = ip % n
        wgt = weights[ip, 0] if rational else 1.0
        for i in range(d + 1):
            nb = work[ders + i * (p + 1) + a]
            for c in range(3):
                work[acc + 4 * i + c] += nb * poles[ip, 0, c] * wgt
            work[acc + 4 * i + 3] += nb * wgt
    for i in range(order + 1):
        for c in range(3):
            val = work[acc + 4 * i + c]
            if rational:
                for j in range(1, i + 1):
                    val -= binomial(i, j) * work[acc + 4 * j + 3] * out[i - j, c]
                val /= work[acc + 3]
            out[i, c] = val
