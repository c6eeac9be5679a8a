"""A closed triangle mesh met by a dexel grid's rays: every crossing, sorted along each ray.

Each triangle (3, 3) mm is projected on the grid's plane and every ray through it gives one
crossing: t along the ray (from ``lo[k]``), the triangle's face number, and c = n . e_k of
its unit outward normal (c > 0: the ray leaves the solid there). Rays are moved off their
lines by a tiny fixed shift (``NUDGE`` of the resolution) so that a ray through a shared
edge or vertex is counted once: a closed mesh gives an even number of crossings per ray,
alternately entering and leaving. Results are CSR arrays: ``start`` (rays + 1,), ``t``,
``face``, ``cos`` (crossings,).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

NUDGE = (1.2345e-7, 2.3456e-7)   # of the resolution, along u and v


@njit(cache=True)
def _hits(k, lo, res, nu, nv, tris, count_only, start, fill, t_out, f_out, c_out, d_out,
          faces):
    u, v = (k + 1) % 3, (k + 2) % 3
    du, dv = NUDGE[0] * res, NUDGE[1] * res
    for i in range(tris.shape[0]):
        a, b, c = tris[i, 0], tris[i, 1], tris[i, 2]
        e1 = b - a
        e2 = c - a
        n0 = e1[1] * e2[2] - e1[2] * e2[1]
        n1 = e1[2] * e2[0] - e1[0] * e2[2]
        n2 = e1[0] * e2[1] - e1[1] * e2[0]
        nn = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        nk = n0 if k == 0 else (n1 if k == 1 else n2)
        if nn == 0.0 or nk == 0.0:
            continue
        # this grid samples the triangle for the report when k is its normal's largest
        # component (the lowest such axis on a tie): every patch is counted by one grid
        m0, m1, m2 = abs(n0), abs(n1), abs(n2)
        top = 0 if (m0 >= m1 and m0 >= m2) else (1 if m1 >= m2 else 2)
        au, av, bu, bv, cu, cv = a[u], a[v], b[u], b[v], c[u], c[v]
        i0 = max(0, int(math.floor((min(au, bu, cu) - lo[u]) / res - 0.5)))
        i1 = min(nu - 1, int(math.ceil((max(au, bu, cu) - lo[u]) / res - 0.5)))
        j0 = max(0, int(math.floor((min(av, bv, cv) - lo[v]) / res - 0.5)))
        j1 = min(nv - 1, int(math.ceil((max(av, bv, cv) - lo[v]) / res - 0.5)))
        area = (bu - au) * (cv - av) - (bv - av) * (cu - au)
        if area == 0.0:
            continue
        for p in range(i0, i1 + 1):
            pu = lo[u] + (p + 0.5) * res + du
            for q in range(j0, j1 + 1):
                pv = lo[v] + (q + 0.5) * res + dv
                w0 = ((bu - pu) * (cv - pv) - (bv - pv) * (cu - pu)) / area
                w1 = ((cu - pu) * (av - pv) - (cv - pv) * (au - pu)) / area
                w2 = 1.0 - w0 - w1
                if w0 < 0.0 or w1 < 0.0 or w2 < 0.0:
                    continue
                r = p * nv + q
                if count_only:
                    start[r + 1] += 1
                    continue
                j = fill[r]
                fill[r] += 1
                t_out[j] = w0 * a[k] + w1 * b[k] + w2 * c[k] - lo[k]
                f_out[j] = faces[i]
                c_out[j] = nk / nn
                d_out[j] = top == k


@njit(cache=True)
def _sort_rays(start, t, f, c, d):
    for r in range(start.shape[0] - 1):
        s, e = start[r], start[r + 1]
        if e - s < 2:
            continue
        order = np.argsort(t[s:e])
        t[s:e] = t[s:e][order]
        f[s:e] = f[s:e][order]
        c[s:e] = c[s:e][order]
        d[s:e] = d[s:e][order]


def crossings(k: int, lo, res: float, nu: int, nv: int, tris: np.ndarray,
              faces: np.ndarray) -> tuple[np.ndarray, ...]:
    """(start, t, face, cos, dominant) of the triangles ``tris`` (T, 3, 3) with face
    numbers ``faces`` (T,) on the grid along ``k`` (module doc); ``dominant``: whether this
    grid is the one that samples the crossing's triangle for the report."""
    lo = np.asarray(lo, float)
    tris = np.ascontiguousarray(tris, float)
    faces = np.asarray(faces, np.int32)
    start = np.zeros(nu * nv + 1, np.int64)
    dummy_f, dummy_t, dummy_d = np.zeros(0, np.int32), np.zeros(0), np.zeros(0, np.bool_)
    _hits(k, lo, res, nu, nv, tris, True, start, start, dummy_t, dummy_f, dummy_t, dummy_d,
          faces)
    start = np.cumsum(start)
    n = start[-1]
    t, f, c, d = np.empty(n), np.empty(n, np.int32), np.empty(n), np.empty(n, np.bool_)
    _hits(k, lo, res, nu, nv, tris, False, start, start[:-1].copy(), t, f, c, d, faces)
    _sort_rays(start, t, f, c, d)
    return start, t, f, c, d


def solid_intervals(start: np.ndarray, t: np.ndarray, kmax: int = 0
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The material of a closed mesh along each ray from its crossings: (iv (rays, K, 2)
    float32, cnt (rays,) int32), pairs of (enter, leave) crossings."""
    per = np.diff(start) // 2
    k = max(int(per.max()) if len(per) else 1, 1, kmax)
    iv = np.zeros((len(per), k, 2), np.float32)
    cnt = per.astype(np.int32)
    for r in np.flatnonzero(per):
        s = start[r]
        iv[r, :per[r]] = t[s:s + 2 * per[r]].reshape(-1, 2)
    return iv, cnt
