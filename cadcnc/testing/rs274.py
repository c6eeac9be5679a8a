"""LinuxCNC's standalone G-code interpreter (``rs274``, Debian package linuxcnc-uspace) read
back: the moves a controller would make of a G-code file, in mm (rs274's canonical
commands print 4 decimals). The calls are read as the simulation reads foreign G-code
(:func:`cadcnc.io.gcode_reader.canonical_calls`), strictly: any error rs274 reports fails
the test."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from ..core.errors import InputError
from ..io.gcode_reader import canonical_calls

RS274 = shutil.which("rs274")
"""The interpreter's path, or None where LinuxCNC is not installed."""
DECIMALS = 4
"""rs274's canonical output prints 4 decimals in mm."""
MOVES = ("STRAIGHT_FEED", "STRAIGHT_TRAVERSE")


def _calls(ngc_file: Path) -> list[tuple[str, list[str]]]:
    try:
        return canonical_calls(ngc_file, strict=True)
    except InputError as e:
        raise AssertionError(str(e)) from None


def _ends(calls, kinds) -> list[tuple[str, np.ndarray]]:
    return [(name, np.array([float(a) for a in args[:3]])) for name, args in calls
            if name in kinds]


def feed_points(folder: Path, text: str) -> np.ndarray:
    """(k, 3) the STRAIGHT_FEED end points of the G-code ``text`` (written to ``folder``);
    fails on any error rs274 reports and on a program without its end."""
    src = Path(folder) / "prog.ngc"
    src.write_text(text)
    return np.array([p for _, p in _ends(_calls(src), MOVES[:1])])


def move_points(ngc_file: Path, folder: Path | None = None) -> np.ndarray:
    """(M, 3) the STRAIGHT_FEED and STRAIGHT_TRAVERSE end points of ``ngc_file`` in order
    (the first is the machine's home)."""
    return np.array([p for _, p in _ends(_calls(ngc_file), MOVES)])


def moves(ngc_file: Path) -> list[tuple[str, np.ndarray]]:
    """rs274's moves of ``ngc_file`` in order: (kind, end point (3,) in work coordinates),
    kind ``STRAIGHT_FEED`` or ``STRAIGHT_TRAVERSE``."""
    return _ends(_calls(ngc_file), MOVES)
