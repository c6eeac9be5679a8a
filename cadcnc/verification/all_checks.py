""":func:`verify`: every check of a toolpath against OCCT, with timings.

The stages, in order: each face of the pair against its offset (:mod:`.surface_checks`),
the path against OCCT's intersection of the offset surfaces (:mod:`.reference`), the
ball against every face of the part (:mod:`.whole_part`), then the step lengths, the
theory and the stop (:mod:`.path_checks`). The gate (:mod:`.gate`) runs only the first
and the third. Lengths in mm, times in s.
"""

from __future__ import annotations

import time

import numpy as np

from ..core.errors import require
from ..core.tolerances import Tolerances
from ..program.toolpath import Toolpath
from .check_records import WholePartCheck
from .path_checks import check_feed, check_stop, check_theory, followed_edge, intended_span
from .probe import offset_surface, shape_distances
from .reference import check_reference
from .report import VerificationReport
from .surface_checks import SAMPLE_UNSEEDED, check_pair, prepare
from .whole_part import check_whole_part

COVER_RADIUS_STEPS = 0.6  # a centre covers the reference within 0.6 f_max of it


def verify(toolpath, part=None, *, tol: Tolerances | None = None,
           sample_unseeded: int = SAMPLE_UNSEEDED, reference_spacing_mm: float = 0.01,
           whole_part: bool = True, progress=None) -> VerificationReport:
    """Check ``toolpath`` against OCCT; see the package docstring and docs/notes/validation.md.

    ``part``: the :class:`~cadcnc.geometry.part.Part` the path was computed on (default:
    the STEP file named by ``toolpath.job.source``). ``tol``: the thresholds (default the
    job's tolerances): ``hit`` (whole-part hits), ``gouge`` (the default limit of
    ``report.ok()``), ``noise``, ``off_face``, ``classify``, ``classify_loose``,
    ``closed``, and the verdict's ``accuracy``, ``hausdorff``, ``coverage``.
    ``sample_unseeded``: how many cycles per face are re-projected without seeds.
    ``reference_spacing_mm``: sample spacing of OCCT's intersection curve.
    ``whole_part``: False skips the ball against the other faces (and along the moves).
    ``progress(done, total, stage)`` is called as stages advance ("surfaces", "reference",
    "whole part").
    """
    require("toolpath", toolpath, Toolpath, "a cadcnc Toolpath")
    tol = toolpath.job.tolerances if tol is None else tol
    part, probes = prepare(toolpath, part, tol)
    timer = {}
    t0 = time.perf_counter()
    surfaces = check_pair(toolpath, probes, tol, sample_unseeded, progress)
    timer["surfaces"] = time.perf_counter() - t0
    tool, faces, offsets = toolpath.job.tool, toolpath.faces, toolpath.offsets
    edge = followed_edge(toolpath, part)
    span, target = intended_span(toolpath, edge)
    f_max = float(np.max(toolpath.commanded[1:])) if len(toolpath) > 1 else 1.0
    t1 = time.perf_counter()
    if progress:
        progress(0, 1, "reference")
    ref = check_reference(
        *(offset_surface(probes[n], off) for n, off in zip(faces, offsets)),
        toolpath.points, span=span, target=target, cover_radius=COVER_RADIUS_STEPS * f_max,
        spacing=reference_spacing_mm,
        residual_probes=[(probes[n], off) for n, off in zip(faces, offsets)], tol=tol)
    timer["reference"] = time.perf_counter() - t1
    edge_dev = None
    if edge is not None and max(offsets) == 0.0:
        edge_dev = float(np.nanmax(shape_distances(edge.edge, toolpath.points)))
    t2 = time.perf_counter()
    whole, sweep = (check_whole_part(part, probes, toolpath, surfaces, tool.offset, tol,
                                     progress)
                    if whole_part else (WholePartCheck(ball_radius_mm=tool.offset,
                                                       hit_tolerance_mm=tol.hit), None))
    timer["whole_part"] = time.perf_counter() - t2
    timer["total"] = time.perf_counter() - t0
    return VerificationReport(
        faces=tuple(faces), n_points=len(toolpath), radius=tool.radius,
        ball_radius=tool.offset, offsets=tuple(offsets), stop_reason=toolpath.stop_reason,
        stop_detail=toolpath.stop_detail, surfaces=surfaces, reference=ref,
        feed=check_feed(toolpath, tol), theory=check_theory(toolpath, surfaces, tol),
        whole_part=whole, stop=check_stop(toolpath, probes, ref, span, f_max, tol),
        edge_deviation_mm=edge_dev, seconds=timer, tolerances=tol, sweep=sweep)
