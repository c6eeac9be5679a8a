"""A whole program's feed plan: its runs (:mod:`.runs`) each planned near time-optimally
to the axes' limits (:func:`.run_plan.plan_run`; a repeated run, such as a raster's
passes, once), their profiles back to back in time, and the arc length of every period
made a block at a time. Times s, lengths mm.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..core.errors import InputError
from . import topp
from .machine import Machine
from .pieces import Piece, constant_speed
from .profile import Profile
from .run_plan import PlanError, plan_run
from .runs import Run, runs_of

__all__ = ["BLOCK_ROWS", "MAX_PERIODS", "FeedPlan", "PlanError", "Profile", "plan_feed"]

MAX_PERIODS = 50_000_000
BLOCK_ROWS = 1 << 16   # periods of targets made at a time (FeedPlan.blocks): a few MB
SAME_RUN = 1e-11
"""Runs whose path derivatives agree within this (absolute, in their units, and relative)
share one plan: the limits are then met within about 1e-7 of themselves on the other
run, far inside MARGIN."""


def _constant_run(first: int, piece: Piece, machine: Machine) -> tuple[Run, Profile]:
    """The piece alone, at its programmed speed throughout (rapids at the axes' velocity),
    no ramp, no limit: what a stream ignoring the machine does."""
    v = constant_speed(piece, machine)
    s = np.array([0.0, piece.length])
    w = np.array([v * v, v * v])
    t, vv, a, S = topp.time_law(s, w, np.zeros(1))
    empty = np.zeros((2, 3))
    run = Run(first, [piece], s.copy(), s, empty, empty, empty, empty, empty, np.full(2, v))
    return run, Profile(t, s, vv, a, S, 0.0)


@dataclass
class FeedPlan:
    """Every run's profile, back to back in time: run k starts at ``starts[k]`` s."""

    pieces: list
    runs: list[Run]
    profiles: list[Profile]
    machine: Machine
    planned: bool = True   # False: at the programmed feed, the limits ignored

    @cached_property
    def starts(self) -> np.ndarray:
        """(runs + 1,) when each run starts, and the end (s)."""
        return np.concatenate(([0.0], np.cumsum([p.duration for p in self.profiles])))

    @property
    def duration(self) -> float:
        return float(self.starts[-1])

    @property
    def measured(self) -> bool:
        """Whether a run was planned with its limits where they are (Profile.measured)."""
        return any(p.measured for p in self.profiles)

    @property
    def periods(self) -> int:
        """Periods to the end: the stream has periods + 1 positions (the start at t = 0)."""
        return int(math.ceil(self.duration / self.machine.period - 1e-9))  # ceil's round-off

    def targets(self, max_periods: int = MAX_PERIODS) -> tuple[np.ndarray, np.ndarray]:
        """Per position n = 0..periods (time n Ts): the piece and the arc length in it
        (:meth:`blocks` joined: the whole stream's targets in memory)."""
        pieces, s = [], []
        for piece, _, block in self.blocks(max_periods):
            pieces.append(np.full(len(block), piece, dtype=np.int64))
            s.append(block)
        return np.concatenate(pieces), np.concatenate(s)

    def checked_periods(self, max_periods: int = MAX_PERIODS) -> int:
        """:attr:`periods`, InputError over ``max_periods``."""
        n = self.periods
        if n > max_periods:
            raise InputError(f"the stream would need {n} periods ({self.duration:.1f} s at "
                             f"{self.machine.period * 1e3:g} ms), over the limit of "
                             f"{max_periods}: raise --max-periods, or check the feed and "
                             "the machine's limits")
        return n

    def blocks(self, max_periods: int = MAX_PERIODS, size: int | None = None):
        """Yield ``(piece, row, s)``: the positions n = row .. row + len(s) - 1 (time n Ts)
        lie in piece ``piece`` at arc lengths ``s`` (mm) in it; rows in order, at most
        ``size`` (default BLOCK_ROWS) a block, a piece's rows consecutive (pieces between
        two periods have none). The targets of a stream of any length, a block at a time."""
        n = self.checked_periods(max_periods)
        size = size or BLOCK_ROWS
        period, starts = self.machine.period, self.starts
        bounds = _first_periods(starts, period, n)
        for j, run in enumerate(self.runs):
            lengths = np.diff(run.offsets)
            for a in range(bounds[j], bounds[j + 1], size):
                b = min(a + size, bounds[j + 1])
                at = self.profiles[j].position(np.arange(a, b) * period - starts[j])
                k = np.clip(np.searchsorted(run.offsets, at, side="right") - 1, 0,
                            len(run.pieces) - 1)
                s = np.clip(at - run.offsets[k], 0.0, lengths[k])
                cuts = (np.flatnonzero(k[1:] != k[:-1]) + 1).tolist()
                for lo, hi in zip([0] + cuts, cuts + [len(k)]):
                    yield run.first + int(k[lo]), a + lo, s[lo:hi]


def _first_periods(starts: np.ndarray, period: float, n: int) -> list[int]:
    """Per run j, its first position: the first k in 0..n with k * period >= starts[j]
    (run 0 from 0, and n + 1 after the last), without a time per period in memory."""
    out = [0]
    for start in starts[1:-1]:   # (starts[-1]: the end of the last run)
        k = min(max(math.ceil(start / period), 0), n + 1)
        while k > 0 and (k - 1) * period >= start:
            k -= 1
        while k <= n and k * period < start:
            k += 1
        out.append(max(k, out[-1]))
    return out + [n + 1]


def plan_feed(pieces: list[Piece], machine: Machine, planned: bool = True,
              derate=(1.0, 1.0, 1.0), measured: bool = True) -> FeedPlan:
    """The plan of every run: to the machine's limits (each scaled by ``derate``: v, a,
    j), or (``planned=False``) every piece at the programmed feed ignoring them.
    ``measured`` False: no run that bends is planned with its limits where they are
    (:func:`.run_plan.plan_run`)."""
    if not pieces:
        raise InputError("the program has nothing to stream (no cut or move)")
    if not planned:
        pairs = [_constant_run(k, p, machine) for k, p in enumerate(pieces)]
        return FeedPlan(pieces, [r for r, _ in pairs], [p for _, p in pairs], machine, False)
    runs = runs_of(pieces, machine)
    planned_runs: dict[bytes, list[tuple[Run, Profile]]] = {}   # a run repeated (a
    profiles = []                                                 # raster's passes and
    for run in runs:                                              # links) planned once
        same = planned_runs.setdefault(_run_key(run), [])
        profile = next((p for r, p in same if _same_run(r, run)), None)
        if profile is None:
            profile = plan_run(run, machine, derate, measured)
            same.append((run, profile))
        profiles.append(profile)
    return FeedPlan(pieces, runs, profiles, machine, True)


_DERIVATIVES = ("T", "K", "D", "jump", "kink")


def _run_key(run: Run) -> bytes:
    """The run's lengths and speed caps exactly and its path's derivatives to 1e-6: runs
    that may share a plan (:func:`_same_run` decides). The arrays' sizes, then their
    values, in one buffer: equal keys, equal arrays."""
    exact = [run.offsets, run.s, run.cap]
    derivatives = [getattr(run, name) for name in _DERIVATIVES]
    sizes = np.array([a.size for a in exact + derivatives], dtype=np.int64)
    rounded = np.round(np.concatenate([d.ravel() for d in derivatives]), 6) + 0.0  # (no -0)
    h = hashlib.blake2b(sizes.tobytes(), digest_size=32)
    h.update(np.concatenate(exact).tobytes())
    h.update(rounded.tobytes())
    return h.digest()


def _same_run(a: Run, b: Run) -> bool:
    """Whether one plan serves both runs: the same lengths and caps, and derivatives within
    SAME_RUN (a raster's repeated passes differ by round-off where they lie on the part)."""
    return (np.array_equal(a.offsets, b.offsets) and np.array_equal(a.s, b.s)
            and np.array_equal(a.cap, b.cap)
            and all(_close(getattr(a, n), getattr(b, n)) for n in _DERIVATIVES))


def _close(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal, or within SAME_RUN (absolute and relative) everywhere; a NaN or an infinity
    that differs: not close."""
    if np.array_equal(a, b):
        return True
    with np.errstate(invalid="ignore"):
        return bool(np.all(np.abs(a - b) <= SAME_RUN * (1.0 + np.abs(b))))
