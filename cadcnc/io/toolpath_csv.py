"""A toolpath as CSV: one row per cycle with a header row; written atomically."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ..core.errors import InputError
from ..program.toolpath import Toolpath
from .atomic import write_text

CSV_COLUMNS = (
    ["cycle", "t_s", "x", "y", "z", "step", "commanded"]
    + [f"q{i}{a}" for i in (1, 2) for a in "xyz"]
    + ["u1", "w1", "u2", "w2"]
    + [f"n{i}{a}" for i in (1, 2) for a in "xyz"]
    + ["eps1", "eps2", "bound1", "bound2"]
)
CSV_UNITS = ("cycle: index (0 = start); t_s: s; x..z, step, commanded, q*, eps*, bound*: mm; "
             "u, w: native surface parameters; n*: unit normals; bound: eq. 16 steady-state "
             "error bound")


def toolpath_rows(path: Toolpath) -> np.ndarray:
    """(N, len(CSV_COLUMNS)) float array, one row per cycle, in CSV_COLUMNS order."""
    n = len(path)
    period = path.job.period
    nan = np.full(n, np.nan)
    b = path.bounds
    cols = [np.arange(n), np.arange(n) * period, *path.points.T, path.steps, path.commanded,
            *path.contacts[:, 0].T, *path.contacts[:, 1].T,
            path.uv[:, 0, 0], path.uv[:, 0, 1], path.uv[:, 1, 0], path.uv[:, 1, 1],
            *path.normals[:, 0].T, *path.normals[:, 1].T,
            nan if b is None else b[0].eps, nan if b is None else b[1].eps,
            nan if b is None else b[0].eq16, nan if b is None else b[1].eq16]
    return np.column_stack(cols).astype(float)


def toolpath_csv(path: Toolpath) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    for row in toolpath_rows(path):
        w.writerow([str(int(row[0]))] + [repr(float(v)) for v in row[1:]])
    return buf.getvalue()


def write_csv(path: Toolpath, out) -> None:
    """Write one row per cycle with a header row (columns: CSV_COLUMNS; units: CSV_UNITS)."""
    write_text(out, toolpath_csv(path))


def read_csv(file) -> dict[str, np.ndarray]:
    """{column: (N,) float array} from a file written by :func:`write_csv`, or by
    ``cadcnc path`` (a program: a first column ``segment``, rows of every cut)."""
    file = Path(file)
    try:
        with open(file, newline="", encoding="utf-8") as fh:
            rows = list(csv.reader(fh))
    except FileNotFoundError:
        raise InputError(f"{file}: no such file") from None
    header = rows[0] if rows else []
    if header not in (CSV_COLUMNS, ["segment", *CSV_COLUMNS]):
        raise InputError(f"{file}: not a cadcnc toolpath or program CSV (unexpected header)")
    data = np.array([[float(v) for v in r] for r in rows[1:]], dtype=float).reshape(
        -1, len(header))
    return {name: data[:, i] for i, name in enumerate(header)}
