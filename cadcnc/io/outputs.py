"""Toolpaths rendered by the output file's suffix: .json, .csv or .ngc."""

from __future__ import annotations

from pathlib import Path

from ..errors import OutputError
from ..program.toolpath import Toolpath
from .gcode import to_ngc
from .output_set import check_destination, write_one
from .toolpath_csv import toolpath_csv
from .toolpath_json import toolpath_json

SUFFIXES = (".json", ".csv", ".ngc")


def check_output(out, inputs=()) -> str:
    """The format of ``out`` from its suffix, or OutputError (checked before computing)."""
    check_destination(out, SUFFIXES, inputs)
    return Path(out).suffix.lower()[1:]


def render(paths: list[Toolpath], out, **gcode_options) -> str:
    """The text of ``out`` by its suffix: one G-code program for all paths; JSON and CSV
    hold exactly one path."""
    kind = Path(out).suffix.lower()[1:]
    if kind == "ngc":
        return to_ngc(paths, **gcode_options)
    if kind not in ("json", "csv"):
        raise OutputError(f"{out}: unknown output format {kind!r}; use one of "
                          f"{', '.join(SUFFIXES)}")
    if len(paths) != 1:
        raise OutputError(f"{out}: {kind.upper()} holds one path, got {len(paths)}")
    return (toolpath_json if kind == "json" else toolpath_csv)(paths[0])


def write_toolpaths(paths: list[Toolpath], out, **gcode_options) -> None:
    """Write one file by suffix, atomically (see :func:`render`)."""
    write_one(out, render(paths, out, **gcode_options), SUFFIXES)
