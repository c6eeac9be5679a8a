"""Time-optimal speed along a fixed path under per-axis acceleration limits (compiled).

The phase plane of one run: at grid point k the squared speed w_k = v², on knot k the
tangential acceleration u_k (constant, so w_{k+1} = w_k + 2 h_k u_k). At both ends of a
knot, per axis i, for every T_i in [Tc - Tr, Tc + Tr] and K_i in [Kc - Kr, Kc + Kr] (the
path's derivatives anywhere the smoothed motion can be when it is there):

    |T_i u + K_i w| <= A_i          (the axis's acceleration)
    3 Kmax_i v |u| <= C_i            (the jerk's Coriolis term, C_i a share of J_i)
    w <= wl                          (every speed limit: feed, velocity, jerk terms)

A backward pass finds the largest speed from which the rest of the run can still stop in
time (the feasible speeds at a point form an interval from 0: :func:`.knot.largest`
finds its top in closed form);
a forward pass then accelerates as hard as the constraints and that speed allow. The
result is the time-optimal profile on the grid (the reachability analysis of TOPP-RA,
Pham & Pham 2018, with the constraints above). Lengths mm, speeds mm/s, times s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .knot import ROWS, bounds, coefficients, feasible, largest
from .reach import dequeue, enqueue


@njit(cache=True, error_model="numpy")
def passes(s, wl, Tc, Tr, Kc, Kr, Kmax, A, C):
    """(w (n,), u (n - 1,)): the time-optimal squared speeds from rest at s[0] to rest at
    s[-1] and the accelerations between (knots of length 0, a join, keep the speed)."""
    n = len(s)
    cu, cw, rhs = np.empty((n, ROWS)), np.empty((n, ROWS)), np.empty((n, ROWS))
    cor = np.empty(n)   # each knot's constraints, made once for both passes
    rows = np.zeros(n, dtype=np.int64)   # how many of each knot's rows are written
    buf = np.empty((4, ROWS + 1))   # largest's: the affine bounds on u
    a_max = np.max(np.abs(A))
    wb = np.empty(n)
    wb[n - 1] = 0.0
    for k in range(n - 2, -1, -1):
        h = s[k + 1] - s[k]
        top = wl[k]
        if h <= 0.0:
            wb[k] = min(top, wb[k + 1])
            continue
        cor[k], m = coefficients(k, h, Tc, Tr, Kc, Kr, Kmax, A, C, cu[k], cw[k], rhs[k])
        rows[k] = m
        if feasible(top, h, wb[k + 1], cu[k, :m], cw[k, :m], rhs[k, :m], cor[k]):
            wb[k] = top
        else:
            wb[k] = largest(top, h, wb[k + 1], cu[k, :m], cw[k, :m], rhs[k, :m], cor[k],
                            buf, a_max)
    w = np.empty(n)
    u = np.zeros(n - 1)
    w[0] = 0.0
    for k in range(n - 1):
        h = s[k + 1] - s[k]
        if h <= 0.0:
            w[k + 1] = min(w[k], wb[k + 1])
            continue
        m = rows[k]
        lo, hi = bounds(w[k], h, cu[k, :m], cw[k, :m], rhs[k, :m], cor[k])
        x = min(hi, (wb[k + 1] - w[k]) / (2.0 * h))
        x = max(x, lo)
        u[k] = x
        w[k + 1] = min(max(w[k] + 2.0 * h * x, 0.0), wb[k + 1])
    return w, u


@njit(cache=True, error_model="numpy")
def knot_at(t, tau: float, k: int) -> int:
    """The knot holding ``tau``: the last k <= n - 2 with t[k] <= tau (0 before the
    start), searched forward from ``k`` (a knot at or before it: callers whose times
    only grow keep it, so that a sweep is linear)."""
    last = len(t) - 2
    k = min(max(k, 0), last)
    while k < last and t[k + 1] <= tau:
        k += 1
    return k


@njit(cache=True, error_model="numpy")
def _integral(t, s, v, a, S, tau: float, k: int) -> float:
    """The time integral of s(t) from 0 to tau (s = 0 before 0, s[-1] after the end);
    ``k``: a knot at or before tau's (:func:`knot_at`)."""
    if tau <= 0.0:
        return 0.0
    n = len(t)
    end = t[n - 1]
    k = knot_at(t, tau, k)
    x = min(tau, end) - t[k]
    return (S[k] + s[k] * x + v[k] * x * x / 2.0 + a[k] * x ** 3 / 6.0
            + s[n - 1] * max(tau - end, 0.0))


@njit(cache=True, error_model="numpy")
def averaged(t, s, v, a, S, window: float, tau: float, k: int = 0) -> float:
    """s(t) averaged over the ``window`` s before ``tau`` (s(tau) itself if window 0);
    ``k``: a knot at or before that of tau - window (0: search from the start)."""
    if window <= 0.0:
        n = len(t)
        k = knot_at(t, tau, k)
        y = min(max(tau, 0.0), t[n - 1]) - t[k]
        return min(max(s[k] + v[k] * y + a[k] * y * y / 2.0, 0.0), s[n - 1])
    early = knot_at(t, tau - window, k)
    x = (_integral(t, s, v, a, S, tau, early)
         - _integral(t, s, v, a, S, tau - window, early)) / window
    return min(max(x, 0.0), s[len(s) - 1])


@njit(cache=True, error_model="numpy")
def averaged_sweep(t, s, v, a, S, window: float, tau, out) -> None:
    """:func:`averaged` at every time of ``tau`` (non-decreasing) into ``out``, in one
    forward sweep of the knots."""
    k = 0
    for i in range(len(tau)):
        out[i] = averaged(t, s, v, a, S, window, tau[i], k)
        k = knot_at(t, tau[i] - window, k)


@njit(cache=True, error_model="numpy")
def ranges(t, s, v, a, S, window: float):
    """(lo, hi) (n,): where the averaged motion is while grid point k is in its window,
    s_f(t_k) .. s_f(t_k + window): every place whose path derivatives meet this point's
    speed and acceleration."""
    n = len(t)
    lo, hi = np.empty(n), np.empty(n)
    k0 = k1 = 0
    for k in range(n):   # t only grows: both searches sweep forward
        lo[k] = min(averaged(t, s, v, a, S, window, t[k], k0), s[k])
        hi[k] = max(averaged(t, s, v, a, S, window, t[k] + window, k1), s[k])
        k0 = knot_at(t, t[k] - window, k0)   # the knots these calls started from
        k1 = knot_at(t, (t[k] + window) - window, k1)
    return lo, hi


@njit(cache=True, error_model="numpy")
def time_law(s, w, u):
    """t (n,), v (n,), a (n,) and the time integral S (n,) of s on the grid (knots of length
    0 take no time)."""
    n = len(s)
    v = np.sqrt(np.maximum(w, 0.0))
    t, a, S = np.zeros(n), np.zeros(n), np.zeros(n)
    for i in range(n - 1):
        h = s[i + 1] - s[i]
        dt = 2.0 * h / (v[i] + v[i + 1]) if h > 0.0 else 0.0
        a[i] = u[i] if h > 0.0 else 0.0
        t[i + 1] = t[i] + dt
        S[i + 1] = S[i] + (s[i] * dt + v[i] * dt ** 2 / 2.0 + a[i] * dt ** 3 / 6.0)
    return t, v, a, S


@njit(cache=True, error_model="numpy")
def window_needed(t, v, a, Tabs, Kmax, static, J, C, window: float):
    """(n - 1,) per knot k, the shortest averaging window (s) that keeps every axis's jerk
    within J in the windows ending on knot k once the profile (t, v, a) is averaged over
    ``window``: the tangential part |T_i| (a(t) - a(t - W)) / W takes what the curvature
    terms leave, the Coriolis term 3 K v a and ``static`` (n, 3), D v³ and a join's or a
    curvature jump's one-period jolt at the speed limits (inf: no room). The extremes of
    a and v over knots lo..k come from sliding-window queues (:mod:`.reach`, O(n))."""
    n = len(t)
    need = np.zeros(n - 1)
    qlo = np.empty(n, dtype=np.int64)   # knots with rising a (the window's minimum first)
    qhi = np.empty(n, dtype=np.int64)   # knots with falling a (its maximum first)
    qv = np.empty(n, dtype=np.int64)    # grid points with falling v
    h1 = t1 = h2 = t2 = h3 = t3 = 0
    lo = 0
    for k in range(n - 1):   # the windows ending on knot k: knots lo..k
        while t[lo + 1] <= t[k] - window:
            lo += 1
        t1 = enqueue(qlo, h1, t1, a, k, -1.0)
        t2 = enqueue(qhi, h2, t2, a, k, 1.0)
        t3 = enqueue(qv, h3, t3, v, k, 1.0)
        h1 = dequeue(qlo, h1, t1, lo)
        h2 = dequeue(qhi, h2, t2, lo)
        h3 = dequeue(qv, h3, t3, lo)
        amin, amax, vmax = a[k], a[k], max(v[k], v[k + 1])
        if h1 < t1:
            amin = min(amin, a[qlo[h1]])
        if h2 < t2:
            amax = max(amax, a[qhi[h2]])
        if h3 < t3:
            vmax = max(vmax, v[qv[h3]])
        da = amax - amin
        if da <= 0.0:
            continue
        am = max(abs(amin), abs(amax))
        for i in range(3):
            curv = min(3.0 * Kmax[k, i] * vmax * am, C[i]) + static[k, i]
            room = J[i] - curv
            if room <= 0.0:
                need[k] = math.inf
                break
            need[k] = max(need[k], Tabs[k, i] * da / room)
    return need


@njit(cache=True, error_model="numpy")
def _above(w, j: int, level: float) -> tuple:
    """(a, b): the grid points around j where w >= level, without a gap."""
    a = j
    while a > 0 and w[a - 1] >= level:
        a -= 1
    b = j
    while b < len(w) - 1 and w[b + 1] >= level:
        b += 1
    return a, b


@njit(cache=True, error_model="numpy")
def _turn(t, u, k: int, window: float, tiny: float) -> tuple:
    """(p, q): knots before and after the last sign change of the acceleration in the
    windows ending on knot k (u[p] and u[q] of opposite signs), or (-1, -1)."""
    q = k
    while q > 0 and abs(u[q]) <= tiny:
        q -= 1
    p = q
    while p > 0 and t[p] > t[k] - 2.0 * window and not (u[p] * u[q] < 0.0
                                                         and abs(u[p]) > tiny):
        p -= 1
    if u[p] * u[q] < 0.0 and abs(u[p]) > tiny:
        return p, q
    return -1, -1


@njit(cache=True, error_model="numpy")
def _flatten_at(s, w, u, wl, p: int, q: int, window: float) -> bool:
    """Lower ``wl`` around the turn between knots p and q into a cruise of ``window`` s:
    a peak to the highest level held that long, a valley's speed held over +-v window /
    2. False if nothing can be done (a peak too short to cruise, a stop)."""
    peak = u[p] > 0.0
    j = p + 1
    for i in range(p + 1, q + 1):
        if (w[i] > w[j]) if peak else (w[i] < w[j]):
            j = i
    if peak:
        lo, hi = 0.0, w[j]
        for _ in range(40):
            m = 0.5 * (lo + hi)
            a, b = _above(w, j, m)
            if s[b] - s[a] >= math.sqrt(m) * window:
                lo = m
            else:
                hi = m
        if lo <= 1e-6 * w[j]:   # relative to w: no feed left (round-off of the bisection)
            return False
        a, b = _above(w, j, lo)
        for i in range(a, b + 1):
            wl[i] = min(wl[i], lo)
        return True
    if w[j] <= 0.0:
        return False
    r = 0.5 * math.sqrt(w[j]) * window
    for i in range(len(s)):
        if abs(s[i] - s[j]) <= r:
            wl[i] = min(wl[i], w[j])
    return True


@njit(cache=True, error_model="numpy")
def flatten(s, t, w, u, wl, need, window: float) -> int:
    """Lower ``wl`` (in place) so that each turn of the profile that needs a longer window
    than ``window`` (acceleration straight into deceleration at a peak, or the reverse at
    a valley) becomes a cruise of at least ``window`` s; the turns flattened."""
    n = len(s)
    done = 0
    tiny = 1e-9 * np.max(np.abs(u)) if len(u) else 0.0   # relative: round-off of u
    k = 0
    while k < n - 1:
        if need[k] > window:
            p, q = _turn(t, u, k, window, tiny)
            if p >= 0 and _flatten_at(s, w, u, wl, p, q, window):
                done += 1
                end = t[q] + window   # the next turn lies past this one's window
                k += 1   # and past k (a cruise before k can put q's window behind it)
                while k < n - 1 and t[k] <= end:
                    k += 1
                continue
        k += 1
    return done
