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
def capsule(o0, o1, o2, k, a0, a1, a2, b0, b1, b2, r):
    """The line o + t e_k against the points within ``r`` of the segment [a, b]."""
    d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
    ln2 = d0 * d0 + d1 * d1 + d2 * d2
    lo, hi = sphere(o0, o1, o2, k, a0, a1, a2, r)
    if ln2 <= 0.0:
        return lo, hi
    t2, u2 = sphere(o0, o1, o2, k, b0, b1, b2, r)
    if t2 <= u2:
        if lo > hi:
            lo, hi = t2, u2
        else:
            lo, hi = min(lo, t2), max(hi, u2)
    ln = math.sqrt(ln2)
    u0, u1, u2_ = d0 / ln, d1 / ln, d2 / ln
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


@njit(cache=True, error_model="numpy")
def swept_tool(o0, o1, o2, k, p00, p01, p02, p10, p11, p12, ax0, ax1, ax2, r, length,
               tmin=-1e300, tmax=1e300):
    """The line o + t e_k against the tool (ball ``r``, shank to ``length`` along the unit
    axis ``ax``) swept from ``p0`` to ``p1`` (each given by its 3 coordinates, scalars so
    that a call allocates nothing): (t_in, t_out). ``tmin``, ``tmax``: where the ray's
    material lies; an end of the swept interval beyond them may be returned as +-1e300."""
    v0, v1, v2 = p10 - p00, p11 - p01, p12 - p02
    e0, e1, e2 = ax0 * length, ax1 * length, ax2 * length
    # n = e x v: the parallelogram's normal (unnormalised)
    n0, n1, n2 = e1 * v2 - e2 * v1, e2 * v0 - e0 * v2, e0 * v1 - e1 * v0
    nn = n0 * n0 + n1 * n1 + n2 * n2
    vv = v0 * v0 + v1 * v1 + v2 * v2
    ee = length * length
    if nn <= PARALLEL * vv * ee or vv == 0.0 or length == 0.0:
        # a segment: the move along the axis, a shankless ball, or no move
        if length == 0.0:
            return capsule(o0, o1, o2, k, p00, p01, p02, p10, p11, p12, r)
        s0 = min(0.0, v0 * ax0 + v1 * ax1 + v2 * ax2)
        s1 = max(0.0, v0 * ax0 + v1 * ax1 + v2 * ax2) + length
        return capsule(o0, o1, o2, k, p00 + s0 * ax0, p01 + s0 * ax1,
                       p02 + s0 * ax2, p00 + s1 * ax0, p01 + s1 * ax1,
                       p02 + s1 * ax2, r)
    ak = ax0 if k == 0 else (ax1 if k == 1 else ax2)
    h, hv = 0.0, 0.0
    if ak == 0.0:
        # a ray across the axis in the shank's band (above both centres, where every
        # vertical segment of the parallelogram spans its height h): the 2-D stadium of the
        # moved segment at h alone, which holds the bottom edge's balls' slice (not computed)
        h = (o0 - p00) * ax0 + (o1 - p01) * ax1 + (o2 - p02) * ax2
        hv = v0 * ax0 + v1 * ax1 + v2 * ax2
        if h > min(0.0, hv) and max(0.0, hv) <= h <= min(0.0, hv) + length:
            return capsule(o0, o1, o2, k, p00 + h * ax0, p01 + h * ax1,
                           p02 + h * ax2, p10 + (h - hv) * ax0,
                           p11 + (h - hv) * ax1, p12 + (h - hv) * ax2, r)
    lo, hi = capsule(o0, o1, o2, k, p00, p01, p02, p10, p11, p12, r)
    if ak == 1.0 or ak == -1.0:
        # a ray along the axis: the swept balls' lowest and highest points on it come from
        # the bottom and top edges, and it misses both or meets both (the same horizontal
        # distance to them)
        if lo > hi:
            return lo, hi
        ok, pk0, pk1 = (o0, p00, p10) if k == 0 else ((o1, p01, p11) if k == 1 else
                                                       (o2, p02, p12))
        if ak > 0.0 and min(pk0, pk1) + length - ok >= tmax:
            return lo, 1e300       # the shank reaches past the material
        if ak < 0.0 and max(pk0, pk1) - length - ok <= tmin:
            return -1e300, hi
        t, u = capsule(o0, o1, o2, k, p00 + e0, p01 + e1, p02 + e2,
                       p10 + e0, p11 + e1, p12 + e2, r)
        if t > u:               # a grazing ray, met by one of them in round-off
            return lo, hi
        return min(lo, t), max(hi, u)
    if ak == 0.0:
        # a ray across the axis at height h above p0 (h, hv from above), not in the band
        if h <= min(0.0, hv):
            return lo, hi          # below both centres: the bottom edge's balls alone
        if h <= min(0.0, hv) + length:
            # between the centres' heights: the balls below h, and the stadium of the part
            # of the moved segment whose vertical segments span h (s hv <= h)
            sa, sb = (0.0, h / hv) if hv > 0.0 else (h / hv, 1.0)
            t, u = capsule(o0, o1, o2, k, p00 + sa * v0 + (h - sa * hv) * ax0,
                           p01 + sa * v1 + (h - sa * hv) * ax1,
                           p02 + sa * v2 + (h - sa * hv) * ax2,
                           p00 + sb * v0 + (h - sb * hv) * ax0,
                           p01 + sb * v1 + (h - sb * hv) * ax1,
                           p02 + sb * v2 + (h - sb * hv) * ax2, r)
            if t > u:
                return lo, hi
            return (t, u) if lo > hi else (min(lo, t), max(hi, u))
    return _parallelogram(o0, o1, o2, k, p00, p01, p02, p10, p11, p12, v0, v1, v2, e0, e1,
                          e2, n0, n1, n2, r, lo, hi)


@njit(cache=True, error_model="numpy")
def _parallelogram(o0, o1, o2, k, p00, p01, p02, p10, p11, p12, v0, v1, v2, e0, e1, e2, n0,
                   n1, n2, r, lo, hi):
    """The general case of :func:`swept_tool`: [lo, hi] (the bottom edge's capsule) united
    with the other three edges' capsules and the parallelogram's slab (normal n = e x v)."""
    nn = n0 * n0 + n1 * n1 + n2 * n2
    t, u = capsule(o0, o1, o2, k, p00 + e0, p01 + e1, p02 + e2,
                   p10 + e0, p11 + e1, p12 + e2, r)
    if t <= u:
        lo, hi = (t, u) if lo > hi else (min(lo, t), max(hi, u))
    t, u = capsule(o0, o1, o2, k, p00, p01, p02, p00 + e0, p01 + e1, p02 + e2, r)
    if t <= u:
        lo, hi = (t, u) if lo > hi else (min(lo, t), max(hi, u))
    t, u = capsule(o0, o1, o2, k, p10, p11, p12, p10 + e0, p11 + e1, p12 + e2, r)
    if t <= u:
        lo, hi = (t, u) if lo > hi else (min(lo, t), max(hi, u))
    # the slab: x - p0 = alpha e + beta v + gamma n, 0 <= alpha, beta <= 1, |gamma| |n| <= r
    w0, w1, w2 = o0 - p00, o1 - p01, o2 - p02
    # dual vectors: f_e = (v x n) / (e . (v x n)), f_v = (n x e) / (v . (n x e))
    g0, g1, g2 = v1 * n2 - v2 * n1, v2 * n0 - v0 * n2, v0 * n1 - v1 * n0
    ge = g0 * e0 + g1 * e1 + g2 * e2
    h0, h1, h2 = n1 * e2 - n2 * e1, n2 * e0 - n0 * e2, n0 * e1 - n1 * e0
    hv = h0 * v0 + h1 * v1 + h2 * v2
    sn = math.sqrt(nn)
    ta, tb = -1e300, 1e300
    gk = g0 if k == 0 else (g1 if k == 1 else g2)
    ta, tb = _slab(ta, tb, (g0 * w0 + g1 * w1 + g2 * w2) / ge, gk / ge, 0.0, 1.0)
    hk = h0 if k == 0 else (h1 if k == 1 else h2)
    ta, tb = _slab(ta, tb, (h0 * w0 + h1 * w1 + h2 * w2) / hv, hk / hv, 0.0, 1.0)
    nk = n0 if k == 0 else (n1 if k == 1 else n2)
    ta, tb = _slab(ta, tb, (n0 * w0 + n1 * w1 + n2 * w2) / sn, nk / sn, -r, r)
    if ta <= tb:
        lo, hi = (ta, tb) if lo > hi else (min(lo, ta), max(hi, tb))
    return lo, hi
