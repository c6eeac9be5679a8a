"""The time-optimal v/a bound of a program on a machine, computed by TOPP-RA (``toppra``).

Independent of cadcnc's planner (it shares no code with ``cadcnc.controller``): the
program's moves (the cuts' points, the links' straight moves) are cut into stretches at
every corner (a turn of the chord direction over CORNER_DEG) and every curvature jump at
a join of two moves (over JUMP per mm); each stretch is a cubic spline through its points
in arc length, moved from rest to rest at 100 % of each axis's velocity and acceleration,
no jerk limit, at most the programmed feed (rapids: the axes' limits alone). The bound is
the sum of the stretches' times: no plan that stops at those places and keeps those
limits can be faster (up to the grid's resolution, GRID mm).
"""

from __future__ import annotations

import math

import numpy as np

CORNER_DEG = 1.0
JUMP = 1e-3     # 1/mm
GRID = 0.05     # mm between TOPP-RA's grid points (at most 20 000 per stretch)
MIN_GAP = 1e-3  # mm: the closest two points of a stretch's spline
RAPID = 1e6     # mm/s: a rapid's feed bound (TOPP-RA takes no infinite bound)


def _curvature(p: np.ndarray) -> np.ndarray:
    """(n,) curvature of the circle through each point and its neighbours."""
    if len(p) < 3:
        return np.zeros(len(p))
    a, b, c = p[1:-1] - p[:-2], p[2:] - p[1:-1], p[2:] - p[:-2]
    k = 2 * np.linalg.norm(np.cross(a, b), axis=1) / (
        np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1) * np.linalg.norm(c, axis=1))
    return np.r_[k[:1], k, k[-1:]]


def moves(program, feed_mm_min: float) -> list[tuple[np.ndarray, float]]:
    """Every move in order: (points (n, 3) mm, speed cap mm/s; inf for a rapid)."""
    f = feed_mm_min / 60.0
    out = []
    for seg in program.segments:
        pts = np.asarray(seg.points, dtype=float)
        if seg.kind == "cut":
            keep = np.r_[True, np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-12]  # mm: repeats
            out.append((pts[keep], f))
            continue
        for m, rapid in enumerate(seg.rapid):
            if np.linalg.norm(pts[m + 1] - pts[m]) > 1e-12:   # mm: not a repeat
                out.append((pts[m:m + 2], math.inf if rapid else f))
    return out


def stretches(program, feed_mm_min: float) -> list[list[tuple[np.ndarray, float]]]:
    """The moves grouped into stretches moved through without a stop."""
    groups, cur = [], []
    for pts, cap in moves(program, feed_mm_min):
        if cur:
            prev = cur[-1][0]
            t0 = prev[-1] - prev[-2]
            t1 = pts[1] - pts[0]
            turn = math.degrees(math.acos(np.clip(t0 @ t1 / np.linalg.norm(t0)
                                                  / np.linalg.norm(t1), -1, 1)))
            jump = abs(_curvature(prev)[-1] - _curvature(pts)[0])
            if turn > CORNER_DEG or jump > JUMP:
                groups.append(cur)
                cur = []
        cur.append((pts, cap))
    groups.append(cur)
    return groups


def _instance(group, machine):
    """TOPP-RA's problem for one stretch from rest to rest, v and a at 100 %."""
    import toppra as ta
    import toppra.algorithm as algo
    import toppra.constraint as constraint
    ta.setup_logging("WARNING")
    dense, caps, ends = [group[0][0][:1]], [], [0.0]
    for p, cap in group:   # straight moves cut into 4 GRID pieces: the spline stays on them
        for a, b in zip(p[:-1], p[1:]):
            n = max(1, math.ceil(np.linalg.norm(b - a) / (4 * GRID))) if len(p) == 2 else 1
            dense.append(a + np.linspace(0, 1, n + 1)[1:, None] * (b - a))
        caps.append(cap)
        ends.append(ends[-1] + float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()))
    x = np.vstack(dense)
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))]
    keep = [0]   # points at least MIN_GAP apart (a cut's last step may be a few nm, where
    for i in range(1, len(s)):   # a spline through them turns wild)
        if s[i] - s[keep[-1]] >= MIN_GAP:
            keep.append(i)
        elif i == len(s) - 1:
            keep[-1] = i if len(keep) > 1 else keep[-1]
    x = x[keep]
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))]
    L = float(s[-1])
    ends, caps = np.asarray(ends) * (L / ends[-1]), np.asarray(caps)
    V, A = np.asarray(machine.max_velocity), np.asarray(machine.max_acceleration)

    def limits(si: float) -> np.ndarray:
        """(4, 2): the axes' velocity and the feed, as |d s / d t| (the fourth coordinate)."""
        k = min(max(int(np.searchsorted(ends, si, side="right")) - 1, 0), len(caps) - 1)
        at_joint = k > 0 and abs(si - ends[k]) < 1e-9   # mm: on the joint of two pieces
        cap = caps[k] if not at_joint else min(caps[k], caps[k - 1])
        cap = min(cap, RAPID)
        return np.vstack([np.c_[-V, V], [[-cap, cap]]])

    path = ta.SplineInterpolator(s, np.c_[x, s])
    acc = constraint.JointAccelerationConstraint(np.vstack([np.c_[-A, A], [[-1e8, 1e8]]]))
    n = int(min(max(L / GRID, 50), 20000))
    return algo.TOPPRA([constraint.JointVelocityConstraintVarying(limits), acc], path,
                       gridpoints=np.linspace(0, L, n + 1), parametrizer="ParametrizeConstAccel")


def stretch_time(group, machine) -> float:
    """Seconds of one stretch from rest to rest (TOPP-RA, v and a at 100 %)."""
    traj = _instance(group, machine).compute_trajectory(0, 0)
    if traj is None:
        raise RuntimeError("TOPP-RA found no profile for a stretch")
    return float(traj.duration)


def bound_feed(program, machine, feed_mm_min: float | None = None):
    """(s, v): the bound's speed (mm/s) against arc length along the whole program (mm),
    on TOPP-RA's grid points, stretch after stretch."""
    feed = program.job.feed if feed_mm_min is None else feed_mm_min
    out_s, out_v, at = [], [], 0.0
    for g in stretches(program, feed):
        inst = _instance(g, machine)
        sd = inst.compute_parameterization(0, 0)[1]
        if sd is None:
            raise RuntimeError("TOPP-RA found no profile for a stretch")
        grid = np.asarray(inst.problem_data.gridpoints)
        out_s.append(at + grid)
        out_v.append(np.asarray(sd))
        at += float(grid[-1])
    return np.concatenate(out_s), np.concatenate(out_v)


def va_bound(program, machine, feed_mm_min: float | None = None) -> float:
    """Seconds: the time-optimal v/a bound of the program (see the module doc)."""
    feed = program.job.feed if feed_mm_min is None else feed_mm_min
    return sum(stretch_time(g, machine) for g in stretches(program, feed))
