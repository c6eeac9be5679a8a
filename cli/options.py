"""Command-line strings to the library's typed records: the Job, tolerances, G-code options."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

from cadcnc.errors import InputError
from cadcnc.io.gcode import blend_for
from cadcnc.job import SAFE_MARGIN, Job, PairPath, Tool, check_number
from cadcnc.tolerances import DEFAULT, Tolerances
from cadcnc.units import parse_duration, parse_feed, parse_length, parse_point

JOB_OPTIONS = ("faces", "radius")  # feed and period have defaults (cli/operation.py)


def tolerances(args) -> Tolerances:
    """The default tolerances with the gouge limit given by ``--gouge-tolerance``."""
    gouge = parse_length(args.gouge_tolerance, "gouge tolerance", allow_zero=False)
    return dataclasses.replace(DEFAULT, gouge=gouge)


def job_from_args(args, source: str) -> Job:
    """The :class:`Job` of ``path``/``verify``'s options (mm, mm/min, s), validated once."""
    missing = [f"--{n}" for n in JOB_OPTIONS if getattr(args, n) is None]
    if missing:
        raise InputError(f"computing a path needs {', '.join(missing)}")
    if args.edge is not None and args.edge < 1:
        raise InputError(f"--edge numbers the shared concave edges from 1, got {args.edge}")
    stretch = getattr(args, "stretch", None)
    if stretch is not None and stretch < 1:
        raise InputError(f"--stretch numbers the stretches of an edge from 1, got {stretch}")
    tool = Tool(parse_length(args.radius, "radius"), parse_length(args.allowance, "allowance"))
    op = PairPath(faces=tuple(args.faces),
                  start=None if args.start is None else parse_point(args.start, "start"),
                  end=None if args.end is None else parse_point(args.end, "end"),
                  edge=None if args.edge is None else args.edge - 1, stretch=stretch)
    return Job(tool, parse_feed(args.feed), parse_duration(args.period), op, source=source,
               clearance=clearance(args), tolerances=tolerances(args),
               flip_material=getattr(args, "flip_material", False))


def clearance(args) -> float | None:
    """``--clearance`` (alias ``--safe-z``) in mm, or None for the part's top + margin."""
    if getattr(args, "clearance", None) is None:
        return None
    try:
        z = float(args.clearance)
    except ValueError:
        z = float("nan")
    if not math.isfinite(z):
        raise InputError(f"--clearance: expected a finite height in mm, got {args.clearance!r}")
    return z


def wants_gcode(outputs) -> bool:
    return any(Path(o).suffix.lower() == ".ngc" for o in outputs or ())


def gcode_options(args, clearance_z: float | None, parts) -> dict:
    """Keyword arguments of :func:`cadcnc.io.to_ngc`: chord tolerance, tool tip, rapid
    height (the clearance given, else the highest part's top plus the safe margin)."""
    tol = None if args.tolerance is None else parse_length(args.tolerance, "tolerance", False)
    if clearance_z is None:
        clearance_z = max(part.top for part in parts) + SAFE_MARGIN
    spindle = None if args.spindle is None else check_number("--spindle", args.spindle, "rpm")
    return dict(tolerance=tol, tool_tip=args.tool_tip, safe_z=clearance_z, spindle=spindle,
                blend=blend_for(tolerances(args).gouge))


def program_gcode_options(args) -> dict:
    """Keyword arguments of :func:`cadcnc.io.program_gcode.program_ngc`: chord tolerance,
    tool tip, spindle, plunge feed (default the feed). The links' height is the job's
    clearance (``--clearance``), else the part's top plus the safe margin."""
    tol = None if args.tolerance is None else parse_length(args.tolerance, "tolerance", False)
    spindle = None if args.spindle is None else check_number("--spindle", args.spindle, "rpm")
    plunge = getattr(args, "plunge_feed", None)
    plunge = None if plunge is None else parse_feed(plunge, "plunge feed")
    return dict(tolerance=tol, tool_tip=args.tool_tip, spindle=spindle, plunge_feed=plunge,
                blend=blend_for(tolerances(args).gouge))
