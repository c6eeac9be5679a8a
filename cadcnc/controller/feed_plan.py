"""The feed along each piece, planned to the axes' velocity, acceleration and jerk limits.

The path p(s) is fixed; the plan chooses only s(t). Per axis i, with T = p', K = p'',
D = p''' (derivatives in arc length, from the kernel's points):

- velocity      T_i v                                   <= m V_i
- acceleration  T_i s'' + K_i v^2                       <= m A_i
- jerk          T_i s''' + 3 K_i v s'' + D_i v^3        <= m J_i

The curvature terms get the share c of A and J (none on a straight move), the tangential
terms the rest: |s''| <= a_t, |s'''| <= j_t (the smallest share over the axes), and the
speed limit v_lim(s) keeps |K_i| v^2 <= c m A_i and 3|K_i| v a_t + |D_i| v^3 <= c m J_i.
Then:

1. v_lim(s): the programmed speed, the accuracy rule's step, and the terms above;
2. eroded: the smallest v_lim within +-v_max T_f (see 4);
3. forward and backward passes over the whole piece (v^2 grows at most 2 a_t per mm),
   from rest to rest: the time-optimal profile under acceleration a_t;
4. that s(t) averaged over a moving window T_f = 2 a_t / j_t: the jerk is then at most
   j_t, the acceleration stays within a_t, and every speed averaged comes from within
   v_max T_f of the point reached, where the eroded limit holds.

Every bound holds in continuous time, so it holds for the finite differences of the
positions sampled each period too (an average of the derivative). Times s, lengths mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..errors import InputError
from .machine import Machine
from .pieces import Piece, constant_speed

MARGIN = 0.98
"""Share of every limit the plan uses; the rest covers the curvature sampled between
the kernel's points and the kernel's step landing within a few nm of the plan."""
CURVATURE_SHARE = 0.5
"""Share of the acceleration and jerk limits left to the curvature (centripetal) terms."""
END_KNOTS = 40  # extra knots near each end (2^-k of the first step): a start from rest
WIDEN = 2       # samples: derivatives and limits widened to cover the points between
MAX_PERIODS = 50_000_000


def _widened(x: np.ndarray, w: int = WIDEN) -> np.ndarray:
    """x's running maximum over +-w samples (along axis 0)."""
    out = x.copy()
    for k in range(1, w + 1):
        out[k:] = np.maximum(out[k:], x[:-k])
        out[:-k] = np.maximum(out[:-k], x[k:])
    return out


def derivatives(points: np.ndarray, s: np.ndarray):
    """|T|, |K|, |D| per axis at each point ((n, 3) each): |p'|, |p''|, |p'''| in arc
    length from finite differences, widened over +-WIDEN points."""
    n = len(points)
    h = np.diff(s)
    d1 = np.diff(points, axis=0) / h[:, None]
    T = np.abs(np.vstack([d1[:1], d1]))
    T[1:-1] = np.maximum(T[1:-1], np.abs(d1[1:]))
    K = np.zeros((n, 3))
    D = np.zeros((n, 3))
    if n >= 3:
        K[1:-1] = 2.0 * np.diff(d1, axis=0) / (h[:-1] + h[1:])[:, None]
        K[0], K[-1] = K[1], K[-2]
        dk = np.abs(np.diff(K, axis=0)) / h[:, None]
        D[:-1], D[1:] = dk, np.maximum(D[1:], dk)
        K = np.abs(K)
    return _widened(T), _widened(K), _widened(D)


def _range_min(x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """min(x[lo[i]:hi[i]]) for every i (hi > lo), by a sparse table."""
    table = [x]
    while (1 << len(table)) <= len(x):
        prev, w = table[-1], 1 << (len(table) - 1)
        table.append(np.minimum(prev[:-w], prev[w:]))
    k = np.floor(np.log2(hi - lo)).astype(int)
    out = np.empty(len(lo))
    for level in np.unique(k):
        sel = k == level
        t = table[level]
        out[sel] = np.minimum(t[lo[sel]], t[hi[sel] - (1 << level)])
    return out


@dataclass
class Profile:
    """One piece's planned motion s(t), t from 0 (at rest at s = 0) to ``duration`` (at
    rest at s = L): the accelerated profile on ``t``, ``s``, ``v``, ``a`` (the interval
    k from t[k] has acceleration a[k]) and ``S`` = its time integral, averaged over
    ``window`` s."""

    t: np.ndarray
    s: np.ndarray
    v: np.ndarray
    a: np.ndarray
    S: np.ndarray
    window: float
    v_limit: np.ndarray | None = None   # (n,) the eroded limit at the piece's points

    @property
    def length(self) -> float:
        return float(self.s[-1])

    @property
    def duration(self) -> float:
        return float(self.t[-1]) + self.window

    def position(self, tau: np.ndarray) -> np.ndarray:
        """s (mm) at local times ``tau`` (s), clipped to [0, L]."""
        tau = np.ascontiguousarray(tau, dtype=float)
        out = np.empty(tau.shape)
        _positions(self.t, self.s, self.v, self.a, self.S, self.window, tau.ravel(),
                   out.ravel())
        return out


@njit(cache=True, error_model="numpy")
def _integral(t, s, v, a, S, tau: float) -> float:
    """S(tau) = integral of s from 0 to tau (s = 0 before 0, L after the end)."""
    if tau <= 0.0:
        return 0.0
    end = t[-1]
    k = min(max(np.searchsorted(t, tau, side="right") - 1, 0), len(t) - 2)
    x = min(tau, end) - t[k]
    return (S[k] + s[k] * x + v[k] * x * x / 2.0 + a[k] * x ** 3 / 6.0
            + s[-1] * max(tau - end, 0.0))


@njit(cache=True, error_model="numpy")
def _positions(t, s, v, a, S, window: float, tau, out) -> None:
    """Profile.position into ``out``: s(t) averaged over ``window`` (or s(t) if 0)."""
    L = s[-1]
    for i in range(len(tau)):
        if window > 0.0:
            x = (_integral(t, s, v, a, S, tau[i])
                 - _integral(t, s, v, a, S, tau[i] - window)) / window
        else:
            k = min(max(np.searchsorted(t, tau[i], side="right") - 1, 0), len(t) - 2)
            y = min(max(tau[i], 0.0), t[-1]) - t[k]
            x = s[k] + v[k] * y + a[k] * y * y / 2.0
        out[i] = min(max(x, 0.0), L)


def _knotted(piece: Piece, v_lim: np.ndarray):
    """The arc lengths with END_KNOTS knots added inside the first and last step (their
    limit that of the step), so that a start from rest is resolved finely."""
    s = piece.s
    L, n = s[-1], len(s)
    first = s[1] * 0.5 ** np.arange(END_KNOTS + 1, 1, -1)   # up to a quarter step
    last = L - (L - s[-2]) * 0.5 ** np.arange(2, END_KNOTS + 2)
    eps = 4.0 * np.spacing(L)   # knots closer than this to an end are not distinct
    first, last = first[first > eps], last[L - last > eps]
    ss = np.concatenate([s[:1], first, s[1:-1], last, s[-1:]])
    vv = np.concatenate([v_lim[:1], np.full(len(first), min(v_lim[0], v_lim[1])),
                         v_lim[1:-1], np.full(len(last), min(v_lim[-2], v_lim[-1])),
                         v_lim[-1:]])
    return ss, vv, n


@njit(cache=True, error_model="numpy")
def _passes(ss: np.ndarray, w: np.ndarray, a: float) -> None:
    """Forward and backward passes on squared speeds ``w`` (in place): v^2 changes by at
    most 2 a per mm between knots ``ss``. A loop: cumulative forms lose v^2 near the ends
    to round-off when a L is large."""
    for i in range(1, len(w)):
        w[i] = min(w[i], w[i - 1] + 2.0 * a * (ss[i] - ss[i - 1]))
    for i in range(len(w) - 2, -1, -1):
        w[i] = min(w[i], w[i + 1] + 2.0 * a * (ss[i + 1] - ss[i]))


@njit(cache=True, error_model="numpy")
def _time_law(ss: np.ndarray, w: np.ndarray):
    """t, v, a and the integral S on knots ``ss`` of squared speeds ``w`` (v^2 linear in s
    between knots: constant acceleration)."""
    n = len(ss)
    v = np.sqrt(np.maximum(w, 0.0))
    t, a, S = np.zeros(n), np.zeros(n), np.zeros(n)
    for i in range(n - 1):
        h = ss[i + 1] - ss[i]
        dt = 2.0 * h / (v[i] + v[i + 1])
        a[i] = (w[i + 1] - w[i]) / (2.0 * h)
        t[i + 1] = t[i] + dt
        S[i + 1] = S[i] + (ss[i] * dt + v[i] * dt ** 2 / 2.0 + a[i] * dt ** 3 / 6.0)
    return t, v, a, S


def plan_piece(piece: Piece, machine: Machine) -> Profile:
    """The jerk-limited profile of one piece, from rest to rest (see the module doc)."""
    A = MARGIN * np.asarray(machine.max_acceleration)
    J = MARGIN * np.asarray(machine.max_jerk)
    V = MARGIN * np.asarray(machine.max_velocity)
    T, K, D = derivatives(piece.points, piece.s)
    share = CURVATURE_SHARE if K.any() or D.any() else 0.0
    t_max = T.max(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        a_t = float(np.min((1.0 - share) * A / t_max))
        j_t = float(np.min((1.0 - share) * J / t_max))
        limits = [np.full(len(T), piece.cap), np.min(V / T, axis=1)]
        if share:
            cA, cJ = share * A, share * J
            limits += [np.min(np.sqrt(cA / K), axis=1), np.min(np.cbrt(cJ / (2.0 * D)), axis=1),
                       np.min(cJ / (6.0 * K * a_t), axis=1)]
    if piece.step_cap is not None:
        limits.append(piece.step_cap)
    v_lim = np.nan_to_num(np.min(limits, axis=0), nan=math.inf)
    window = 2.0 * a_t / j_t
    reach = float(np.max(v_lim)) * window
    s = piece.s
    lo = np.maximum(np.searchsorted(s, s - reach, side="left") - 1, 0)
    hi = np.minimum(np.searchsorted(s, s + reach, side="right") + 1, len(s))
    v_lim = _range_min(v_lim, lo, hi)
    ss, vv, _ = _knotted(piece, v_lim)
    w = vv ** 2
    w[0] = w[-1] = 0.0   # from rest, to rest
    _passes(ss, w, a_t)
    t, v, a, S = _time_law(ss, w)
    return Profile(t, ss, v, a, S, window, v_lim)


def constant_piece(piece: Piece, machine: Machine) -> Profile:
    """The piece at its programmed speed throughout (rapids at the axes' velocity), no
    ramp, no limit: what a stream ignoring the machine does."""
    v = constant_speed(piece, machine)
    ss = np.array([0.0, piece.length])
    t, vv, a, S = _time_law(ss, np.array([v * v, v * v]))
    return Profile(t, ss, vv, a, S, 0.0, np.full(len(piece.s), v))


@dataclass
class FeedPlan:
    """Every piece's profile, back to back in time: piece k starts at ``starts[k]`` s."""

    pieces: list
    profiles: list[Profile]
    machine: Machine
    planned: bool = True   # False: at the programmed feed, the limits ignored

    @property
    def starts(self) -> np.ndarray:
        return np.r_[0.0, np.cumsum([p.duration for p in self.profiles])]

    @property
    def duration(self) -> float:
        return float(self.starts[-1])

    @property
    def periods(self) -> int:
        """Periods to the end: the stream has periods + 1 positions (the start at t = 0)."""
        return int(math.ceil(self.duration / self.machine.period - 1e-9))

    def targets(self) -> tuple[np.ndarray, np.ndarray]:
        """Per position n = 0..periods (time n Ts): the piece and the arc length in it."""
        n = self.periods
        if n > MAX_PERIODS:
            raise InputError(f"the stream would need {n} periods (over {MAX_PERIODS}): a "
                             "limit or the feed is far too small")
        times = np.arange(n + 1) * self.machine.period
        starts = self.starts
        k = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, len(self.pieces) - 1)
        s = np.empty(n + 1)
        for j in np.unique(k):
            sel = k == j
            s[sel] = self.profiles[j].position(times[sel] - starts[j])
        return k, s


def plan_feed(pieces: list[Piece], machine: Machine, planned: bool = True) -> FeedPlan:
    """The plan of every piece: to the machine's limits, or (``planned=False``) at the
    programmed feed ignoring them."""
    if not pieces:
        raise InputError("the program has nothing to stream (no cut or move)")
    make = plan_piece if planned else constant_piece
    return FeedPlan(pieces, [make(p, machine) for p in pieces], machine, planned)
