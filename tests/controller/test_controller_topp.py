"""The plan's compiled pieces against closed forms: the time-optimal profile of a straight
move (trapezoid or triangle, t = L / v + v / a), the boxes of the path's derivatives
(every value in each range inside its box), and the averaged motion's ranges."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cadcnc.controller import knot, reach, runs, topp


def _line(L: float, n: int, v: float, a: float):
    """A straight move along X: knots, speed limits, derivatives (no curvature)."""
    s = np.linspace(0.0, L, n + 1)
    T = np.tile([1.0, 0.0, 0.0], (n + 1, 1))
    zero = np.zeros((n + 1, 3))
    wl = np.full(n + 1, v * v)
    A = np.array([a, a, a])
    return s, wl, T, zero, zero, zero, zero, A, np.full(3, math.inf)


@pytest.mark.parametrize("L, v, a", [(60.0, 57.15, 381.0), (10.0, 57.15, 381.0),
                                     (2.0, 100.0, 500.0)])
def test_a_straight_move_takes_its_closed_form_time(L, v, a):
    s, wl, Tc, Tr, Kc, Kr, Kmax, A, C = _line(L, 4000, v, a)
    w, u = topp.passes(s, wl, Tc, Tr, Kc, Kr, Kmax, A, C)
    t, vv, aa, S = topp.time_law(s, w, u)
    if L >= v * v / a:    # trapezoid: cruise at v
        exact = L / v + v / a
    else:                 # triangle: peak sqrt(a L)
        exact = 2.0 * math.sqrt(L / a)
    assert t[-1] == pytest.approx(exact, rel=2e-3)
    assert np.abs(u).max() <= a * (1 + 1e-9) and vv.max() <= v * (1 + 1e-9)
    assert w[0] == 0.0 and w[-1] == 0.0


def test_boxes_hold_every_value_in_their_range():
    rng = np.random.default_rng(1)
    for _ in range(200):
        n = int(rng.integers(2, 60))
        s = np.sort(rng.uniform(0, 10, n))
        x = rng.normal(size=(n, 3))
        lo_s, hi_s = s - rng.uniform(0, 2, n), s + rng.uniform(0, 2, n)
        lo, hi = reach.boxes(s, x, lo_s, hi_s)
        for k in range(n):
            sel = (s >= lo_s[k]) & (s <= hi_s[k])
            assert (lo[k] <= x[sel].min(axis=0)).all() and (hi[k] >= x[sel].max(axis=0)).all()


def test_the_averaged_motion_stays_in_its_ranges():
    """Every averaged position while knot k is in the window lies in k's range."""
    s, wl, Tc, Tr, Kc, Kr, Kmax, A, C = _line(20.0, 400, 50.0, 400.0)
    w, u = topp.passes(s, wl, Tc, Tr, Kc, Kr, Kmax, A, C)
    t, v, a, S = topp.time_law(s, w, u)
    window = 0.05
    lo, hi = topp.ranges(t, s, v, a, S, window)
    for k in range(0, len(t), 7):
        for tau in np.linspace(t[k], t[k] + window, 11):
            x = topp.averaged(t, s, v, a, S, window, tau)
            assert lo[k] - 1e-12 <= x <= hi[k] + 1e-12


@pytest.mark.parametrize("L", [3.0, 10.0, 60.0])
def test_a_straight_move_is_within_2_percent_of_ruckig(L):
    """Ruckig (time-optimal, jerk-limited, rest to rest) on a straight move of L mm: the
    planned run, at the same limits, takes at most 2 % longer (a 0.5 mm move, where the
    optimum never holds its acceleration, takes 26 % longer: docs/notes/controller.md)."""
    from ruckig import InputParameter, Result, Ruckig, Trajectory

    from cadcnc.controller import Machine
    from cadcnc.controller.pieces import Piece
    from cadcnc.controller.run_plan import MARGIN, plan_run
    from cadcnc.controller.runs import runs_of

    v, a, j = 57.15, 381.0, 7620.0
    inp = InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [L]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    traj = Trajectory(1)
    assert Ruckig(1).calculate(inp, traj) in (Result.Working, Result.Finished)
    m = Machine(0.001, (v / MARGIN,) * 3, (a / MARGIN,) * 3, (j / MARGIN,) * 3)
    piece = Piece(np.array([[0.0, 0.0, 0.0], [L, 0.0, 0.0]]), np.array([0.0, L]), math.inf, 0)
    planned = plan_run(runs_of([piece], m)[0], m).duration
    assert traj.duration * (1 - 1e-6) <= planned <= 1.02 * traj.duration


def _bisected(top, h, w_next, cu, cw, rhs, cor) -> float:
    """The top of the feasible speeds from 0 by bisection of the predicate alone."""
    a, b = 0.0, top
    for _ in range(200):
        m = 0.5 * (a + b)
        if knot.feasible(m, h, w_next, cu, cw, rhs, cor):
            a = m
        else:
            b = m
    return a


def test_the_closed_form_largest_speed_is_the_bisected_one():
    """Random curved knots (curvature, its box, the Coriolis term binding or not): the
    closed form is feasible and equals the bisection of the feasibility test."""
    rng = np.random.default_rng(7)
    cu_all, cw_all, rhs_all = (np.empty(knot.ROWS) for _ in range(3))
    buf = np.empty((4, knot.ROWS + 1))
    A, checked = np.array([1000.0, 800.0, 500.0]), 0
    for _ in range(400):
        T = rng.normal(size=(2, 3))
        T /= np.linalg.norm(T, axis=1)[:, None]
        Kc = rng.normal(scale=0.3, size=(2, 3))
        Kr, Tr = np.abs(rng.normal(scale=0.02, size=(2, 3))), np.full((2, 3), 0.01)
        Kmax = np.abs(Kc) + Kr
        C = np.full(3, rng.choice([math.inf, 5_000.0, 500.0]))
        h, w_next = rng.uniform(0.01, 1.0), rng.uniform(0.0, 2e4)
        cor, m = knot.coefficients(0, h, T, Tr, Kc, Kr, Kmax, A, C, cu_all, cw_all, rhs_all)
        cu, cw, rhs = cu_all[:m], cw_all[:m], rhs_all[:m]
        top = 1e6
        if knot.feasible(top, h, w_next, cu, cw, rhs, cor):
            continue
        got = knot.largest(top, h, w_next, cu, cw, rhs, cor, buf, float(A.max()))
        ref = _bisected(top, h, w_next, cu, cw, rhs, cor)
        assert knot.feasible(got, h, w_next, cu, cw, rhs, cor)
        assert got == pytest.approx(ref, rel=1e-9, abs=1e-9)
        checked += 1
    assert checked > 200


def test_the_crossing_walk_is_the_lowest_pair_crossing():
    """knot._crossing (a walk along the binding pairs) against every (lower, upper) pair's
    crossing: the lowest one below the start where the bounds meet, else the start."""
    rng = np.random.default_rng(11)
    checked = 0
    for _ in range(3000):
        nl, nu = rng.integers(1, 14, size=2)
        lp, up = rng.normal(scale=100.0, size=nl) - 50.0, rng.normal(scale=100.0, size=nu) + 50.0
        lq, uq = rng.normal(scale=0.1, size=nl), rng.normal(scale=0.1, size=nu)
        w = 10.0 ** rng.uniform(2, 6)
        got = knot._crossing(w, lp, lq, nl, up, uq, nu)
        if (lp + lq * got).max() > (up + uq * got).min() + 1e-9 * (1.0 + got):
            continue   # the bounds never meet below w: the caller's check refuses it
        d = lq[:, None] - uq[None, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            cross = np.where(d > 0.0, (up[None, :] - lp[:, None]) / d, np.inf)
        want = min(w, cross.min())
        assert got == pytest.approx(want, rel=1e-12, abs=1e-9), (got, want)
        checked += want < w
    assert checked > 200   # the bounds meet below w in about a tenth of the draws


@pytest.mark.parametrize("n", [1, 2, 3, 50, 2000])
def test_knots_keep_the_ends_and_no_step_below_min_knot(n):
    """The ends kept; kept knots at least MIN_KNOT apart (the last excepted); a point
    dropped only within MIN_KNOT of the knot before it, or (one) of the end."""
    rng = np.random.default_rng(n)
    s = np.cumsum(np.r_[0.0, rng.exponential(runs.MIN_KNOT, n - 1)])
    flat = np.zeros((n, 3))
    keep = runs._linear_knots(s, flat, flat, 0.0, 0.0, 0.0)   # no merging but MIN_KNOT's
    assert keep[0] == 0 and keep[-1] == n - 1
    assert n == 1 or (np.diff(keep) > 0).all()
    assert (np.diff(s[keep[:-1]]) >= runs.MIN_KNOT).all()
    dropped = np.setdiff1d(np.arange(n), keep)
    far = dropped[s[dropped] - s[keep[np.searchsorted(keep, dropped) - 1]] >= runs.MIN_KNOT]
    assert len(far) <= 1 and (s[-1] - s[far] < runs.MIN_KNOT).all()
    assert n < 50 or len(dropped) > 0   # the sample has points to drop


def _wavy(n: int, seed: int) -> tuple:
    """A cut-like grid: steps of about 0.1 mm (some of a few nm), T and K of a wave with
    a little noise, D, jump and cap drawn at random."""
    rng = np.random.default_rng(seed)
    h = np.where(rng.random(n - 1) < 0.05, 1e-6, rng.uniform(0.05, 0.15, n - 1))
    s = np.cumsum(np.r_[0.0, h])
    phase = s[:, None] / np.array([17.0, 23.0, 41.0]) + np.array([0.0, 1.0, 2.0])
    T = np.cos(phase) + 1e-6 * rng.standard_normal((n, 3))
    K = 0.05 * np.sin(2.0 * phase) + 1e-6 * rng.standard_normal((n, 3))
    D, jump = rng.exponential(0.01, (n, 3)), rng.exponential(1e-4, (n, 3))
    return s, T, K, D, jump, rng.uniform(10.0, 100.0, n)


@pytest.mark.parametrize("seed", range(4))
def test_knots_merge_only_where_T_and_K_pass_linearly(seed):
    """A cut's points merge into knots at most CUT_KNOT apart between which every
    point's T and K lie within eps of the line through the two knots' values, each knot
    taken as far as that allows; no knot shorter than MIN_KNOT (the last excepted if the
    cut has one step)."""
    s, T, K, *_ = _wavy(3000, seed)
    eps_t, eps_k = runs._linear_room(K)
    assert eps_t == runs.KNOT_SHARE and eps_k == runs.KNOT_SHARE * np.abs(K).max()
    keep = runs._linear_knots(s, T, K, runs.CUT_KNOT, eps_t, eps_k)
    n = len(s)
    assert keep[0] == 0 and keep[-1] == n - 1 and (np.diff(keep) > 0).all()
    assert (np.diff(s[keep]) >= runs.MIN_KNOT).all()
    assert 4 * len(keep) < n   # merging happens on such a wave

    def straight(a: int, c: int) -> bool:
        f = ((s[a + 1:c] - s[a]) / (s[c] - s[a]))[:, None]
        return bool((np.abs(T[a + 1:c] - (T[a] + f * (T[c] - T[a]))) <= eps_t).all()
                    and (np.abs(K[a + 1:c] - (K[a] + f * (K[c] - K[a]))) <= eps_k).all())

    for a, c in zip(keep[:-1], keep[1:]):
        forced = s[c - 1] - s[a] < runs.MIN_KNOT   # the knot grown only to MIN_KNOT
        assert forced or (s[c] - s[a] <= runs.CUT_KNOT and straight(a, c))
        if c + 1 < n and not forced:   # one point more would break a rule
            assert s[c + 1] - s[a] > runs.CUT_KNOT or not straight(a, c + 1)


@pytest.mark.parametrize("seed", range(4))
def test_merged_knots_carry_the_limits_of_every_point_they_pass(seed):
    """Each point between two knots has its D and jump at most, and its speed cap at
    least, those of both knots (the motion passes it at speeds between theirs); a knot
    has its own."""
    s, T, K, D, jump, cap = _wavy(1500, seed)
    keep = runs._linear_knots(s, T, K, runs.CUT_KNOT, *runs._linear_room(K))
    D2, jump2, cap2 = runs._held(keep, D, jump, cap)
    for j, k in enumerate(keep):
        assert (D2[j] >= D[k]).all() and (jump2[j] >= jump[k]).all() and cap2[j] <= cap[k]
    for j, (a, c) in enumerate(zip(keep[:-1], keep[1:])):
        inner = slice(a + 1, c)
        for x in (j, j + 1):
            assert (D2[x] >= D[inner]).all() and (jump2[x] >= jump[inner]).all()
            assert (cap2[x] <= cap[inner]).all()
    # nothing more than that: a knot's values are those of the points it stands for
    assert set(D2[:, 0]) <= set(D[:, 0]) and set(cap2) <= set(cap)


def _root_bisected(q: float, p: float, c: float, x: float) -> float:
    """The reference: the first root of q x³ + p x + c below x by 200 halvings of its
    monotone bracket (on the side where the cubic is >= 0), in Python floats."""
    f = lambda y: q * (y * y * y) + p * y + c   # noqa: E731
    if f(x) >= 0.0 and not (q > 0.0 and p < 0.0):
        return x
    hi = x if not (q > 0.0 and p < 0.0) else min(x, math.sqrt(-p / (3.0 * q)))
    if f(hi) >= 0.0:
        return x
    lo = 0.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) >= 0.0 else (lo, mid)
    return lo


def test_the_coriolis_root_is_the_first_root_on_its_feasible_side():
    """knot._cubic_root (Newton) against a long bisection on random cubics of every sign
    pattern: on the feasible side (the cubic >= 0 there) and within 1e-14 of the root."""
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(4000):
        q, p = rng.normal(scale=10.0 ** rng.uniform(-3, 3), size=2)
        c = 10.0 ** rng.uniform(-2, 4)
        x = 10.0 ** rng.uniform(-1, 3)
        got = knot._cubic_root(q, p, c, x)
        want = _root_bisected(q, p, c, x)
        assert 0.0 <= got <= x
        assert q * (got * got * got) + p * got + c >= 0.0 or got == 0.0   # as compiled
        assert abs(got - want) <= 1e-14 * max(want, 1.0), (q, p, c, x, got, want)
        checked += want < x
    assert checked > 500   # most cases bind: the root lies below x


def _all_rows(k, h, Tc, Tr, Kc, Kr, A):
    """Every one of a knot's ROWS constraints, duplicates and empty rows included (the
    definition: 2 ends x 3 axes x the 4 corners of the (T, K) box)."""
    rows = []
    for e in range(2):
        j = k + e
        reach = 2.0 * h if e == 1 else 0.0
        for i in range(3):
            for s1 in (-1.0, 1.0):
                kw = s1 * Kc[j, i] + Kr[j, i]
                for s2 in (-1.0, 1.0):
                    rows.append((s1 * Tc[j, i] + s2 * Tr[j, i] + kw * reach, kw, A[i]))
    return (np.array(c) for c in zip(*rows))


@pytest.mark.parametrize("kind", ["straight", "planar", "curved", "boxed"])
def test_the_rows_left_out_change_no_bound(kind):
    """The rows :func:`knot.coefficients` leaves out (repeats, rows that bound nothing)
    change no float: the bounds at any speed, feasibility and the largest speed equal
    those of all ROWS rows, on straight, planar and curved knots."""
    rng = np.random.default_rng(11)
    cu_all, cw_all, rhs_all = (np.empty(knot.ROWS) for _ in range(3))
    buf = np.empty((4, knot.ROWS + 1))
    A, fewer = np.array([1000.0, 800.0, 500.0]), 0
    for _ in range(300):
        T = rng.normal(size=3)
        if kind == "planar":
            T[1] = 0.0
        T = np.tile(T / np.linalg.norm(T), (2, 1))
        Tr, Kc, Kr = np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3))
        if kind in ("curved", "boxed"):
            T += rng.normal(scale=0.05, size=(2, 3))
            Kc = rng.normal(scale=0.3, size=(2, 3))
        if kind == "boxed":
            Tr, Kr = np.full((2, 3), 0.01), np.abs(rng.normal(scale=0.02, size=(2, 3)))
        Kmax = np.abs(Kc) + Kr
        C = np.full(3, rng.choice([math.inf, 5_000.0, 500.0]))
        h, w_next = rng.uniform(0.01, 1.0), rng.uniform(0.0, 2e4)
        cor, m = knot.coefficients(0, h, T, Tr, Kc, Kr, Kmax, A, C, cu_all, cw_all, rhs_all)
        rows = (cu_all[:m], cw_all[:m], rhs_all[:m])
        full = tuple(_all_rows(0, h, T, Tr, Kc, Kr, A))
        fewer += m < knot.ROWS
        for w in rng.uniform(0.0, 1e5, size=8):
            assert knot.bounds(w, h, *rows, cor) == knot.bounds(w, h, *full, cor)
        for top in (1e6, rng.uniform(0.0, 1e4)):
            assert knot.feasible(top, h, w_next, *rows, cor) == \
                knot.feasible(top, h, w_next, *full, cor)
            assert knot.largest(top, h, w_next, *rows, cor, buf, 1000.0) == \
                knot.largest(top, h, w_next, *full, cor, buf, 1000.0)
    assert fewer == (0 if kind == "boxed" else 300)
