"""A whole program as one position per servo period, at the planned feed (no OCCT).

:func:`stream_program` plans the feed (:mod:`.feed_plan`), then computes each period's
position on the exact path: a cut's by its own stepper re-run with the per-cycle feed
override (the kernel computes every position, following the plan in its compiled loop,
:mod:`cadcnc.interp.planned_follow`; the step commanded each period is the planned arc length
minus the distance the kernel has travelled; where the accurate step is shorter than a
period's advance, the piece's ``substeps`` equal cycles a period), a link move's in
closed form. The steppers
come from the caller (``steppers(cut_index, segment, period)``, built
where the part's faces are, e.g. :func:`cadcnc.ops.stream_steppers.stepper_factory`); a
cut without one (a convex roll-over arc) is interpolated from its own points by a cubic
Hermite in arc length (each piece's rows: :mod:`.cut_rows`). Positions: (N, 3) float64,
absolute X Y Z in mm; row 0 is the program's first point at t = 0, row n the position at
n Ts.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from numba import njit

from ..core.progress import Progress
from ..core.scratch import rows_array
from ..program.program import Program
from .cut_rows import piece_rows
from .feed_plan import MAX_PERIODS, FeedPlan, PlanError, plan_feed
from .link_blends import stream_pieces
from .machine import AXES, Machine
from .pieces import programmed_time

StepperFactory = Callable[[int, object, float], object]
"""steppers(cut_index, cut_segment, period) -> a fresh stepper from the cut's first point
landing on its last (record off), or None when the cut has none."""


@dataclass
class Stream:
    """The positions of every period, the plan they follow and where each piece's rows
    are. ``kernel_cuts`` / ``hermite_cuts``: cuts positioned by the kernel / by their
    points."""

    positions: np.ndarray
    plan: FeedPlan
    programmed_time: float
    starts: np.ndarray        # (pieces + 1,) each piece's first row (the last: N)
    kernel_cuts: int = 0
    hermite_cuts: int = 0
    notes: list[str] = field(default_factory=list)

    @property
    def machine(self) -> Machine:
        return self.plan.machine

    @property
    def periods(self) -> int:
        return len(self.positions) - 1

    @property
    def cycle_time(self) -> float:
        return self.periods * self.machine.period

    @property
    def rows(self) -> np.ndarray:
        """(N,) the piece of each row (made on demand: 8 bytes a period)."""
        return np.repeat(np.arange(len(self.starts) - 1), np.diff(self.starts))

    def derivatives(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Finite-difference velocity, acceleration and jerk of the positions (mm/s...;
        whole arrays: for short streams and plots)."""
        ts, x = self.machine.period, self.positions
        return (np.diff(x, axis=0) / ts, np.diff(x, 2, axis=0) / ts ** 2,
                np.diff(x, 3, axis=0) / ts ** 3)

    def shares(self) -> dict[str, tuple[float, float, float]]:
        """Per axis, the largest |v|, |a|, |j| of the positions as a share of the limits
        (a block of rows at a time)."""
        peak, _ = _peaks(self.positions)
        limits, ts = self.machine.limits(), self.machine.period
        return {name: tuple(float(p / ts ** (k + 1) / lim)
                            for p, lim in zip(peak[k].tolist(), limits[k].tolist()))
                for k, name in enumerate(("velocity", "acceleration", "jerk"))}

    @property
    def rounded(self) -> frozenset[int]:
        """Segment indices of the links streamed with rounded corners."""
        return frozenset(p.segment for p in self.plan.pieces
                         if p.cut is None and len(p.points) > 2)

    def segment_moves(self, program: Program) -> list[np.ndarray]:
        """Per program segment, the streamed positions inside it, led by the row before
        (so every chord of the stream belongs to exactly one segment): the gate's moves.
        Read-only views of the positions (a segment's rows are consecutive)."""
        starts = _segment_rows(self.starts, [p.segment for p in self.plan.pieces],
                               len(program.segments))
        view = self.positions.view()
        view.flags.writeable = False
        return [view[max(starts[k] - 1, 0):max(starts[k + 1], 1)]
                for k in range(len(program.segments))]

    def summary(self) -> dict:
        """Cycle time, periods, shares of the limits per axis, time lost to the limits."""
        shares = self.shares()
        return {
            "periods": self.periods, "period_s": self.machine.period,
            "cycle_time_s": self.cycle_time, "programmed_time_s": self.programmed_time,
            "time_lost_s": self.cycle_time - self.programmed_time,
            **{f"max_{k}_share": dict(zip(AXES, v)) for k, v in shares.items()},
            "kernel_cuts": self.kernel_cuts, "hermite_cuts": self.hermite_cuts,
            "machine": self.machine.source}


def _segment_rows(starts: np.ndarray, segments: list[int], count: int) -> np.ndarray:
    """(count + 1,) where each program segment's rows start, from the pieces' first rows
    ``starts`` and their ``segments`` (non-decreasing): row 0 belongs to segment 0."""
    segments = np.asarray(segments)
    if (segments[1:] < segments[:-1]).any():
        raise ValueError("the stream's pieces are not in the order of their segments")
    first = np.searchsorted(segments, np.arange(count + 1), side="left")
    out = np.asarray(starts)[first]
    out[1:] = np.maximum(out[1:], 1)
    out[0] = 0
    return out


CHUNK = 100_000   # rows differenced or printed at a time
SLACK = 1e-6      # relative: the finite differences' allowance over a limit
REPLANS = 3       # plans again with the limit that was broken lowered by as much ...
NOISE = 1.5       # ... unless it is broken this much: the positions' noise, not the plan
NOISY_PERIOD = 1e-4   # s: below it the positions' rounding can break the jerk


def _peaks(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(3, 3) peaks and (3, 3) rows: per order k = 1, 2, 3 of finite difference and per
    axis, the largest |k-th difference| of the positions (mm) and the period where it is
    first reached (CHUNK rows at a time: the differences' temporaries stay bounded
    whatever the stream's length; a block with a position that is not a number is
    skipped, the stream's check names it)."""
    peak, where = np.zeros((3, 3)), np.zeros((3, 3), dtype=np.int64)
    for start in range(0, max(len(positions) - 1, 1), CHUNK):
        _block_peaks(np.ascontiguousarray(positions[start:start + CHUNK + 3]), start,
                     peak, where)
    return peak, where


@njit(cache=True)
def _block_peaks(block: np.ndarray, start: int, peak: np.ndarray, where: np.ndarray) -> None:
    """:func:`_peaks` of one block whose first row is ``start``: each order's differences
    as NumPy's repeated ``diff`` makes them; an order with a difference that is not a
    number leaves the peaks as they are."""
    n = len(block)
    d = block.copy()
    for k in range(1, 4):
        if n <= k:
            return
        m = n - k
        for i in range(m):
            for a in range(3):
                d[i, a] = d[i + 1, a] - d[i, a]
        top, row = np.zeros(3), np.zeros(3, dtype=np.int64)
        bad = False
        for a in range(3):
            for i in range(m):
                x = abs(d[i, a])
                if x != x:
                    bad = True
                elif x > top[a] or i == 0:
                    top[a], row[a] = x, i
        if bad:
            continue
        for a in range(3):
            if top[a] > peak[k - 1, a]:
                peak[k - 1, a] = top[a]
                where[k - 1, a] = start + row[a] + k


def _over(positions: np.ndarray, machine: Machine) -> list[tuple[float, int, int]]:
    """Per quantity (velocity, acceleration, jerk): the largest finite-difference share
    of an axis's limit, its period and its axis (:func:`_peaks`; of axes at the same
    share, the one reaching it first)."""
    peak, where = _peaks(positions)
    limits = machine.limits()
    out = []
    for q in range(3):
        share = peak[q] / (machine.period ** (q + 1) * limits[q])
        top = share.max()
        a = min((a for a in range(3) if share[a] == top), key=lambda a: where[q, a])
        out.append((float(top), int(where[q, a]), a))
    return out


def _refusal(over: list[tuple[float, int, int]], machine: Machine) -> PlanError:
    """The refusal, naming the limit, the axis and the period, and the likely cause: the
    positions' own rounding when the period is short and the excess large."""
    names = ("velocity", "acceleration", "jerk")
    q = max(range(3), key=lambda i: over[i][0])
    share, row, axis = over[q]
    if share > NOISE and machine.period < NOISY_PERIOD:
        why = (f"the positions' own rounding at a {machine.period * 1e6:g} us period: a "
               "longer servo period may stream")
    else:
        why = ("the plan could not keep this limit along this path after "
               f"{REPLANS} replans: please report it; a lower feed may stream")
    return PlanError(
        "the stream is over the machine's limits: nothing written: it would reach "
        f"{100 * share:.1f} % of axis {AXES[axis]}'s {names[q]} limit at period {row} "
        f"({why})")


def stream_program(program: Program, machine: Machine, steppers: StepperFactory | None = None,
                   *, feed: float | None = None, planned: bool = True,
                   max_periods: int = MAX_PERIODS, progress: Progress | None = None,
                   blend: float = 0.0, exact: frozenset[int] = frozenset(),
                   on_plan: Callable[[FeedPlan], None] | None = None,
                   scratch: str | None = None) -> Stream:
    """Every period's position of ``program`` on ``machine`` (see the module doc).

    ``feed`` (mm/min) replaces the program's feed; ``planned=False`` streams at the
    programmed feed ignoring the limits (a comparison, not for a machine). A plan over
    ``max_periods`` periods is refused before any position is computed (InputError);
    ``progress(done, total, "periods")`` hears of the work after each block of periods
    (:data:`~.feed_plan.BLOCK_ROWS` at most). A planned
    stream whose finite differences break a limit is planned again, first with every
    bending run's limits held over its averaging window's reach (the first plan measures
    some where they are, which the run's grid may not resolve: :mod:`.run_plan`), then
    with the limit that was broken lowered by as much (REPLANS times at most), then
    refused (PlanError). ``blend`` (mm)
    rounds the corners of the links that pay for it within it, but not of the segments
    in ``exact`` (:func:`.link_blends.stream_pieces`); a blend is positioned on its samples by
    the Hermite. ``on_plan(plan)`` hears of each plan before its positions are computed
    (to count, bound or announce the periods; a replan is heard again). ``scratch``: the
    folder of a long stream's positions file (:func:`~cadcnc.core.scratch.rows_array`)."""
    pieces = stream_pieces(program, machine, feed, blend, exact)
    derate, measured, replans = np.ones(3), True, 0
    while True:
        stream = None   # a replan's positions replace these (one scratch file at a time)
        stream = _stream(program, machine, pieces, steppers, planned, derate, max_periods,
                         progress, on_plan, scratch, measured)
        if not planned:
            return stream
        over = _over(stream.positions, machine)
        shares = np.array([o[0] for o in over])
        if (shares <= 1.0 + SLACK).all():
            return stream
        if measured and stream.plan.measured:   # limits taken where they are: now held
            measured = False
            continue
        measured = False
        if shares.max() > NOISE or replans == REPLANS:
            break
        replans += 1
        # the path's derivatives between coarse points: plan again with less of the limit
        derate = np.where(shares > 1.0, derate / (shares * (1.0 + 1e-2)), derate)  # 1 % under
    raise _refusal(over, machine)


def _stream(program, machine, pieces, steppers, planned, derate, max_periods,
            progress, on_plan=None, scratch=None, measured: bool = True) -> Stream:
    """One plan (limits scaled by ``derate``; ``measured``: see
    :func:`~.feed_plan.plan_feed`) and its positions, a block of periods at a time
    (:meth:`FeedPlan.blocks`: no per-period array but the positions)."""
    plan = plan_feed(pieces, machine, planned, tuple(derate), measured)
    if on_plan is not None:
        on_plan(plan)
    total = plan.checked_periods(max_periods)
    positions = rows_array(total + 1, scratch, "the stream's positions")
    starts = np.full(len(pieces) + 1, total + 1, dtype=np.int64)
    counts = {"kernel": 0, "hermite": 0}
    current, rows_of = -1, None

    def begin(j: int, row: int) -> None:   # the pieces after ``current`` up to j
        nonlocal current, rows_of
        if j < current:
            raise ValueError("the stream's rows are not in the order of their pieces")
        for q in range(current + 1, j + 1):
            if rows_of is not None and hasattr(rows_of, "close"):
                rows_of.close()
            rows_of, starts[q] = piece_rows(program, machine, pieces[q], steppers,
                                             counts), row
        current = j

    for j, row, s in plan.blocks(max_periods):
        if j != current:
            begin(j, row)
        positions[row:row + len(s)] = rows_of(s)
        if progress is not None:
            progress(row + len(s) - 1, total, "periods")
    begin(len(pieces) - 1, total + 1)   # pieces after the last period: none, or empty
    if hasattr(rows_of, "close"):
        rows_of.close()
    positions[0] = pieces[0].points[0]
    positions[-1] = pieces[-1].points[-1]
    if progress is not None:
        progress(total, total, "periods")
    return Stream(positions, plan, programmed_time(pieces, machine), starts,
                  counts["kernel"], counts["hermite"])


def stream_text(positions: np.ndarray) -> str:
    """One line per period, ``X Y Z`` in mm with 9 decimals (halstreamer, cfg=fff); made
    CHUNK rows at a time (the lines of one chunk, not of the whole stream, in memory)."""
    return "".join("".join(f"{x:.9f} {y:.9f} {z:.9f}\n" for x, y, z in
                           positions[a:a + CHUNK].tolist())
                   for a in range(0, len(positions), CHUNK))
