"""The paper's error bounds for both surfaces of a path in one compiled pass.

Mirrors ``error_bounds.pair_bounds`` (numpy, the reference; tests/interp/test_kernel_bounds.py
compares the two on fixture paths) element by element, operation for operation in numpy's
order, so the numbers are the same (numpy's vectorised ``x ** 3`` may round its last bit
differently from ``math.pow``: eq11 only). numpy's version costs about 0.4 ms on a
1000-point path (some forty array operations on strided views of the record); this one a
few tens of microseconds.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .cycle import PAPER_INVERSE_LIMIT

FIELDS = 10
"""Rows of ``out`` per surface, in SurfaceBounds' field order: eps, k, k_max, k_min, tau,
eq11, eq12, eq15, eps_ss, eq16."""
_BIG = np.finfo(np.float64).max  # np.nan_to_num's replacement of inf


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _curvatures(ff: np.ndarray, ru: np.ndarray, rw: np.ndarray, t: np.ndarray) -> tuple:
    """surface_curvatures for one row: (k, k_max, k_min, tau)."""
    E, F, G, L, M, N = ff[0], ff[1], ff[2], ff[3], ff[4], ff[5]
    det = E * G - F * F
    tu = ru[0] * t[0] + ru[1] * t[1] + ru[2] * t[2]
    tw = rw[0] * t[0] + rw[1] * t[1] + rw[2] * t[2]
    a = (G * tu - F * tw) / det
    b = (E * tw - F * tu) / det
    first = E * a * a + 2.0 * F * a * b + G * b * b
    k = (L * a * a + 2.0 * M * a * b + N * b * b) / first
    H = (E * N - 2.0 * F * M + G * L) / (2.0 * det)
    K = (L * N - M * M) / det
    x = H * H - K
    disc = math.sqrt(x if not x < 0.0 else 0.0)   # np.maximum(x, 0): NaN stays NaN
    tau = ((E * M - F * L) * a * a + (E * N - G * L) * a * b + (F * N - G * M) * b * b) / (
        math.sqrt(det) * first)
    return k, H + disc, H - disc, tau


@numba.njit(cache=True, nogil=True, error_model="numpy")
def pair_bounds(R: np.ndarray, points: np.ndarray, contacts: np.ndarray, normals: np.ndarray,
                ru: np.ndarray, rw: np.ndarray, forms: np.ndarray, t: np.ndarray,
                f: np.ndarray, limit: float = PAPER_INVERSE_LIMIT) -> np.ndarray:
    """(2, FIELDS, N): both surfaces' bounds. ``R`` (2,) offsets (mm); ``points`` (N, 3);
    ``contacts``, ``normals``, ``ru``, ``rw`` (N, 2, 3); ``forms`` (N, 2, 6); ``t`` (N, 3);
    ``f`` (N,) (mm); ``limit``: cycle.PAPER_INVERSE_LIMIT (an argument, not a global: numba's
    cache would keep a global's value from another file)."""
    n_pts = points.shape[0]
    out = np.empty((2, FIELDS, n_pts))
    for j in range(n_pts):
        c1 = _curvatures(forms[j, 0], ru[j, 0], rw[j, 0], t[j])
        c2 = _curvatures(forms[j, 1], ru[j, 1], rw[j, 1], t[j])
        n1, n2, q1, q2 = normals[j, 0], normals[j, 1], contacts[j, 0], contacts[j, 1]
        # mp_length's geometry (the offsets enter below)
        d2 = 0.0
        for c in range(3):
            o = (q1[c] + n1[c] / c1[0]) - (q2[c] + n2[c] / c2[0])
            d2 += o * o
        dot = n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]
        x = 1.0 - dot * dot
        s = math.sqrt(x if not x < 0.0 else 0.0)
        rho1, rho2 = 1.0 / abs(c1[0]), 1.0 / abs(c2[0])
        fj = f[j]
        for i in range(2):
            k, kmax, kmin, tau = c1 if i == 0 else c2
            r = R[i]
            e2 = 0.0
            for c in range(3):
                d = points[j, c] - (contacts[j, i, c] + r * normals[j, i, c])
                e2 += d * d
            eps = math.sqrt(e2)
            mp = (rho1 + r) * (rho2 + r) * s / math.sqrt(d2)
            if not math.isfinite(mp):
                mp = math.inf
            ak = abs(k)
            dk = abs(kmax - kmin)
            one = 1.0 + ak * r
            one2 = one * one
            coeff = dk + dk * dk * r + tau * tau * r
            eq11 = tau * tau * r * fj * fj / (2.0 * one2) + abs(tau) * math.pow(fj, 3.0) / (
                2.0 * one2 * mp)
            if math.isnan(eq11):
                eq11 = 0.0
            elif math.isinf(eq11):
                eq11 = _BIG if eq11 > 0 else -_BIG
            fe = fj + eps
            eq12 = coeff / (2.0 * one2) * (fe * fe)
            g = math.sqrt(dk * dk + tau * tau)
            eq15 = g * r * fe / one
            ss_den = 1.0 + r * (ak - g)
            eps_ss = r * g * fj / ss_den if ss_den > 0 else math.inf
            eq16 = coeff / (2.0 * one * ss_den) * fj * fj if ss_den > 0 else math.inf
            a, b = abs(kmax - k), abs(kmin - k)
            rho = r * (a if a >= b or math.isnan(a) else b) / abs(1.0 - r * k)
            if rho > limit:  # the exact inverse moved it: eq. 12 from eps
                eps_ss, eq16 = eps, eq12
            row = out[i]
            row[0, j], row[1, j], row[2, j], row[3, j], row[4, j] = eps, k, kmax, kmin, tau
            row[5, j], row[6, j], row[7, j], row[8, j], row[9, j] = (eq11, eq12, eq15, eps_ss,
                                                                     eq16)
    return out
