"""The stepper following a planned arc length, one period per row, in the compiled loop.

A controller's feed plan gives, per period n, the arc length the cutter should have
travelled. ``follow`` commands each period the step that closes the gap (the planned
length minus the distance the kernel has travelled), through ``step.step``: the same
track, accuracy rule (step shortening), trial cycle and end landing as any period, so
every position is the kernel's on the exact path. It hands back to the caller only for
what ``step`` leaves to it (a stop, a landing on a limit, an exact trim check) and at the
cycle or record limit; the caller finishes that period and calls again from the next row.

``plan`` (rows, 3): per period the planned length ``target`` (mm, as the kernel's chord
sum), the blend weight ``w`` and ``left``, the planned distance still to go (mm). Where
w > 0 (the last stretch of a path with an end) the command moves onto the distance left
to the end point: (1 - w) (target - travelled) + w (arc to the end - left), the arc being
the chord d to the end times (1 + k^2 d^2 / 24) (k: the path's curvature there); once
the plan has nothing left (left <= 0) the command reaches at least past the end,
d (1 + landing) + 1e-12. A command <= 0 holds the position. ``args``: end point (3),
k, landing, feed per mm of step (60 / Ts) and the period Ts, so the step is the one
``Stepper.step(feed)`` makes of that feed, to the last bit.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .layout import CYCLES, TRAVELLED, P
from .step import DONE, MAX_CYCLES, RECORD_FULL, step

_jit = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)

LANDING_PAST = 1e-12   # mm: the last step asks this much past the end, so that it lands

A_END, A_K, A_LANDING, A_TO_FEED, A_PERIOD = 0, 3, 4, 5, 6   # offsets in ``args``
ARGS = 7


@_jit
def command(plan: np.ndarray, n: int, args: np.ndarray, S: np.ndarray) -> float:
    """The step (mm) commanded for period n from the state S (see the module doc)."""
    f = plan[n, 0] - S[TRAVELLED]
    w = plan[n, 1]
    if w > 0.0:
        left = plan[n, 2]
        d = math.sqrt((args[A_END] - S[P]) ** 2 + (args[A_END + 1] - S[P + 1]) ** 2
                      + (args[A_END + 2] - S[P + 2]) ** 2)
        k = args[A_K]
        f = (1.0 - w) * f + w * (d * (1.0 + k * k * d * d / 24.0) - left)
        if left <= 0.0:
            f = max(f, d * (1.0 + args[A_LANDING]) + LANDING_PAST)
    return f


@_jit
def follow(F: np.ndarray, I: np.ndarray, S: np.ndarray, R: np.ndarray, n_rec: int,
           plan: np.ndarray, args: np.ndarray, out: np.ndarray, n0: int,
           max_cycles: int) -> tuple:
    """Rows n0.. of ``out`` (the centre after each period) until the plan's end or an
    event: (status, row, rows recorded). DONE: every row written. Else row ``row`` is
    not written: the caller finishes the period (status as ``step``'s; MAX_CYCLES,
    RECORD_FULL: no step taken) and goes on from row + 1 (row, after RECORD_FULL)."""
    to_feed = args[A_TO_FEED]
    period = args[A_PERIOD]
    for n in range(n0, plan.shape[0]):
        f = command(plan, n, args, S)
        if f > 0.0:
            if S[CYCLES] >= max_cycles:
                return MAX_CYCLES, n, n_rec
            if n_rec >= R.shape[0]:
                return RECORD_FULL, n, n_rec
            status = step(F, I, S, R, n_rec, f * to_feed * period / 60.0)
            if status != DONE:
                return status, n, n_rec
            if n_rec >= 0:
                n_rec += 1
        out[n, 0] = S[P]
        out[n, 1] = S[P + 1]
        out[n, 2] = S[P + 2]
    return DONE, plan.shape[0], n_rec
