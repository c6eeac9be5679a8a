"""The finishing shortcut of a CadQuery script: :func:`finish` of faces selected on a part.

It turns a face selection into the part's face numbers (:func:`face_numbers`), builds the
finishing record of the strategy and the :class:`~cadcnc.core.job.Job`, and runs it the
one way every operation runs (:func:`cadcnc.ops.run.run`). Lengths mm, feed mm/min,
period s, angles degrees.
"""

from __future__ import annotations

import numbers
from dataclasses import fields

import numpy as np

from ...core.errors import InputError
from ...core.job import DEFAULT_FEED, DEFAULT_PERIOD, FINISHING, Job, Tool
from ...core.progress import Progress
from ...geometry.part import Part
from ...program.program import Program
from ..run import run

JOB_KEYWORDS = ("allowance", "feed", "period", "max_planes")


def finish(part, faces, *, radius: float, strategy: str = "raster",
           progress: Progress | None = None, **options) -> Program:
    """The finishing program of ``faces`` of ``part`` by ``strategy`` ("raster",
    "waterline" or "steep-shallow").

    ``part``: a :class:`~cadcnc.geometry.part.Part`, or a CadQuery Workplane or Shape;
    ``faces``: face numbers (1-based), CadQuery/OCCT faces of the part, or a Workplane
    selection such as ``wp.faces(">Z")``; ``radius``: the ball's R (mm). ``options``: the
    fields of the strategy's record (:class:`~cadcnc.core.job.Raster`: ``stepover`` or
    ``scallop``, ``angle``, ``pattern``; :class:`~cadcnc.core.job.Waterline`: ``stepdown``
    or ``scallop``, ``side``; :class:`~cadcnc.core.job.SteepShallow`: those and
    ``threshold``, ``overlap``), and ``allowance`` (mm), ``feed`` (mm/min), ``period`` (s)
    and ``max_planes`` (:func:`~cadcnc.ops.run.run`). Anything else of a Job (clearance,
    tolerances, tool axis): build the Job and call :func:`~cadcnc.ops.run.run`.
    """
    kind = FINISHING.get(strategy)
    if kind is None:
        raise InputError(f"strategy must be one of {', '.join(FINISHING)}, got {strategy!r}")
    own = {f.name for f in fields(kind)} - {"faces"}
    unknown = set(options) - own - set(JOB_KEYWORDS)
    if unknown:
        raise InputError(f"{strategy} finishing takes {', '.join(sorted(own))}, not "
                         f"{', '.join(sorted(unknown))}")
    if not isinstance(part, Part):
        part = Part.from_cadquery(part)
    op = kind(face_numbers(part, faces), **{k: v for k, v in options.items() if k in own})
    job = Job(Tool(radius, options.get("allowance", 0.0)), options.get("feed", DEFAULT_FEED),
              options.get("period", DEFAULT_PERIOD), op, source=part.source)
    extra = {"max_planes": options["max_planes"]} if "max_planes" in options else {}
    return run(part, job, progress=progress, **extra)


def face_numbers(part: Part, faces) -> tuple[int, ...]:
    """The 1-based numbers of ``faces`` in ``part``: numbers, faces of the part (CadQuery
    or OCCT), or a CadQuery Workplane selection; InputError for anything else."""
    if hasattr(faces, "vals") and callable(faces.vals):  # a Workplane selection
        faces = faces.vals()
    elif isinstance(faces, (numbers.Integral, np.integer)) or hasattr(faces, "wrapped"):
        faces = [faces]
    try:
        items = list(faces)
    except TypeError:
        raise InputError(f"faces must be face numbers, CadQuery faces or a Workplane "
                         f"selection, got {type(faces).__name__}") from None
    if not items:
        raise InputError("no face selected: give at least one face")
    out = []
    for f in items:
        if isinstance(f, bool):
            raise InputError(f"face numbers are integers from 1, got {f!r}")
        if isinstance(f, (numbers.Integral, np.integer)):
            part.face(int(f))  # FaceNumberError names the range
            out.append(int(f))
            continue
        kind = getattr(getattr(f, "wrapped", f), "ShapeType", None)
        if kind is None or type(f).__name__ not in ("Face", "TopoDS_Face"):
            raise InputError(f"faces must be face numbers or faces, got a "
                             f"{type(f).__name__}")
        n = part.face_number(f)
        if n == 0:
            raise InputError(f"a face given is not a face of the part {part.source} (a "
                             "selection from another shape, or a copy of it?)")
        out.append(n)
    return tuple(out)
