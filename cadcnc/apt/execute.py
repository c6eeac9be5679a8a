"""Executing a program's entries: check them all, then compute or stream each path.

:func:`check` loads every part and checks every face number and every EDGE end (the two
faces share that concave edge) before any path is computed; :func:`run_job` and
:func:`stream_job` then compute one entry through :mod:`cadcnc.ops.path.pair_path`. A library
error comes back as the same kind of error prefixed with the PATH statement's line.
"""

from __future__ import annotations

from dataclasses import replace

from ..core.errors import CadcncError, InputError
from ..geometry.part import load_step
from ..ops.path.pair_path import path_for_job, plan_path, shared_edge_for, stepper_for
from .program_entries import ProgramEntry


def _at(entry: ProgramEntry, e: CadcncError, source: str) -> CadcncError:
    """The same kind of error, prefixed with the program line of the PATH statement."""
    message = f"{source}:{entry.line}: PATH {entry.name}: {e}"
    try:
        return type(e)(message)
    except TypeError:  # an error type that needs more than a message
        return InputError(message)


def _resolve(entry: ProgramEntry, part) -> ProgramEntry:
    """The entry with its faces checked on ``part`` and a lone EDGE end made a point."""
    op = entry.job.operation
    s1, s2 = part.face(op.faces[0]), part.face(op.faces[1])
    if not entry.on_edge:
        return entry
    edge = shared_edge_for(s1, s2, op.edge or 0)
    if entry.pending is None:  # EDGE, EDGE: the job's own default
        return entry
    s, e = entry.pending
    start = edge.start if s.edge else s.point
    end = edge.end if e.edge else e.point
    job = replace(entry.job, operation=replace(op, start=start, end=end))
    return replace(entry, job=job, pending=None)


def check(entries: list[ProgramEntry], source: str = "<program>", load=None
          ) -> list[tuple[ProgramEntry, object]]:
    """Load the parts and check every entry before any path is computed.

    Returns [(entry, part)], each entry ready to run (a lone EDGE end resolved to the
    edge's point). ``load(file)``: the part loader (default :func:`load_step`), called
    once per part file.
    """
    load = load or load_step
    parts: dict[str, object] = {}
    out = []
    for entry in entries:
        try:
            file = entry.job.source
            if file not in parts:
                parts[file] = load(file)
            out.append((_resolve(entry, parts[file]), parts[file]))
        except CadcncError as e:
            raise _at(entry, e, source) from e
    return out


def _checked(entry: ProgramEntry, source: str):
    if entry.pending is not None:
        raise InputError(f"{source}:{entry.line}: PATH {entry.name}: the EDGE end is not "
                         "resolved yet: check() the program first")


def run_job(entry: ProgramEntry, part, progress=None, source: str = "<program>"):
    """The :class:`~cadcnc.program.toolpath.Toolpath` of one checked entry.

    ``progress(cycles, 0, "<mm> mm")`` is called every 10 000 cycles.
    """
    _checked(entry, source)
    try:
        return path_for_job(part, entry.job, progress=progress)
    except CadcncError as e:
        raise _at(entry, e, source) from e


def stream_job(entry: ProgramEntry, part, source: str = "<program>"):
    """(stepper, increments): the stepper and a generator of its per-period (dx, dy, dz)."""
    _checked(entry, source)
    i, j = entry.job.operation.faces
    try:
        stepper = stepper_for(plan_path(part.face(i), part.face(j), entry.job), record=False)
    except CadcncError as e:
        raise _at(entry, e, source) from e

    def increments():
        while (dp := stepper.step()) is not None:
            yield dp

    return stepper, increments()
