"""A program rendered by the output file's suffix: .json (version 2), .csv, .ngc, .png, .glb.

Every operation's program is written here, by one suffix list (:data:`SUFFIXES`). CSV of a
program: the toolpath CSV's columns (:data:`~cadcnc.io.toolpath_csv.CSV_COLUMNS`)
after a first column ``segment``, the 1-based index of the cut in the program's
``segments`` (links included in the count, so segment numbers match the JSON and the
G-code comments). One row per cycle of every cut, in machining order; links have no row
(they carry no contacts: their moves are in the JSON and the G-code).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

from ..core.errors import OutputError
from ..geometry.setup import job_setup
from ..parallel.pool import check_jobs
from ..parallel.tasks import beside
from ..program.program import Program
from ..program.transform import in_part_coordinates
from .output_set import check_destination
from .program_gcode import program_ngc
from .program_json import join_pieces, json_pieces, program_json, segments_text
from .program_plot import program_picture_bytes
from .toolpath_csv import CSV_COLUMNS, toolpath_rows

SUFFIXES = (".json", ".csv", ".ngc", ".png", ".glb")
"""The outputs every command writes, by suffix."""
PROGRAM_CSV_COLUMNS = ["segment", *CSV_COLUMNS]


def program_csv(program: Program) -> str:
    """One row per cycle of every cut (see the module doc)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(PROGRAM_CSV_COLUMNS)
    for k, seg in enumerate(program.segments, 1):
        if seg.kind != "cut":
            continue
        for row in toolpath_rows(seg.path):
            w.writerow([str(k), str(int(row[0]))] + [repr(float(v)) for v in row[1:]])
    return buf.getvalue()


def render(program: Program, out, part=None, title: str = "", **gcode) -> str | bytes:
    """The content of ``out`` by its suffix. ``gcode``: :func:`program_ngc` keywords
    (tolerance, tool_tip, spindle, plunge_feed); ``part`` is needed for pictures and for
    a program of another tool axis than +Z (in its work coordinates: JSON, CSV and
    pictures are written in part coordinates, the G-code in work coordinates with the
    setup in a comment). Several outputs, on worker processes: :func:`render_all`."""
    kind = Path(out).suffix.lower()
    setup = job_setup(program.job, part)
    if kind == ".json":
        return program_json(program, setup)
    if kind == ".csv":
        return program_csv(in_part_coordinates(program, setup))
    if kind == ".ngc":
        notes = () if setup is None else tuple(f"setup: {s}" for s in setup.describe())
        return program_ngc(program, title=title, notes=notes, **gcode)
    if kind in (".png", ".glb"):
        return program_picture_bytes(program, part, out, title)
    raise OutputError(f"{out}: unknown output format {kind!r}; use one of "
                      f"{', '.join(SUFFIXES)}")


def render_all(program: Program, outs, part=None, title: str = "", jobs: int | None = 1,
               **gcode) -> dict:
    """``{out: content}`` of every output in ``outs``, as :func:`render` makes each. With
    ``jobs`` > 1 and the ``part``, on worker processes at once (:class:`RenderPieces`):
    each JSON in runs of segments, the pictures whole, the G-code and CSV here
    meanwhile; the same bytes."""
    outs = list(outs)
    n = check_jobs(jobs)
    if n == 1 or part is None or not outs:
        return {out: render(program, out, part, title, **gcode) for out in outs}
    pieces = RenderPieces(program, outs, part, title, n, gcode)
    here, done = beside(pieces.here, render_piece, pieces.tasks, part, jobs,
                        "writing outputs", pieces.sizes)
    return pieces.joined(here, done)


LOCAL = (".ngc", ".csv")
"""Outputs :class:`RenderPieces` makes in the caller's process: quick to make from the
program, which a worker would first have to be sent whole."""


class RenderPieces:
    """:func:`render_all`'s work on ``jobs`` processes: every JSON in runs of segments
    and every picture whole as worker ``tasks`` (:func:`render_piece` each), the LOCAL
    outputs by :meth:`here` in this process meanwhile; :meth:`joined` makes ``{out:
    content}`` of the two, in the order of ``outs``."""

    def __init__(self, program: Program, outs, part, title: str, jobs: int, gcode: dict):
        setup = job_setup(program.job, part)
        self.tasks: list[tuple] = []
        self._where: dict = {}   # out -> (head, tail, first task, how many); tail None: whole
        self._local: list = []
        self._args = program, part, title, gcode
        for out in outs:
            kind = check_output(out)   # an unknown suffix refused here, not in a worker
            if f".{kind}" in LOCAL:
                self._where[out] = None
                self._local.append(out)
            elif kind == "json":
                head, tail, runs = json_pieces(program, setup, jobs)
                self._where[out] = (head, tail, len(self.tasks), len(runs))
                self.tasks += [("runs", run) for run in runs]
            else:
                self._where[out] = ("", None, len(self.tasks), 1)
                self.tasks.append(("whole", program, out, title, gcode))
        self.sizes = [_size(t) for t in self.tasks]

    def here(self) -> dict:
        """``{out: content}`` of the LOCAL outputs, made in this process."""
        program, part, title, gcode = self._args
        return {out: render(program, out, part, title, **gcode) for out in self._local}

    def joined(self, here: dict, done: list) -> dict:
        """``{out: content}`` from :meth:`here`'s outputs and the tasks' results ``done``."""
        contents = {}
        for out, where in self._where.items():
            if where is None:
                contents[out] = here[out]
                continue
            head, tail, first, count = where
            if tail is None:
                contents[out] = done[first]
            else:
                contents[out] = join_pieces(head, tail, done[first:first + count]) \
                    if count else head
        return contents


def render_piece(part, task, beat=None):
    """One task of :class:`RenderPieces` (an on_workers task, on the worker's part)."""
    if task[0] == "runs":
        return segments_text(task[1])
    _, program, out, title, gcode = task
    return render(program, out, part, title, **gcode)


def _size(task) -> float:
    """A task's expected cost: its points (a whole output: every point of the program)."""
    if task[0] == "runs":
        return float(sum(len(seg.points) for seg in task[1]))
    return float(sum(len(seg.points) for seg in task[1].segments))


def check_output(out, inputs=()) -> str:
    """The format of ``out`` from its suffix, or OutputError (checked before computing)."""
    check_destination(out, SUFFIXES, inputs)
    return Path(out).suffix.lower()[1:]
