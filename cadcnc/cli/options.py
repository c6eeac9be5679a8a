"""Command-line strings to the library's typed records: a Job for every command, the
tolerances, the run's settings, the machine and the G-code writer's keywords."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

from cadcnc.controller.machine import Machine, read_machine_ini
from cadcnc.core.errors import InputError
from cadcnc.core.job import Job, PairPath, Pencil, Tool, check_number, finishing
from cadcnc.core.tolerances import BOUNDS, CHORD_TOLERANCE_MAX, DEFAULT, Tolerances
from cadcnc.core.units import parse_duration, parse_feed, parse_length, parse_point
from cadcnc.io.gcode import blend_for
from cadcnc.parallel.pool import check_jobs
from cadcnc.pipeline.operate import Settings

from .feedback import say_error

JOB_OPTIONS = ("faces", "radius")  # feed and period have defaults (operation_options.py)


def tolerances(args) -> Tolerances:
    """The default tolerances with the gouge limit given by ``--gouge-tolerance``, within
    its bound (docs/reliability.md)."""
    gouge = parse_length(args.gouge_tolerance, "gouge tolerance", allow_zero=False)
    hi = BOUNDS["gouge"][1]
    if gouge > hi:
        raise InputError(f"--gouge-tolerance {gouge:g} mm is over its bound {hi:g} mm: a "
                         "looser limit would pass gouges the gate exists to refuse "
                         "(docs/reliability.md)")
    return dataclasses.replace(DEFAULT, gouge=gouge)


def job_of(args, operation, source: str) -> Job:
    """The :class:`Job` of the options every command shares (mm, mm/min, s) with
    ``operation``, validated once."""
    tool = Tool(parse_length(args.radius, "radius", allow_zero=False),
                parse_length(args.allowance, "allowance"))
    plunge = getattr(args, "plunge_feed", None)
    spindle = getattr(args, "spindle", None)
    z = clearance(args)
    if z is not None and getattr(args, "tool_tip", False):
        z += tool.radius   # the tip's height given: the job holds the ball centre's
    return Job(tool, parse_feed(args.feed), parse_duration(args.period), operation,
               source=source, clearance=z, tolerances=tolerances(args),
               flip_material=getattr(args, "flip_material", False),
               plunge_feed=None if plunge is None else parse_feed(plunge, "plunge feed"),
               spindle=None if spindle is None else check_number("--spindle", spindle, "rpm"),
               **setup_keywords(args))


def setup_keywords(args) -> dict:
    """``axis`` and ``origin`` of the Job from --axis and --origin (when given)."""
    out = {}
    if getattr(args, "axis", None) is not None:
        out["axis"] = args.axis
    if getattr(args, "origin", None) is not None:
        out["origin"] = parse_point(args.origin, "origin")
    return out


def path_job(args, source: str) -> Job:
    """The :class:`Job` of ``path``/``verify``'s options."""
    missing = [f"--{n}" for n in JOB_OPTIONS if getattr(args, n) is None]
    if missing:
        raise InputError(f"computing a path needs {', '.join(missing)}")
    if args.edge is not None and args.edge < 1:
        raise InputError(f"--edge numbers the shared concave edges from 1, got {args.edge}")
    stretch = getattr(args, "stretch", None)
    if stretch is not None and stretch < 1:
        raise InputError(f"--stretch numbers the stretches of an edge from 1, got {stretch}")
    op = PairPath(faces=tuple(args.faces),
                  start=None if args.start is None else parse_point(args.start, "start"),
                  end=None if args.end is None else parse_point(args.end, "end"),
                  edge=None if args.edge is None else args.edge - 1, stretch=stretch)
    return job_of(args, op, source)


def pencil_job(args, source: str) -> Job:
    """The :class:`Job` of ``pencil``'s options."""
    return job_of(args, Pencil(args.faces, args.side), source)


def finish_job(args, source: str) -> Job:
    """The :class:`Job` of ``finish``'s options."""
    spacing = {name: None if getattr(args, name) is None else
               parse_length(getattr(args, name), name, allow_zero=False)
               for name in ("stepover", "scallop", "stepdown")}
    if all(v is None for v in spacing.values()):
        raise InputError("give --stepover S or --scallop H (raster), --stepdown D or "
                         "--scallop H (waterline): the passes' spacing")
    given = {name: _degrees(args, name) for name in ("angle", "threshold")
             if getattr(args, name) is not None}
    given.update({name: getattr(args, name) for name in ("pattern", "side")
                  if getattr(args, name) is not None})
    if args.overlap is not None:
        given["overlap"] = parse_length(args.overlap, "overlap")
    return job_of(args, finishing(args.strategy, args.faces, own_only=True, **spacing,
                                  **given), source)


def _degrees(args, name: str) -> float:
    """``--NAME`` in degrees, or InputError naming the option."""
    try:
        return float(getattr(args, name))
    except ValueError:
        raise InputError(f"--{name}: expected degrees, got {getattr(args, name)!r}") from None


BUILDERS = {"path": path_job, "pencil": pencil_job, "finish": finish_job}
"""The Job of each operation command's options (``cadcnc batch`` maps a job file's
operations through it)."""


def settings_of(args, processes: int | None = None) -> Settings:
    """How an operation command's program is judged and written: ``--max-cycles``, the
    G-code keywords when a .ngc is among the outputs, ``--allow-partial/gouge``, and the
    processes: ``processes``, else ``--jobs`` (default every core)."""
    return Settings(args.max_cycles, gcode_keywords(args) if wants_gcode(args.output)
                    else None, args.allow_partial, args.allow_gouge,
                    check_jobs(getattr(args, "processes", None)) if processes is None
                    else processes)


def machine_of(args) -> Machine:
    """The Machine of --machine / --jerk (InputError on a bad file or value)."""
    jerk = None if args.jerk is None else parse_length(args.jerk, "jerk", allow_zero=False)
    if args.machine is not None:
        return read_machine_ini(args.machine, jerk,
                                warn=lambda text: say_error(f"cadcnc: warning: {text}"))
    m = Machine.default()
    return m if jerk is None else dataclasses.replace(
        m, max_jerk=(jerk,) * 3, source=m.source.split(",")[0] + f", jerk {jerk:g}")


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


def gcode_keywords(args) -> dict:
    """Keyword arguments of :func:`cadcnc.io.program_gcode.program_ngc` besides the job's
    (spindle and plunge feed are in the job): chord tolerance, tool tip, G64 P blending."""
    tol = None if args.tolerance is None else parse_length(args.tolerance, "tolerance", False)
    if tol is not None and tol > CHORD_TOLERANCE_MAX:
        raise InputError(f"--tolerance {tol:g} mm is over its bound {CHORD_TOLERANCE_MAX:g} "
                         "mm (points dropped and G64 P blending that far from the path; "
                         "docs/reliability.md)")
    return dict(tolerance=tol, tool_tip=args.tool_tip,
                blend=blend_for(tolerances(args).gouge))
