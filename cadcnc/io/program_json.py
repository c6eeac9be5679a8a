"""A program as JSON (format version 2) and back; version 1 toolpath files read as programs.

Layout (``format: "cadcnc-program"``, ``version: 2``)::

    {"format": "cadcnc-program", "version": 2,
     "job": {...}                     the program's job (Job.to_inputs keys),
     "segments": [                    in machining order
        {"kind": "cut", "faces": [i, j], "edge": k, "stretch": s, "at_limit": false,
         "points": [[x, y, z], ...],
         "stop_reason": ..., ... every key of a version 1 toolpath (inputs, contacts,
         normals, uv, steps, commanded, bounds, accuracy_*)},
        {"kind": "link", "points": [[x, y, z], ...], "rapid": [true, false, ...]}, ...],
     "skipped": [{"faces": [i, j], "edge": k, "reason": ..., "detail": ...}, ...],
     "notes": ["start (...) is outside every feasible stretch ...: moved ...", ...],
     "summary": {"complete": ..., "cut_length_mm": ..., "link_length_mm": ...,
                 "time_at_feed_s": ..., "cuts": ..., "links": ..., "skipped": ...}}

Points are ball centres in mm, in part coordinates; a program of another tool axis than +Z
(:mod:`cadcnc.geometry.setup`) adds ``"setup": {"axis", "rotation", "origin"}`` and is
read back into its work coordinates; ``rapid[k]`` says whether link move k (point k to k + 1) is
a rapid (else a feed move at the plunge feed). Written atomically.
"""

from __future__ import annotations

import gc
import json
import os

import numpy as np

from ..core.errors import InputError, require
from ..core.job import Job
from ..core.jsonable import plain
from ..geometry.setup import Setup
from ..program.program import CutSegment, LinkSegment, Program, Skipped
from ..program.transform import in_part_coordinates, in_setup_coordinates
from . import toolpath_json as v1
from .atomic import write_text

FORMAT = "cadcnc-program"
VERSION = 2


def _cut_to_dict(seg: CutSegment) -> dict:
    d = v1.toolpath_to_dict(seg.path)
    del d["format"], d["version"]
    return {"kind": "cut", "faces": d.pop("faces"), "edge": seg.edge,
            "stretch": seg.stretch, "at_limit": seg.at_limit, "points": d.pop("points"), **d}


def _segment_to_dict(seg) -> dict:
    if seg.kind == "cut":
        return _cut_to_dict(seg)
    return {"kind": "link", "points": seg.points.tolist(), "rapid": seg.rapid.tolist()}


def program_to_dict(program: Program, segments=None) -> dict:
    """Everything in a :class:`Program` as JSON-ready objects (see the module doc);
    ``segments``: what stands for the segments' list (default: the list itself)."""
    return {
        "format": FORMAT, "version": VERSION,
        "job": plain(program.job.to_inputs(), nonfinite_as_strings=True),
        "segments": [_segment_to_dict(seg) for seg in program.segments]
        if segments is None else segments,
        "skipped": [{"faces": list(s.faces), "edge": s.edge, "reason": s.reason,
                     "detail": s.detail} for s in program.skipped],
        "notes": list(program.notes),
        "summary": plain({"complete": program.complete, **program.totals()},
                         nonfinite_as_strings=True),
    }


def _segment(d: dict, k: int):
    kind = d.get("kind") if isinstance(d, dict) else None
    if kind == "link":
        pts = np.array(d["points"], dtype=float)
        if not np.all(np.isfinite(pts)):
            raise InputError(f"segment {k} (link) has a non-finite point")
        return LinkSegment(pts, d.get("rapid", [True] * (len(pts) - 1)))
    if kind == "cut":
        try:
            path = v1.toolpath_from_dict(v1.cut_as_toolpath_dict(d))
        except InputError as e:
            raise InputError(f"segment {k} (cut): {e}") from None
        return CutSegment(path, d.get("edge"), d.get("stretch"), bool(d.get("at_limit")))
    raise InputError(f"segment {k}: kind must be \"cut\" or \"link\", got {kind!r}")


def program_from_dict(d: dict) -> Program:
    """The :class:`Program` of a version 2 dict, or of a version 1 toolpath dict."""
    if isinstance(d, dict) and d.get("format") == v1.FORMAT:
        return Program.of_paths([v1.toolpath_from_dict(d)])
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise InputError("not a cadcnc program or toolpath (no \"format\": "
                         "\"cadcnc-program\" or \"cadcnc-toolpath\")")
    if d.get("version") != VERSION:
        raise InputError(f"program format version {d.get('version')!r} is not supported "
                         f"(this cadcnc reads version {VERSION}, and toolpath version "
                         f"{v1.VERSION})")
    try:
        segments = [_segment(s, k) for k, s in enumerate(d["segments"], 1)]
        skipped = [Skipped(tuple(s["faces"]), s["reason"], s.get("detail", ""), s.get("edge"))
                   for s in d.get("skipped", [])]
        cuts = [s for s in segments if s.kind == "cut"]
        job = Job.from_inputs(d["job"], cuts[0].path.faces if cuts else (None, None))
    except (KeyError, TypeError, ValueError) as e:
        raise InputError(f"program JSON is incomplete or malformed ({type(e).__name__}: "
                         f"{e})") from None
    if not cuts and not skipped:
        raise InputError("program JSON has no cut segment and nothing skipped")
    program = Program(job, segments, skipped, [str(n) for n in d.get("notes", [])])
    return in_setup_coordinates(program, setup_of_dict(d.get("setup")))


def setup_of_dict(d) -> Setup | None:
    """The recorded setup (None when there is none); InputError when malformed."""
    if d is None:
        return None
    try:
        setup = Setup.from_dict(d)
        ok = setup.axis.shape == (3,) and setup.rotation.shape == (3, 3) and \
            setup.origin.shape == (3,) and np.allclose(setup.rotation @ setup.rotation.T,
                                                       np.eye(3), atol=1e-9)  # orthonormal
    except (KeyError, TypeError, ValueError):
        ok = False
    if not ok:
        raise InputError("the program's setup must hold an axis (3), a rotation (3 x 3, "
                         "orthonormal) and an origin (3)")
    return setup


def program_json(program: Program, setup: Setup | None = None) -> str:
    """The JSON text of ``program``; a ``setup``'s program (in its work coordinates) is
    written in part coordinates with the setup. (On worker processes:
    :func:`cadcnc.io.outputs.render_all`, from :func:`json_pieces`.)"""
    return json_pieces(program, setup, 1)[0]


def json_pieces(program: Program, setup: Setup | None, jobs: int) -> tuple[str, str, list]:
    """(text, "", []) for one process; else (head, tail, runs): the program's JSON is
    ``join_pieces(head, tail, [segments_text(run) for run in runs])``, the runs
    (:func:`_runs`) made anywhere. Either way the segments are made into text one at a
    time: a finishing program's points as Python lists at once (tens of millions of
    objects) cost the garbage collector more than the text itself."""
    if setup is not None and not setup.identity:
        program = in_part_coordinates(program, setup)
    else:
        setup = None
    runs = _runs(program.segments, jobs)
    d = program_to_dict(program, _HOLE)
    if setup is not None:
        d["setup"] = setup.to_dict()
    text = json.dumps(d, separators=_SEPARATORS) + "\n"
    head, tail = text.split(json.dumps(_HOLE))   # no file name holds its NUL characters
    if len(runs) < 2:
        return join_pieces(head, tail, [segments_text(program.segments)]), "", []
    return head, tail, runs


def join_pieces(head: str, tail: str, texts: list[str]) -> str:
    """The JSON of :func:`json_pieces`' runs, their texts in order (one copy of the
    text: a finishing program's JSON is tens of MB)."""
    parts = [head, "["]
    for k, text in enumerate(texts):
        parts += [",", text] if k else [text]
    return "".join(parts + ["]", tail])


_SEPARATORS = (",", ":")
_HOLE = "\x00segments\x00"
RUNS_PER_JOB = 4
"""Runs of segments per process when the JSON is made on workers (the last to end small)."""


def _runs(segments, jobs: int) -> list[list]:
    """``segments`` cut into about RUNS_PER_JOB * ``jobs`` runs of similar point counts
    (one run: no workers)."""
    if jobs < 2 or len(segments) < 2:
        return [list(segments)]
    sizes = np.cumsum([len(seg.points) for seg in segments])
    n = min(RUNS_PER_JOB * jobs, len(segments))
    ends = np.searchsorted(sizes, sizes[-1] * np.arange(1, n) / n, side="right")
    bounds = [0, *sorted(set(int(e) for e in ends) - {0, len(segments)}), len(segments)]
    return [list(segments[a:b]) for a, b in zip(bounds, bounds[1:])]


def segments_text(segments) -> str:
    """The JSON of a run of segments (:func:`json_pieces`), as it stands in the list.

    The cycle collector is held off meanwhile: a cut's points become lists of Python
    floats that refer to nothing else and die with its text (no cycle to find), but
    their numbers would set off full collections of everything the process holds (0.3 s
    a finishing program of 57 000 points). Its earlier state is restored after."""
    was = gc.isenabled()
    gc.disable()
    try:
        return ",".join(json.dumps(_segment_to_dict(seg), separators=_SEPARATORS)
                        for seg in segments)
    finally:
        if was:
            gc.enable()


def write_program_json(program: Program, out) -> None:
    """Write ``program`` to ``out`` as JSON version 2 (atomic)."""
    write_text(out, program_json(program))


def read_program(file) -> Program:
    """Read a program (version 2) or toolpath (version 1) JSON file; errors name the file."""
    require("file", file, (str, os.PathLike), "a JSON file's path")
    return v1.read_json_file(file, "program", program_from_dict)


def read_program_and_setup(file) -> tuple[Program, Setup | None]:
    """A program file's :class:`Program` in its work coordinates and its recorded setup
    (None for the +Z identity): :func:`~cadcnc.program.transform.in_part_coordinates`
    turns it back into part coordinates."""
    require("file", file, (str, os.PathLike), "a JSON file's path")
    return v1.read_json_file(file, "program", lambda d: (
        program_from_dict(d), setup_of_dict(d.get("setup")) if isinstance(d, dict) else None))
