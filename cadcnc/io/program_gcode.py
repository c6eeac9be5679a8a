"""RS274/NGC of a :class:`~cadcnc.program.program.Program`: its cuts and links, in order.

The same conventions as :mod:`cadcnc.io.gcode` (mm, absolute, ``G64 P<tolerance>``,
points dropped by Douglas-Peucker within ``tolerance`` on cuts, fewest decimals keeping
rounding within a tenth of it). Each segment's moves are written as they are: a cut's
points as ``G1`` at the job's feed, a link's moves as ``G0`` (rapid) or ``G1`` at the
plunge feed. The program starts with a rapid to the first segment's height and ends with
``M2``. With ``tool_tip`` the programmed point is the ball's tip (centre Z - R). Each
segment starts with a comment ``(segment k: cut, ...)`` or ``(segment k: link)``, k its
1-based index in ``program.segments`` (as the CSV's ``segment`` column).
"""

from __future__ import annotations

import math
import re

import numpy as np

from ..core.errors import InputError
from ..core.job import SAFE_MARGIN, check_number
from ..program.linking import linked
from ..program.program import CutSegment, Program
from .atomic import write_text
from .gcode import (
    DEFAULT_GOUGE,
    DEFAULT_TOLERANCE,
    WORD,
    blend_for,
    blend_word,
    comment,
    digits_for,
    num,
    programmed_moves,
    programmed_points,
    simplify,
)


def program_ngc(program: Program, *, tolerance: float | None = None, tool_tip: bool = False,
                spindle: float | None = None, plunge_feed: float | None = None,
                blend: float | None = None, title: str = "", notes=()) -> str:
    """One RS274/NGC program for ``program`` (see the module doc); InputError on a point
    or word that cannot be written. ``spindle`` and ``plunge_feed`` default to the job's;
    ``notes``: comment lines after the title (a setup's axis and work zero)."""
    tol, digits, feed, plunge, spindle, dz = _writable(program, tolerance, tool_tip, spindle,
                                                       plunge_feed)
    n = lambda v: num(v, digits)  # noqa: E731
    xyz = lambda p: f"X{n(p[0])} Y{n(p[1])} Z{n(p[2] - dz)}"  # noqa: E731
    point_name = "tool tip (ball centre Z - R)" if tool_tip else "ball centre"
    first = program.segments[0].points[0]
    lines = [
        "%",
        comment(f"cadcnc {title}".strip()),
        *(comment(note) for note in notes),
        comment(f"programmed point: {point_name}; units mm; +Z is the spindle axis"),
        comment(f"tolerance {tol:g} mm ({'points dropped' if tolerance else 'every point kept'}"
                 f"); {digits} decimals; feed {num(feed, 3)}, plunge {num(plunge, 3)} "
                 "mm/min"),
        "G17 G21 G40 G90 G94",
        blend_word(blend_for(DEFAULT_GOUGE) if blend is None else blend),
        f"G0 Z{n(first[2] - dz)}",
    ]
    if spindle:
        lines.append(f"S{num(spindle, 0)} M3")
    lines.append(f"G0 X{n(first[0])} Y{n(first[1])}")
    current = None  # the feed word in force
    for k, seg in enumerate(program.segments, 1):
        if seg.kind == "cut":
            path = seg.path
            keep = simplify(seg.points, tolerance) if tolerance else np.arange(len(seg.points))
            lines.append(comment(
                f"segment {k}: cut, faces {path.faces[0]} {path.faces[1]}, {len(keep)} of "
                f"{len(seg.points)} points, stop: {path.stop_reason}"))
            cut_feed = path.job.feed   # each cut at its own job's feed (APT programs)
            if current != cut_feed:
                lines.append(f"F{num(cut_feed, 3)}")
                current = cut_feed
            lines += [f"G1 {xyz(p)}" for p in seg.points[keep[1:]]]
            continue
        lines.append(comment(f"segment {k}: link"))
        for p, rapid in zip(seg.points[1:], seg.rapid):
            if rapid:
                lines.append(f"G0 {xyz(p)}")
                continue
            if current != plunge:
                lines.append(f"F{num(plunge, 3)}")
                current = plunge
            lines.append(f"G1 {xyz(p)}")
    if spindle:
        lines.append("M5")
    lines += ["M2", "%"]
    return "\n".join(lines) + "\n"


def _writable(program: Program, tolerance, tool_tip, spindle, plunge_feed) -> tuple:
    """(tolerance, decimals, feed, plunge feed, spindle, Z offset) :func:`program_ngc`
    writes ``program`` with; InputError when a point or a word cannot be written."""
    if not program.segments:
        raise InputError("the program has no segment: nothing to write")
    tol = DEFAULT_TOLERANCE if tolerance is None else float(tolerance)
    feed = program.job.feed
    plunge_feed = program.job.plunge_feed if plunge_feed is None else plunge_feed
    spindle = program.job.spindle if spindle is None else spindle
    plunge = feed if plunge_feed is None else check_number("plunge feed", plunge_feed,
                                                            "mm/min")
    if spindle is not None:
        check_number("spindle speed", spindle, "rpm")
    for name, f in (("feed", feed), ("plunge feed", plunge)):
        if float(num(f, 3)) <= 0:
            raise InputError(f"{name} {f:g} mm/min prints as F0: too slow for G-code")
    for k, seg in enumerate(program.segments, 1):
        if not np.all(np.isfinite(seg.points)):
            raise InputError(f"segment {k} ({seg.kind}) has a non-finite point: nothing "
                             "written")
    dz = program.job.tool.radius if tool_tip else 0.0
    return tol, digits_for(tol), feed, plunge, spindle, dz


_SEGMENT = re.compile(r"^\(segment \d+: (cut|link)")


def segment_moves(text: str, tool_tip_offset: float = 0.0) -> list[np.ndarray]:
    """Per segment of a program written by :func:`program_ngc`, the (M_k, 3) ball-centre
    positions the machine visits, as written (points dropped, rounded, the tool-tip offset
    ``tool_tip_offset`` added back to Z), each starting at the position the segment starts
    from. Every move of the program is in exactly one list."""
    pos = [math.nan, math.nan, math.nan]
    out: list[list] = []
    for line in text.splitlines():
        if _SEGMENT.match(line):
            out.append([] if any(math.isnan(v) for v in pos) else [tuple(pos)])
            continue
        if not line.startswith(("G0 ", "G1 ")):
            continue
        for axis, value in WORD.findall(line):
            pos["XYZ".index(axis)] = float(value)
        if out and not any(math.isnan(v) for v in pos):
            out[-1].append(tuple(pos))
    return [np.array(m, dtype=float).reshape(-1, 3) + (0.0, 0.0, tool_tip_offset)
            for m in out]


def program_written_moves(program: Program, *, tolerance: float | None = None,
                          tool_tip: bool = False, spindle: float | None = None,
                          plunge_feed: float | None = None, **_text) -> list[np.ndarray]:
    """Per segment of ``program``, the positions :func:`program_ngc` with these options
    commands, as :func:`segment_moves` reads them from its text (the same floats: each
    coordinate as its written decimal), without writing the text: what the
    whole-program gouge gate checks. InputError as :func:`program_ngc`; ``_text``: its
    options that change only the text (title, notes, blend)."""
    _, digits, _, _, _, dz = _writable(program, tolerance, tool_tip, spindle, plunge_feed)
    pos = _as_written(program.segments[0].points[:1], digits, dz)
    out = []
    for seg in program.segments:
        if seg.kind == "cut" and tolerance:
            pts = seg.points[simplify(seg.points, tolerance)[1:]]
        else:
            pts = seg.points[1:]
        moves = np.vstack([pos, _as_written(pts, digits, dz)])
        out.append(moves)
        pos = moves[-1:]
    return out


def _as_written(points: np.ndarray, digits: int, dz: float) -> np.ndarray:
    """(N, 3) ball centres as :func:`program_ngc` writes them and the machine reads them
    back: each coordinate (Z less ``dz``) to ``digits`` decimals, Z plus ``dz`` again."""
    pts = np.array(points, dtype=float).reshape(-1, 3)
    pts[:, 2] -= dz
    return written_decimals(pts.ravel(), digits).reshape(-1, 3) + (0.0, 0.0, dz)


DOUBT = 1e-6
"""A value times 10^digits nearer a half than this is rounded as Python formats it (the
product's own rounding is below 2^-50 of 2^50 = 1 there)."""


def written_decimals(values: np.ndarray, digits: int) -> np.ndarray:
    """(N,) ``float(f"{v:.{digits}f}")`` of each value ("-0" read as 0): the decimal a
    program writes, read back. Vectorised: the text's integer k = v 10^digits rounded
    half to even, and k / 10^digits is the double nearest that decimal (one correctly
    rounded division); a product within DOUBT of a half, or too large to be exact, is
    formatted and parsed as written."""
    scale = 10.0 ** digits
    x = values * scale
    out = np.rint(x) / scale
    doubt = ~(np.abs(x) < 2.0 ** 50) | (np.abs(np.abs(x - np.trunc(x)) - 0.5) < DOUBT)
    out[doubt] = [float(f"{v:.{digits}f}") for v in values[doubt].tolist()]
    return out + 0.0


def to_ngc(paths, *, safe_z: float | None = None, **options) -> str:
    """The G-code of toolpaths machined in order: :func:`program_ngc` of their program,
    each reached from and left to ``safe_z`` (mm, programmed coordinates; default the
    highest programmed point plus SAFE_MARGIN). ``options``: :func:`program_ngc`'s."""
    paths = list(paths)
    if not paths:
        raise InputError("no toolpath to write")
    top = max(float(programmed_points(p, options.get("tool_tip", False))[:, 2].max())
              for p in paths)
    if safe_z is None:
        safe_z = top + SAFE_MARGIN
    elif not math.isfinite(safe_z) or safe_z < top:
        raise InputError(f"safe Z {safe_z:g} mm is below the path's highest point {top:g} mm")
    dz = paths[0].job.tool.radius if options.get("tool_tip") else 0.0
    program = Program(paths[0].job, linked([CutSegment(p) for p in paths], safe_z + dz))
    return program_ngc(program, **options)


def write_ngc(paths, out, **options) -> None:
    """Write :func:`to_ngc` to ``out`` atomically."""
    write_text(out, to_ngc(paths, **options))


def written_moves(path, **options) -> np.ndarray:
    """(M, 3) ball-centre positions the machine is commanded to visit for ``path`` alone,
    written with :func:`to_ngc` ``options`` (dropped, rounded, tool tip taken back, the
    approach and retract included): what the gouge gate must check."""
    text = to_ngc([path], **options)
    return programmed_moves(text, path.job.tool.radius if options.get("tool_tip") else 0.0)
