"""Outputs: atomic files, toolpath JSON and CSV, G-code, plots; written by suffix."""

from .atomic import atomic_write, write_bytes, write_text
from .gcode import to_ngc, write_ngc
from .outputs import SUFFIXES, check_output, write_toolpaths
from .plot import write_picture
from .toolpath_csv import CSV_COLUMNS, read_csv, toolpath_csv, write_csv
from .toolpath_json import (
    ARRAYS, FORMAT, VERSION, read_json, toolpath_from_dict, toolpath_to_dict, write_json,
)

__all__ = [
    "atomic_write", "write_bytes", "write_text", "to_ngc", "write_ngc", "SUFFIXES",
    "check_output", "write_toolpaths", "write_picture", "CSV_COLUMNS", "read_csv",
    "toolpath_csv", "write_csv", "ARRAYS", "FORMAT", "VERSION", "read_json",
    "toolpath_from_dict", "toolpath_to_dict", "write_json",
]
