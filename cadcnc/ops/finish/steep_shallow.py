"""Steep-and-shallow finishing: waterline on the steep, raster on the shallow, one program.

The slope of a point of a face is the angle of its outward normal N from +Z,
acos(N_z). With ``--threshold A`` (deg):

- the **waterline** cuts (:mod:`.waterline`, levels planned over the samples steeper than
  A) are kept where their contact's slope exceeds A;
- the **raster** cuts (the existing passes, :func:`~.raster.raster_program` of the
  record's :meth:`~cadcnc.core.operations.SteepShallow.raster`, planes planned over the
  samples at most A steep) are kept where it does not;
- ``--overlap MM``: each keeps also what lies within MM (over the surface, measured to
  the nearest sample of the other region, so to within the samples' spacing) of its
  region, so that the two overlap at the boundary.

A cut is split where it leaves its region; pieces shorter than two points are dropped.
The waterline cuts come first (top to bottom), then the raster passes, linked as one
program; one uncut report covers the union: the steep samples measured across the levels,
the shallow ones across the planes (:func:`~.uncut.uncut_report`), merged. Lengths mm.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
from scipy.spatial import cKDTree

from ...core.job import Job
from ...core.progress import Progress
from ...core.work_limits import MAX_PLANES
from ...geometry.part import Part
from ...program.program import CutSegment, Program
from .plan import FaceSamples, plan_planes
from .raster import raster_program
from .uncut import UncutReport, uncut_report
from .waterline import entered_program, waterline_cuts, waterline_samples


def subset(samples: FaceSamples, mask: np.ndarray) -> FaceSamples:
    """The samples where ``mask`` (N,) is True."""
    return FaceSamples(*(getattr(samples, k)[mask] for k in (
        "points", "normals", "ru", "rw", "ruu", "ruw", "rww", "faces", "areas")),
        samples.spacing, None if samples.edge is None else samples.edge[mask])


def steep_mask(normals: np.ndarray, threshold_deg: float) -> np.ndarray:
    """(N,) whether the slope acos(N_z) of each normal (N, 3) exceeds the threshold."""
    return normals[:, 2] < math.cos(math.radians(threshold_deg))


def within(cut: CutSegment, keep: np.ndarray) -> list[CutSegment]:
    """The runs of ``cut`` where ``keep`` (N,) holds, each of two points at least."""
    out, k, n = [], 0, len(keep)
    while k < n:
        if not keep[k]:
            k += 1
            continue
        j = k
        while j < n and keep[j]:
            j += 1
        if j - k >= 2:
            if k == 0 and j == n:
                out.append(cut)
            else:
                p = cut.path
                part = replace(p, points=p.points[k:j], contacts=p.contacts[k:j],
                               normals=p.normals[k:j], uv=p.uv[k:j],
                               steps=np.r_[0.0, p.steps[k + 1:j]],
                               commanded=np.r_[0.0, p.commanded[k + 1:j]], bounds=None)
                out.append(CutSegment(part, at_limit=True))
        k = j
    return out


def region_cuts(cuts, steep: bool, threshold: float, overlap: float,
                other: np.ndarray) -> list[CutSegment]:
    """The parts of ``cuts`` in the steep (or shallow) region, grown by ``overlap`` mm
    towards ``other`` (K, 3), the contacts of the other region's samples."""
    tree = cKDTree(other) if overlap > 0 and len(other) else None
    out = []
    for cut in cuts:
        n = cut.path.normals[:, 0]
        keep = steep_mask(n, threshold) == steep
        if tree is not None:
            keep |= tree.query(cut.path.contacts[:, 0], distance_upper_bound=overlap)[0] \
                <= overlap
        out += within(cut, keep)
    return out


def merged(a: UncutReport, b: UncutReport) -> UncutReport:
    """One report of two sample sets' reports (the union)."""
    out = replace(a, max_scallop=max(a.max_scallop, b.max_scallop),
                  max_leftover=max(a.max_leftover, b.max_leftover), area=a.area + b.area,
                  over_limit_area=a.over_limit_area + b.over_limit_area,
                  n_samples=a.n_samples + b.n_samples, unmachined=dict(a.unmachined))
    for key, area in b.unmachined.items():
        out.unmachined[key] = out.unmachined.get(key, 0.0) + area
    return out


def steep_shallow_program(part: Part, job: Job, *, progress: Progress | None = None,
                          max_planes: int = MAX_PLANES, clock=time.monotonic,
                          work: dict | None = None) -> Program:
    """The program of a :class:`~cadcnc.core.job.SteepShallow` ``job`` on ``part`` (the
    module doc)."""
    op = job.operation
    for n in op.faces:
        part.face(n)  # FaceNumberError names the range
    work = {} if work is None else work
    samples = waterline_samples(part, job, work)
    steep = steep_mask(samples.normals, op.threshold)
    high, low = subset(samples, steep), subset(samples, ~steep)
    contacts = samples.points + job.tool.allowance * samples.normals
    cuts, skipped, notes, reports = [], [], [], []
    if len(high):
        wl = waterline_cuts(part, job, high, progress=progress, max_levels=max_planes,
                            clock=clock, work=work)
        cuts += region_cuts(wl.cuts, True, op.threshold, op.overlap, contacts[~steep])
        skipped += wl.skipped
        notes += wl.plan.moved
        reports.append((high, wl.plan))
    if len(low):
        rjob = replace(job, operation=op.raster())
        ras = raster_program(part, rjob, progress=progress, max_planes=max_planes,
                             clock=clock)
        cuts += region_cuts(ras.cuts, False, op.threshold, op.overlap, contacts[steep])
        skipped += [s for s in ras.skipped if s.reason in ("failed", "stopped short",
                                                           "collision")]
        plan = plan_planes(low, job.tool.radius, job.tool.allowance, op.angle,
                           stepover=op.stepover, scallop=op.scallop, max_planes=max_planes)
        reports.append((low, plan))
    program = entered_program(part, job, cuts, skipped)
    measured = [uncut_report(program, part, s, p) for s, p in reports]
    report = measured[0] if len(measured) == 1 else merged(*measured)
    program.skipped += report.skipped()
    program.notes += notes + report.notes()
    return program
