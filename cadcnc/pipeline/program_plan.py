"""The one place the pipeline asks the operations for a program: :func:`plan`."""

from __future__ import annotations

from ..core.job import Job
from ..core.work_limits import MAX_CYCLES
from ..ops.run import run
from ..program.program import Program


def plan(part, job: Job, *, progress=None, times: dict | None = None,
         max_cycles: int = MAX_CYCLES, processes: int | None = 1) -> Program:
    """The program of ``job`` on ``part``, not yet gated (:func:`cadcnc.ops.run.run`).
    ``progress`` and ``times``: the operation's callback and per-stage seconds;
    ``max_cycles``: the work limit; ``processes``: processes computing it (None: every
    core); the program does not depend on it."""
    return run(part, job, progress=progress, times=times, max_cycles=max_cycles,
               processes=processes)
