"""A stream checked before it is written: its own positions against the machine's limits.

:func:`check_stream` takes the positions about to be written (an (N, 3) array, mm, one
row per servo period), the period and the limits as plain numbers, and the program's
first and last points. It judges by finite differences alone (velocity
``diff(x) / T``, acceleration ``diff(x, 2) / T^2``, jerk ``diff(x, 3) / T^3`` per axis,
within the limit times 1 + :data:`~cadcnc.core.tolerances.STREAM_LIMIT_SLACK`) and by the ends
(within :data:`~cadcnc.core.tolerances.STREAM_END` of the program's). It shares no code with
the feed planner (:mod:`cadcnc.controller`), so a planner's defect cannot hide here.

:func:`check_program_on_part` asks whether a program was computed on the part given: each
cut's first centre must lie at its offset from the faces it names, at the contacts it
records (else the program belongs to another part: an input error naming both).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.errors import FaceNumberError, InputError
from ..core.tolerances import STREAM_END, STREAM_LIMIT_SLACK

AXES = "XYZ"
CHUNK = 1 << 17   # rows differenced at a time: about 13 MB of differences for any stream
KINDS = (("velocity", "mm/s"), ("acceleration", "mm/s^2"), ("jerk", "mm/s^3"))


@dataclass
class StreamCheck:
    """The verdict: ``ok``; ``problems``, one sentence each; ``peaks[kind][axis]`` the
    largest |finite difference| (mm/s, mm/s², mm/s³); ``over[kind][axis]`` how many
    periods exceed the limit."""

    ok: bool
    problems: list[str] = field(default_factory=list)
    peaks: dict = field(default_factory=dict)
    over: dict = field(default_factory=dict)


class StreamChecker:
    """:func:`check_stream` fed a block of rows at a time (a stream printed or written in
    chunks), with the same verdict as the whole array at once: the last three rows of each
    block are kept for the next block's differences."""

    def __init__(self, period: float, limits, what: str = "the stream"):
        self.period, self.what = period, what
        self.limits = [np.asarray(lim, dtype=np.float64) for lim in limits]
        self.rows = 0
        self.tail = np.empty((0, 3))
        self.first = self.last = None
        self.bad_shape: tuple | None = None
        self.not_finite: int | None = None
        self.peak = np.zeros((3, 3))
        self.where = np.zeros((3, 3), dtype=np.int64)
        self.count = np.zeros((3, 3), dtype=np.int64)

    def feed(self, rows) -> None:
        """The next rows ((n, 3) mm; read CHUNK rows at a time, so a mapped file's rows
        need not be in memory at once)."""
        x = np.asarray(rows)
        if x.ndim != 2 or x.shape[1] != 3:
            self.bad_shape = x.shape if self.bad_shape is None else self.bad_shape
            return
        for lo in range(0, len(x), CHUNK):
            self._block(np.asarray(x[lo:lo + CHUNK], dtype=np.float64))

    def _block(self, x: np.ndarray) -> None:
        if not len(x) or self.bad_shape is not None or self.not_finite is not None:
            self.rows += len(x)
            return
        finite = np.isfinite(x).all(axis=1)
        if not finite.all():
            self.not_finite = self.rows + int(np.flatnonzero(~finite)[0])
            self.rows += len(x)
            return
        if self.first is None:
            self.first = x[0].copy()
        self.last = x[-1].copy()
        self._differences(x)

    def _differences(self, x: np.ndarray) -> None:
        both = np.concatenate([self.tail, x])
        origin = self.rows - len(self.tail)   # the stream's row of both[0]
        for k in range(3):
            order = k + 1
            new = max(len(self.tail) - order, 0)   # the first difference not taken yet
            if len(both) - new <= order:
                continue
            d = np.abs(np.diff(both[new:], order, axis=0)) / self.period ** order
            top = d.max(axis=0)
            better = top > self.peak[k]
            self.where[k][better] = origin + new + d.argmax(axis=0)[better]
            self.peak[k] = np.maximum(self.peak[k], top)
            allowed = self.limits[k] * (1.0 + STREAM_LIMIT_SLACK)
            self.count[k] += (d > allowed).sum(axis=0)
        self.rows += len(x)
        self.tail = both[-3:].copy()

    def result(self, start, end) -> StreamCheck:
        """The verdict on every row fed, its ends against ``start`` and ``end`` (mm)."""
        what = self.what
        if self.bad_shape is not None or self.rows < 1:
            shape = (0, 3) if self.bad_shape is None else self.bad_shape
            return StreamCheck(False, [f"{what}: not an (N, 3) array of positions: {shape}"])
        if self.not_finite is not None:
            return StreamCheck(False, [f"{what}: position {self.not_finite} is not finite"])
        problems: list[str] = []
        for name, row, want in (("first", self.first, start), ("last", self.last, end)):
            off = float(np.abs(row - np.asarray(want, dtype=np.float64)).max())
            if not off <= STREAM_END:
                problems.append(f"{what}: its {name} position is {off:.3g} mm from the "
                                f"program's {name} point (at most {STREAM_END:g} mm)")
        peaks, over = {}, {}
        for k, ((kind, unit), limit) in enumerate(zip(KINDS, self.limits)):
            peak, count = self.peak[k], self.count[k]
            peaks[kind] = dict(zip(AXES, peak.tolist()))
            over[kind] = dict(zip(AXES, count.tolist()))
            for a in range(3):
                if count[a]:
                    problems.append(
                        f"{what}: {kind} of axis {AXES[a]} reaches {peak[a]:.6g} {unit} at "
                        f"period {self.where[k][a]} ({100 * peak[a] / limit[a]:.4g} % of the "
                        f"machine's {limit[a]:g}), over the limit in {count[a]} periods")
        return StreamCheck(not problems, problems, peaks, over)


def check_stream(positions, period: float, limits, start, end,
                 what: str = "the stream") -> StreamCheck:
    """Check ``positions`` ((N, 3) mm) streamed every ``period`` s against ``limits`` =
    (velocity, acceleration, jerk), each three numbers per axis X Y Z (mm/s, mm/s²,
    mm/s³), and its ends against ``start`` and ``end`` (mm) (module doc)."""
    checker = StreamChecker(period, limits, what)
    checker.feed(positions)   # (its verdict names a wrong shape, or no rows, too)
    return checker.result(start, end)


def check_program_on_part(program, part, name: str, part_name: str, within: float) -> None:
    """InputError unless every cut of ``program`` lies on ``part``: its first centre at
    its offset (within ``within`` mm) from the faces it names, at the contacts it records.
    ``name`` and ``part_name``: the program's and the part's files, for the message."""
    for k, seg in enumerate(program.cuts):
        path = seg.path
        if path is None or path.uv is None or not len(path.points):
            continue
        centre = np.asarray(path.points[0], dtype=np.float64)
        for side, face in enumerate(path.faces):
            if face is None:
                continue
            try:
                surface = part.face(face)
            except FaceNumberError:
                raise InputError(f"{name}: cut {k + 1} is on face {face}, which {part_name} "
                                 f"does not have: the program was computed on another part "
                                 f"({program.job.source or 'unnamed'})") from None
            u, w = (float(t) for t in path.uv[0, side])
            try:
                gap = float(np.linalg.norm(centre - surface.point(u, w)))
            except Exception:   # noqa: BLE001 - a contact off this face's surface
                gap = float("inf")
            offset = float(path.job.offsets[side])
            if not abs(gap - offset) <= within:
                raise InputError(
                    f"{name}: cut {k + 1} does not lie on {part_name}: its first centre is "
                    f"{gap:.6g} mm from face {face} at its recorded contact, not the "
                    f"offset {offset:g} mm: the program was computed on another part "
                    f"({program.job.source or 'unnamed'}); give that part with --part")
