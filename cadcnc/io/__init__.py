"""Outputs: atomic files and output sets; programs written by suffix (JSON version 2, CSV,
G-code, pictures); the toolpath JSON and CSV readers of format version 1."""

from .atomic import atomic_write, write_bytes, write_text
from .outputs import PROGRAM_CSV_COLUMNS, SUFFIXES, check_output, program_csv, render
from .plot import write_picture
from .toolpath_csv import CSV_COLUMNS, read_csv, toolpath_csv, write_csv
from .toolpath_json import (
    ARRAYS,
    FORMAT,
    VERSION,
    read_json,
    toolpath_from_dict,
    toolpath_to_dict,
    write_json,
)

__all__ = [
    "atomic_write", "write_bytes", "write_text", "SUFFIXES", "check_output", "render",
    "program_csv", "PROGRAM_CSV_COLUMNS", "write_picture", "CSV_COLUMNS", "read_csv",
    "toolpath_csv", "write_csv", "ARRAYS", "FORMAT", "VERSION", "read_json",
    "toolpath_from_dict", "toolpath_to_dict", "write_json",
]
