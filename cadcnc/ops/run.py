"""One entry for every operation: :func:`run` a :class:`~cadcnc.core.job.Job` on a part."""

from __future__ import annotations

from ..core.errors import InputError
from ..geometry.part import Part
from ..geometry.setup import setup_part
from ..core.job import Finish, Job, PairPath, Pencil
from ..program.program import Program
from ..core.work_limits import MAX_CYCLES
from ..parallel.pool import start
from .path.pair_program import program_for_job
from .pencil.pencil import CHAIN_GAP, pencil_program


def run(part, job: Job, *, progress=None, times: dict | None = None,
        max_cycles: int = MAX_CYCLES, jobs: int | None = 1) -> Program:
    """The :class:`~cadcnc.program.program.Program` of ``job`` on ``part`` (a
    :class:`~cadcnc.geometry.part.Part`, or a CadQuery Workplane or Shape): the pair's
    corner for :class:`~cadcnc.core.job.PairPath` (every feasible stretch, cut and linked),
    every inner corner for :class:`~cadcnc.core.job.Pencil`, the raster passes for
    :class:`~cadcnc.core.job.Finish`. ``progress``: the operation's progress callback
    (:func:`program_for_job`: ``(cycles, mm)``; pencil and finish: ``(done, total,
    what)``); ``times``: pencil's seconds per stage
    (:func:`pencil_program`); ``max_cycles``: the interpolation cycles the path or pencil
    program may need, estimated and refused up front over it. The program is not gated: see :func:`cadcnc.verification.gate_program`.
    ``jobs``: processes running pencil's corners and finishing's planes (None: every
    core; default 1, this process); the program is the same whatever it is."""
    if not isinstance(job, Job):
        raise InputError(f"job must be a cadcnc.Job, got {type(job).__name__}")
    start(jobs)   # the workers' server warms up while the part is read and planned
    if not isinstance(part, Part):
        part = Part.from_cadquery(part, job.tolerances)
    part = setup_part(part, job)   # the tool axis up: the program in work coordinates
    check_clearance(part, job)
    op = job.operation
    if isinstance(op, PairPath):
        return program_for_job(part, job, progress=progress, max_cycles=max_cycles)
    if isinstance(op, Pencil):
        return pencil_program(part, job, progress=progress, times=times,
                              max_cycles=max_cycles, jobs=jobs)
    if isinstance(op, Finish):
        # finishing's modules and scipy.optimize: about 0.5 s CPU a path or pencil doesn't pay
        from .finish.finish import finish_program  # noqa: PLC0415

        return finish_program(part, job, progress=progress, jobs=jobs)
    raise InputError(f"unknown operation {type(op).__name__}")


def cut_back_gap(job: Job) -> float | None:
    """The chain gap (mm) with which a program of ``job`` is relinked once its gouging cuts
    are cut back to their last verified point (pencil, finish), or None: a path follows
    the pair the user named and is judged whole."""
    op = job.operation
    if isinstance(op, Finish):
        from .finish.finish import JOIN  # noqa: PLC0415 - as in run: finishing's modules

        return JOIN
    return CHAIN_GAP if isinstance(op, Pencil) else None


def check_clearance(part: Part, job: Job) -> None:
    """InputError unless the job's clearance keeps the ball above the part's top: the
    ball centre at least R above it (the links rapid across at that height)."""
    if job.clearance is None:
        return
    lowest = part.top + job.tool.radius
    if job.clearance < lowest:
        raise InputError(f"clearance {job.clearance:g} mm (the ball centre's height) is "
                         f"below the part's top {part.top:g} mm plus the ball radius: the "
                         f"lowest allowed is {lowest:g} mm (with --tool-tip, "
                         f"{lowest - job.tool.radius:g} mm)")
