"""The jerk of a run's averaged motion itself, axis by axis (compiled).

:func:`.topp.window_needed` bounds the averaged motion's curvature terms by the window's
highest speed times its largest acceleration, which a steep start makes large: a window
it calls too short is often long enough. :func:`peak_share` measures instead. The raw
profile (t, s, v, a) has a constant acceleration on each knot, so on every interval
between two consecutive times of {t_k} and {t_k + W} the averaged motion's jerk
j_f = (a(x) - a(x - W)) / W is constant and its speed and acceleration are polynomials
(v_f = (s(x) - s(x - W)) / W, a_f = (v(x) - v(x - W)) / W). Per axis i the jerk

    |T_i(s_f) j_f + 3 K_i(s_f) v_f a_f| + D_i(s_f) v_f^3   (D = |p'''|: at its worst sign)

is evaluated at both ends and the middle of every interval, with T, K, D interpolated
linearly on the run's grid at the averaged arc length s_f; a join's jolt is added where
the motion passes it. Lengths mm, times s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .topp import knot_at


@njit(cache=True, error_model="numpy")
def _raw(t, s, v, a, S, k: int, x: float) -> tuple:
    """(time integral of s from 0, s, v, a) of the raw profile at time ``x`` by knot
    ``k``'s polynomial (its values at the ends of the knot's interval are the limits
    from inside)."""
    y = x - t[k]
    return (S[k] + s[k] * y + v[k] * y * y / 2.0 + a[k] * y ** 3 / 6.0,
            s[k] + v[k] * y + a[k] * y * y / 2.0, v[k] + a[k] * y, a[k])


@njit(cache=True, error_model="numpy")
def _merged(t, window: float):
    """(2n,) the times t (non-decreasing) and t + window in order: two sorted
    sequences merged (O(n), the same values a sort gives)."""
    n = len(t)
    out = np.empty(2 * n)
    i = j = 0
    for q in range(2 * n):
        if j >= n or (i < n and t[i] <= t[j] + window):
            out[q] = t[i]
            i += 1
        else:
            out[q] = t[j] + window
            j += 1
    return out


@njit(cache=True, error_model="numpy")
def peak_share(t, s, v, a, S, window: float, grid, T, K, D, jump, kink, J,
               period: float) -> float:
    """The largest (|T_i j + 3 K_i v a| + D_i v^3) / J_i of the profile (t, s, v, a, S:
    :func:`.topp.time_law`'s) averaged over ``window`` s (> 0), over its whole duration
    and every axis; ``grid`` (n,) and T, K, D, jump, kink (n, 3) the run's path
    derivatives and joins (a join's one-period jolt, |jump_i| v^2 / period + |kink_i| v /
    period^2, added where the averaged motion passes it, at its speed there)."""
    inf = np.full(3, np.inf)
    return shares(t, s, v, a, S, window, grid, T, K, D, jump, kink, inf, inf, J, period,
                  np.full(len(grid), np.inf))[2]


@njit(cache=True, error_model="numpy")
def shares(t, s, v, a, S, window: float, grid, T, K, D, jump, kink, V, A, J,
           period: float, cap) -> tuple:
    """(velocity, acceleration, jerk): the largest shares of the limits that the profile
    averaged over ``window`` takes, measured as :func:`peak_share` measures the jerk:
    |T_i v| / V_i and the speed over the programmed one ``cap`` (n,) (the lower of the
    two grid points around), |T_i a + K_i v^2| / A_i."""
    n = len(t)
    times = _merged(t, window)
    worst_v = worst_a = worst = 0.0
    k1 = k0 = g = 0
    end = t[n - 1]
    for q in range(2 * n - 1):
        lo, hi = times[q], times[q + 1]
        if not hi > lo:
            continue
        mid = 0.5 * (lo + hi)
        # the knots holding the interval now and one window before: one polynomial each
        k1 = knot_at(t, mid, k1)
        k0 = knot_at(t, mid - window, k0)
        ended, started = mid > end, mid - window > 0.0   # at rest after, before
        for x in (lo, mid, hi):
            if ended:
                i1, s1, v1, a1 = S[n - 1] + s[n - 1] * (x - end), s[n - 1], 0.0, 0.0
            else:
                i1, s1, v1, a1 = _raw(t, s, v, a, S, k1, x)
            if started:
                i0, s0, v0, a0 = _raw(t, s, v, a, S, k0, x - window)
            else:
                i0, s0, v0, a0 = 0.0, s[0], 0.0, 0.0
            vf = (s1 - s0) / window
            af = (v1 - v0) / window
            jf = (a1 - a0) / window
            sf = (i1 - i0) / window
            while g < n - 2 and grid[g + 1] <= sf:
                g += 1
            h = grid[g + 1] - grid[g]
            f = min(max((sf - grid[g]) / h, 0.0), 1.0) if h > 0.0 else 0.0
            worst_v = max(worst_v, vf / min(cap[g], cap[g + 1]))
            for i in range(3):
                Ti = T[g, i] + f * (T[g + 1, i] - T[g, i])
                Ki = K[g, i] + f * (K[g + 1, i] - K[g, i])
                Di = D[g, i] + f * (D[g + 1, i] - D[g, i])
                jolt = (max(abs(jump[g, i]), abs(jump[g + 1, i])) * vf * vf / period
                        + max(abs(kink[g, i]), abs(kink[g + 1, i])) * vf / period ** 2)
                jerk = abs(Ti * jf + 3.0 * Ki * vf * af) + Di * vf ** 3 + jolt
                if not math.isfinite(jerk):
                    return math.inf, math.inf, math.inf
                worst = max(worst, jerk / J[i])
                worst_v = max(worst_v, abs(Ti * vf) / V[i])
                worst_a = max(worst_a, abs(Ti * af + Ki * vf * vf) / A[i])
    return worst_v, worst_a, worst
