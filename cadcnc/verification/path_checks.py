"""Checks of the path as a whole: step lengths, theory against measurement, the stop.

Everything is read from the toolpath's :class:`~cadcnc.core.job.Job` (period, end point, edge)
and its per-cycle arrays. Lengths in mm, feeds in mm/min.
"""

from __future__ import annotations

import numpy as np

from ..core.tolerances import Tolerances
from ..core.trim_labels import INSIDE
from ..geometry.part import CONCAVE
from .check_records import (
    BOUND_NAMES,
    FeedCheck,
    ReferenceCheck,
    StopCheck,
    SurfaceCheck,
    TheoryRow,
)
from .probe import FaceProbe

SHORTENED_LAST_STEP = ("end", "closed", "boundary")  # stop reasons that may land short


def check_feed(toolpath, tol: Tolerances) -> FeedCheck:
    """Measured step lengths against the commanded f_k (a shortened last step excluded)."""
    pts = toolpath.points
    if len(pts) < 2:
        return FeedCheck()
    measured = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    commanded = np.asarray(toolpath.commanded[1:], float)
    rel = np.abs(measured - commanded) / commanded
    excluded = bool(toolpath.stop_reason in SHORTENED_LAST_STEP
                    and measured[-1] < commanded[-1])
    body = rel[:-1] if excluded else rel
    worst = int(np.argmax(body)) + 1 if len(body) else -1
    period = toolpath.job.period
    return FeedCheck(
        max_rel_error=float(body.max()) if len(body) else 0.0, worst_cycle=worst,
        worst_step_mm=float(measured[worst - 1]) if worst > 0 else np.nan,
        worst_commanded_mm=float(commanded[worst - 1]) if worst > 0 else np.nan,
        excluded_last=excluded, last_step_mm=float(measured[-1]),
        recorded_vs_measured_mm=float(np.abs(measured - toolpath.steps[1:]).max()),
        commanded_min_mm=float(commanded.min()), commanded_max_mm=float(commanded.max()),
        feed_profile=bool(commanded.max() - commanded.min() > tol.noise),
        feed_min_mm_min=float(commanded.min() / period * 60.0),
        feed_max_mm_min=float(commanded.max() / period * 60.0))


def check_theory(toolpath, surfaces: list[SurfaceCheck], tol: Tolerances) -> list[TheoryRow]:
    """Measured per-cycle deviation of point k+1 against the bounds of the step leaving k.

    Deviations within ``tol.noise`` of a bound are round-off, not an excess.
    """
    out = []
    for side, s in enumerate(surfaces):
        b = None if toolpath.bounds is None else toolpath.bounds[side]
        over = np.maximum(-s.deviation[1:], 0.0)
        absdev = np.abs(s.deviation[1:])
        row = TheoryRow(face=s.face, measured_overcut_mm=float(over.max(initial=0.0)),
                        measured_abs_mm=float(absdev.max(initial=0.0)))
        if b is not None and len(over):
            for name in BOUND_NAMES:
                bound = np.asarray(getattr(b, name), float)[:-1]
                setattr(row, f"{name}_max_mm", float(np.nanmax(bound)))
                setattr(row, f"{name}_exceeded_overcut", int((over > bound + tol.noise).sum()))
                setattr(row, f"{name}_exceeded_abs", int((absdev > bound + tol.noise).sum()))
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = np.where(absdev > tol.noise, absdev / b.eq16[:-1], 0.0)
            row.worst_ratio_to_eq16 = float(np.nanmax(ratio))
            row.worst_ratio_cycle = int(np.nanargmax(ratio)) + 1
        out.append(row)
    return out


def followed_edge(toolpath, part):
    """The shared concave edge the path follows by default (no start point), or None."""
    op = toolpath.job.operation
    if op.start is not None:
        return None
    concave = [e for e in part.shared_edges(*toolpath.faces) if e.edge_class == CONCAVE]
    k = op.edge or 0  # None (every edge) in a program: its first edge
    return concave[k] if k < len(concave) else None


def intended_span(toolpath, edge) -> tuple[str, np.ndarray | None]:
    """How far the path was meant to go: ("closed"|"end"|"target", target point)."""
    if toolpath.stop_reason == "closed":
        return "closed", None
    if toolpath.stop_reason == "end":
        return "end", None
    end = toolpath.job.operation.end
    if end is not None:
        return "target", np.asarray(end, float)
    if edge is not None:
        return ("closed", None) if edge.closed else ("target", np.asarray(edge.end, float))
    return "end", None


def check_stop(toolpath, probes: dict[int, FaceProbe], ref: ReferenceCheck, span: str,
               f_max: float, tol: Tolerances) -> StopCheck:
    """Where the last contacts lie (loose classifier), and whether that matches the stop."""
    last = toolpath.points[-1]
    states = []
    for side, n in enumerate(toolpath.faces):
        probe = probes[n]
        res = probe.project_seeded(last, *toolpath.uv[-1, side]) or probe.project_global(last)
        states.append(probe.state(*res[:2], loose=True))
    reason = toolpath.stop_reason
    tail = ref.gaps[-1] if ref.gaps else None
    remaining = (ref.span_mm - tail[0]) if tail and tail[1] >= ref.span_mm - tol.closed else 0.0
    consistent = None
    if reason == "boundary":
        consistent = any(s != INSIDE for s in states)
    elif reason == "closed":
        consistent = bool(np.linalg.norm(last - toolpath.points[0]) <= f_max)
    elif reason == "end":
        consistent = True
    return StopCheck(reason=reason, last_contact_states=states, span=span,
                     remaining_mm=float(remaining), consistent=consistent,
                     left_face=[n for n, s in zip(toolpath.faces, states) if s != INSIDE])
