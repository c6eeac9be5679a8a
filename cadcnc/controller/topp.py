"""Time-optimal speed along a fixed path under per-axis acceleration limits (compiled).

The phase plane of one run: at grid point k the squared speed w_k = v², on knot k the
tangential acceleration u_k (constant, so w_{k+1} = w_k + 2 h_k u_k). At both ends of a
knot, per axis i, for every T_i in [Tc - Tr, Tc + Tr] and K_i in [Kc - Kr, Kc + Kr] (the
path's derivatives anywhere the smoothed motion can be when it is there):

    |T_i u + K_i w| <= A_i          (the axis's acceleration)
    3 Kmax_i v |u| <= C_i            (the jerk's Coriolis term, C_i a share of J_i)
    w <= wl                          (every speed limit: feed, velocity, jerk terms)

A backward pass finds the largest speed from which the rest of the run can still stop in
time (the feasible speeds at a point form an interval from 0: a bisection finds its top);
a forward pass then accelerates as hard as the constraints and that speed allow. The
result is the time-optimal profile on the grid (the reachability analysis of TOPP-RA,
Pham & Pham 2018, with the constraints above). Lengths mm, speeds mm/s, times s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

BISECTIONS = 48   # the top of a point's feasible speeds to 2^-48 of its limit


@njit(cache=True, error_model="numpy")
def _bounds(k: int, w: float, h: float, Tc, Tr, Kc, Kr, Kmax, A, C) -> tuple:
    """(lo, hi): the tangential accelerations on knot k (length h > 0) feasible from w."""
    lo, hi = -w / (2.0 * h), math.inf
    for e in range(2):
        j = k + e
        reach = 2.0 * h if e == 1 else 0.0
        for i in range(3):
            for s1 in (-1.0, 1.0):
                kw = s1 * Kc[j, i] + Kr[j, i]
                for s2 in (-1.0, 1.0):
                    cu = s1 * Tc[j, i] + s2 * Tr[j, i] + kw * reach
                    rhs = A[i] - kw * w
                    if cu > 0.0:
                        hi = min(hi, rhs / cu)
                    elif cu < 0.0:
                        lo = max(lo, rhs / cu)
                    elif rhs < 0.0:
                        return 1.0, -1.0
    if w > 0.0:
        for i in range(3):
            km = max(Kmax[k, i], Kmax[k + 1, i])
            if km > 0.0:
                c = C[i] / (3.0 * km * math.sqrt(w))
                lo, hi = max(lo, -c), min(hi, c)
    return lo, hi


@njit(cache=True, error_model="numpy")
def _feasible(k, w, h, w_next, Tc, Tr, Kc, Kr, Kmax, A, C) -> bool:
    lo, hi = _bounds(k, w, h, Tc, Tr, Kc, Kr, Kmax, A, C)
    return lo <= hi and w + 2.0 * h * lo <= w_next + 1e-12 * w   # (w - w: round-off)


@njit(cache=True, error_model="numpy")
def passes(s, wl, Tc, Tr, Kc, Kr, Kmax, A, C):
    """(w (n,), u (n - 1,)): the time-optimal squared speeds from rest at s[0] to rest at
    s[-1] and the accelerations between (knots of length 0, a join, keep the speed)."""
    n = len(s)
    wb = np.empty(n)
    wb[n - 1] = 0.0
    for k in range(n - 2, -1, -1):
        h = s[k + 1] - s[k]
        top = wl[k]
        if h <= 0.0:
            wb[k] = min(top, wb[k + 1])
            continue
        if _feasible(k, top, h, wb[k + 1], Tc, Tr, Kc, Kr, Kmax, A, C):
            wb[k] = top
            continue
        a, b = 0.0, top
        for _ in range(BISECTIONS):
            m = 0.5 * (a + b)
            if _feasible(k, m, h, wb[k + 1], Tc, Tr, Kc, Kr, Kmax, A, C):
                a = m
            else:
                b = m
        wb[k] = a
    w = np.empty(n)
    u = np.zeros(n - 1)
    w[0] = 0.0
    for k in range(n - 1):
        h = s[k + 1] - s[k]
        if h <= 0.0:
            w[k + 1] = min(w[k], wb[k + 1])
            continue
        lo, hi = _bounds(k, w[k], h, Tc, Tr, Kc, Kr, Kmax, A, C)
        x = min(hi, (wb[k + 1] - w[k]) / (2.0 * h))
        x = max(x, lo)
        u[k] = x
        w[k + 1] = min(max(w[k] + 2.0 * h * x, 0.0), wb[k + 1])
    return w, u


@njit(cache=True, error_model="numpy")
def erode(s, wl, window: float):
    """Each limit w_k applied over s_k +- sqrt(w_k) window: a motion averaged over
    ``window`` s whose every speed kept the limits is then within them where it is."""
    n = len(s)
    out = wl.copy()
    for k in range(n):
        r = math.sqrt(wl[k]) * window
        if not math.isfinite(r):
            continue
        j = k - 1
        while j >= 0 and s[k] - s[j] <= r:
            out[j] = min(out[j], wl[k])
            j -= 1
        j = k + 1
        while j < n and s[j] - s[k] <= r:
            out[j] = min(out[j], wl[k])
            j += 1
    return out


@njit(cache=True, error_model="numpy")
def boxes(s, x, reach: float):
    """(lo, hi) (n, 3): the smallest and largest x over s_k +- reach."""
    n = len(s)
    lo, hi = x.copy(), x.copy()
    a = 0
    b = 0
    for k in range(n):
        while s[k] - s[a] > reach:
            a += 1
        while b + 1 < n and s[b + 1] - s[k] <= reach:
            b += 1
        for i in range(3):
            mn, mx = x[a, i], x[a, i]
            for j in range(a + 1, b + 1):
                mn = min(mn, x[j, i])
                mx = max(mx, x[j, i])
            lo[k, i], hi[k, i] = mn, mx
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
    curvature jump's one-period jolt at the speed limits (inf: no room)."""
    n = len(t)
    need = np.zeros(n - 1)
    lo = 0
    for k in range(n - 1):   # the windows ending on knot k: knots lo..k
        while t[lo + 1] <= t[k] - window:
            lo += 1
        amin, amax, vmax = a[k], a[k], max(v[k], v[k + 1])
        for j in range(lo, k):
            amin = min(amin, a[j])
            amax = max(amax, a[j])
            vmax = max(vmax, v[j])
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
def flatten(s, t, w, u, wl, need, window: float) -> int:
    """Lower ``wl`` (in place) so that each turn of the profile that needs a longer window
    than ``window`` (acceleration straight into deceleration at a peak, or the reverse at
    a valley) becomes a cruise of at least ``window`` s; the turns flattened."""
    n = len(s)
    done = 0
    tiny = 1e-9 * np.max(np.abs(u)) if len(u) else 0.0
    k = 0
    while k < n - 1:
        if need[k] <= window:
            k += 1
            continue
        q = k   # the turn in the window ending on knot k: u's last sign, then the other
        while q > 0 and abs(u[q]) <= tiny:
            q -= 1
        p = q
        while p > 0 and t[p] > t[k] - 2.0 * window and not (u[p] * u[q] < 0.0 and
                                                             abs(u[p]) > tiny):
            p -= 1
        if not (u[p] * u[q] < 0.0 and abs(u[p]) > tiny):
            k += 1
            continue
        j = p + 1
        for i in range(p + 1, q + 1):
            if (w[i] > w[j]) if u[p] > 0.0 else (w[i] < w[j]):
                j = i
        if u[p] > 0.0:   # a peak at j: the highest level cruising >= window
            lo, hi = 0.0, w[j]
            for _ in range(40):
                m = 0.5 * (lo + hi)
                a = j
                while a > 0 and w[a - 1] >= m:
                    a -= 1
                b = j
                while b < n - 1 and w[b + 1] >= m:
                    b += 1
                if s[b] - s[a] >= math.sqrt(m) * window:
                    lo = m
                else:
                    hi = m
            if lo <= 1e-6 * w[j]:   # no level cruises long enough: the window grows
                k += 1
                continue
            a = j
            while a > 0 and w[a - 1] >= lo:
                a -= 1
            b = j
            while b < n - 1 and w[b + 1] >= lo:
                b += 1
            for i in range(a, b + 1):
                wl[i] = min(wl[i], lo)
        elif w[j] <= 0.0:    # a stop at j: nothing to hold
            k += 1
            continue
        else:                # a valley at j: hold its speed over +-v window / 2
            r = 0.5 * math.sqrt(w[j]) * window
            i = j
            while i >= 0 and s[j] - s[i] <= r:
                wl[i] = min(wl[i], w[j])
                i -= 1
            i = j
            while i < n and s[i] - s[j] <= r:
                wl[i] = min(wl[i], w[j])
                i += 1
        done += 1
        k += 1
        while k < n - 1 and t[k] <= t[j] + window:
            k += 1
    return done
