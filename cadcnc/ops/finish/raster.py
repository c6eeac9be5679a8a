"""Raster finishing: passes of the ball over selected faces on guide planes, one program.

:func:`raster_program` samples the selected faces, places vertical guide planes at the pass angle
(:mod:`.plan`: a fixed stepover, or the spacing that keeps the scallop within a
height), runs one pass per plane (:func:`~cadcnc.ops.finish.passes.pass_cuts`: the paper's
guide-surface interpolation, the ball touching the faces, its centre on the plane), every
other pass reversed for a zigzag, and links the cuts (:func:`~cadcnc.program.linking.linked`):
a zigzag stays down between two cuts only where that straight move of the ball and shank is
verified clear of the part (:class:`~cadcnc.guard.stay_down.StayDown`: a cheap witness
refutes it, else :class:`~cadcnc.guard.moves.MoveClearance` proves it at least
R' - 1 µm from every face), otherwise, and always for one-way, it retracts to the
clearance height. Each pass is entered where the tool can get to it, as every cut is
(:mod:`cadcnc.ops.entries`: a pass under an overhang from its other end, a point between
or the side). What the passes left uncut (largest scallop, area not machined and
why) is reported in the program's notes and skipped list (:mod:`.uncut`). Lengths
mm, feed mm/min, period s, angles degrees.
"""

from __future__ import annotations

import time

from ...core.errors import InputError
from ...core.job import Job
from ...core.progress import Progress
from ...core.work_limits import MAX_PLANES, Heartbeat
from ...geometry.part import Part
from ...parallel.pool import check_jobs
from ...parallel.tasks import beside, on_workers
from ...program.linking import linked, linked_cuts
from ...program.program import CutSegment, Program, Skipped
from ..common import FINISH_JOIN as JOIN
from ..common import safe_height
from ..entries import entered_items
from .pass_setup import pass_setup
from .passes import GuidePlane, PassResult, pass_cuts
from .plan import MAX_SAMPLES, centre_chord, plan_planes, sample_faces
from .uncut import measured_rows, uncut_from_rows, uncut_tasks
from .waterline import stay_down_links

SAMPLES_PER_SPACING = 4
"""The faces are sampled this many times per plane spacing (stepover, or the flat
spacing of the scallop height)."""


def raster_program(part: Part, job: Job, *, progress: Progress | None = None,
                   max_planes: int = MAX_PLANES, clock=time.monotonic,
                   work: dict | None = None, processes: int | None = 1) -> Program:
    """The program of a :class:`~cadcnc.core.job.Raster` ``job`` on ``part``:
    ``progress(done, total, what)`` after each plane, and inside a plane at least every
    HEARTBEAT_S seconds of ``clock`` (``done`` then counting the planes finished). The
    planes are estimated before any is placed and refused over ``max_planes``
    (:class:`~cadcnc.core.work_limits.WorkLimitError`, exit 2); the face samples are at most
    MAX_SAMPLES. ``work``: a dict given ``planes_estimate``, ``planes``,
    ``samples_estimate``, ``samples`` and ``cycles`` (every stepper cycle run). ``processes``:
    processes running the planes (None: every core); the program does not depend on it
    (the heartbeat inside a plane is then only the planes' ends)."""
    op, pattern = job.operation, job.operation.pattern
    for n in op.faces:
        part.face(n)  # FaceNumberError names the range
    work = {} if work is None else work
    plan, samples = plan_for_job(part, job, max_planes=max_planes, work=work)
    total, done = len(plan.offsets), 0
    beat = Heartbeat(progress and (lambda text: progress(done, total, text)), clock=clock)
    work.update(planes=total, samples=len(samples), cycles=0)
    cuts: list[CutSegment] = []
    skipped: list[Skipped] = []
    tasks = [(job, k, float(offset), pattern == "zigzag" and k % 2 == 1)
             for k, offset in enumerate(plan.offsets)]

    def arrived(k: int, res) -> None:
        nonlocal done
        done += 1   # reported now, which restarts the heartbeat's interval
        beat.beat(f"plane {done} at {plan.offsets[k]:.3f} mm", force=True)

    pass_setup(part, op.faces, job)  # the planes' guards, built before forked workers copy them
    for res in on_workers(_plane, tasks, part, processes, arrived, "plane", beat):
        cuts += res.cuts
        skipped += res.skipped
        work["cycles"] += res.cycles
    stay_down = stay_down_links(part, job) if pattern == "zigzag" else None
    z_safe = safe_height(part, job)
    items, unreachable, notes = entered_items(
        part, job, cuts, z_safe, tick=lambda k, n: beat.beat(f"entries: {k} of {n} cuts"),
        processes=processes)
    # the uncut report needs only the cut points: measured on the workers while this
    # process links the cuts
    tasks = uncut_tasks([c.points for c in linked_cuts(items)], job, samples, plan,
                        check_jobs(processes))
    segments, rows = beside(lambda: linked(items, z_safe, join=JOIN, stay_down=stay_down),
                            measured_rows, tasks, part, processes, "the uncut report's block")
    program = Program(job, segments, skipped + unreachable, notes)
    report = uncut_from_rows(rows, job, part, samples, plan)
    program.skipped += report.skipped()
    program.notes += report.notes()
    return program


def _plane(part: Part, task, beat=None) -> PassResult:
    """One plane's pass (:func:`~cadcnc.parallel.tasks.on_workers`' task)."""
    job, k, offset, reverse = task
    tell = None if beat is None else (lambda text: beat.beat(
        lambda: f"plane {k + 1}: " + (text() if callable(text) else text)))
    return pass_cuts(part, job.operation.faces, GuidePlane(job.operation.angle, offset), job,
                     reverse=reverse, beat=tell)


def plan_for_job(part: Part, job: Job, *, max_planes: int = MAX_PLANES,
                 work: dict | None = None):
    """(plan, samples): the guide planes of a finishing ``job`` and the samples of its
    faces they were placed from; InputError for a face the ball cannot reach at all,
    WorkLimitError for more than ``max_planes`` planes (estimated before any is placed).
    ``work``: given ``samples_estimate`` and ``planes_estimate``."""
    op, tool = job.operation, job.tool
    spacing = op.stepover if op.stepover is not None else float(
        centre_chord(op.scallop, 0.0, tool.radius, tool.allowance))
    if not spacing > 0.0:   # a scallop below what floats resolve
        raise InputError(f"scallop {op.scallop:g} mm is too small to space planes for "
                         "(the spacing is 0): give a larger --scallop")
    work = {} if work is None else work
    work["samples_estimate"] = MAX_SAMPLES   # sample_faces coarsens its grid to stay within
    samples = sample_faces(part, op.faces, spacing / SAMPLES_PER_SPACING)
    for n in op.faces:
        mine = samples.faces == n
        if mine.any() and (samples.normals[mine, 2] < 0).all():
            raise InputError(f"face {n} points down (its normals have -Z components "
                             "everywhere): a ball cannot reach it from +Z")
    plan = plan_planes(samples, tool.radius, tool.allowance, op.angle,
                       stepover=op.stepover, scallop=op.scallop, max_planes=max_planes,
                       work=work)
    return plan, samples
