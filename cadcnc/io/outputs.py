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

from ..errors import OutputError
from ..geometry.setup import job_setup
from ..program.program import Program
from ..program.transform import in_part_coordinates
from .program_gcode import program_ngc
from .program_json import program_json
from .program_plot import program_picture_bytes
from .output_set import check_destination
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


def render(program: Program, out, part=None, title: str = "", jobs: int | None = 1,
           **gcode) -> str | bytes:
    """The content of ``out`` by its suffix. ``gcode``: :func:`program_ngc` keywords
    (tolerance, tool_tip, spindle, plunge_feed); ``part`` is needed for pictures and for
    a program of another tool axis than +Z (in its work coordinates: JSON, CSV and
    pictures are written in part coordinates, the G-code in work coordinates with the
    setup in a comment). ``jobs``: processes making a JSON (:func:`program_json`)."""
    kind = Path(out).suffix.lower()
    setup = job_setup(program.job, part)
    if kind == ".json":
        return program_json(program, setup, part=part, jobs=jobs)
    if kind == ".csv":
        return program_csv(in_part_coordinates(program, setup))
    if kind == ".ngc":
        notes = () if setup is None else tuple(f"setup: {s}" for s in setup.describe())
        return program_ngc(program, title=title, notes=notes, **gcode)
    if kind in (".png", ".glb"):
        return program_picture_bytes(program, part, out, title)
    raise OutputError(f"{out}: unknown output format {kind!r}; use one of "
                      f"{', '.join(SUFFIXES)}")


def check_output(out, inputs=()) -> str:
    """The format of ``out`` from its suffix, or OutputError (checked before computing)."""
    check_destination(out, SUFFIXES, inputs)
    return Path(out).suffix.lower()[1:]
