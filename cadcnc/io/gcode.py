"""The conventions of cadcnc's G-code (LinuxCNC dialect, plain enough for most 3-axis
controls), shared by its one writer (:mod:`cadcnc.io.program_gcode`) and its readers.

Conventions (docs/program.md "G-code"): mm (G21), absolute (G90), XY plane (G17), feed per
minute (G94), path blending ``G64 P<blend>`` (a tenth of the gouge limit, counted by the gate);
the part's +Z is the spindle axis and the path is reached from above: rapid to a safe Z, rapid over the first point, rapid down to
``clearance`` above it, feed down onto it, one ``G1`` per kept point, rapid back up to the
safe Z, ``M2``. The programmed point is the ball centre, or with ``tool_tip=True`` the tip
of the ball (Z - R, R the cutter radius without allowance).

Point dropping (``tolerance`` given): Douglas-Peucker, keeping a point whenever dropping it
would move the polyline by ``tolerance`` or more; every dropped point lies within
``tolerance`` of the chord that replaces it, and the two polylines are then within
``tolerance`` of each other (Hausdorff). Coordinates are printed with the fewest decimals
for which rounding moves a point (all three axes together, sqrt(3)/2 * 10^-d) by at most a
tenth of the tolerance; without ``tolerance`` every point is kept and digits follow
:data:`DEFAULT_TOLERANCE` (1 um: 4 decimals).
"""

from __future__ import annotations

import math
import re

import numpy as np

from ..core.errors import InputError
from ..core.tolerances import DEFAULT as _DEFAULT_TOLERANCES

DEFAULT_GOUGE = _DEFAULT_TOLERANCES.gouge  # mm: the default gouge limit

DEFAULT_TOLERANCE = 0.001  # mm
BLEND_SHARE = 0.1
"""G64 P (how far the machine may leave the programmed polyline when blending moves) is
this share of the gouge limit; the gouge gate counts it: every written move must keep the
ball within the limit less P of the part."""


def blend_for(gouge_mm: float) -> float:
    """The G64 P blending tolerance (mm) for a gouge limit (mm)."""
    return BLEND_SHARE * gouge_mm


def blend_word(blend: float) -> str:
    """``G64 P<blend>`` with enough decimals to print ``blend`` (mm) exactly to 1e-7."""
    if not (math.isfinite(blend) and blend > 0):
        raise InputError(f"G64 P blending tolerance must be > 0 mm, got {blend!r}")
    return f"G64 P{num(blend, 7)}"
CLEARANCE = 2.0  # mm above the first point where the rapid approach ends


def digits_for(tolerance: float) -> int:
    """Fewest decimals d with sqrt(3)/2 * 10**-d <= tolerance / 10 (3-D rounding error)."""
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise InputError(f"G-code tolerance must be > 0 mm, got {tolerance!r}")
    d = math.ceil(-math.log10(tolerance / 10 / (math.sqrt(3) / 2)) - 1e-12)  # log10's round-off
    return max(d, 0)


def _segment_distances(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each row of ``points`` to the segment a-b."""
    ab = b - a
    denom = ab @ ab
    if denom == 0.0:
        return np.linalg.norm(points - a, axis=1)
    t = np.clip((points - a) @ ab / denom, 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def simplify(points: np.ndarray, tolerance: float) -> np.ndarray:
    """Indices of the points kept by Douglas-Peucker (first and last always kept).

    A stretch i..j collapses to its chord only if every point in it is closer than
    ``tolerance`` to the chord. Iterative (no recursion limit). ``points`` is (N, 3).
    """
    pts = np.asarray(points, dtype=float)
    n = len(pts)
    if n <= 2 or tolerance <= 0:
        return np.arange(n)
    keep = np.zeros(n, dtype=bool)
    keep[0] = keep[-1] = True
    stack = [(0, n - 1)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        d = _segment_distances(pts[i + 1:j], pts[i], pts[j])
        k = int(np.argmax(d))
        if d[k] >= tolerance:
            m = i + 1 + k
            keep[m] = True
            stack.append((i, m))
            stack.append((m, j))
    return np.flatnonzero(keep)


def comment(text: str) -> str:
    """An NGC comment: no parentheses inside, ASCII only."""
    text = re.sub(r"[()]", lambda m: "[" if m.group() == "(" else "]", str(text))
    return "(" + text.encode("ascii", "replace").decode() + ")"


def num(v: float, digits: int) -> str:
    s = f"{v:.{digits}f}"
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def programmed_points(path, tool_tip: bool = False) -> np.ndarray:
    """The path's points as programmed: ball centres, or tips (Z - R) with ``tool_tip``."""
    pts = np.array(path.points, dtype=float)
    if tool_tip:
        pts[:, 2] -= path.job.tool.radius
    return pts


WORD = re.compile(r"([XYZ])(-?\d+(?:\.\d*)?)")


def programmed_moves(text: str, tool_tip_offset: float = 0.0) -> np.ndarray:
    """(M, 3) ball-centre positions of every G0/G1 move of a program written by
    :func:`~cadcnc.io.program_gcode.program_ngc`, in order, as the machine will execute them (rounding included).

    ``tool_tip_offset`` (mm): R when the program gives the ball's tip, added back to Z.
    Moves before the first complete X, Y, Z position are skipped (the first rapid gives Z
    only).
    """
    pos = [math.nan, math.nan, math.nan]
    out = []
    for line in text.splitlines():
        if not line.startswith(("G0 ", "G1 ")):
            continue
        for axis, value in WORD.findall(line):
            pos["XYZ".index(axis)] = float(value)
        if not any(math.isnan(v) for v in pos):
            out.append((pos[0], pos[1], pos[2] + tool_tip_offset))
    return np.array(out, dtype=float).reshape(-1, 3)
