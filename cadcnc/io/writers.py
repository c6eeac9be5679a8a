"""Toolpaths to files and back: JSON (everything, round-trips), CSV (one row per cycle).

Every write is atomic: the bytes go to a temporary file in the destination's folder, which
replaces the destination only once complete (``os.replace``), so a failed run never leaves
a half-written file. G-code lives in :mod:`cadcnc.gcode`.

JSON layout (``format: "cadcnc-toolpath"``, ``version: 1``): ``faces``, ``inputs`` (every
parameter of the run: radius, allowance mm; feed mm/min; period s; start, end, offsets,
edge, source), ``offsets``, ``stop_reason``, ``stop_detail``, ``summary`` (points,
length_mm, duration_s, worst_predicted_mm) and the per-point arrays ``points`` (N, 3),
``contacts`` (N, 2, 3), ``normals`` (N, 2, 3), ``uv`` (N, 2, 2), ``steps`` (N,),
``commanded`` (N,), ``bounds`` (two objects of (N,) arrays, one per surface). Non-finite
numbers are written as the strings ``"Infinity"``, ``"-Infinity"``, ``"NaN"`` (JSON has no
literal for them).
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import tempfile
from dataclasses import asdict, fields
from pathlib import Path

import numpy as np

from ..interp.error_bounds import SurfaceBounds
from ..errors import InputError, OutputError
from ..program.toolpath import Toolpath

FORMAT = "cadcnc-toolpath"
VERSION = 1
ARRAYS = ("points", "contacts", "normals", "uv", "steps", "commanded")


# -- atomic writes ---------------------------------------------------------------------------
@contextlib.contextmanager
def atomic_write(path, mode: str = "w", newline: str | None = None):
    """Open a temporary file beside ``path``; on success it replaces ``path``.

    On any exception the temporary file is removed and ``path`` is left as it was.
    ``OSError`` from creating or replacing the file becomes :class:`OutputError`.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(f"{path}: cannot write, folder {folder} does not exist")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    except OSError as e:
        raise OutputError(f"{path}: cannot write ({e.strerror})") from e
    try:
        kwargs = {} if "b" in mode else {"encoding": "utf-8", "newline": newline}
        with os.fdopen(fd, mode, **kwargs) as fh:
            yield fh
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException as e:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(e, OSError):
            raise OutputError(f"{path}: cannot write ({e.strerror or e})") from e
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_text(path, text: str) -> None:
    with atomic_write(path) as fh:
        fh.write(text)


def write_bytes(path, data: bytes) -> None:
    with atomic_write(path, "wb") as fh:
        fh.write(data)


# -- JSON --------------------------------------------------------------------------------------
def _encode(arr) -> list:
    """Nested lists of floats; non-finite values as JSON-legal strings."""
    a = np.asarray(arr, dtype=float)
    if np.all(np.isfinite(a)):
        return a.tolist()
    out = a.astype(object)
    out[np.isnan(a)] = "NaN"
    out[np.isposinf(a)] = "Infinity"
    out[np.isneginf(a)] = "-Infinity"
    return out.tolist()


def _decode(data, shape_tail: tuple = ()) -> np.ndarray:
    a = np.array(data, dtype=object)
    a = a.astype(float) if a.size else np.zeros((0, *shape_tail))
    return a


def _plain(value):
    """Inputs as JSON: numpy scalars and arrays to Python numbers and lists."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def toolpath_to_dict(path: Toolpath) -> dict:
    """Everything in a :class:`Toolpath` as JSON-ready Python objects (see module doc)."""
    d = {
        "format": FORMAT,
        "version": VERSION,
        "faces": list(path.faces),
        "inputs": _plain(path.inputs),
        "offsets": list(map(float, path.offsets)),
        "stop_reason": path.stop_reason,
        "stop_detail": path.stop_detail,
        "summary": {
            "points": len(path),
            "length_mm": path.length,
            "duration_s": path.duration,
            "worst_predicted_mm": path.worst_predicted_mm,
        },
    }
    d["summary"] = _plain(d["summary"])
    for name in ARRAYS:
        d[name] = _encode(getattr(path, name))
    d["bounds"] = None if path.bounds is None else [
        {k: _encode(v) for k, v in asdict(b).items()} for b in path.bounds]
    return d


def toolpath_from_dict(d: dict) -> Toolpath:
    """The :class:`Toolpath` written by :func:`toolpath_to_dict` (bounds included)."""
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise InputError("not a cadcnc toolpath (no \"format\": \"cadcnc-toolpath\")")
    if d.get("version") != VERSION:
        raise InputError(f"toolpath format version {d.get('version')!r} is not supported "
                         f"(this cadcnc reads version {VERSION})")
    try:
        arrays = {
            "points": _decode(d["points"], (3,)),
            "contacts": _decode(d["contacts"], (2, 3)),
            "normals": _decode(d["normals"], (2, 3)),
            "uv": _decode(d["uv"], (2, 2)),
            "steps": _decode(d["steps"]),
            "commanded": _decode(d["commanded"]),
        }
        bounds = None
        if d.get("bounds") is not None:
            names = [f.name for f in fields(SurfaceBounds)]
            bounds = tuple(SurfaceBounds(**{k: _decode(b[k]) for k in names})
                           for b in d["bounds"])
        faces = tuple(None if f is None else int(f) for f in d["faces"])
        path = Toolpath(**arrays, offsets=tuple(map(float, d["offsets"])),
                        stop_reason=d["stop_reason"], stop_detail=d.get("stop_detail", ""),
                        faces=faces, inputs=dict(d.get("inputs") or {}), bounds=bounds)
    except (KeyError, TypeError, ValueError) as e:
        raise InputError(f"toolpath JSON is incomplete or malformed ({type(e).__name__}: "
                         f"{e})") from None
    n = len(path.points)
    if path.points.shape != (n, 3) or path.contacts.shape != (n, 2, 3):
        raise InputError(f"toolpath JSON arrays disagree in shape: points "
                         f"{path.points.shape}, contacts {path.contacts.shape}")
    return path


def write_json(path: Toolpath, out) -> None:
    """Write ``path`` to ``out`` as JSON (atomic)."""
    write_text(out, json.dumps(toolpath_to_dict(path), separators=(",", ":")) + "\n")


def read_json(file) -> Toolpath:
    """Read a toolpath JSON file; errors name the file."""
    file = Path(file)
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{file}: no such file") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise InputError(f"{file}: not a toolpath JSON file ({e})") from None
    try:
        return toolpath_from_dict(data)
    except InputError as e:
        raise InputError(f"{file}: {e}") from None


# -- CSV ---------------------------------------------------------------------------------------
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
    period = float(path.inputs.get("period", float("nan")))
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
    """{column: (N,) float array} from a file written by :func:`write_csv`."""
    file = Path(file)
    try:
        with open(file, newline="", encoding="utf-8") as fh:
            rows = list(csv.reader(fh))
    except FileNotFoundError:
        raise InputError(f"{file}: no such file") from None
    if not rows or rows[0] != CSV_COLUMNS:
        raise InputError(f"{file}: not a cadcnc toolpath CSV (unexpected header)")
    data = np.array([[float(v) for v in r] for r in rows[1:]], dtype=float).reshape(
        -1, len(CSV_COLUMNS))
    return {name: data[:, i] for i, name in enumerate(CSV_COLUMNS)}


# -- by suffix ---------------------------------------------------------------------------------
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
        from .gcode import write_ngc

        write_ngc(paths, out, **gcode_options)
        return
    if len(paths) != 1:
        raise OutputError(f"{out}: {kind.upper()} holds one path, got {len(paths)}")
    (write_json if kind == "json" else write_csv)(paths[0], out)
