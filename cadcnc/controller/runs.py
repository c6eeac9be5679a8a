"""A program's pieces grouped into runs: the stretches the planner moves through without
stopping, and the path's derivatives along each run (no OCCT).

Pieces meet at rest only where the path needs it: at a corner, where the tangent turns so
much that passing it at any speed worth having would jolt an axis in one servo period.
Tangent-continuous joins (a collinear rapid and plunge, a cut flowing into the next cut)
stay inside one run, at the speed the sampled jerk and acceleration allow there.

A run's grid is its pieces' points end to end in arc length (a straight move cut into
knots of at most LINE_KNOT mm); each join is a zero-length interval between the two
pieces' own derivatives at it. Arrays per grid point: ``s`` (n,) mm from the run's start,
``T``, ``K`` (n, 3) the signed path derivatives p', p'' in arc length, ``D`` (n, 3) |p'''|,
``jump`` (n, 3) the curvature change (1/mm) taken in less than one knot (a curvature
jump, apart from the smooth change ``D`` accounts for), ``kink`` (n, 3) the change of the
unit tangent at a join; ``cap`` (n,) mm/s the programmed speed and the accuracy rule's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numba import njit

from .machine import Machine
from .path_derivatives import cut_derivatives
from .path_derivatives import end_derivatives as path_end
from .pieces import STRAIGHT_K, Piece

LINE_KNOT = 0.25       # mm: the largest knot of a straight move (the plan's resolution)
CUT_KNOT = 0.5         # mm: the longest knot of a cut's grid. A cut's points are as close
                       # as the 1 um accuracy rule asks (often 0.1 mm) and the plan's cost
                       # goes with its knots: points its derivatives pass linearly merge
KNOT_SHARE = 1e-3      # ... where T and K stay within this share of their scale of the
                       # line between two knots (MARGIN's room: 5e-3)
LINE_KNOTS_MAX = 4000  # knots of one straight move at most
MIN_KNOT = 1e-4        # mm: the shortest knot of a cut's grid
STOP_SPEED = 10.0      # mm/s: a join slower than this is a stop at rest (a corner, or a
                       # curvature jump that lets the feed through at a crawl)
STOP_SHARE = 0.5       # ... or slower than this share of the fastest the axes allow there
JOIN_SHARE = 0.25
"""Share of an axis's jerk (and acceleration) that the one-period jolt of a join or a
curvature jump may take; the rest stays with the smooth motion around it."""


@dataclass
class Run:
    """Pieces ``first``..``first + len(pieces) - 1`` of the program, moved through from
    rest to rest; ``offsets`` (len(pieces) + 1,) where each starts in the run (mm)."""

    first: int
    pieces: list[Piece]
    offsets: np.ndarray
    s: np.ndarray
    T: np.ndarray
    K: np.ndarray
    D: np.ndarray
    jump: np.ndarray
    kink: np.ndarray
    cap: np.ndarray

    @property
    def length(self) -> float:
        return float(self.offsets[-1])

    @cached_property
    def bends(self) -> bool:
        """Whether the path bends (p'' over STRAIGHT_K somewhere), not only by round-off."""
        return bool(np.max(np.abs(self.K), initial=0.0) > STRAIGHT_K)

    @cached_property
    def tangent_reach(self) -> np.ndarray:
        """(3,) the largest |T_i| along the run: how much each axis moves with the path."""
        return np.max(np.abs(self.T), axis=0)

    @cached_property
    def curved(self) -> bool:
        """Whether the path's derivatives change along the run (curvature, jumps, joins)."""
        return bool(np.any(self.K) or np.any(self.jump) or np.any(self.kink)
                    or np.ptp(self.T, axis=0).max() > 0.0)


def end_derivatives(piece: Piece, end: bool) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangent and p'' (1/mm) at the piece's start (``end`` False) or end."""
    return path_end(piece.points, piece.s, end)


def join_speed(before: Piece, after: Piece, machine: Machine) -> tuple[float, np.ndarray,
                                                                       np.ndarray]:
    """The fastest pass through the join of two pieces (mm/s; 0: a stop, at a corner or
    where the pass would crawl) and the jumps of the unit tangent and of p'' there ((3,)
    each).

    In sampled time a tangent jump dt at speed v changes an axis's velocity by v |dt_i|
    within one period: acceleration v |dt_i| / Ts and jerk v |dt_i| / Ts²; a jump dK of
    p'' changes its acceleration by v² |dK_i|: jerk v² |dK_i| / Ts. Each stays within
    JOIN_SHARE of the axis's limit."""
    t0, k0 = end_derivatives(before, True)
    t1, k1 = end_derivatives(after, False)
    v, axes, dt, dk = _join_limits(t0, k0, t1, k1, machine.limits(), machine.period,
                                   JOIN_SHARE)
    top = min(before.cap, after.cap, axes)
    v = min(v, top)
    return (0.0 if v < max(STOP_SPEED, STOP_SHARE * top) else v), dt, dk


@njit(cache=True, error_model="numpy")
def _join_limits(t0, k0, t1, k1, limits, ts: float, share: float):
    """The join's speed limit (mm/s) from its tangent and p'' jumps, the axes' velocity
    limit along either tangent, and the jumps dt, dk (3,); ``limits`` (3, 3): V, A, J
    per axis."""
    dt, dk = t1 - t0, k1 - k0
    v = w = axes = math.inf
    for i in range(3):
        A, J = limits[1, i], limits[2, i]
        v = min(v, share * min(A * ts, J * ts * ts) / abs(dt[i]))
        w = min(w, math.sqrt(share * J * ts / abs(dk[i])))
        axes = min(axes, limits[0, i] / max(abs(t0[i]), abs(t1[i])))
    return min(v, w), axes, dt, dk


def _line_grid(piece: Piece) -> np.ndarray:
    n = int(min(max(math.ceil(piece.length / LINE_KNOT), 2), LINE_KNOTS_MAX))   # (from
    # rest to rest needs two knots: one accelerating, one braking)
    return np.linspace(0.0, piece.length, n + 1)


def _cut_derivatives(piece: Piece) -> tuple[np.ndarray, ...]:
    """T, K (signed), D = |p'''| and the curvature jumps at the piece's points
    (:func:`.path_derivatives.cut_derivatives`)."""
    return cut_derivatives(piece.points, piece.s, end_derivatives(piece, False)[0],
                           end_derivatives(piece, True)[0])


def _piece_grid(piece: Piece, machine: Machine, alone: bool = False):
    """s, T, K, D, jump, cap at the grid points of one piece (``alone``: a run of its own,
    moved from rest to rest: at least two knots, one to accelerate and one to brake)."""
    if len(piece.points) == 2:   # a straight move (or a cut of one step)
        s = _line_grid(piece)
        n = len(s)
        t = (piece.points[1] - piece.points[0]) / piece.length
        zero = np.zeros((n, 3))
        return s, np.tile(t, (n, 1)), zero, zero.copy(), zero.copy(), np.full(n, piece.cap)
    T, K, D, jump = _cut_derivatives(piece)
    cap = np.full(len(piece.s), piece.cap)
    if piece.step_cap is not None:
        cap = np.minimum(cap, piece.step_cap)
    eps_t, eps_k = _linear_room(K)
    keep = _linear_knots(piece.s, T, K, CUT_KNOT, eps_t, eps_k)
    if alone and len(keep) == 2 and len(piece.s) > 2:   # a short straight cut alone
        keep = np.array([0, len(piece.s) // 2, len(piece.s) - 1])
    D, jump, cap = _held(keep, D, jump, cap)
    return piece.s[keep], T[keep], K[keep], D, jump, cap


def _linear_room(K: np.ndarray) -> tuple[float, float]:
    """(eps_T, eps_K 1/mm): how far a cut's T and K may stray from the line between two
    knots: KNOT_SHARE of the unit tangent, and of the cut's largest curvature (the speed
    on a bend is at most sqrt(A / K), where K v^2 then strays by at most that share of
    A). From the path alone, so that a machine's limits never change the grid."""
    top = max(float(np.max(np.abs(K), initial=0.0)), STRAIGHT_K)
    return KNOT_SHARE, KNOT_SHARE * top


@njit(cache=True)
def _linear_knots(s: np.ndarray, T: np.ndarray, K: np.ndarray, longest: float,
                  eps_t: float, eps_k: float) -> np.ndarray:
    """Indices of the points kept as knots: from each knot the farthest point within
    ``longest`` mm such that T and K at every point between stay within eps_t, eps_k of
    the straight line between the two knots' values, and at least MIN_KNOT on (a cut's
    last step may be a few nm: from rest to rest over it takes no finite time on the
    grid); the first and the last point always (compiled: a cut has thousands)."""
    n = len(s)
    keep = np.empty(max(n, 2), dtype=np.int64)
    keep[0] = 0
    m, a = 1, 0
    while a < n - 1:
        c = a + 1
        while c + 1 < n and (s[c] - s[a] < MIN_KNOT or (
                s[c + 1] - s[a] <= longest and _straight(s, T, K, a, c + 1, eps_t, eps_k))):
            c += 1
        keep[m] = c
        m += 1
        a = c
    if m > 2 and s[n - 1] - s[keep[m - 2]] < MIN_KNOT:   # the last knot too short
        keep[m - 2] = n - 1
        m -= 1
    return keep[:m].copy()


@njit(cache=True)
def _straight(s, T, K, a: int, c: int, eps_t: float, eps_k: float) -> bool:
    """Whether T and K at the points strictly between a and c are within eps_t, eps_k of
    the lines through their values at a and c (in arc length)."""
    h = s[c] - s[a]
    for i in range(a + 1, c):
        f = (s[i] - s[a]) / h if h > 0.0 else 0.0
        for j in range(3):
            if abs(T[i, j] - (T[a, j] + f * (T[c, j] - T[a, j]))) > eps_t:
                return False
            if abs(K[i, j] - (K[a, j] + f * (K[c, j] - K[a, j]))) > eps_k:
                return False
    return True


@njit(cache=True)
def _held(keep: np.ndarray, D: np.ndarray, jump: np.ndarray, cap: np.ndarray) -> tuple:
    """D, jump (m, 3) and cap (m,) at the kept knots ``keep`` (m,) of a grid of n points:
    each knot holds the largest D and jump and the smallest cap of every point between
    it and the knots on either side (a point between two knots is passed at speeds
    between theirs, so both carry its limits)."""
    m, n = len(keep), len(cap)
    D2, jump2, cap2 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m)
    for j in range(m):
        a = keep[j - 1] + 1 if j > 0 else 0
        b = keep[j + 1] - 1 if j + 1 < m else n - 1
        a, b = min(a, keep[j]), max(b, keep[j])
        cap2[j] = cap[a]
        for i in range(3):
            D2[j, i] = D[a, i]
            jump2[j, i] = jump[a, i]
        for p in range(a + 1, b + 1):
            cap2[j] = min(cap2[j], cap[p])
            for i in range(3):
                D2[j, i] = max(D2[j, i], D[p, i])
                jump2[j, i] = max(jump2[j, i], jump[p, i])
    return D2, jump2, cap2


def _run(first: int, pieces: list[Piece], machine: Machine, joins: list) -> Run:
    grids = [_piece_grid(p, machine, len(pieces) == 1) for p in pieces]
    offsets = np.concatenate(([0.0], np.cumsum([p.length for p in pieces])))
    s = np.concatenate([g[0] + o for g, o in zip(grids, offsets)])
    T, K, D, jump, cap = (np.concatenate([g[i] for g in grids]) for i in range(1, 6))
    kink = np.zeros_like(T)
    at = 0
    for g, join in zip(grids[:-1], joins):   # the join: last point of one, first of next
        at += len(g[0])
        v, dt, dk = join
        kink[at - 1] = kink[at] = np.abs(dt)
        jump[at - 1] = np.maximum(jump[at - 1], np.abs(dk))
        jump[at] = np.maximum(jump[at], np.abs(dk))
        cap[at - 1] = cap[at] = min(cap[at - 1], cap[at], v)
    return Run(first, pieces, offsets, s, T, K, D, jump, kink, cap)


def runs_of(pieces: list[Piece], machine: Machine) -> list[Run]:
    """The pieces grouped into runs, each from rest to rest (see the module doc)."""
    out, start, joins = [], 0, []
    for k in range(1, len(pieces) + 1):
        join = None if k == len(pieces) else join_speed(pieces[k - 1], pieces[k], machine)
        if join is None or join[0] <= 0.0:
            out.append(_run(start, pieces[start:k], machine, joins))
            start, joins = k, []
        else:
            joins.append(join)
    return out
