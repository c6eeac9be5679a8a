"""One plan of one run (compiled): the erosion, the path's derivative boxes, the
phase-plane passes, the time law and the window each knot needs, in one call.

:func:`plan_once` is what :mod:`.run_plan` repeats while it searches a run's window and
Coriolis share; done in one compiled call it has no temporaries and no interpreter cost per
step, and computes exactly what the same steps in NumPy would. :func:`speed_limits` is the
run's squared speed limit before erosion. Arrays: ``s`` (n,) mm, ``T``, ``K``, ``D``,
``jump``, ``kink`` (n, 3) as :class:`~.runs.Run`'s; speeds mm/s, times s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import reach, topp

_BIG = np.finfo(np.float64).max   # what np.nan_to_num puts for an infinity


@njit(cache=True, error_model="numpy")
def speed_limits(cap, T, D, jump, V, J, period: float, d_share: float,
                 join_share: float):
    """(n,) the squared speed limit at each grid point: the programmed speed, every axis's
    velocity, the jerk's D v³ term within ``d_share`` of J and a join's one-period jolt
    within ``join_share`` of J (no limit: inf)."""
    n = len(cap)
    out = np.empty(n)
    terms = np.empty(10)
    for k in range(n):
        terms[0] = cap[k] ** 2
        for i in range(3):
            terms[1 + i] = (V[i] / abs(T[k, i])) ** 2
            terms[4 + i] = (d_share * J[i] / D[k, i]) ** (2.0 / 3.0)
            terms[7 + i] = join_share * J[i] * period / jump[k, i]
        m = terms[0]
        for x in terms:
            if math.isnan(x):   # 0 / 0 anywhere: no limit
                m = math.inf
                break
            m = min(m, x)
        out[k] = -_BIG if m == -math.inf else m
    return out


@njit(cache=True, error_model="numpy")
def plan_once(s, wl, T, K, D, jump, kink, A, J, period: float, window: float,
              coriolis: float, reach_lo, reach_hi, reach_given: bool, eroded: bool = True):
    """One plan of the run with averaging ``window`` and the Coriolis term's share
    ``coriolis`` of J, the path's derivatives taken over [reach_lo, reach_hi] around each
    point (``reach_given`` False: +- the top speed times the window), the speed limits
    held over the window's reach (``eroded`` False: where they are, for a plan whose
    averaged motion is measured): t, w, u, v, a, S and per knot the window needed
    (:func:`.topp.window_needed`)."""
    n = len(s)
    wl_e = reach.erode(s, wl, window) if eroded else wl.copy()
    top2 = 0.0
    for k in range(n):
        if math.isfinite(wl_e[k]):
            top2 = max(top2, wl_e[k])
    top = math.sqrt(top2)
    if not reach_given:
        reach_lo = s - top * window
        reach_hi = s + top * window
    t_lo, t_hi = reach.boxes(s, T, reach_lo, reach_hi)
    k_lo, k_hi = reach.boxes(s, K, reach_lo, reach_hi)
    Tc, Tr = 0.5 * (t_lo + t_hi), 0.5 * (t_hi - t_lo)
    Kc, Kr = 0.5 * (k_lo + k_hi), 0.5 * (k_hi - k_lo)
    Kmax = np.maximum(np.abs(k_lo), np.abs(k_hi))
    C = coriolis * J
    w, u = topp.passes(s, wl_e, Tc, Tr, Kc, Kr, Kmax, A, C)
    t, v, a, S = topp.time_law(s, w, u)
    static = np.empty((n, 3))
    for k in range(n):
        cap = min(wl_e[k], top * top)
        for i in range(3):
            x = (D[k, i] * cap ** 1.5 + jump[k, i] * cap / period
                 + kink[k, i] * math.sqrt(cap) / period ** 2)
            if math.isnan(x):
                x = 0.0
            elif x == math.inf:
                x = _BIG
            elif x == -math.inf:
                x = -_BIG
            static[k, i] = x
    static = reach.boxes(s, static, reach_lo, reach_hi)[1]
    Tabs = np.maximum(np.abs(t_lo), np.abs(t_hi))
    need = topp.window_needed(t, v, a, Tabs, Kmax, static, J, C, window)
    return t, w, u, v, a, S, need
