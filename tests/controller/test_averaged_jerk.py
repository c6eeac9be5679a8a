"""The averaged motion's jerk as :func:`cadcnc.controller.averaged_jerk.peak_share` measures
it, against the motion itself on a quarter arc whose path is known in closed form.

The reference shares nothing with the measure but the raw profile (the plan): the
averaged arc length s_f(t) is the raw s(t) sampled every 10 us and averaged over the
window by the trapezoid rule, its derivatives are finite differences, and the path's
T, K, p''' are the circle's. The measure must equal the largest share found that way (to
the sampling's error) and bound the third differences of the positions p(s_f(t)).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from cadcnc.controller import plan_once
from cadcnc.controller.averaged_jerk import peak_share, shares

RADIUS = 9.0
A = np.array([381.0, 381.0, 254.0])
J = np.array([7620.0, 7620.0, 5080.0])
V = np.array([57.15, 57.15, 42.3])
PERIOD = 0.001
DT = 1e-5


def _arc(n: int = 141):
    """A quarter circle of RADIUS in XZ: s (n,) and T, K, |p'''| (n, 3) in closed form."""
    th = np.linspace(0.0, math.pi / 2, n)
    s = RADIUS * th
    T = np.c_[np.cos(th), np.zeros(n), np.sin(th)]
    K = np.c_[-np.sin(th), np.zeros(n), np.cos(th)] / RADIUS
    D = np.abs(np.c_[-np.cos(th), np.zeros(n), -np.sin(th)]) / RADIUS ** 2
    return s, T, K, D


def _plan(coriolis: float, window: float):
    s, T, K, D = _arc()
    zero = np.zeros_like(T)
    wl = plan_once.speed_limits(np.full(len(s), 166.7), T, D, zero, V, J, PERIOD, 0.25, 0.25)
    t, w, u, v, a, S, need = plan_once.plan_once(s, wl, T, K, D, zero, zero, A, J, PERIOD,
                                                 window, coriolis, s, s, False)
    return (t, s, v, a, S), (T, K, D, zero)


def _averaged_arc_length(t, s, v, a, window: float):
    """(tau, s_f): the raw profile sampled every DT and averaged over ``window``."""
    tau = np.arange(-window, t[-1] + 2 * window, DT)
    k = np.clip(np.searchsorted(t, tau, side="right") - 1, 0, len(t) - 2)
    y = tau - t[k]
    raw = np.where(tau <= 0.0, s[0], np.where(tau >= t[-1], s[-1],
                                               s[k] + v[k] * y + a[k] * y * y / 2))
    m = int(round(window / DT))
    cum = np.r_[0.0, np.cumsum((raw[1:] + raw[:-1]) / 2 * DT)]
    return tau[m:], (cum[m:] - cum[:-m]) / window


def _reference(coriolis: float, window: float) -> tuple[float, float]:
    """(the largest share by the closed-form path and finite differences of s_f, the
    largest |third difference| of the positions over J)."""
    (t, s, v, a, S), _ = _plan(coriolis, window)
    tau, sf = _averaged_arc_length(t, s, v, a, window)
    vf = np.gradient(sf, DT)
    af = np.gradient(vf, DT)
    jf = np.gradient(af, DT)
    th = sf / RADIUS
    T = np.c_[np.cos(th), np.zeros_like(th), np.sin(th)]
    K = np.c_[-np.sin(th), np.zeros_like(th), np.cos(th)] / RADIUS
    D = np.abs(np.c_[-np.cos(th), np.zeros_like(th), -np.sin(th)]) / RADIUS ** 2
    share = (np.abs(T * jf[:, None] + 3 * K * (vf * af)[:, None]) + D * vf[:, None] ** 3) / J
    # positions every period, their third differences
    pick = slice(0, None, int(round(PERIOD / DT)))
    p = RADIUS * np.c_[np.sin(th[pick]), np.zeros_like(th[pick]), 1.0 - np.cos(th[pick])]
    jerk = np.abs(np.diff(p, 3, axis=0)) / PERIOD ** 3 / J
    # the finite differences' edges (np.gradient's one-sided ends) left out
    return float(share[5:-5].max()), float(jerk.max())


@pytest.mark.parametrize("coriolis, window", [(0.25, 0.05), (0.65, 0.05), (0.65, 0.07)])
def test_the_measure_is_the_averaged_motions_jerk(coriolis, window):
    (t, s, v, a, S), (T, K, D, zero) = _plan(coriolis, window)
    measured = peak_share(t, s, v, a, S, window, s, T, K, D, zero, zero, J, PERIOD)
    share, fd = _reference(coriolis, window)
    # the grid's linear T, K, D against the circle's, and the sampling: a few 1e-3
    assert measured == pytest.approx(share, rel=5e-3)
    assert fd <= measured * (1.0 + 1e-3)   # the positions never jerk more than measured
    assert 0.5 < measured < 3.0            # a real motion, not a degenerate one


def test_a_longer_window_measures_less_jerk():
    """The tangential part goes as 1 / window: the window the planner grows pays off."""
    (t, s, v, a, S), (T, K, D, zero) = _plan(0.65, 0.05)
    short = peak_share(t, s, v, a, S, 0.05, s, T, K, D, zero, zero, J, PERIOD)
    long = peak_share(t, s, v, a, S, 0.08, s, T, K, D, zero, zero, J, PERIOD)
    assert long < short


def test_a_joins_jolt_is_added_where_the_motion_passes_it():
    (t, s, v, a, S), (T, K, D, zero) = _plan(0.25, 0.05)
    plain = peak_share(t, s, v, a, S, 0.05, s, T, K, D, zero, zero, J, PERIOD)
    jump = zero.copy()
    jump[70] = [0.0, 0.0, 0.05]   # a jump of p'' mid-arc, on Z
    jolted = peak_share(t, s, v, a, S, 0.05, s, T, K, D, jump, zero, J, PERIOD)
    assert jolted > plain


@pytest.mark.parametrize("coriolis, window", [(0.65, 0.05), (1.0, 0.07)])
def test_the_velocity_and_acceleration_measured_are_the_averaged_motions(coriolis,
                                                                         window):
    """:func:`shares` measures the averaged motion's velocity (against each axis's V and
    the programmed speed) and acceleration (|T_i a + K_i v^2| against A_i) as it measures
    the jerk: against the circle's T, K and finite differences of s_f."""
    (t, s, v, a, S), (T, K, D, zero) = _plan(coriolis, window)
    cap = np.full(len(s), 60.0)
    got_v, got_a, got_j = shares(t, s, v, a, S, window, s, T, K, D, zero, zero, V, A, J,
                                 PERIOD, cap)
    tau, sf = _averaged_arc_length(t, s, v, a, window)
    vf = np.gradient(sf, DT)
    af = np.gradient(vf, DT)
    th = sf / RADIUS
    Tc = np.c_[np.cos(th), np.zeros_like(th), np.sin(th)]
    Kc = np.c_[-np.sin(th), np.zeros_like(th), np.cos(th)] / RADIUS
    ref_v = max(float((np.abs(Tc * vf[:, None]) / V).max()), float(vf.max() / 60.0))
    ref_a = float((np.abs(Tc * af[:, None] + Kc * (vf ** 2)[:, None]) / A)[5:-5].max())
    assert got_v == pytest.approx(ref_v, rel=2e-3)
    assert got_a == pytest.approx(ref_a, rel=5e-3)
    assert got_j == peak_share(t, s, v, a, S, window, s, T, K, D, zero, zero, J, PERIOD)
    assert 0.5 < got_v and 0.5 < got_a   # a real motion, near its limits
