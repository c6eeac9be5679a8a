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


def _differences(x: np.ndarray, period: float, order: int):
    """Per chunk: (first row, |diff(x, order)| / T^order) over the whole array."""
    n = len(x) - order
    for lo in range(0, max(n, 0), CHUNK):
        hi = min(n, lo + CHUNK)
        yield lo, np.abs(np.diff(x[lo:hi + order], order, axis=0)) / period ** order


def check_stream(positions, period: float, limits, start, end,
                 what: str = "the stream") -> StreamCheck:
    """Check ``positions`` ((N, 3) mm) streamed every ``period`` s against ``limits`` =
    (velocity, acceleration, jerk), each three numbers per axis X Y Z (mm/s, mm/s²,
    mm/s³), and its ends against ``start`` and ``end`` (mm) (module doc)."""
    x = np.asarray(positions, dtype=np.float64)
    problems: list[str] = []
    if x.ndim != 2 or x.shape[1] != 3 or len(x) < 1:
        return StreamCheck(False, [f"{what}: not an (N, 3) array of positions: {x.shape}"])
    if not np.isfinite(x).all():
        bad = int(np.flatnonzero(~np.isfinite(x).all(axis=1))[0])
        return StreamCheck(False, [f"{what}: position {bad} is not finite"])
    for name, row, want in (("first", x[0], start), ("last", x[-1], end)):
        off = float(np.abs(row - np.asarray(want, dtype=np.float64)).max())
        if not off <= STREAM_END:
            problems.append(f"{what}: its {name} position is {off:.3g} mm from the program's "
                            f"{name} point (at most {STREAM_END:g} mm)")
    peaks, over = {}, {}
    for order, ((kind, unit), limit) in enumerate(zip(KINDS, limits), 1):
        limit = np.asarray(limit, dtype=np.float64)
        allowed = limit * (1.0 + STREAM_LIMIT_SLACK)
        peak, where, count = np.zeros(3), np.zeros(3, dtype=np.int64), np.zeros(3, np.int64)
        for lo, d in _differences(x, period, order):
            top = d.max(axis=0)
            better = top > peak
            where[better] = lo + d.argmax(axis=0)[better]
            peak = np.maximum(peak, top)
            count += (d > allowed).sum(axis=0)
        peaks[kind] = dict(zip(AXES, peak.tolist()))
        over[kind] = dict(zip(AXES, count.tolist()))
        for a in range(3):
            if count[a]:
                problems.append(
                    f"{what}: {kind} of axis {AXES[a]} reaches {peak[a]:.6g} {unit} at period "
                    f"{where[a]} ({100 * peak[a] / limit[a]:.4g} % of the machine's "
                    f"{limit[a]:g}), over the limit in {count[a]} periods")
    return StreamCheck(not problems, problems, peaks, over)


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
