"""Write toolpaths by the output file's suffix: .json, .csv or .ngc."""

from __future__ import annotations

from pathlib import Path

from ..errors import OutputError
from ..program.toolpath import Toolpath
from .gcode import write_ngc
from .toolpath_csv import write_csv
from .toolpath_json import write_json

SUFFIXES = (".json", ".csv", ".ngc")


def check_output(out) -> str:
    """The format of ``out`` from its suffix, or OutputError (checked before computing)."""
    out = Path(out)
    suffix = out.suffix.lower()
    if suffix not in SUFFIXES:
        raise OutputError(f"{out}: unknown output format {suffix or '(no suffix)'!r}; use "
                          f"one of {', '.join(SUFFIXES)}")
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(f"{out}: cannot write, folder {folder} does not exist")
    if out.is_dir():
        raise OutputError(f"{out}: is a folder")
    return suffix[1:]


def write_toolpaths(paths: list[Toolpath], out, **gcode_options) -> None:
    """Write by suffix: one G-code program for all paths; JSON/CSV need exactly one path."""
    kind = check_output(out)
    if kind == "ngc":
        write_ngc(paths, out, **gcode_options)
        return
    if len(paths) != 1:
        raise OutputError(f"{out}: {kind.upper()} holds one path, got {len(paths)}")
    (write_json if kind == "json" else write_csv)(paths[0], out)
