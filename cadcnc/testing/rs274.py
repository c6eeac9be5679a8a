"""LinuxCNC's standalone G-code interpreter (``rs274``, Debian package linuxcnc-uspace) read
back: the moves a controller would make of a G-code file, in mm (rs274's canonical
commands print 4 decimals)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np

RS274 = shutil.which("rs274")
"""The interpreter's path, or None where LinuxCNC is not installed."""
DECIMALS = 4
"""rs274's canonical output prints 4 decimals in mm."""
FEED_RE = re.compile(r"STRAIGHT_FEED\(([^)]*)\)")
MOVE_RE = re.compile(r"(STRAIGHT_FEED|STRAIGHT_TRAVERSE)\(([^)]*)\)")


def _run(ngc_file: Path, canon_file: Path) -> subprocess.CompletedProcess:
    run = subprocess.run([RS274, "-g", str(ngc_file), str(canon_file)], capture_output=True,
                         text=True, timeout=60)
    if run.returncode != 0:
        raise AssertionError(f"rs274 exited {run.returncode}: {run.stderr}")
    return run


def _point(numbers: str) -> list[float]:
    return [float(v) for v in numbers.split(",")[:3]]


def feed_points(folder: Path, text: str) -> np.ndarray:
    """(k, 3) the STRAIGHT_FEED end points of the G-code ``text`` (written to ``folder``);
    fails on any error rs274 reports and on a program without its end."""
    src, out = Path(folder) / "prog.ngc", Path(folder) / "canon.txt"
    src.write_text(text)
    run = _run(src, out)
    errors = [ln for ln in run.stderr.splitlines() if ln.strip() and ln.strip() != "executing"]
    if errors:
        raise AssertionError(run.stderr)
    canon = out.read_text()
    if "PROGRAM_END()" not in canon:
        raise AssertionError("rs274 read no PROGRAM_END")
    return np.array([_point(m.group(1)) for m in FEED_RE.finditer(canon)])


def move_points(ngc_file: Path, folder: Path) -> np.ndarray:
    """(M, 3) the STRAIGHT_FEED and STRAIGHT_TRAVERSE end points of ``ngc_file`` in order
    (the first is the machine's home)."""
    canon = Path(folder) / "canon.txt"
    _run(ngc_file, canon)
    return np.array([_point(m.group(2)) for m in MOVE_RE.finditer(canon.read_text())])


def moves(ngc_file: Path) -> list[tuple[str, np.ndarray]]:
    """rs274's moves of ``ngc_file`` in order: (kind, end point (3,) in work coordinates),
    kind ``STRAIGHT_FEED`` or ``STRAIGHT_TRAVERSE``; the canonical text is written beside
    the file (suffix ``.canon``)."""
    canon = Path(ngc_file).with_suffix(".canon")
    _run(ngc_file, canon)
    text = canon.read_text()
    if "PROGRAM_END()" not in text:
        raise AssertionError("rs274 read no PROGRAM_END")
    return [(m.group(1), np.array(_point(m.group(2)))) for m in MOVE_RE.finditer(text)]
