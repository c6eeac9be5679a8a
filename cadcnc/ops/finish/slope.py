"""The slope factor a cusp's chord sees: g along the cross-section, not at one sample.

Guide planes ``n . p = const`` a distance Delta apart cut the offset surface (the ball
centres) in two curves. In the cross-section through a sample's ideal centre q_i (the
plane through q_i normal to the pass direction t = N x n) the centre-to-centre chord is at
most the arc between the planes, ``integral df / g``, g = sqrt(1 - (n . N)^2) the rate at
which f = n . p grows along the surface across the passes: at most Delta / g_min, g_min
the smallest g on that arc, not Delta / g_i. Where g falls across the strip (a slope
steepening across the passes) while the allowed chord c rises (a concave curvature
easing), the sample with the smallest c sees the chord of a smaller g than its own, and
``Delta = min c_i g_i`` leaves its cusp above H (wl_dome's flank: 0.0516 for 0.05).

So the planes keep ``Delta <= c_i g_j`` for every sample i between them and every sample j
on i's cross-section arc between them: the **pairs** (i, j) of samples whose ideal centres
lie within c_i of each other (the arc within the strip is at most c_i long, so it lies
within c_i of q_i) and within one sample spacing s of i's cross-section
(|t_i . (q_j - q_i)| <= s). A pair binds a strip when f_i lies in it and f_j within
``reach_j`` of it, the f-distance from a point of the arc to its nearest sample
(s g_j max(1, B_j) / 2, B = 1 - R' k the offset's stretch): at the strip's ends the arc's g
is then that of a sample at or just past the end. Sampled, as the spacing is. The
waterline levels take the same rule with n = +Z (g the sine of the slope). Lengths mm.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

CHUNK = 4096
"""Samples whose neighbourhoods are gathered at a time (bounds the memory held)."""


def cross_pairs(q: np.ndarray, normals: np.ndarray, normal: np.ndarray, chord: np.ndarray,
                serve: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """(i, j), each (P,), sample numbers: j on i's cross-section within i's chord (the
    module doc; i itself included). ``q`` (N, 3) ideal centres, ``normals`` (N, 3) the
    faces' normals, ``normal`` (3,) the planes' n, ``chord`` (N,) the allowed chord c (mm),
    ``serve`` (N,) the samples the planes serve (the only ones paired), ``spacing`` s (mm)."""
    idx = np.flatnonzero(serve & np.isfinite(chord))
    if not len(idx):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    tree = cKDTree(q[idx])
    t = np.cross(normals[idx], normal)
    t /= np.maximum(np.linalg.norm(t, axis=1), 1e-300)[:, None]   # no / 0
    out_i, out_j = [], []
    for a in range(0, len(idx), CHUNK):
        mine = np.arange(a, min(a + CHUNK, len(idx)))
        near = tree.query_ball_point(q[idx[mine]], chord[idx[mine]])
        count = np.fromiter(map(len, near), np.int64, len(mine))
        i = np.repeat(mine, count)
        j = np.concatenate([np.asarray(n, np.int64) for n in near] + [np.zeros(0, np.int64)])
        keep = np.abs(np.einsum("nk,nk->n", t[i], q[idx[j]] - q[idx[i]])) <= spacing
        out_i.append(idx[i[keep]])
        out_j.append(idx[j[keep]])
    return np.concatenate(out_i), np.concatenate(out_j)


def least_over_pairs(values: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """(N,) for each sample i the smallest ``values`` (N,) over its pairs' j (its own where
    it has none): a bound on the slope factor its strip can see, whatever the strip."""
    out = np.array(values, float)
    np.minimum.at(out, i, values[j])
    return out


def strip_pairs(samples, q: np.ndarray, f: np.ndarray, normal: np.ndarray, k: np.ndarray,
                g: np.ndarray, chord: np.ndarray, serve: np.ndarray, offset: float):
    """(pairs, bound) of samples (a FaceSamples) at ideal centres ``q`` (N, 3), centre
    coordinate ``f`` (N,) along the planes' ``normal`` (3,), curvature ``k`` and slope
    factor ``g`` across them, allowed chord ``chord`` (all (N,)); ``serve`` (N,) the samples
    the planes serve; ``offset`` R' (mm). ``pairs`` (f_i, f_j - reach_j, f_j + reach_j,
    c_i g_j) for :func:`~.plan.adaptive_offsets`; ``bound`` (N,) c_i times the smallest
    g_j of i's pairs (inf where not served): a spacing that holds whatever the strip, for
    the estimate (module doc)."""
    i, j = cross_pairs(q, samples.normals, normal, chord, serve, samples.spacing)
    reach = 0.5 * samples.spacing * g * np.maximum(1.0, 1.0 - offset * k)
    pairs = (f[i], f[j] - reach[j], f[j] + reach[j], chord[i] * g[j])
    return pairs, np.where(serve, chord * least_over_pairs(g, i, j), np.inf)
