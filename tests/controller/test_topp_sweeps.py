"""The phase plane's sliding computations against the plain loops they replace.

:func:`cadcnc.controller.reach.erode` applies each speed limit over +- v W with a segment
tree (its reach bisected on an ordered grid), and
:func:`~cadcnc.controller.topp.window_needed` takes the extremes of the
acceleration and the speed over each window from sliding queues, and
:func:`~cadcnc.controller.averaged_jerk.peak_share` merges its interval ends instead of
sorting them. Each must give the very floats of the direct computations written here
(every point's reach walked point by point; every window's knots scanned; a sort), on
grids with repeated points (joins), limits that reach past either end, none (inf) and a
negative one, and windows from none to the whole run.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from cadcnc.controller import averaged_jerk, reach, topp


def _erode_walked(s, wl, window: float) -> np.ndarray:
    out = wl.copy()
    for k in range(len(s)):
        r = math.sqrt(wl[k]) * window if wl[k] >= 0.0 else math.nan
        if not math.isfinite(r):
            continue
        for j in range(k - 1, -1, -1):
            if not s[k] - s[j] <= r:
                break
            out[j] = min(out[j], wl[k])
        for j in range(k + 1, len(s)):
            if not s[j] - s[k] <= r:
                break
            out[j] = min(out[j], wl[k])
    return out


def _needed_scanned(t, v, a, Tabs, Kmax, static, J, C, window: float) -> np.ndarray:
    n = len(t)
    need = np.zeros(n - 1)
    for k in range(n - 1):
        lo = 0
        while t[lo + 1] <= t[k] - window:
            lo += 1
        knots = range(lo, k + 1)
        amin = min(a[j] for j in knots)
        amax = max(a[j] for j in knots)
        vmax = max([v[j] for j in range(lo, k + 2)])
        da = amax - amin
        if da <= 0.0:
            continue
        am = max(abs(amin), abs(amax))
        for i in range(3):
            room = J[i] - (min(3.0 * Kmax[k, i] * vmax * am, C[i]) + static[k, i])
            if room <= 0.0:
                need[k] = math.inf
                break
            need[k] = max(need[k], Tabs[k, i] * da / room)
    return need


def _grid(rng, n: int) -> np.ndarray:
    s = np.cumsum(rng.uniform(0.0, 0.3, n))
    s[0] = 0.0
    s[n // 3:n // 3 + 3] = s[n // 3]   # a join: repeated points
    return s


@pytest.mark.parametrize("seed", range(6))
def test_erosion_equals_the_walked_reach(seed):
    rng = np.random.default_rng(seed)
    n = 400
    s = _grid(rng, n)
    wl = rng.uniform(0.0, 1.0, n) ** 3 * 4.0e4
    wl[rng.integers(0, n, 8)] = math.inf
    wl[5] = 0.0
    wl[7] = -np.finfo(float).max   # as speed_limits gives -inf
    for window in (0.0, 1e-3, 0.05, 0.5, 50.0):
        got = reach.erode(s, wl, window)
        want = _erode_walked(s, wl, window)
        assert np.array_equal(got, want), window
    assert (reach.erode(s, wl, 0.05) < wl).any()   # the limits did reach others
    s[n // 2] = s[n // 2 + 5]   # out of order (no run's grid is): its reach walked
    for window in (0.05, 0.5):
        assert np.array_equal(reach.erode(s, wl, window), _erode_walked(s, wl, window))


@pytest.mark.parametrize("seed", range(6))
def test_window_needed_equals_the_scanned_windows(seed):
    rng = np.random.default_rng(100 + seed)
    n = 300
    t = np.cumsum(rng.uniform(0.0, 2e-3, n))
    t[0] = 0.0
    t[50:53] = t[50]   # knots that take no time
    v = rng.uniform(0.0, 200.0, n)
    a = rng.normal(0.0, 500.0, n)
    a[100:140] = 250.0   # a stretch of constant acceleration: da = 0
    Tabs = rng.uniform(0.0, 1.0, (n, 3))
    Kmax = rng.uniform(0.0, 0.2, (n, 3))
    static = rng.uniform(0.0, 2000.0, (n, 3))
    static[200, 1] = math.inf
    J = np.array([20_000.0, 16_000.0, 10_000.0])
    C = 0.25 * J
    for window in (1e-4, 0.01, 0.1, 10.0):
        got = topp.window_needed(t, v, a, Tabs, Kmax, static, J, C, window)
        want = _needed_scanned(t, v, a, Tabs, Kmax, static, J, C, window)
        assert np.array_equal(got, want), window
        assert np.isinf(got).any() and (got > 0.0).any()


@pytest.mark.parametrize("seed", range(4))
def test_measured_jerk_times_equal_the_sorted_times(seed):
    """The averaged jerk's interval ends (the knots' times and the same a window later)
    merged in order equal the sorted union, repeated times (joins) included."""
    rng = np.random.default_rng(200 + seed)
    t = np.cumsum(rng.uniform(0.0, 2e-3, 500))
    t[0] = 0.0
    t[80:84] = t[80]
    for window in (0.0, 1e-5, 0.05, 0.13, 10.0):
        assert np.array_equal(averaged_jerk._merged(t, window),
                              np.sort(np.r_[t, t + window])), window
