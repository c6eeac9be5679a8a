"""One protocol for every operation: :func:`run` a :class:`~cadcnc.core.job.Job` on a part.

Each operation record type (:mod:`cadcnc.core.operations`) has one :class:`Operation` in
:data:`REGISTRY`: its planner, ``plan(part, job, options) -> Program`` (the part already
in the job's setup, the clearance checked), and the chain gap with which its program is
relinked once gouging cuts are cut back. :func:`run` reads the part, turns it into the
job's setup and calls the planner of the job's record; nothing else chooses by the type
of the record. A new operation is a record in core and a :func:`register` call here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from ..core.errors import InputError
from ..core.job import Job, PairPath, Pencil, Raster, SteepShallow, Waterline
from ..core.progress import Progress
from ..core.work_limits import MAX_CYCLES, MAX_PLANES
from ..geometry.part import Part
from ..geometry.setup import setup_part
from ..parallel.pool import kept_pools, start
from ..program.program import Program
from .common import CHAIN_GAP, FINISH_JOIN


@dataclass(frozen=True)
class RunOptions:
    """How an operation runs, not what it cuts (the program does not depend on it, but for
    the limits' refusals): ``progress`` (:data:`~cadcnc.core.progress.Progress`), ``times``
    (a dict given the seconds per stage, pencil), ``max_cycles`` (interpolation cycles a
    path or pencil program may need, refused up front over it), ``max_planes`` (finishing
    planes or levels, likewise), ``processes`` (worker processes; None: every core)."""

    progress: Progress | None = None
    times: dict | None = None
    max_cycles: int = MAX_CYCLES
    max_planes: int = MAX_PLANES
    processes: int | None = 1


class Planner(Protocol):
    """``plan(part, job, options) -> Program``: one operation's program of ``job`` on
    ``part`` (already in the job's setup, its clearance checked)."""

    def __call__(self, part: Part, job: Job, options: RunOptions) -> Program: ...


@dataclass(frozen=True)
class Operation:
    """An operation's planner, and the chain gap (mm) with which its program is relinked
    once its gouging cuts are cut back to their last verified point; None: the program is
    judged whole (a path follows the pair the user named)."""

    plan: Planner
    cut_back_gap: float | None = None


REGISTRY: dict[type, Operation] = {}
"""The :class:`Operation` of each operation record type."""


def register(kind: type, operation: Operation) -> None:
    """Make ``operation`` the one that runs jobs whose record is a ``kind``."""
    REGISTRY[kind] = operation


def operation_of(job: Job) -> Operation:
    """The registered :class:`Operation` of ``job``'s record (InputError if none)."""
    op = REGISTRY.get(type(job.operation))
    if op is None:
        raise InputError(f"unknown operation {type(job.operation).__name__}")
    return op


def run(part, job: Job, *, progress: Progress | None = None, times: dict | None = None,
        max_cycles: int = MAX_CYCLES, max_planes: int = MAX_PLANES,
        processes: int | None = 1) -> Program:
    """The :class:`~cadcnc.program.program.Program` of ``job`` on ``part`` (a
    :class:`~cadcnc.geometry.part.Part`, or a CadQuery Workplane or Shape), in the job's
    work coordinates: the pair's corner for a PairPath (every feasible stretch, cut and
    linked), every inner corner for a Pencil, the passes, levels or both for the finishing
    records. The keywords are :class:`RunOptions`' (``processes``: processes running pencil's
    corners and finishing's planes; the program is the same whatever it is). The program is
    not gated: see :func:`cadcnc.verification.gate_program`."""
    if not isinstance(job, Job):
        raise InputError(f"job must be a cadcnc.Job, got {type(job).__name__}")
    operation = operation_of(job)
    start(processes)   # the workers' server warms up while the part is read and planned
    if not isinstance(part, Part):
        part = Part.from_cadquery(part, job.tolerances)
    part = setup_part(part, job)   # the tool axis up: the program in work coordinates
    check_clearance(part, job)
    with kept_pools():   # one pool for the operation's stages (planes, corners, entries)
        return operation.plan(part, job, RunOptions(progress, times, max_cycles, max_planes, processes))


def cut_back_gap(job: Job) -> float | None:
    """The chain gap (mm) with which a program of ``job`` is relinked once its gouging cuts
    are cut back (:class:`Operation`)."""
    return operation_of(job).cut_back_gap


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


def _pair(part: Part, job: Job, o: RunOptions) -> Program:
    from .path.pair_program import program_for_job  # noqa: PLC0415

    return program_for_job(part, job, progress=o.progress, max_cycles=o.max_cycles)


def _pencil(part: Part, job: Job, o: RunOptions) -> Program:
    from .pencil.pencil_program import pencil_program  # noqa: PLC0415

    return pencil_program(part, job, progress=o.progress, times=o.times,
                          max_cycles=o.max_cycles, processes=o.processes)


# finishing's modules and scipy.optimize: about 0.5 s CPU a path or pencil doesn't pay,
# so the finishing planners import them when first run
def _raster(part: Part, job: Job, o: RunOptions) -> Program:
    from .finish.raster import raster_program  # noqa: PLC0415

    return raster_program(part, job, progress=o.progress, max_planes=o.max_planes,
                          processes=o.processes)


def _waterline(part: Part, job: Job, o: RunOptions) -> Program:
    from .finish.waterline import waterline_program  # noqa: PLC0415

    return waterline_program(part, job, progress=o.progress, max_planes=o.max_planes)


def _steep_shallow(part: Part, job: Job, o: RunOptions) -> Program:
    from .finish.steep_shallow import steep_shallow_program  # noqa: PLC0415

    return steep_shallow_program(part, job, progress=o.progress, max_planes=o.max_planes)


register(PairPath, Operation(_pair))
register(Pencil, Operation(_pencil, CHAIN_GAP))
register(Raster, Operation(_raster, FINISH_JOIN))
register(Waterline, Operation(_waterline, FINISH_JOIN))
register(SteepShallow, Operation(_steep_shallow, FINISH_JOIN))
