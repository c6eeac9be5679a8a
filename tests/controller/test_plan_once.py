"""The plan's compiled core against the same steps written in NumPy, and the averaged
motion's forward sweeps against a binary search of every time.

:func:`cadcnc.controller.plan_once.plan_once` repeats erosion, boxes, passes, time law and
the window each knot needs in one compiled call; here the same steps are spelled out with
NumPy's array arithmetic on a quarter arc with a curvature jump at its join (the finishing
pass's shape): the profiles agree to round-off (NumPy's vectorised power and libm's may
differ in the last bit). The sweeps that turn a profile into per-period arc lengths must
pick the very knot a binary search picks: equal bits.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from cadcnc.controller import plan_once, reach, topp
from cadcnc.controller.runs import JOIN_SHARE

V = np.array([57.15, 57.15, 42.3])
A = np.array([381.0, 381.0, 254.0])
J = np.array([7620.0, 7620.0, 5080.0])
PERIOD = 0.001


def _arc_run(n: int = 150, radius: float = 9.0):
    """A line of 10 mm along X into a quarter arc of ``radius`` in XZ: s, T, K, D, jump,
    kink (n, 3), cap (n,) as a run's grid has them."""
    s_line = np.linspace(0.0, 10.0, n // 3)
    th = np.linspace(0.0, math.pi / 2, n - n // 3)
    s = np.r_[s_line, 10.0 + radius * th]
    T = np.r_[np.tile([1.0, 0.0, 0.0], (len(s_line), 1)),
              np.c_[np.cos(th), np.zeros_like(th), np.sin(th)]]
    K = np.r_[np.zeros((len(s_line), 3)),
              np.c_[-np.sin(th), np.zeros_like(th), np.cos(th)] / radius]
    D = np.r_[np.zeros((len(s_line), 3)), np.abs(np.c_[-np.cos(th), np.zeros_like(th),
                                                        -np.sin(th)]) / radius ** 2]
    jump = np.zeros_like(T)
    jump[len(s_line) - 1:len(s_line) + 1] = np.abs(K[len(s_line)])
    kink = np.zeros_like(T)
    cap = np.full(len(s), 166.7)
    return s, T, K, D, jump, kink, cap


def _speed_limits_numpy(s, T, D, jump, cap, d_share: float):
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        terms = [cap ** 2, np.min((V / np.abs(T)) ** 2, axis=1),
                 np.min((d_share * J / D) ** (2.0 / 3.0), axis=1),
                 np.min(JOIN_SHARE * J * PERIOD / jump, axis=1)]
    return np.nan_to_num(np.min(terms, axis=0), nan=math.inf, posinf=math.inf)


def _plan_numpy(s, wl, T, K, D, jump, kink, window: float, coriolis: float):
    wl_e = reach.erode(s, wl, window)
    top = float(np.sqrt(np.max(wl_e[np.isfinite(wl_e)], initial=0.0)))
    span = (s - top * window, s + top * window)
    t_lo, t_hi = reach.boxes(s, T, *span)
    k_lo, k_hi = reach.boxes(s, K, *span)
    Kmax = np.maximum(np.abs(k_lo), np.abs(k_hi))
    C = coriolis * J
    w, u = topp.passes(s, wl_e, 0.5 * (t_lo + t_hi), 0.5 * (t_hi - t_lo),
                       0.5 * (k_lo + k_hi), 0.5 * (k_hi - k_lo), Kmax, A, C)
    t, v, a, S = topp.time_law(s, w, u)
    cap = np.minimum(wl_e, top * top)[:, None]
    with np.errstate(invalid="ignore", over="ignore"):
        static = D * cap ** 1.5 + jump * cap / PERIOD + kink * np.sqrt(cap) / PERIOD ** 2
    static = reach.boxes(s, np.nan_to_num(static, nan=0.0), *span)[1]
    Tabs = np.maximum(np.abs(t_lo), np.abs(t_hi))
    need = topp.window_needed(t, v, a, Tabs, Kmax, static, J, C, window)
    return t, w, u, v, a, S, need


def test_the_compiled_plan_is_the_numpy_steps():
    s, T, K, D, jump, kink, cap = _arc_run()
    wl = plan_once.speed_limits(cap, T, D, jump, V, J, PERIOD, 0.25, JOIN_SHARE)
    ref = _speed_limits_numpy(s, T, D, jump, cap, 0.25)
    assert np.allclose(wl, ref, rtol=1e-14, atol=0.0)
    assert np.isinf(wl).sum() == np.isinf(ref).sum()
    for window, share in ((0.05, 0.25), (0.08, 0.4)):
        got = plan_once.plan_once(s, ref, T, K, D, jump, kink, A, J, PERIOD, window, share,
                                  s, s, False)
        want = _plan_numpy(s, ref, T, K, D, jump, kink, window, share)
        for name, x, y in zip("t w u v a S need".split(), got, want):
            scale = max(float(np.max(np.abs(y[np.isfinite(y)]), initial=0.0)), 1e-300)
            assert np.array_equal(np.isfinite(x), np.isfinite(y)), name
            fin = np.isfinite(y)
            assert np.max(np.abs(x[fin] - y[fin]), initial=0.0) <= 1e-12 * scale, name
        assert got[0][-1] > 0.0 and got[1][0] == 0.0 and got[1][-1] == 0.0


@njit(cache=False)
def _knot_searched(t, x: float) -> int:
    return min(max(np.searchsorted(t, x, side="right") - 1, 0), len(t) - 2)


@njit(cache=False)
def _integral_searched(t, s, v, a, S, x: float) -> float:
    if x <= 0.0:
        return 0.0
    end = t[-1]
    k = _knot_searched(t, x)
    y = min(x, end) - t[k]
    return S[k] + s[k] * y + v[k] * y * y / 2.0 + a[k] * y ** 3 / 6.0 + s[-1] * max(x - end,
                                                                                    0.0)


@njit(cache=False)
def _averaged_searched(t, s, v, a, S, window: float, tau: float) -> float:
    """topp.averaged with every knot found by a binary search (the reference; compiled,
    so that its arithmetic rounds as the library's)."""
    if window <= 0.0:
        k = _knot_searched(t, tau)
        y = min(max(tau, 0.0), t[-1]) - t[k]
        return min(max(s[k] + v[k] * y + a[k] * y * y / 2.0, 0.0), s[-1])
    x = (_integral_searched(t, s, v, a, S, tau)
         - _integral_searched(t, s, v, a, S, tau - window)) / window
    return min(max(x, 0.0), s[-1])


def test_the_sweeps_pick_the_knots_a_binary_search_picks():
    s, T, K, D, jump, kink, cap = _arc_run(90)
    wl = plan_once.speed_limits(cap, T, D, jump, V, J, PERIOD, 0.25, JOIN_SHARE)
    s[40:42] = s[40]   # a zero-length knot (a join): equal times in t
    for window in (0.0, 0.05):
        t, w, u, v, a, S, _ = plan_once.plan_once(s, wl, T, K, D, jump, kink, A, J, PERIOD,
                                                  max(window, 0.05), 0.25, s, s, False)
        tau = np.r_[-0.01, np.arange(0.0, t[-1] + window + 0.01, PERIOD / 3)]
        out = np.empty(len(tau))
        topp.averaged_sweep(t, s, v, a, S, window, tau, out)
        want = [_averaged_searched(t, s, v, a, S, window, x) for x in tau]
        assert np.array_equal(out, want)
        lo, hi = topp.ranges(t, s, v, a, S, 0.05)
        for k in range(len(t)):
            assert lo[k] == min(_averaged_searched(t, s, v, a, S, 0.05, t[k]), s[k])
            assert hi[k] == max(_averaged_searched(t, s, v, a, S, 0.05, t[k] + 0.05), s[k])


def test_a_repeated_run_is_planned_once_as_it_would_be_alone():
    """Three straight moves meeting at right angles (three runs), the first and last
    the same move: planned once, shared, and equal to each run planned on its own."""
    from cadcnc.controller import Machine
    from cadcnc.controller.feed_plan import plan_feed
    from cadcnc.controller.pieces import Piece
    from cadcnc.controller.run_plan import plan_run

    corners = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 0.0, 5.0],
                        [20.0, 0.0, 5.0]])
    pieces = [Piece(corners[k:k + 2], np.array([0.0, np.linalg.norm(corners[k + 1]
                                                                     - corners[k])]),
                    100.0, k) for k in range(3)]
    machine = Machine.default()
    plan = plan_feed(pieces, machine)
    assert len(plan.runs) == 3
    assert plan.profiles[0] is plan.profiles[2] and plan.profiles[1] is not plan.profiles[0]
    for run, profile in zip(plan.runs, plan.profiles):
        alone = plan_run(run, machine)
        assert alone.duration == profile.duration and np.array_equal(alone.v, profile.v)


def test_runs_equal_but_for_round_off_share_a_plan_and_others_do_not():
    """The same R 9 quarter arc at two places (its tangents then differ by round-off)
    shares one plan, within 1e-9 of the second's own; the arc at R 9.001 has its own."""
    from cadcnc.controller import Machine
    from cadcnc.controller.feed_plan import plan_feed
    from cadcnc.controller.pieces import Piece
    from cadcnc.controller.run_plan import plan_run

    def arc(radius: float, at) -> np.ndarray:
        phi = np.linspace(0.0, 0.5 * np.pi, 60)
        return np.c_[radius * np.cos(phi), radius * np.sin(phi), 0.0 * phi] + at

    moves = []
    for radius, at in ((9.0, (0.0, 0.0, 0.0)), (9.0, (0.1234567, 0.7654321, 5.0)),
                       (9.001, (0.0, 0.0, 10.0))):
        p = arc(radius, np.asarray(at))
        moves += [p, np.array([p[-1], p[-1] + (0.0, 0.0, 5.0)])]   # a corner: a new run
    lengths = [np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
               for p in moves]
    lengths[2] = lengths[0]   # as a program gives them: the arc lengths of its steps
    pieces = [Piece(p, s, 150.0, k) for k, (p, s) in enumerate(zip(moves, lengths))]
    machine = Machine.default()
    plan = plan_feed(pieces, machine)
    arcs = [k for k, run in enumerate(plan.runs) if run.curved]
    assert len(arcs) == 3
    first, moved, wider = (plan.runs[k] for k in arcs)
    assert not np.array_equal(first.T, moved.T)   # the round-off is there
    assert plan.profiles[arcs[0]] is plan.profiles[arcs[1]]
    assert plan.profiles[arcs[2]] is not plan.profiles[arcs[0]]
    alone = plan_run(moved, machine)
    assert plan.profiles[arcs[1]].duration == pytest.approx(alone.duration, rel=1e-9)


def test_each_runs_first_period_is_the_one_a_time_per_period_gives():
    """feed_plan._first_periods against the searches over a time per period it replaces,
    on random run starts, starts on a period exactly, and empty runs."""
    from cadcnc.controller.feed_plan import _first_periods

    rng = np.random.default_rng(5)
    for period in (0.001, 0.0005, 0.004, 1e-6 * 3):
        for _ in range(200):
            durations = rng.choice([0.0, period, 3 * period, rng.uniform(0, 50 * period)],
                                   size=rng.integers(1, 8))
            starts = np.r_[0.0, np.cumsum(durations)]
            n = max(int(math.ceil(starts[-1] / period)) + int(rng.integers(-3, 3)), 0)
            times = np.arange(n + 1) * period
            r = np.clip(np.searchsorted(starts, times, side="right") - 1, 0,
                        len(durations) - 1)
            want = np.searchsorted(r, np.arange(len(durations) + 1), side="left")
            assert _first_periods(starts, period, n) == want.tolist()


def test_a_short_straight_cut_alone_is_planned_from_rest_to_rest():
    """A cut of 5 points over 3.8 µm in a straight line (r0901_ec's pencil at R 2 has
    one) merges into one knot; alone in its run it moves from rest to rest, which one
    knot cannot do (no time would do): it keeps a middle knot and is planned in a
    finite time, within its limits."""
    from cadcnc.controller import Machine
    from cadcnc.controller.feed_plan import plan_feed
    from cadcnc.controller.pieces import Piece

    p = np.linspace([0.0, 0.0, 0.0], [-8.1e-7, 1.02e-6, 3.83e-3], 5)
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
    corner = np.array([p[-1], p[-1] + (5.0, 0.0, 0.0)])   # a rapid at a right angle
    pieces = [Piece(p, s, 166.7, 0, cut=0),
              Piece(corner, np.array([0.0, 5.0]), math.inf, 1)]
    plan = plan_feed(pieces, Machine.default())
    assert len(plan.runs) == 2 and len(plan.runs[0].s) == 3
    duration = plan.profiles[0].duration
    assert 0.0 < duration < 0.1 and plan.profiles[0].v.max() > 0.0
