"""One piece's positions per period, a block of periods at a time (no OCCT): a cut's by
its own stepper re-run following the plan (the kernel, :mod:`cadcnc.interp.planned_follow`;
``substeps`` equal cycles a period where the accurate step is shorter than a period's
advance; over the last BLEND mm the target moves onto the distance left to the end), a
link's straight move in closed form, a blend or a cut without a stepper by a cubic
Hermite through its points in arc length. Positions (rows, 3) mm; arc lengths mm.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import GeometryError
from ..core.tolerances import STREAM_END
from ..interp.cycle import CLOSED, END
from ..interp.planned_follow import follow
from .pieces import Piece

SHORT_CUT = 0.01  # mm: a cut shorter than this is positioned from its points (cubic
                  # Hermite through the kernel's own points, nm from the path): the kernel
                  # re-run on it can step past its end before its end test applies (the
                  # test waits for two steps' travel, for closed loops)
SETTLE_STEP = 1e-12   # mm: the steps that settle a cut's start onto the kernel's path,
SETTLE_STEPS = 8      # at most this many (until one moves less than SETTLE_MIN)
SETTLE = 1.0      # mm: the settling move given out over this much of the cut's ends
SETTLE_MIN = 1e-9  # mm: ... where it is over this (below, the rows are the kernel's)
LANDING = 1e-6   # relative: the last step of a cut commanded this much past its end
BLEND = 1.0
"""mm before a cut's end (at most its length) where the target moves onto the distance
left. The kernel's path is a few 1e-7 of its length longer or shorter than the program's
points say (1e-5 mm on a 40 mm cut); moving that onto the end over the last B mm adds
about 60 x that x (v / B)³ to the jerk (the weight's third derivative, at a stop's speed
there): at 0.2 mm 1 % of the limit on the slab's waterline, 125 times less at 1 mm."""


def _line(piece: Piece, s: np.ndarray) -> np.ndarray:
    a, b = piece.points[0], piece.points[-1]
    return a + np.outer(s / piece.length, b - a)


def _hermite(piece: Piece, s: np.ndarray) -> np.ndarray:
    """Cubic Hermite in arc length through the piece's points, tangents by central
    differences: positions at ``s`` (mm)."""
    p, ss = piece.points, piece.s
    if len(p) < 3:
        return _line(piece, s)
    d = np.gradient(p, ss, axis=0)
    k = np.clip(np.searchsorted(ss, s, side="right") - 1, 0, len(ss) - 2)
    h = ss[k + 1] - ss[k]
    x = ((s - ss[k]) / h)[:, None]
    h00, h10 = 2 * x ** 3 - 3 * x ** 2 + 1, x ** 3 - 2 * x ** 2 + x
    h01, h11 = -2 * x ** 3 + 3 * x ** 2, x ** 3 - x ** 2
    return h00 * p[k] + h10 * h[:, None] * d[k] + h01 * p[k + 1] + h11 * h[:, None] * d[k + 1]


def _blend(x: np.ndarray) -> np.ndarray:
    """The C2 weight from 0 (x <= 0) to 1 (x >= 1): 10 x³ - 15 x⁴ + 6 x⁵."""
    x = np.clip(x, 0.0, 1.0)
    return x ** 3 * (10.0 - 15.0 * x + 6.0 * x * x)


def follow_plan(piece: Piece, s: np.ndarray, before: float = 0.0,
                travelled: float = 0.0) -> np.ndarray:
    """(rows, 3) the per-period plan the kernel follows on a cut (kernel/follow.py): the
    target length as the kernel's chord sum, the blend weight onto the distance left to
    the end (C2 from 0 to 1 over the last BLEND mm, or the whole cut if shorter), and the
    planned length left.
    ``before``, ``travelled``: the arc length and the target length of the row before
    s[0] (0, 0: s starts the cut), so that a cut's plan is made a block at a time, the
    same numbers as at once."""
    ds = np.diff(s, prepend=before)
    kappa = np.interp(s, piece.s, piece.kappa)
    plan = np.empty((len(s), 3))
    plan[:, 0] = np.cumsum(np.concatenate(([travelled],
                                           ds * (1.0 - kappa ** 2 * ds ** 2 / 24.0))))[1:]
    plan[:, 2] = left = piece.length - s
    plan[:, 1] = _blend(1.0 - left / min(BLEND, piece.length))
    return plan


def substep_lengths(s: np.ndarray, before: float, m: int) -> np.ndarray:
    """(len(s) * m,) the arc lengths of m kernel cycles a period: each period's advance
    from the row before (``before`` for s[0]) in m equal parts, the period's own last."""
    edges = np.concatenate(([before], s))
    parts = np.arange(1, m + 1) / m
    out = edges[:-1, None] + np.diff(edges)[:, None] * parts
    out[:, -1] = s
    return out.ravel()


def _landed(stepper, piece: Piece, what: str) -> None:
    """Nothing once the stepper has landed on the cut's last point (GeometryError if it
    stopped on the way or missed it): the kernel's path is a few 1e-7 of its length longer
    or shorter than the program's points say, so over the last BLEND mm the target moves
    smoothly onto the distance left to the end, and the rest of the cut may lie between
    two periods."""
    if stepper.stop_reason not in (None, END, CLOSED):
        raise GeometryError(f"{what}: the stepper stopped while streaming "
                            f"({stepper.stop_reason}: {stepper.stop_detail})")
    end = piece.points[-1]
    p = np.asarray(stepper.p)
    to_feed = 60.0 / stepper.period
    for _ in range(3):   # the rest of the cut lies between two periods: land on its end
        if stepper.stop_reason is not None:
            break
        feed = float(np.linalg.norm(end - p)) * (1.0 + LANDING) * to_feed
        dp = stepper.step(feed + 1e-9)   # mm/min: > 0 on the end itself
        p = p if dp is None else p + dp
    if stepper.stop_reason not in (END, CLOSED) or np.linalg.norm(p - end) > STREAM_END:
        raise GeometryError(f"{what}: the stepper did not land on the cut's last point "
                            f"(stopped: {stepper.stop_reason}; {np.linalg.norm(p - end):.3g} "
                            "mm from it)")


class _CutRows:
    """One cut's positions by its stepper, a block of rows at a time (the plan it follows
    made a block at a time too: the same numbers as at once).

    The kernel's first step corrects the recorded start onto its exact path (a few nm
    across it where the start came from a search): before the cut is followed, steps of
    SETTLE_STEP mm (SETTLE_STEPS at most) settle it there, the plan's lengths are counted from there, and
    where the move is over SETTLE_MIN it is taken back and given out over the cut's
    first SETTLE mm (C2; at most a third of the cut), and, on a closed loop, which lands
    on its recorded start again, over its last SETTLE mm: no period jolts, and the
    positions leave the exact path by at most that move."""

    def __init__(self, stepper, piece: Piece, what: str):
        self.stepper, self.piece, self.what = stepper, piece, what
        self.before = self.travelled = 0.0
        self.across = None   # (3,) the settling move, once made (zeros: none to give out)

    def _settle(self) -> None:
        start = np.asarray(self.stepper.p, float)
        self.across = np.zeros(3)
        for _ in range(SETTLE_STEPS):   # each step's correction is a Newton step's
            dp = self.stepper.step(SETTLE_STEP * 60.0 / self.stepper.period)
            if dp is None:   # stopped there: the rows will say so
                return
            self.travelled = self.stepper.travelled
            if np.linalg.norm(dp) <= SETTLE_MIN:
                break
        moved = np.asarray(self.stepper.p, float) - start
        if np.linalg.norm(moved) > SETTLE_MIN:
            self.across = moved

    def __call__(self, s: np.ndarray) -> np.ndarray:
        piece, m = self.piece, self.piece.substeps
        if self.across is None:
            self._settle()
        plan = follow_plan(piece, substep_lengths(s, self.before, m), self.before,
                           self.travelled)
        out = follow(self.stepper, plan, piece.points[-1], float(piece.kappa[-1]), LANDING)
        if len(s):
            self.before, self.travelled = float(s[-1]), float(plan[-1, 0])
        rows = out[m - 1::m]
        if self.across.any():
            rows = self._given_out(rows, s)
        return rows

    def _given_out(self, rows: np.ndarray, s: np.ndarray) -> np.ndarray:
        """The rows with the settling move taken back near the start and, on a closed loop
        (which lands on its recorded start), near the end, but the rows landed there."""
        piece = self.piece
        span = min(SETTLE, piece.length / 3.0)
        back = 1.0 - _blend(s / span)
        if self.stepper.closed:
            landed = np.all(rows == piece.points[-1], axis=1)
            back = back + np.where(landed, 0.0, _blend((s - piece.length + span) / span))
        return rows - back[:, None] * self.across

    def close(self) -> None:
        _landed(self.stepper, self.piece, self.what)


def piece_rows(program, machine, piece: Piece, steppers, counts: dict):
    """``rows(s)``: the positions of ``piece`` at arc lengths ``s`` (a block at a time; a
    cut's by its stepper, whose ``close()`` checks its landing); ``counts`` the cuts
    positioned by the kernel and by their points."""
    if piece.cut is None:   # a link's straight move, or a blend by its samples
        line = len(piece.points) == 2
        return lambda s: (_line if line else _hermite)(piece, s)
    stepper = None if steppers is None or piece.length < SHORT_CUT else steppers(
        piece.cut, program.cuts[piece.cut], machine.period)
    if stepper is None:
        counts["hermite"] += 1
        return lambda s: _hermite(piece, s)
    counts["kernel"] += 1
    return _CutRows(stepper, piece, f"cut {piece.cut + 1}")
