"""A toolpath as JSON and back (everything round-trips); written atomically.

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

import json
from dataclasses import asdict, fields
from pathlib import Path

import numpy as np

from ..core.errors import InputError
from ..core.job import Job
from ..core.jsonable import plain
from ..interp.error_bounds import SurfaceBounds
from ..program.toolpath import Toolpath
from .atomic import write_text

FORMAT = "cadcnc-toolpath"
VERSION = 1
ARRAYS = ("points", "contacts", "normals", "uv", "steps", "commanded")


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


def toolpath_to_dict(path: Toolpath) -> dict:
    """Everything in a :class:`Toolpath` as JSON-ready Python objects (see module doc)."""
    d = {
        "format": FORMAT,
        "version": VERSION,
        "faces": list(path.faces),
        "inputs": plain(path.job.to_inputs(), nonfinite_as_strings=True),
        "offsets": list(map(float, path.offsets)),
        "stop_reason": path.stop_reason,
        "stop_detail": path.stop_detail,
        "summary": plain({
            "points": len(path),
            "length_mm": path.length,
            "duration_s": path.duration,
            "worst_predicted_mm": path.worst_predicted_mm,
        }, nonfinite_as_strings=True),
    }
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
        if len(faces) != 2 or len(d["offsets"]) != 2:
            raise ValueError(f"faces and offsets need two values each, got {d['faces']} "
                             f"and {d['offsets']}")
        inputs = dict(d.get("inputs") or {})
        inputs.setdefault("offsets", d["offsets"])
        path = Toolpath(**arrays, job=Job.from_inputs(inputs, faces),
                        stop_reason=d["stop_reason"], stop_detail=d.get("stop_detail", ""),
                        bounds=bounds)
    except (KeyError, TypeError, ValueError) as e:
        raise InputError(f"toolpath JSON is incomplete or malformed ({type(e).__name__}: "
                         f"{e})") from None
    n = len(path.points)
    if n == 0:
        raise InputError("toolpath JSON has no points")
    shapes = {name: getattr(path, name).shape for name in ARRAYS}
    want = {"points": (n, 3), "contacts": (n, 2, 3), "normals": (n, 2, 3), "uv": (n, 2, 2),
            "steps": (n,), "commanded": (n,)}
    if shapes != want:
        raise InputError(f"toolpath JSON arrays disagree in shape: "
                         f"{', '.join(f'{k} {v}' for k, v in shapes.items())}")
    for name in ("points", "contacts", "uv"):
        if not np.all(np.isfinite(getattr(path, name))):
            raise InputError(f"toolpath JSON has a non-finite number in {name!r}")
    if len(path.faces) != 2:
        raise InputError(f"toolpath JSON needs two faces, got {list(path.faces)}")
    return path


def toolpath_json(path: Toolpath) -> str:
    """``path`` as compact JSON text (see the module doc)."""
    return json.dumps(toolpath_to_dict(path), separators=(",", ":")) + "\n"


def write_json(path: Toolpath, out) -> None:
    """Write ``path`` to ``out`` as JSON (atomic)."""
    write_text(out, toolpath_json(path))


def read_json_file(file, what: str, parse):
    """``parse(data)`` of the JSON in ``file``; every error names the file (``what``: the
    kind of file expected, for the message)."""
    file = Path(file)
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{file}: no such file") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise InputError(f"{file}: not a {what} JSON file ({e})") from None
    except (ValueError, RecursionError) as e:   # a 4300-digit integer; nesting too deep
        raise InputError(f"{file}: not a {what} JSON file: {_short(e)}") from None
    try:
        return parse(data)
    except InputError as e:
        raise InputError(f"{file}: {e}") from None
    except (KeyError, IndexError, TypeError, ValueError, AttributeError, OverflowError,
            RecursionError) as e:
        raise InputError(f"{file}: a malformed {what} JSON file ({type(e).__name__}: "
                         f"{_short(e)})") from None


def _short(e: BaseException) -> str:
    """The error's message cut to one readable line."""
    text = str(e).splitlines()[0] if str(e) else type(e).__name__
    return text if len(text) <= 200 else text[:200] + "..."


def read_json(file) -> Toolpath:
    """Read a toolpath JSON file (or a program of one cut); errors name the file."""
    return read_json_file(file, "toolpath",
                          lambda data: toolpath_from_dict(one_cut_of_program(data)))


PROGRAM_FORMAT = "cadcnc-program"
CUT_KEYS = ("kind", "edge", "stretch", "at_limit")
"""Keys of a program's cut segment that a version 1 toolpath does not have."""


def cut_as_toolpath_dict(cut: dict) -> dict:
    """A program's cut segment (dict) as a version 1 toolpath dict."""
    body = {k: v for k, v in cut.items() if k not in CUT_KEYS}
    return {**body, "format": FORMAT, "version": VERSION}


def one_cut_of_program(data):
    """``data`` itself, or the only cut of a program (version 2) dict as a version 1
    toolpath dict: old callers of :func:`read_json` keep working on one-cut programs."""
    if not (isinstance(data, dict) and data.get("format") == PROGRAM_FORMAT):
        return data
    cuts = [s for s in data.get("segments") or [] if isinstance(s, dict)
            and s.get("kind") == "cut"]
    if len(cuts) != 1:
        raise InputError(f"a program of {len(cuts)} cuts is not one toolpath: read it with "
                         "cadcnc.io.program_json.read_program")
    return cut_as_toolpath_dict(cuts[0])
