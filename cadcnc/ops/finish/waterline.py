"""Waterline finishing: the selected faces cut level by level, top to bottom, one program.

:func:`waterline_program` samples the selected faces (:func:`~.plan.sample_faces`),
places the levels (:mod:`.levels`: a fixed stepdown, or the spacing that keeps the
scallop within a height on the walls; a level at a horizontal face or tangency moved by
half a stepdown), finds every loop and open piece of each level exactly
(:func:`~.loops.level_cuts`: the raster passes' guide-surface interpolation with a
horizontal guide plane, offsets (R', 0)), and links them: straight at the feed where that
move of the ball and shank is verified clear of the part (within a level, and from one
level down to the next: a ramp), otherwise a retract and a plunge, each loop entered by
the rule of :mod:`cadcnc.ops.entries` (as raster's passes and pencil's corners). What the
levels left (the flat areas, for raster; scallops over the limit) is reported like
raster's (:mod:`.uncut`). Lengths mm.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ...core.job import Job
from ...core.progress import Progress
from ...core.work_limits import MAX_PLANES, Heartbeat
from ...geometry.offset_section import offset_face
from ...geometry.part import Part
from ...guard.stay_down import StayDown
from ...program.program import CutSegment, Program, Skipped
from ..common import FINISH_JOIN as JOIN
from ..common import safe_height
from ..entries import entered_program_segments
from .levels import CRITICAL_MM, LevelPlan, check_stepdown, critical_heights, plan_levels
from .loops import level_cuts
from .pass_setup import pass_setup
from .plan import MAX_SAMPLES, FaceSamples, centre_chord, sample_faces
from .uncut import uncut_report

SAMPLES_PER_SPACING = 4


@dataclass
class WaterlineCuts:
    """The cuts of every level, top to bottom, what was not cut, the plan and samples."""

    cuts: list[CutSegment] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)
    plan: LevelPlan | None = None
    samples: FaceSamples | None = None
    per_level: list[int] = field(default_factory=list)


def level_spacing(job: Job) -> float:
    """mm: the stepdown, or the flat-floor chord of the scallop height (the samples' and
    the estimate's scale)."""
    op, tool = job.operation, job.tool
    if op.stepdown is not None:
        return op.stepdown
    return float(centre_chord(op.scallop, 0.0, tool.radius, tool.allowance))


def waterline_samples(part: Part, job: Job, work: dict) -> FaceSamples:
    """The samples of the job's faces the levels are placed from."""
    work["samples_estimate"] = MAX_SAMPLES
    return sample_faces(part, job.operation.faces, level_spacing(job) / SAMPLES_PER_SPACING)


def waterline_cuts(part: Part, job: Job, samples: FaceSamples, *,
                   progress: Progress | None = None,
                   max_levels: int = MAX_PLANES, clock=time.monotonic,
                   work: dict | None = None) -> WaterlineCuts:
    """Every level's cuts of a waterline ``job`` over ``samples`` of its faces (the module
    doc); ``progress(done, total, what)`` after each level and at least every heartbeat."""
    op, tool = job.operation, job.tool
    check_stepdown(op.stepdown, tool.radius)
    work = {} if work is None else work
    setup = pass_setup(part, op.faces, job)
    critical = critical_heights(part, op.faces, samples, tool.offset) + [
        (float(c[:, 2].mean()), f"face {f}, a horizontal edge's offset")
        for f, fe in setup.edges.items() for _, c, _ in fe.samples
        if float(np.ptp(c[:, 2])) <= CRITICAL_MM]
    plan = plan_levels(samples, tool.radius, tool.allowance, stepdown=op.stepdown,
                       scallop=op.scallop, critical=critical, max_levels=max_levels,
                       work=work)
    out = WaterlineCuts(plan=plan, samples=samples)
    total, done = len(plan.offsets), 0
    beat = Heartbeat(progress and (lambda text: progress(done, total, text)), clock=clock)
    work.update(planes=total, samples=len(samples), cycles=0)
    offsets = {f: offset_face(part.face(f).topods, tool.offset) for f in op.faces}
    near = None
    for k, z in enumerate(plan.offsets):
        res = level_cuts(setup, offsets, float(z), job, op.side, near=near,
                         beat=lambda text, k=k: beat.beat(
                             lambda: f"level {k + 1}: " + (text() if callable(text) else text)))
        out.cuts += res.cuts
        out.skipped += res.skipped
        out.per_level.append(len(res.cuts))
        work["cycles"] += res.cycles
        if res.cuts:
            near = res.cuts[-1].points[-1]
        done = k + 1
        beat.beat(f"level {done} at z {z:.3f} mm", force=True)
    return out


def stay_down_links(part: Part, job: Job):
    """The stay-down test of the job's links (:class:`~cadcnc.guard.stay_down.StayDown`:
    the straight move of ball and shank verified clear of the whole part)."""
    setup = pass_setup(part, job.operation.faces, job)
    return StayDown(part, {f: (part.face(f), setup.guard(f).height_cells(f))
                           for f in job.operation.faces}, job.tool.offset, job.tool.shank,
                    job.tolerances.hit)


def entered_program(part: Part, job: Job, cuts: list[CutSegment], skipped: list[Skipped]
                    ) -> Program:
    """The program of the levels' ``cuts`` in order, each entered by the one rule of
    :mod:`cadcnc.ops.entries` (a loop whose start the tool cannot plunge onto is entered
    elsewhere, or from the side, and noted; with none clear it is skipped, ``unreachable``),
    linked straight where the move is clear."""
    segments, unreachable, notes = entered_program_segments(
        part, job, cuts, safe_height(part, job), join=JOIN,
        stay_down=stay_down_links(part, job))
    return Program(job, segments, skipped + unreachable, notes)


def waterline_program(part: Part, job: Job, *, progress: Progress | None = None,
                      max_planes: int = MAX_PLANES, clock=time.monotonic,
                      work: dict | None = None) -> Program:
    """The program of a :class:`~cadcnc.core.job.Waterline` ``job`` on ``part`` (the
    module doc)."""
    for n in job.operation.faces:
        part.face(n)  # FaceNumberError names the range
    work = {} if work is None else work
    samples = waterline_samples(part, job, work)
    res = waterline_cuts(part, job, samples, progress=progress, max_levels=max_planes,
                         clock=clock, work=work)
    program = entered_program(part, job, res.cuts, res.skipped)
    report = uncut_report(program, part, samples, res.plan)
    program.skipped += report.skipped()
    program.notes += res.plan.moved + report.notes()
    return program
