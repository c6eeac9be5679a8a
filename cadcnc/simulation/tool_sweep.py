"""A ray against the volume a ball-end tool sweeps along one straight move, in closed form.

The tool is a ball of radius R (centre c) on a shank of radius R along the unit tool axis
``a`` up to ``c + L a``: the set of points within R of the segment [c, c + L a] (a capsule;
its top cap lies above the stock when L reaches past it, see :mod:`.tool_moves`). Moved from
``p0`` to ``p1`` (v = p1 - p0) it sweeps the points within R of the parallelogram
{p0 + s v + h a : s in [0, 1], h in [0, L]}: the parallelogram's slab (thickness 2R along
its normal) united with the capsules of its four edges. That set is convex, so a line meets
it in one interval, the hull of the pieces' intervals. Lines are axis-aligned here (the
dexel rays): origin ``o`` (3,) and direction the unit vector of axis ``k`` (0, 1, 2).
Every function returns (t_in, t_out) with t_in > t_out for a miss; lengths mm.

Plain numba functions: ``fn.py_func`` is the Python reference the tests compare against.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

PARALLEL = 1e-12   # below this |sin|^2 a line is taken as parallel to an axis or a plane


@njit(cache=True, error_model="numpy")
def sphere(o0, o1, o2, k, c0, c1, c2, r):
    """The line o + t e_k against the ball of radius ``r`` centred at c: (t_in, t_out)."""
    w0, w1, w2 = o0 - c0, o1 - c1, o2 - c2
    if k == 0:
        b, q = w0, w1 * w1 + w2 * w2
    elif k == 1:
        b, q = w1, w0 * w0 + w2 * w2
    else:
        b, q = w2, w0 * w0 + w1 * w1
    h = r * r - q
    if h < 0.0:
        return 1.0, -1.0
    s = math.sqrt(h)
    return -b - s, -b + s


@njit(cache=True, error_model="numpy")
def segment(a0, a1, a2, b0, b1, b2):
    """The segment [a, b]'s squared length, length and unit direction (5 floats; the
    direction is NaN for a point): what :func:`capsule` needs beyond its ends."""
    d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
    ln2 = d0 * d0 + d1 * d1 + d2 * d2
    ln = math.sqrt(ln2)
    return ln2, ln, d0 / ln, d1 / ln, d2 / ln


@njit(cache=True, error_model="numpy")
def capsule(o0, o1, o2, k, a0, a1, a2, b0, b1, b2, r):
    """The line o + t e_k against the points within ``r`` of the segment [a, b]."""
    ln2, ln, u0, u1, u2_ = segment(a0, a1, a2, b0, b1, b2)
    return capsule_of(o0, o1, o2, k, a0, a1, a2, b0, b1, b2, ln2, ln, u0, u1, u2_, r)


@njit(cache=True, error_model="numpy")
def capsule_of(o0, o1, o2, k, a0, a1, a2, b0, b1, b2, ln2, ln, u0, u1, u2_, r):
    """:func:`capsule` with the segment's :func:`segment` given (computed once a move)."""
    lo, hi = sphere(o0, o1, o2, k, a0, a1, a2, r)
    if ln2 <= 0.0:
        return lo, hi
    t2, u2 = sphere(o0, o1, o2, k, b0, b1, b2, r)
    if t2 <= u2:
        if lo > hi:
            lo, hi = t2, u2
        else:
            lo, hi = min(lo, t2), max(hi, u2)
    w0, w1, w2 = o0 - a0, o1 - a1, o2 - a2
    du = u0 if k == 0 else (u1 if k == 1 else u2_)     # e_k . u
    wd = w0 if k == 0 else (w1 if k == 1 else w2)      # w . e_k
    wu = w0 * u0 + w1 * u1 + w2 * u2_
    qa = 1.0 - du * du
    c = w0 * w0 + w1 * w1 + w2 * w2 - wu * wu - r * r
    if qa <= PARALLEL:                  # along the axis: inside the cylinder or not
        if c > 0.0 or du == 0.0:
            return lo, hi
        t_a, t_b = -wu / du, (ln - wu) / du
        c_in, c_out = min(t_a, t_b), max(t_a, t_b)
    else:
        qb = wd - wu * du
        disc = qb * qb - qa * c
        if disc < 0.0:
            return lo, hi
        sq = math.sqrt(disc)
        c_in, c_out = (-qb - sq) / qa, (-qb + sq) / qa
        if du != 0.0:                   # clip to 0 <= s(t) = wu + t du <= ln
            t_a, t_b = -wu / du, (ln - wu) / du
            c_in, c_out = max(c_in, min(t_a, t_b)), min(c_out, max(t_a, t_b))
        elif wu < 0.0 or wu > ln:
            return lo, hi
    if c_in <= c_out:
        if lo > hi:
            return c_in, c_out
        return min(lo, c_in), max(hi, c_out)
    return lo, hi


@njit(cache=True, error_model="numpy")
def _slab(lo, hi, c0, c1, vmin, vmax):
    """[lo, hi] cut to the t where vmin <= c0 + c1 t <= vmax."""
    if c1 == 0.0:
        if c0 < vmin or c0 > vmax:
            return 1.0, -1.0
        return lo, hi
    ta, tb = (vmin - c0) / c1, (vmax - c0) / c1
    if ta > tb:
        ta, tb = tb, ta
    return max(lo, ta), min(hi, tb)


# a move's constants (:func:`move_constants`), one row of floats: its ends, axis, radius,
# length, kind, v = p1 - p0, the shank e = length * axis, the parallelogram's normal n = e x v
P0, P1, AX, RAD, LEN, KIND, V, E, N, NN, VV, HV = 0, 3, 6, 9, 10, 11, 12, 15, 18, 21, 22, 23
# segments (a, b, then :func:`segment`'s 5 floats): the bottom edge [p0, p1], the top edge
# [p0 + e, p1 + e], the sides [p0, p0 + e] and [p1, p1 + e], and ONE: the one capsule of a
# degenerate move (no shank, or a move along the axis)
SEG = 11
BOTTOM, TOP, SIDE0, SIDE1, ONE = 24, 24 + SEG, 24 + 2 * SEG, 24 + 3 * SEG, 24 + 4 * SEG
# the slab: dual vectors g (3), h (3), their products ge, hve, |n|, then g_k / ge, h_k / hve,
# n_k / |n| for k = 0, 1, 2
G, H, GE, HVE, SN, GK, HK, NK = 79, 82, 85, 86, 87, 88, 91, 94
CONSTANTS = 97
GENERAL, CAPSULE = 0.0, 1.0    # KIND: the general sweep, or the capsule ONE alone
NO_SEGMENT = (0.0,) * SEG      # band_row's segment when it has none


@njit(cache=True, error_model="numpy")
def _put_segment(c, at, a0, a1, a2, b0, b1, b2):
    """Segment [a, b] and its :func:`segment` into ``c[at:at + SEG]``."""
    c[at], c[at + 1], c[at + 2], c[at + 3], c[at + 4], c[at + 5] = a0, a1, a2, b0, b1, b2
    c[at + 6], c[at + 7], c[at + 8], c[at + 9], c[at + 10] = segment(a0, a1, a2, b0, b1, b2)


@njit(cache=True, error_model="numpy")
def move_constants(c, p00, p01, p02, p10, p11, p12, ax0, ax1, ax2, r, length):
    """Fill ``c`` (CONSTANTS,) with what :func:`swept_ray` needs of one move (the tool of
    :func:`swept_tool` from p0 to p1), computed once a move by the same operations as per ray
    (the results are bit-identical)."""
    v0, v1, v2 = p10 - p00, p11 - p01, p12 - p02
    e0, e1, e2 = ax0 * length, ax1 * length, ax2 * length
    n0, n1, n2 = e1 * v2 - e2 * v1, e2 * v0 - e0 * v2, e0 * v1 - e1 * v0
    nn = n0 * n0 + n1 * n1 + n2 * n2
    vv = v0 * v0 + v1 * v1 + v2 * v2
    for i, x in enumerate((p00, p01, p02, p10, p11, p12, ax0, ax1, ax2, r, length, GENERAL,
                           v0, v1, v2, e0, e1, e2, n0, n1, n2, nn, vv,
                           v0 * ax0 + v1 * ax1 + v2 * ax2)):
        c[i] = x
    if nn <= PARALLEL * vv * (length * length) or vv == 0.0 or length == 0.0:
        c[KIND] = CAPSULE
        if length == 0.0:
            _put_segment(c, ONE, p00, p01, p02, p10, p11, p12)
        else:
            s0, s1 = min(0.0, c[HV]), max(0.0, c[HV]) + length
            _put_segment(c, ONE, p00 + s0 * ax0, p01 + s0 * ax1, p02 + s0 * ax2,
                         p00 + s1 * ax0, p01 + s1 * ax1, p02 + s1 * ax2)
        return
    _put_segment(c, BOTTOM, p00, p01, p02, p10, p11, p12)
    _put_segment(c, TOP, p00 + e0, p01 + e1, p02 + e2, p10 + e0, p11 + e1, p12 + e2)
    _put_segment(c, SIDE0, p00, p01, p02, p00 + e0, p01 + e1, p02 + e2)
    _put_segment(c, SIDE1, p10, p11, p12, p10 + e0, p11 + e1, p12 + e2)
    # dual vectors: f_e = (v x n) / (e . (v x n)), f_v = (n x e) / (v . (n x e))
    g0, g1, g2 = v1 * n2 - v2 * n1, v2 * n0 - v0 * n2, v0 * n1 - v1 * n0
    h0, h1, h2 = n1 * e2 - n2 * e1, n2 * e0 - n0 * e2, n0 * e1 - n1 * e0
    ge, hve, sn = g0 * e0 + g1 * e1 + g2 * e2, h0 * v0 + h1 * v1 + h2 * v2, math.sqrt(nn)
    for i, x in enumerate((g0, g1, g2, h0, h1, h2, ge, hve, sn, g0 / ge, g1 / ge, g2 / ge,
                           h0 / hve, h1 / hve, h2 / hve, n0 / sn, n1 / sn, n2 / sn)):
        c[G + i] = x


@njit(cache=True, error_model="numpy")
def move_table(p0, p1, axis, radius, length):
    """:func:`move_constants` of every move: (N, CONSTANTS) from p0, p1, axis (N, 3),
    radius, length (N,)."""
    out = np.zeros((p0.shape[0], CONSTANTS))
    for m in range(p0.shape[0]):
        move_constants(out[m], p0[m, 0], p0[m, 1], p0[m, 2], p1[m, 0], p1[m, 1], p1[m, 2],
                       axis[m, 0], axis[m, 1], axis[m, 2], radius[m], length[m])
    return out


@njit(cache=True, error_model="numpy")
def _capsule_at(o0, o1, o2, k, c, at, r):
    """The line against the capsule of segment ``at`` of the move's constants ``c``."""
    return capsule_of(o0, o1, o2, k, c[at], c[at + 1], c[at + 2], c[at + 3], c[at + 4],
                      c[at + 5], c[at + 6], c[at + 7], c[at + 8], c[at + 9], c[at + 10], r)


@njit(cache=True, error_model="numpy")
def _join(lo, hi, t, u):
    """The hull of [lo, hi] (empty when lo > hi) and [t, u] (empty when t > u)."""
    if t > u:
        return lo, hi
    return (t, u) if lo > hi else (min(lo, t), max(hi, u))


@njit(cache=True, error_model="numpy")
def swept_tool(o0, o1, o2, k, p00, p01, p02, p10, p11, p12, ax0, ax1, ax2, r, length,
               tmin=-1e300, tmax=1e300):
    """The line o + t e_k against the tool (ball ``r``, shank to ``length`` along the unit
    axis ``ax``) swept from ``p0`` to ``p1`` (each given by its 3 coordinates): (t_in,
    t_out). ``tmin``, ``tmax``: where the ray's material lies; an end of the swept interval
    beyond them may be returned as +-1e300. One ray: :func:`swept_ray` does the work."""
    c = np.empty(CONSTANTS)
    move_constants(c, p00, p01, p02, p10, p11, p12, ax0, ax1, ax2, r, length)
    return swept_ray(o0, o1, o2, k, c, tmin, tmax)


@njit(cache=True, error_model="numpy")
def _in_band(h, hv, length):
    """Whether height h (mm above p0 along the axis) lies in the shank's band: above both
    centres (0 and hv) and below the lower one's shank top."""
    return h > min(0.0, hv) and max(0.0, hv) <= h <= min(0.0, hv) + length


@njit(cache=True, error_model="numpy")
def band_row(o0, o1, o2, k, v, c):
    """For the row of rays o + t e_k through o (3 coordinates) whose coordinate ``v`` alone
    varies: (True, the band segment's 11 floats: ends a, b, then :func:`segment`'s) when
    :func:`swept_ray` meets every one of them as the capsule of that one segment with the
    same bits (a general move, its axis across k and v, the row at a height h != 0 in the
    shank's band: h sums the terms of k and v, both +-0, and the row's own), else (False,
    zeros). Rows of the Y grid under a +Z axis: the segment once a row, not once a ray."""
    ak, av = c[AX + k], c[AX + v]
    if c[KIND] == CAPSULE or ak != 0.0 or av != 0.0:
        return False, NO_SEGMENT
    p00, p01, p02, p10, p11, p12 = c[P0], c[P0 + 1], c[P0 + 2], c[P1], c[P1 + 1], c[P1 + 2]
    ax0, ax1, ax2 = c[AX], c[AX + 1], c[AX + 2]
    hv = c[HV]
    h = (o0 - p00) * ax0 + (o1 - p01) * ax1 + (o2 - p02) * ax2
    if h == 0.0 or not _in_band(h, hv, c[LEN]):
        return False, NO_SEGMENT
    a0, a1, a2 = p00 + h * ax0, p01 + h * ax1, p02 + h * ax2
    b0, b1, b2 = p10 + (h - hv) * ax0, p11 + (h - hv) * ax1, p12 + (h - hv) * ax2
    return True, (a0, a1, a2, b0, b1, b2) + segment(a0, a1, a2, b0, b1, b2)


@njit(cache=True, error_model="numpy")
def swept_ray(o0, o1, o2, k, c, tmin, tmax):
    """:func:`swept_tool` of the move whose :func:`move_constants` are ``c``."""
    r, length = c[RAD], c[LEN]
    if c[KIND] == CAPSULE:     # a segment: the move along the axis, a shankless ball, no move
        return _capsule_at(o0, o1, o2, k, c, ONE, r)
    p00, p01, p02, p10, p11, p12 = c[P0], c[P0 + 1], c[P0 + 2], c[P1], c[P1 + 1], c[P1 + 2]
    ax0, ax1, ax2 = c[AX], c[AX + 1], c[AX + 2]
    ak = c[AX + k]
    h, hv = 0.0, c[HV]
    if ak == 0.0:
        # a ray across the axis in the shank's band (above both centres, where every
        # vertical segment of the parallelogram spans its height h): the 2-D stadium of the
        # moved segment at h alone, which holds the bottom edge's balls' slice (not computed)
        h = (o0 - p00) * ax0 + (o1 - p01) * ax1 + (o2 - p02) * ax2
        if _in_band(h, hv, length):
            return capsule(o0, o1, o2, k, p00 + h * ax0, p01 + h * ax1,
                           p02 + h * ax2, p10 + (h - hv) * ax0,
                           p11 + (h - hv) * ax1, p12 + (h - hv) * ax2, r)
    lo, hi = _capsule_at(o0, o1, o2, k, c, BOTTOM, r)
    if ak == 1.0 or ak == -1.0:
        # a ray along the axis: the swept balls' lowest and highest points on it come from
        # the bottom and top edges, and it misses both or meets both (the same horizontal
        # distance to them)
        if lo > hi:
            return lo, hi
        ok, pk0, pk1 = o0 if k == 0 else (o1 if k == 1 else o2), c[P0 + k], c[P1 + k]
        if ak > 0.0 and min(pk0, pk1) + length - ok >= tmax:
            return lo, 1e300       # the shank reaches past the material
        if ak < 0.0 and max(pk0, pk1) - length - ok <= tmin:
            return -1e300, hi
        # (a grazing ray may be met by one of them in round-off: then that one alone)
        t, u = _capsule_at(o0, o1, o2, k, c, TOP, r)
        return _join(lo, hi, t, u)
    if ak == 0.0:
        # a ray across the axis at height h above p0 (h, hv from above), not in the band
        if h <= min(0.0, hv):
            return lo, hi          # below both centres: the bottom edge's balls alone
        if h <= min(0.0, hv) + length:
            # between the centres' heights: the balls below h, and the stadium of the part
            # of the moved segment whose vertical segments span h (s hv <= h)
            sa, sb = (0.0, h / hv) if hv > 0.0 else (h / hv, 1.0)
            v0, v1, v2 = c[V], c[V + 1], c[V + 2]
            t, u = capsule(o0, o1, o2, k, p00 + sa * v0 + (h - sa * hv) * ax0,
                           p01 + sa * v1 + (h - sa * hv) * ax1,
                           p02 + sa * v2 + (h - sa * hv) * ax2,
                           p00 + sb * v0 + (h - sb * hv) * ax0,
                           p01 + sb * v1 + (h - sb * hv) * ax1,
                           p02 + sb * v2 + (h - sb * hv) * ax2, r)
            return _join(lo, hi, t, u)
    return _parallelogram(o0, o1, o2, k, c, r, lo, hi)


@njit(cache=True, error_model="numpy")
def _parallelogram(o0, o1, o2, k, c, r, lo, hi):
    """The general case of :func:`swept_ray`: [lo, hi] (the bottom edge's capsule) united
    with the other three edges' capsules and the parallelogram's slab (normal n = e x v)."""
    for at in (TOP, SIDE0, SIDE1):
        t, u = _capsule_at(o0, o1, o2, k, c, at, r)
        if t <= u:
            lo, hi = (t, u) if lo > hi else (min(lo, t), max(hi, u))
    # the slab: x - p0 = alpha e + beta v + gamma n, 0 <= alpha, beta <= 1, |gamma| |n| <= r
    w0, w1, w2 = o0 - c[P0], o1 - c[P0 + 1], o2 - c[P0 + 2]
    ta, tb = -1e300, 1e300
    ta, tb = _slab(ta, tb, (c[G] * w0 + c[G + 1] * w1 + c[G + 2] * w2) / c[GE], c[GK + k],
                   0.0, 1.0)
    ta, tb = _slab(ta, tb, (c[H] * w0 + c[H + 1] * w1 + c[H + 2] * w2) / c[HVE], c[HK + k],
                   0.0, 1.0)
    ta, tb = _slab(ta, tb, (c[N] * w0 + c[N + 1] * w1 + c[N + 2] * w2) / c[SN], c[NK + k],
                   -r, r)
    if ta <= tb:
        lo, hi = (ta, tb) if lo > hi else (min(lo, ta), max(hi, tb))
    return lo, hi
