"""Any RS274/NGC program's moves, read by LinuxCNC's own interpreter (``rs274 -g``).

``rs274`` prints the canonical machining calls a program makes; :func:`gcode_moves` keeps
its straight traverses (rapids), straight feeds and arcs (chords within ``chord`` mm of
the arc; planes XY, XZ and YZ, helices) as one polyline of positions (M, 3) in mm (inch
programs converted) with ``rapid`` (M - 1,) per move. Only X, Y and Z are read (a 3-axis
program); the first position is the first move's end.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from ..core.errors import InputError

CALL = re.compile(r"^\s*\d+\s+N\S*\s+([A-Z_]+)\((.*)\)\s*$")
INCH = 25.4
CHORD = 1e-4          # mm: an arc's chords stay this close to it
TIMEOUT_S = 600


def rs274_path() -> str:
    """The ``rs274`` executable; InputError when LinuxCNC's interpreter is not installed."""
    exe = shutil.which("rs274")
    if exe is None:
        raise InputError("reading G-code needs LinuxCNC's rs274 interpreter on the PATH "
                         "(package linuxcnc-uspace), or give a cadcnc program JSON")
    return exe


def canonical_calls(file, strict: bool = False) -> list[tuple[str, list[str]]]:
    """rs274's canonical calls for the program ``file``: [(name, arguments)]; InputError
    naming the file and rs274's message when it does not run to PROGRAM_END, or
    (``strict``: a test's reading) when it reports any error on the way."""
    file = Path(file)
    if not file.is_file():
        raise InputError(f"{file}: no such file")
    with tempfile.TemporaryDirectory(prefix="cadcnc-rs274-") as tmp:
        out = Path(tmp) / "canon.txt"
        # rs274 keeps its tool table in $HOME/.tool.mmap, truncated by each run: runs at
        # once (worker threads, other commands) each get a home of their own
        run = subprocess.run([rs274_path(), "-g", str(file), str(out)], capture_output=True,
                             text=True, timeout=TIMEOUT_S, env={**os.environ, "HOME": tmp})
        text = out.read_text() if out.exists() else ""
    calls = [(m.group(1), [a.strip() for a in m.group(2).split(",")])
             for m in map(CALL.match, text.splitlines()) if m]
    msg = " ".join(ln.strip() for ln in run.stderr.splitlines()
                   if ln.strip() and ln.strip() != "executing")
    if run.returncode != 0 or not any(name == "PROGRAM_END" for name, _ in calls) or \
            (strict and msg):
        raise InputError(f"{file}: rs274 could not read the program ({msg or 'no M2'})")
    return calls


def arc_points(start, args, plane: str, scale: float, chord: float = CHORD) -> np.ndarray:
    """Points (n, 3) mm after ``start`` along rs274's ARC_FEED(first_end, second_end,
    first_centre, second_centre, rotation, axis_end, ...) in ``plane`` ("XY", "XZ", "YZ")."""
    f, s, ax = {"XY": (0, 1, 2), "XZ": (2, 0, 1), "YZ": (1, 2, 0)}[plane]
    e1, e2, c1, c2 = (float(a) * scale for a in args[:4])
    turns = int(float(args[4]))
    end = np.empty(3)
    end[f], end[s], end[ax] = e1, e2, float(args[5]) * scale
    r = math.hypot(start[f] - c1, start[s] - c2)
    a0 = math.atan2(start[s] - c2, start[f] - c1)
    a1 = math.atan2(e2 - c2, e1 - c1)
    sweep = (a1 - a0) % (2 * math.pi) if turns > 0 else -((a0 - a1) % (2 * math.pi))
    if abs(sweep) < 1e-12:   # rad: end on start, a full circle (rs274 gives no 0-turn arc)
        sweep = math.copysign(2 * math.pi, turns)
    sweep += math.copysign(2 * math.pi * (abs(turns) - 1), turns)
    step = 2 * math.acos(max(1 - chord / r, -1.0)) if r > chord else math.pi
    n = max(int(math.ceil(abs(sweep) / step)), 1)
    t = np.arange(1, n + 1) / n
    pts = np.empty((n, 3))
    pts[:, f] = c1 + r * np.cos(a0 + sweep * t)
    pts[:, s] = c2 + r * np.sin(a0 + sweep * t)
    pts[:, ax] = start[ax] + (end[ax] - start[ax]) * t
    pts[-1] = end
    return pts


def gcode_moves(file, chord: float = CHORD) -> tuple[np.ndarray, np.ndarray]:
    """(positions (M, 3) mm, rapid (M - 1,) bool) of the program ``file`` (module doc)."""
    points: list[np.ndarray] = []
    rapid: list[bool] = []
    scale, plane = 1.0, "XY"
    for name, args in canonical_calls(file):
        if name == "USE_LENGTH_UNITS":
            scale = INCH if "INCHES" in args[0] else (10.0 if "CM" in args[0] else 1.0)
        elif name == "SELECT_PLANE":
            plane = {"CANON_PLANE_XZ": "XZ", "CANON_PLANE_YZ": "YZ"}.get(args[0], "XY")
        elif name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            p = np.array([float(a) for a in args[:3]]) * scale
            if points:
                rapid.append(name == "STRAIGHT_TRAVERSE")
            points.append(p)
        elif name == "ARC_FEED":
            if not points:
                raise InputError(f"{file}: the program starts with an arc (no start point)")
            arc = arc_points(points[-1], args, plane, scale, chord)
            points.extend(arc)
            rapid.extend([False] * len(arc))
    if len(points) < 2:
        raise InputError(f"{file}: the program has no move")
    return np.array(points), np.array(rapid, dtype=bool)
