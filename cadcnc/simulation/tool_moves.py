"""The straight moves a simulation applies, in machining order, with each one's tool.

A :class:`Run` is one program as the machine follows it: ball-centre positions (M, 3) in
part coordinates (mm), ``rapid`` (M - 1,) per move, the ball radius R, the tool axis (a
unit vector from the ball centre up the shank, part coordinates) and the shank's top: the
height along the axis (from the part origin) up to which the shank reaches. :class:`Moves`
is every run's moves in one set of arrays for the kernel; the shank of a move is cut at
the stock's box (above it there is nothing to cut), so a long shank costs nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.errors import InputError
from ..program.program import Program
from ..program.transform import in_part_coordinates

JOIN = 1e-9   # mm: segments further apart than this are joined by a feed move


@dataclass
class Run:
    """One program's polyline (module doc): points (M, 3), rapid (M - 1,) bool, mm; the
    shank reaches up to ``shank_top`` along the axis, or ``shank`` mm above the ball
    centre when that is given."""

    points: np.ndarray
    rapid: np.ndarray
    radius: float
    axis: np.ndarray
    shank_top: float
    shank: float | None = None
    name: str = ""
    scallop: float | None = None   # mm: the finish job's scallop target, if any


def run_of_program(program: Program, setup=None, shank: float | None = None,
                   name: str = "") -> Run:
    """The :class:`Run` of a cadcnc ``program`` (its setup's work coordinates, ``setup`` a
    :class:`~cadcnc.geometry.setup.Setup` or None): every cut's and link's moves in order.
    The shank reaches ``shank`` mm above the ball centre, by default the program's own
    tool's (:attr:`~cadcnc.core.tool.Tool.shank`: what the program was computed and
    guarded for)."""
    part = in_part_coordinates(program, setup)
    pts: list[np.ndarray] = []
    rapid: list[np.ndarray] = []
    for seg in part.segments:
        p = np.asarray(seg.points, float)
        flags = np.asarray(seg.rapid, bool) if seg.kind == "link" else np.zeros(len(p) - 1, bool)
        if pts and np.linalg.norm(p[0] - pts[-1][-1]) > JOIN:
            rapid.append(np.zeros(1, bool))      # what the G-code does: a feed move
            pts.append(p[:1])
        pts.append(p if not pts else p[1:])
        rapid.append(flags)
    if not pts:
        raise InputError(f"{name or 'the program'} has no move")
    points = np.concatenate(pts)
    job = program.job
    axis = np.asarray(job.axis, float)
    origin = setup.origin if setup is not None and not setup.identity else np.zeros(3)
    heights = (points - origin) @ axis
    clearance = job.clearance if job.clearance is not None else float(heights.max())
    return Run(points, np.concatenate(rapid), job.tool.radius, axis,
               float(clearance + origin @ axis), job.tool.shank if shank is None else shank,
               name,
               getattr(job.operation, "scallop", None))


def run_of_gcode(points: np.ndarray, rapid: np.ndarray, radius: float,
                 tool_tip: bool = False, shank: float | None = None, name: str = "") -> Run:
    """The :class:`Run` of a 3-axis G-code program's positions (M, 3) (+Z tool axis):
    ball centres, or tool tips (centre Z - R) with ``tool_tip``; the shank up to the
    program's highest point unless ``shank`` (mm above the ball centre) is given."""
    if not radius > 0:
        raise InputError(f"the ball radius must be > 0 mm to read G-code, got {radius}")
    pts = np.asarray(points, float) + (0.0, 0.0, radius if tool_tip else 0.0)
    return Run(pts, np.asarray(rapid, bool), float(radius), np.array([0.0, 0.0, 1.0]),
               float(pts[:, 2].max()), shank, name)


@dataclass
class Moves:
    """Every move of every run: p0, p1, axis (N, 3), radius, length (N,) mm, rapid (N,)
    bool, run (N,) its run's index, bb_lo, bb_hi (N, 3) the swept tool's box."""

    p0: np.ndarray
    p1: np.ndarray
    axis: np.ndarray
    radius: np.ndarray
    length: np.ndarray
    rapid: np.ndarray
    run: np.ndarray
    bb_lo: np.ndarray
    bb_hi: np.ndarray

    def __len__(self) -> int:
        return len(self.p0)


def moves_of_runs(runs: list[Run], lo: np.ndarray, hi: np.ndarray) -> Moves:
    """The :class:`Moves` of ``runs`` in order, shanks cut at the stock box lo..hi (3,)."""
    parts = []
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    for i, run in enumerate(runs):
        p0, p1 = run.points[:-1], run.points[1:]
        h = np.minimum(p0 @ run.axis, p1 @ run.axis)
        if run.shank is not None:
            length = np.full(len(p0), float(run.shank))
        else:
            length = np.maximum(run.shank_top - h, 0.0)
        reach = float((corners @ run.axis).max())           # the box's highest point
        length = np.clip(np.minimum(length, reach - h + run.radius), 0.0, None)
        n = len(p0)
        parts.append((p0, p1, np.tile(run.axis, (n, 1)), np.full(n, run.radius), length,
                      np.asarray(run.rapid, bool)[:n], np.full(n, i)))
    cols = [np.concatenate([p[j] for p in parts]) if parts else np.zeros(0)
            for j in range(7)]
    p0, p1, axis, radius, length, rapid, run_ix = cols
    tops0, tops1 = p0 + axis * length[:, None], p1 + axis * length[:, None]
    stack = np.stack([p0, p1, tops0, tops1])
    r = radius[:, None]
    return Moves(p0, p1, axis, radius, length, rapid.astype(bool), run_ix.astype(np.int64),
                 stack.min(axis=0) - r, stack.max(axis=0) + r)
